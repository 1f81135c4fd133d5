#pragma once
// Demo stage: the demo scene rendered with the I-Buffer upsampler (paper §4), compared with the
// per-pixel reference of the first stage.
//   - the trade-off runs: one frame at each of 2..5 passes (method "ibuffer-K"; one pass is
//     plain per-pixel evaluation, i.e. the reference), and at 3..5 passes with probes (method
//     "ibuffer-probe-K": a primary ray per pixel, the sun ray where needed, AO and soft shadow
//     interpolated), and at 3..5 passes with those probes only where a new sample's sources
//     differ (method "ibuffer-sparse-K"), each added to ctx.results;
//   - the shown frame, at --passes K, or with --passes auto under the pass controller (§4.2,
//     include/infolerp/upsample/pass_controller.hpp, default frame-time bounds 1/60..1/30 s,
//     at most 4 passes): the reference render counts as its first, one-pass frame, then frames
//     are rendered until the controller keeps the pass count it just rendered (at most 12).
// Writes
//   DIR/ibuffer.png   the shown frame
//   DIR/rie.png       its last pass's samples: re-used (blue), interpolated (green), evaluated (red)
//   DIR/error.png     heat map of |ibuffer − reference| on the displayed 8-bit values
//                     (black 0, blue → green → yellow → red at 32/255 and above)
// and prints R/I/E counts per pass of the shown frame.
//
//   bool stage_upsample(demo_context& ctx, const support::scene_clustering* clusters = nullptr);
// Preconditions: ctx.reference holds the reference render (stage 1). clusters: per-triangle
// cluster ids of the scene (e.g. from include/infolerp/cluster); nullptr uses the stand-in
// cluster_by_normal(scene, 2) of tests/support/demo_upsample.hpp. Either is cut at texture seams
// (support::split_at_texture_seams) for the I-Buffer. Returns false on error.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <glm/common.hpp>
#include "demo.hpp"
#include "infolerp/upsample/pass_controller.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "support/demo_clusters.hpp"
#include "support/demo_upsample.hpp"

