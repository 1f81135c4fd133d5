#pragma once
// Demo stage: feature-based clustering of every scene object (clustering paper §3, Algorithm 1:
// visibility → orientation → stretch), written as DIR/clusters.png (the scene from the camera,
// each cluster a distinct colour). Prints each channel's time per object and in all, and the
// visibility rays' progress.
//   bool stage_clusters(demo_context& ctx, support::scene_clustering& out);
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

inline bool stage_clusters(demo_context& ctx, support::scene_clustering& out) {
  static constexpr const char* channel_names[3] = {"visibility", "orientation", "stretch"};
  // Progress: the visibility rays, the channel that grows with the mesh (the others run as
  // thousands of small parallel loops, too short to show).
  std::map<std::string, progress_line> lines;
  const auto progress = [&](const std::string& label, std::size_t done, std::size_t total) {
    lines.try_emplace(label, "clusters " + label + ": visibility rays").first->second(done, total);
  };
  double channel_seconds[3] = {0.0, 0.0, 0.0};  // summed over the objects
  const auto on_object = [&](const std::string& name, const mesh_clustering& r) {
    if (const auto it = lines.find(name); it != lines.end()) it->second.finish();  // stdout after the open line
    std::printf("clusters %s: %u (", name.c_str(), r.cluster_count);
    for (std::size_t i = 0; i < r.channels.size(); ++i) std::printf(i ? ", %u" : "%u", r.channels[i].clusters_after);
    std::printf(" after each channel; ");
    for (std::size_t i = 0; i < r.channels.size() && i < 3; ++i) {
      const channel_report& c = r.channels[i];
      const double seconds = c.prepare_seconds + c.init_seconds + c.growth_seconds + c.smoothing_seconds;
      channel_seconds[i] += seconds;
      std::printf(i ? ", %.3f" : "%.3f", seconds);
    }
    std::printf(" s)%s\n", r.channels[2].skipped ? ", stretch skipped: no texcoords" : "");
  };
  const stopwatch watch;
  auto r = support::cluster_by_features(ctx.scene, make_executor(ctx.options), ctx.options.thresholds, progress, on_object);
  lines.clear();
  double rest = watch.seconds();
  for (int i = 0; i < 3; ++i) {
    record_time(ctx, std::string("clustering: ") + channel_names[i] + " channel", channel_seconds[i]);
    rest -= channel_seconds[i];
  }
  record_time(ctx, "clustering: welding, topology, ids", rest);
  if (!r) {
    report(r.error());
    return false;
  }
  out = std::move(*r);
  const stopwatch image_watch;
  const auto img = render_false_colour(
      ctx, [&](std::uint32_t g, std::uint32_t t, glm::vec2) { return cluster_colour(out.ids[g][t]); });
  const bool saved = save_png(ctx, img, "clusters.png");
  record_time(ctx, "clusters.png", image_watch.seconds());
  return saved;
}

}  // namespace infolerp::demo
