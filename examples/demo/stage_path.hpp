#pragma once
// Demo stage: frames along a camera path with reuse across frames (include/infolerp/upsample/
// frame_reuse.hpp). The camera orbits the scene's target a half degree per frame for 24 frames,
// standing still in frames 12-17; every frame is an I-Buffer frame (4 passes, refined probes
// where the sources differ, min 1 source) that reuses the previous frame's AO and soft shadows
// where the reprojected probe passes the §4 test.
// Writes
//   DIR/path.png   every 4th frame side by side at half size, the pixels evaluated fully in that
//                  frame marked red (the first frame evaluates its coarse grid and boundaries;
//                  later ones only disocclusions, failed tests and the refresh share; standing
//                  frames none)
// and prints per frame the time and the evaluated and reused fractions.
//
//   bool stage_path(demo_context& ctx, const support::scene_clustering& clusters);
// clusters: per-triangle cluster ids of the scene (cut at texture seams here). Returns false on error.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <span>
#include <vector>
#include "demo.hpp"
#include "infolerp/upsample/frame_reuse.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "support/demo_clusters.hpp"
#include "support/demo_upsample.hpp"

namespace infolerp::demo {

namespace detail {
// The demo camera orbited by `degrees` about the vertical through its target.
inline support::camera orbited(const support::camera& c, float degrees) {
  const float a = degrees * 3.14159265f / 180.0f;
  const glm::vec3 d = c.eye - c.target;
  support::camera out = c;
  out.eye = c.target + glm::vec3(d.x * std::cos(a) - d.y * std::sin(a), d.x * std::sin(a) + d.y * std::cos(a), d.z);
  return out;
}
}  // namespace detail

inline bool stage_path(demo_context& ctx, const support::scene_clustering& clusters) {
  const stopwatch watch;
  const auto& o = ctx.options;
  const auto split = support::split_at_texture_seams(ctx.scene, clusters);
  if (!split) {
    report(split.error());
    return false;
  }
  const auto w = static_cast<std::uint32_t>(o.width), h = static_cast<std::uint32_t>(o.height);
  auto up = upsampler<support::demo_sample>::create(w, h, {.passes = 4, .max_passes = 4, .record_kinds = false,
                                                           .keep_ibuffer = true, .min_sources = 1,
                                                           .probe_every_sample = false});
  auto reuse = frame_reuse<support::demo_sample>::create(w, h);
  if (!up || !reuse) {
    report(!up ? up.error() : reuse.error());
    return false;
  }
  const stage_executor exec = make_executor(o);
  constexpr int frames = 24, every = 4;
  const int sw = o.width / 2, sh = o.height / 2;
  support::image img(o.width, o.height), strip(sw * (frames / every), sh);
  double seconds = 0.0;
  for (int f = 0; f < frames; ++f) {
    const float degrees = 0.5f * static_cast<float>(f < 12 ? f : f < 18 ? 12 : f - 5);
    const support::camera cam = detail::orbited(ctx.scene.view, degrees);
    const support::pinhole_rays rays = cam.rays();
    auto src = support::make_demo_ray_cast_source<probe_mode::refine>(ctx.shader, *split, o.width, o.height, true,
                                                                      std::numeric_limits<float>::infinity(),
                                                                      ray_cast_options{}.smooth_angle, &rays);
    if (!src) {
      report(src.error());
      return false;
    }
    const stopwatch frame;
    if (auto s = reuse->render(*up, *src, support::pinhole_frame_of(cam, w, h), std::span<glm::vec3>(img.pixels), exec); !s) {
      report(s);
      return false;
    }
    seconds += frame.seconds();
    const auto& st = reuse->stats();
    std::printf("path frame %2d (%.1f deg): %.3f s, evaluated %.3f%%, reused %.3f%%\n", f, static_cast<double>(degrees),
                frame.seconds(), 100.0 * st.evaluated_fraction(), 100.0 * st.reused_fraction());
    if (f % every != 0) continue;
    // Half size: the 2x2 pixels' mean, red where one of them was evaluated.
    const auto marks = reuse->marks();
    const std::size_t panel = static_cast<std::size_t>(f / every);
    for (int y = 0; y < sh; ++y)
      for (int x = 0; x < sw; ++x) {
        glm::vec3 c(0.0f);
        bool evaluated = false;
        for (int k = 0; k < 4; ++k) {
          const std::size_t i = static_cast<std::size_t>(2 * y + k / 2) * w + static_cast<std::size_t>(2 * x + k % 2);
          c += 0.25f * glm::clamp(img.pixels[i], 0.0f, 1.0f);
          evaluated = evaluated || marks[i] >= static_cast<std::uint8_t>(reuse_mark::evaluated);
        }
        strip.pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(strip.width) + panel * static_cast<std::size_t>(sw) +
                     static_cast<std::size_t>(x)] = evaluated ? glm::vec3(1.0f, 0.0f, 0.0f) : c;
      }
  }
  record_time(ctx, "path: 24 frames with reuse", seconds);
  const bool saved = save_png(ctx, strip, "path.png");
  record_time(ctx, "path: sources, strip", watch.seconds() - seconds);
  return saved;
}

}  // namespace infolerp::demo