namespace infolerp::demo {

namespace detail {

inline support::image error_heat_map(const support::image& img, const support::image& reference) {
  support::image err(img.width, img.height);
  for (std::size_t i = 0; i < img.pixels.size(); ++i) {
    float d = 0.0f;
    for (int c = 0; c < 3; ++c)
      d = std::max(d, std::abs(static_cast<float>(support::to_srgb8(img.pixels[i][c])) -
                               static_cast<float>(support::to_srgb8(reference.pixels[i][c]))));
    const float t = std::min(d / 32.0f, 1.0f);  // 0 .. 1
    glm::vec3 heat = t < 1.0f / 3.0f   ? glm::mix(glm::vec3(0, 0, 1), glm::vec3(0, 1, 0), 3.0f * t)
                     : t < 2.0f / 3.0f ? glm::mix(glm::vec3(0, 1, 0), glm::vec3(1, 1, 0), 3.0f * t - 1.0f)
                                       : glm::mix(glm::vec3(1, 1, 0), glm::vec3(1, 0, 0), 3.0f * t - 2.0f);
    if (d == 0.0f) heat = glm::vec3(0.0f);
    err.pixels[i] = heat;
  }
  return err;
}

}  // namespace detail

inline bool stage_upsample(demo_context& ctx, const support::scene_clustering* clusters = nullptr) {
  const stopwatch watch;
  double frames = 0.0;  // the rows' frame times, recorded one by one
  const auto& o = ctx.options;
  // The I-Buffer's ids: the clusters cut at texture seams (texcoords are interpolated within an id).
  const auto split =
      support::split_at_texture_seams(ctx.scene, clusters != nullptr ? *clusters : support::cluster_by_normal(ctx.scene, 2));
  if (!split) {
    report(split.error());
    return false;
  }
  const support::scene_clustering& ids = *split;
  clusters = &ids;
  constexpr std::uint32_t tradeoff_first = 2, tradeoff_last = 5, auto_max_passes = 4, probe_first = 3, probe_min_sources = 1;
  const auto w = static_cast<std::uint32_t>(o.width), h = static_cast<std::uint32_t>(o.height);
  auto up = upsampler<support::demo_sample>::create(
      w, h, {.passes = 1, .max_passes = std::max({o.passes, tradeoff_last, auto_max_passes})});
  if (!up) {
    report(up.error());
    return false;
  }
  // The library's ready source (upsample/ray_cast_source.hpp) with the reference shader's
  // rays and shade() as its material.
  auto ready = support::make_demo_ray_cast_source(ctx.shader, *clusters, o.width, o.height);
  if (!ready) {
    report(ready.error());
    return false;
  }
  const auto& src = *ready;
  const stage_executor exec = make_executor(o);
  support::image img(o.width, o.height);
  const std::string cluster_note = clusters->name + ", " + std::to_string(clusters->count()) + " clusters";
  auto render = [&](std::uint32_t passes) {
    if (auto s = up->set_passes(passes); !s) return s;
    return up->render(src, std::span<glm::vec3>(img.pixels), exec);
  };
  auto record = [&](const std::string& method, const std::string& setting) {
    const auto& r = add_result(ctx, method, setting, up->stats().seconds, up->stats().evaluated_fraction(), img);
    std::printf("%-12s %6.3f s  x%.2f  PSNR %6.2f dB  evaluated %.2f%% (%s)\n", r.method.c_str(), r.seconds,
                ctx.reference_stats.seconds / r.seconds, r.psnr, 100.0 * r.evaluated, r.setting.c_str());
    record_time(ctx, "I-Buffer row " + r.method, r.seconds);
    frames += r.seconds;
  };

  // The trade-off runs; the shown frame's pass count is rendered last (below) so that its image
  // and R/I/E kinds stay in the upsampler.
  for (std::uint32_t p = tradeoff_first; p <= tradeoff_last; ++p) {
    if (p == o.passes) continue;
    if (auto s = render(p); !s) {
      report(s);
      return false;
    }
    record("ibuffer-" + std::to_string(p), std::to_string(p) + " passes, " + cluster_note);
  }

  // The trade-off runs with refined probes (sample_source.hpp): a primary ray at every pixel,
  // the sun ray only where the sources of the pixel's own cluster cannot vouch for its
  // hard-shadow bit, AO and soft shadow interpolated from those sources.
  {
    auto refining = support::make_demo_ray_cast_source<probe_mode::refine>(ctx.shader, *clusters, o.width, o.height);
    if (!refining) {
      report(refining.error());
      return false;
    }
    const auto& psrc = *refining;
    auto pu = upsampler<support::demo_sample>::create(
        w, h, {.passes = probe_first, .max_passes = tradeoff_last, .record_kinds = false, .min_sources = probe_min_sources});
    if (!pu) {
      report(pu.error());
      return false;
    }
    // The same probes taken only where a new sample's sources differ (probe_every_sample off):
    // a primary ray per boundary sample instead of per pixel ("ibuffer-sparse-K").
    auto su = upsampler<support::demo_sample>::create(w, h, {.passes = probe_first, .max_passes = tradeoff_last,
                                                             .record_kinds = false, .min_sources = probe_min_sources,
                                                             .probe_every_sample = false});
    if (!su) {
      report(su.error());
      return false;
    }
    for (auto* u : {&*pu, &*su})
      for (std::uint32_t p = probe_first; p <= tradeoff_last; ++p) {
        status s = u->set_passes(p);
        if (s) s = u->render(psrc, std::span<glm::vec3>(img.pixels), exec);
        if (!s) {
          report(s);
          return false;
        }
        const bool every = u->options().probe_every_sample;
        const auto& r = add_result(ctx, (every ? "ibuffer-probe-" : "ibuffer-sparse-") + std::to_string(p),
                                   std::to_string(p) + " passes, refined probes (primary " +
                                       (every ? "per pixel" : "where the sources differ") + ", sun where needed), " + cluster_note,
                                   u->stats().seconds, u->stats().evaluated_fraction(), img);
        std::printf("%-16s %6.3f s  x%.2f  PSNR %6.2f dB  evaluated %.2f%% (%s)\n", r.method.c_str(), r.seconds,
                    ctx.reference_stats.seconds / r.seconds, r.psnr, 100.0 * r.evaluated, r.setting.c_str());
        record_time(ctx, "I-Buffer row " + r.method, r.seconds);
        frames += r.seconds;
      }
  }

  std::string chosen;
  if (o.passes != 0) {
    if (auto s = render(o.passes); !s) {
      report(s);
      return false;
    }
    chosen = "ibuffer-" + std::to_string(o.passes);
    record(chosen, std::to_string(o.passes) + " passes, " + cluster_note);
  } else {
    auto controller = pass_controller::create({.max_passes = auto_max_passes, .settle_frames = 1});
    if (!controller) {
      report(controller.error());
      return false;
    }
    // The reference is a one-pass frame (every pixel evaluated): its time seeds the controller.
    if (auto s = controller->update(ctx.reference_stats.seconds); !s) {
      report(s);
      return false;
    }
    std::printf("auto: frame 1: 1 pass (the reference) %.3f s\n", ctx.reference_stats.seconds);
    std::uint32_t rendered = 0;
    for (int frame = 2; frame <= 12 && controller->passes() != rendered; ++frame) {
      rendered = controller->passes();
      if (auto s = render_controlled(*up, *controller, src, std::span<glm::vec3>(img.pixels), exec); !s) {
        report(s);
        return false;
      }
      std::printf("auto: frame %d: %u pass%s %.3f s\n", frame, rendered, rendered == 1 ? "" : "es", up->stats().seconds);
      frames += up->stats().seconds;
    }
    frames -= up->stats().seconds;  // the last frame is recorded as the row below
    chosen = "ibuffer-auto";
    record(chosen, "pass controller chose " + std::to_string(rendered) + (rendered == 1 ? " pass, " : " passes, ") + cluster_note);
  }

  const auto& st = up->stats();
  std::printf("%s: %u passes\n", chosen.c_str(), st.passes);
  for (std::uint32_t p = 0; p < st.passes; ++p)
    std::printf("  pass %u: %ux%u  R %zu  I %zu  E %zu  %.3f s\n", p + 1, st.pass[p].width, st.pass[p].height,
                st.pass[p].reused, st.pass[p].interpolated, st.pass[p].evaluated, st.pass[p].seconds);

  // R/I/E of the last pass in three colours.
  support::image rie(o.width, o.height);
  const glm::vec3 colours[3] = {{0.9f, 0.1f, 0.1f}, {0.1f, 0.7f, 0.2f}, {0.1f, 0.2f, 0.9f}};  // E, I, R
  const auto kinds = up->kinds();
  for (std::size_t i = 0; i < kinds.size(); ++i) rie.pixels[i] = colours[static_cast<int>(kinds[i])];

  const bool saved = save_png(ctx, img, "ibuffer.png") && save_png(ctx, rie, "rie.png") &&
                     save_png(ctx, detail::error_heat_map(img, ctx.reference), "error.png");
  record_time(ctx, "I-Buffer: ids, sources, PSNR/SSIM, images", watch.seconds() - frames);
  return saved;
}

}  // namespace infolerp::demo
