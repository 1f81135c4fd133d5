#pragma once
// Demo stage: cluster the scene (Algorithm 1: visibility → orientation → stretch) with a
// progress bar on stderr, and colour each triangle by its cluster (distinct hues).
//   auto out = demo::stage_clusters(mesh, tracer);           // any infolerp tracer
//   out->colors[t]  RGB in [0,1] of triangle t;  out->clustering.cluster_of[t]  its cluster id
#include <cmath>
#include <cstdio>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/mesh/adaptors.hpp"

namespace demo {

struct clusters_stage_output {
  infolerp::mesh_clustering clustering;
  std::vector<glm::vec3> colors;  // one per triangle
};

// Distinct colour of cluster k: golden-ratio hue steps, alternating brightness.
inline glm::vec3 cluster_color(std::uint32_t k) {
  const double h = std::fmod(0.618033988749895 * k, 1.0) * 6.0;
  const double v = (k % 3 == 0) ? 0.95 : (k % 3 == 1) ? 0.8 : 0.65, s = 0.75;
  const double c = v * s, x = c * (1.0 - std::abs(std::fmod(h, 2.0) - 1.0)), mn = v - c;
  glm::dvec3 rgb = h < 1 ? glm::dvec3(c, x, 0) : h < 2 ? glm::dvec3(x, c, 0) : h < 3 ? glm::dvec3(0, c, x)
                 : h < 4 ? glm::dvec3(0, x, c) : h < 5 ? glm::dvec3(x, 0, c) : glm::dvec3(c, 0, x);
  return glm::vec3(rgb + mn);
}

template <class Tracer>
infolerp::result<clusters_stage_output> stage_clusters(const infolerp::indexed_mesh& mesh, const Tracer& tracer) {
#ifdef _OPENMP
  infolerp::openmp_executor exec;
#else
  infolerp::serial_executor exec;
#endif
  auto progress = [](std::size_t done, std::size_t total) {
    const int width = 40, filled = total ? static_cast<int>(width * done / total) : width;
    std::fprintf(stderr, "\rvisibility [%.*s%*s] %zu/%zu", filled, "########################################",
                 width - filled, "", done, total);
    if (done == total) std::fprintf(stderr, "\n");
  };
  auto r = infolerp::cluster_mesh(mesh, tracer, exec, infolerp::cluster_options{},
                                  infolerp::visibility_channel{.threshold = 0.48, .viewpoints = 64, .progress = progress},
                                  infolerp::orientation_channel{.threshold = 0.05, .bins = 256},
                                  infolerp::stretch_channel{.threshold = 0.1, .bins = 256});
  if (!r) return r.error();
  clusters_stage_output out{std::move(*r), {}};
  out.colors.reserve(out.clustering.cluster_of.size());
  for (std::uint32_t k : out.clustering.cluster_of) out.colors.push_back(cluster_color(k));
  for (const auto& c : out.clustering.channels)
    if (c.skipped) std::fprintf(stderr, "%s\n", c.skipped);
  std::fprintf(stderr, "clusters: %u\n", out.clustering.cluster_count);
  return out;
}

}  // namespace demo
