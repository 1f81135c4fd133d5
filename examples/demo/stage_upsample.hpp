#pragma once
// Demo stage: the demo scene rendered with the I-Buffer upsampler (paper §4), compared with the
// per-pixel reference of the first stage. Writes
//   DIR/ibuffer.png   the upsampled image
//   DIR/rie.png       the last pass's samples: re-used (blue), interpolated (green), evaluated (red)
//   DIR/error.png     heat map of |ibuffer − reference| on the displayed 8-bit values
//                     (black 0, blue → green → yellow → red at 32/255 and above)
// and prints R/I/E counts per pass, the speed-up over the reference and the PSNR.
//
//   bool stage_upsample(demo_context& ctx, const support::scene_clustering* clusters = nullptr,
//                       std::uint32_t passes = 4);
// Preconditions: ctx.reference holds the reference render (stage 1). clusters: per-triangle
// cluster ids of the scene (e.g. from include/infolerp/cluster); nullptr uses the stand-in
// cluster_by_normal(scene, 2) of tests/support/demo_upsample.hpp. Returns false on error.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <span>
#include <glm/common.hpp>
#include "demo.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "support/demo_upsample.hpp"

namespace infolerp::demo {

inline bool stage_upsample(demo_context& ctx, const support::scene_clustering* clusters = nullptr,
                           std::uint32_t passes = 4) {
  const auto& o = ctx.options;
  support::scene_clustering fallback;
  if (clusters == nullptr) {
    fallback = support::cluster_by_normal(ctx.scene, 2);
    clusters = &fallback;
  }
  const auto w = static_cast<std::uint32_t>(o.width), h = static_cast<std::uint32_t>(o.height);
  auto up = upsampler<support::demo_sample>::create(w, h, {.passes = passes, .max_passes = std::max(passes, 4u)});
  if (!up) {
    report(up.error());
    return false;
  }
  const support::demo_ibuffer_source src{&ctx.shader, clusters, o.width, o.height};
  support::image img(o.width, o.height);
  const auto t0 = std::chrono::steady_clock::now();
#ifdef _OPENMP
  const openmp_executor exec{o.threads};
#else
  const serial_executor exec{};
#endif
  if (auto s = up->render(src, std::span<glm::vec3>(img.pixels), exec); !s) {
    report(s);
    return false;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const auto& st = up->stats();
  std::printf("upsample: %u passes, %zu clusters (%s)\n", st.passes, clusters->count(), clusters->name.c_str());
  for (std::uint32_t p = 0; p < st.passes; ++p)
    std::printf("  pass %u: %ux%u  R %zu  I %zu  E %zu  %.3f s\n", p + 1, st.pass[p].width, st.pass[p].height,
                st.pass[p].reused, st.pass[p].interpolated, st.pass[p].evaluated, st.pass[p].seconds);
  const auto psnr = support::psnr(ctx.reference, img);
  std::printf("upsample: %.3f s, speed-up %.2fx over the reference (%.3f s), evaluated %.2f%% of pixels, PSNR %.2f dB\n",
              seconds, ctx.reference_stats.seconds / seconds, ctx.reference_stats.seconds,
              100.0 * st.evaluated_fraction(), psnr ? *psnr : 0.0);

  // R/I/E of the last pass in three colours.
  support::image rie(o.width, o.height);
  const glm::vec3 colours[3] = {{0.9f, 0.1f, 0.1f}, {0.1f, 0.7f, 0.2f}, {0.1f, 0.2f, 0.9f}};  // E, I, R
  const auto kinds = up->kinds();
  for (std::size_t i = 0; i < kinds.size(); ++i) rie.pixels[i] = colours[static_cast<int>(kinds[i])];

  // Heat map of the displayed difference.
  support::image err(o.width, o.height);
  for (std::size_t i = 0; i < img.pixels.size(); ++i) {
    float d = 0.0f;
    for (int c = 0; c < 3; ++c)
      d = std::max(d, std::abs(static_cast<float>(support::to_srgb8(img.pixels[i][c])) -
                               static_cast<float>(support::to_srgb8(ctx.reference.pixels[i][c]))));
    const float t = std::min(d / 32.0f, 1.0f);  // 0 .. 1
    glm::vec3 heat = t < 1.0f / 3.0f   ? glm::mix(glm::vec3(0, 0, 1), glm::vec3(0, 1, 0), 3.0f * t)
                     : t < 2.0f / 3.0f ? glm::mix(glm::vec3(0, 1, 0), glm::vec3(1, 1, 0), 3.0f * t - 1.0f)
                                       : glm::mix(glm::vec3(1, 1, 0), glm::vec3(1, 0, 0), 3.0f * t - 2.0f);
    if (d == 0.0f) heat = glm::vec3(0.0f);
    err.pixels[i] = heat;
  }
  return save_png(ctx, img, "ibuffer.png") && save_png(ctx, rie, "rie.png") && save_png(ctx, err, "error.png");
}

}  // namespace infolerp::demo
