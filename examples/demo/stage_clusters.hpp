#pragma once
// Demo stage: feature-based clustering of every scene object (clustering paper §3, Algorithm 1:
// visibility → orientation → stretch), with a progress bar for the visibility rays, written as
// DIR/clusters.png (the scene from the camera, each cluster a distinct colour).
//   bool stage_clusters(const demo_context& ctx, support::scene_clustering& out);
// out receives scene-wide cluster ids (per object, per triangle) for the upsampler stage; the
// clustering itself is support::cluster_by_features (tests/support/demo_clusters.hpp), which the
// time-against-error harness uses too.
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>
#include <glm/vec3.hpp>
#include "demo.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "support/demo_upsample.hpp"
#include "support/demo_clusters.hpp"

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

inline bool stage_clusters(const demo_context& ctx, support::scene_clustering& out) {
  std::map<std::string, progress_bar> bars;
  const auto progress = [&](const std::string& label, std::size_t done, std::size_t total) {
    bars.try_emplace(label, "visibility " + label).first->second(static_cast<int>(done), static_cast<int>(total));
  };
  const auto on_object = [](const std::string& name, const mesh_clustering& r) {
    std::printf("clusters %s: %u (", name.c_str(), r.cluster_count);
    for (std::size_t i = 0; i < r.channels.size(); ++i) std::printf(i ? ", %u" : "%u", r.channels[i].clusters_after);
    std::printf(" after each channel)%s\n", r.channels[2].skipped ? ", stretch skipped: no texcoords" : "");
  };
#ifdef _OPENMP
  auto r = support::cluster_by_features(ctx.scene, openmp_executor{ctx.options.threads}, ctx.options.thresholds, progress, on_object);
#else
  auto r = support::cluster_by_features(ctx.scene, serial_executor{}, ctx.options.thresholds, progress, on_object);
#endif
  if (!r) {
    report(r.error());
    return false;
  }
  out = std::move(*r);
  const auto img = render_false_colour(
      ctx, [&](std::uint32_t g, std::uint32_t t, glm::vec2) { return cluster_colour(out.ids[g][t]); });
  return save_png(ctx, img, "clusters.png");
}

}  // namespace infolerp::demo
