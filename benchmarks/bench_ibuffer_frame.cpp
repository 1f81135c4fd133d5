// A whole I-Buffer frame as an engine renders it: the library's ready source
// (upsample/ray_cast_source.hpp) with refined probes on the demo scene (1025², 64 AO rays, 16
// soft-shadow rays, the sun, feature clusters cut at texture seams, 2 threads), against
// per-pixel evaluation with the same source, which is also the reference image, tracing its
// rays one at a time (per_pixel_ms) and with Embree's 16-ray packets (per_pixel_packets_ms: the
// source's batch_rays, the fastest per-pixel rays we have). Each iteration renders one frame of
// each of the three, rotating which goes first, so they share the machine's load; counters:
// per_pixel_ms, per_pixel_packets_ms, ibuffer_ms, speedup and speedup_packets (per-pixel time
// over the I-Buffer's), psnr_db of the I-Buffer frame (display values) and its evaluated fraction,
// packets_psnr_db of the packets' per-pixel frame against the single rays' (99 when identical).
// Args: passes, and probes per pixel (1, the default options) or only where sources differ (0).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>
#include "infolerp/core/executor.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "support/demo_clusters.hpp"
#include "support/demo_upsample.hpp"
#include "support/image.hpp"

namespace {

namespace sup = infolerp::support;

constexpr int size = 1025;

// The scene, its clusters, the shader and the ready source, built once for every benchmark.
struct frame_fixture {
  sup::embree_device device;
  std::optional<sup::demo_scene> scene;
  std::optional<sup::scene_clustering> clusters;
  std::optional<sup::reference_shader> shader, packet_shader;
  std::optional<sup::demo_ray_cast_source<infolerp::probe_mode::refine>> source, packet_source;
  std::string error;

  frame_fixture() {
    auto s = sup::make_demo_scene(device);
    if (!s) {
      error = s.error().message();
      return;
    }
    scene.emplace(std::move(*s));
    auto features = sup::cluster_by_features(*scene, infolerp::openmp_executor{});
    auto split = features ? sup::split_at_texture_seams(*scene, *features) : features;
    if (!split) {
      error = split.error().message();
      return;
    }
    clusters.emplace(std::move(*split));
    sup::shader_options so;
    so.pixel_angle = sup::pixel_angle(scene->view, size);
    shader.emplace(*scene, so);
    so.packets = true;
    packet_shader.emplace(*scene, so);
    auto src = sup::make_demo_ray_cast_source<infolerp::probe_mode::refine>(*shader, *clusters, size, size);
    auto packets = sup::make_demo_ray_cast_source<infolerp::probe_mode::refine>(*packet_shader, *clusters, size, size);
    if (!src || !packets) {
      error = (src ? packets : src).error().message();
      return;
    }
    source.emplace(std::move(*src));
    packet_source.emplace(std::move(*packets));
  }
};

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void BM_IBufferFrame_vs_PerPixel(benchmark::State& state) {
  static const frame_fixture fx;
  if (!fx.error.empty()) {
    state.SkipWithError(fx.error.c_str());
    return;
  }
  const auto passes = static_cast<std::uint32_t>(state.range(0));
  auto up = infolerp::upsampler<sup::demo_sample>::create(
      size, size, {.passes = passes, .max_passes = passes, .record_kinds = false, .min_sources = 1,
                   .probe_every_sample = state.range(1) != 0});
  if (!up) {
    state.SkipWithError(up.error().message().c_str());
    return;
  }
  const auto& src = *fx.source;
  const infolerp::openmp_executor exec{};
  sup::image reference(size, size), packet_reference(size, size), frame(size, size);
  const auto per_pixel = [&](const auto& source, sup::image& out) {
    exec.parallel_for(size, 1, [&](std::size_t begin, std::size_t end) {
      sup::enable_flush_to_zero();
      for (auto y = static_cast<std::uint32_t>(begin); y < end; ++y)
        for (std::uint32_t x = 0; x < size; ++x)
          out.at(static_cast<int>(x), static_cast<int>(y)) = source.shade(source.evaluate(x, y), x, y);
    });
  };
  static int first = 0;  // which of the three goes first, rotated over the iterations and rows
  double per_pixel_ms = 0, packets_ms = 0, ibuffer_ms = 0;
  for (auto _ : state) {
    for (int k = 0; k < 3; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      switch ((first + k) % 3) {
        case 0:
          if (!up->render(src, std::span<glm::vec3>(frame.pixels), exec)) state.SkipWithError("render failed");
          ibuffer_ms = ms_since(t0);
          break;
        case 1:
          per_pixel(src, reference);
          per_pixel_ms = ms_since(t0);
          break;
        default:
          per_pixel(*fx.packet_source, packet_reference);
          packets_ms = ms_since(t0);
      }
    }
    first = (first + 1) % 3;
  }
  const auto psnr = sup::psnr(frame, reference);
  // The packets trace the same rays; their frame against the single rays' (99: identical).
  const auto packets_psnr = sup::psnr(packet_reference, reference);
  state.counters["packets_psnr_db"] = packets_psnr ? std::min(*packets_psnr, 99.0) : -1.0;
  state.counters["per_pixel_ms"] = per_pixel_ms;
  state.counters["per_pixel_packets_ms"] = packets_ms;
  state.counters["ibuffer_ms"] = ibuffer_ms;
  state.counters["speedup"] = per_pixel_ms / ibuffer_ms;
  state.counters["speedup_packets"] = packets_ms / ibuffer_ms;
  state.counters["psnr_db"] = psnr ? *psnr : -1.0;
  state.counters["evaluated"] = up->stats().evaluated_fraction();
}
BENCHMARK(BM_IBufferFrame_vs_PerPixel)->Args({4, 1})->Args({6, 0})->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
