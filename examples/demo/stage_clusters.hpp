#pragma once
// Demo stage: feature-based clustering of every scene object (clustering paper §3, Algorithm 1:
// visibility → orientation → stretch), with a progress bar for the visibility rays, written as
// DIR/clusters.png (the scene from the camera, each cluster a distinct colour).
//   bool stage_clusters(const demo_context& ctx, support::scene_clustering& out);
// out receives scene-wide cluster ids (per object, per triangle) for the upsampler stage.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>
#include <glm/vec3.hpp>
#include "demo.hpp"
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "support/demo_upsample.hpp"
#include "support/procedural.hpp"

namespace infolerp::demo {

// Distinct colour of cluster k: golden-ratio hue steps, three brightness levels.
inline glm::vec3 cluster_colour(std::uint32_t k) {
  const double h = std::fmod(0.618033988749895 * k, 1.0) * 6.0;
  const double v = (k % 3 == 0) ? 0.95 : (k % 3 == 1) ? 0.8 : 0.62, s = 0.75;
  const double c = v * s, x = c * (1.0 - std::abs(std::fmod(h, 2.0) - 1.0)), mn = v - c;
  const glm::dvec3 rgb = h < 1 ? glm::dvec3(c, x, 0) : h < 2 ? glm::dvec3(x, c, 0) : h < 3 ? glm::dvec3(0, c, x)
                       : h < 4 ? glm::dvec3(0, x, c) : h < 5 ? glm::dvec3(x, 0, c) : glm::dvec3(c, 0, x);
  return glm::vec3(rgb + mn);
}

// Clusters one mesh with any tracer; returns the clustering (ids per triangle).
template <class Tracer, class Exec>
result<mesh_clustering> cluster_object(const indexed_mesh& mesh, const Tracer& tracer, Exec&& exec, const std::string& label) {
  progress_bar bar("visibility " + label);
  return cluster_mesh(mesh, tracer, exec, cluster_options{},
                      visibility_channel{.threshold = 0.48, .viewpoints = 64,
                                         .progress = [&](std::size_t done, std::size_t total) {
                                           bar(static_cast<int>(done), static_cast<int>(total));
                                         }},
                      orientation_channel{.threshold = 0.05, .bins = 256}, stretch_channel{.threshold = 0.1, .bins = 256});
}

inline bool stage_clusters(const demo_context& ctx, support::scene_clustering& out) {
  out = {"feature", {}, {}};
  std::uint32_t offset = 0;
  for (std::uint32_t g = 0; g < ctx.scene.objects.size(); ++g) {
    const auto& object = ctx.scene.objects[g];
    std::vector<std::uint32_t> remap;
    const indexed_mesh welded = support::weld_positions(object.mesh, remap);  // seams joined; same triangles
#ifdef _OPENMP
    auto r = cluster_object(welded, ctx.scene.tracer, openmp_executor{ctx.options.threads}, object.name);
#else
    auto r = cluster_object(welded, ctx.scene.tracer, serial_executor{}, object.name);
#endif
    if (!r) {
      report(r.error());
      return false;
    }
    std::printf("clusters %s: %u (", object.name.c_str(), r->cluster_count);
    for (std::size_t i = 0; i < r->channels.size(); ++i)
      std::printf(i ? ", %u" : "%u", r->channels[i].clusters_after);
    std::printf(" after each channel)%s\n", r->channels[2].skipped ? ", stretch skipped: no texcoords" : "");
    for (auto& k : r->cluster_of) k += offset;
    offset += r->cluster_count;
    out.ids.push_back(std::move(r->cluster_of));
    out.geometry_of.insert(out.geometry_of.end(), r->cluster_count, g);
  }
  const auto img = render_false_colour(
      ctx, [&](std::uint32_t g, std::uint32_t t, glm::vec2) { return cluster_colour(out.ids[g][t]); });
  return save_png(ctx, img, "clusters.png");
}

}  // namespace infolerp::demo
