// The ready sample source (upsample/ray_cast_source.hpp) against the demo's hand-written one
// (tests/support/demo_upsample.hpp) on the demo scene, per frame, in one process: each
// repetition renders one frame with each source in alternating order, and the counters give
// the min and median of the per-frame ratio ready / hand-written (goal: <= 1.1).
// Arg: passes (1 = per-pixel evaluation, 4 = the I-Buffer). Serial executor, 257², the demo's
// shading (64 AO rays, 16 soft-shadow rays, the sun), clusters by normal split at seams.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <span>
#include <vector>
#include "infolerp/upsample/upsampler.hpp"
#include "support/demo_clusters.hpp"
#include "support/demo_upsample.hpp"

namespace {

namespace sup = infolerp::support;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 == 1 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

void BM_RayCastSource_vs_HandWritten(benchmark::State& state) {
  static const sup::embree_device device;
  static const auto scene = sup::make_demo_scene(device);
  if (!scene) {
    state.SkipWithError(scene.error().message().c_str());
    return;
  }
  constexpr std::uint32_t size = 257;
  const auto passes = static_cast<std::uint32_t>(state.range(0));
  const sup::reference_shader shader(*scene);
  const auto clusters = sup::split_at_texture_seams(*scene, sup::cluster_by_normal(*scene, 2));
  if (!clusters) {
    state.SkipWithError(clusters.error().message().c_str());
    return;
  }
  const sup::demo_ibuffer_source hand{&shader, &*clusters, static_cast<int>(size), static_cast<int>(size)};
  auto ready = sup::make_demo_ray_cast_source(shader, *clusters, static_cast<int>(size), static_cast<int>(size));
  auto up = infolerp::upsampler<sup::demo_sample>::create(size, size, {.passes = passes, .max_passes = passes});
  if (!ready || !up) {
    state.SkipWithError("setup failed");
    return;
  }
  std::vector<glm::vec3> frame(std::size_t{size} * size);
  std::vector<double> hand_ms, ready_ms, ratio;
  bool ready_first = false;
  const auto time = [&](const auto& src) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!up->render(src, std::span<glm::vec3>(frame))) state.SkipWithError("render failed");
    benchmark::DoNotOptimize(frame.data());
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  };
  for (auto _ : state) {
    double h = 0, r = 0;
    if (ready_first) {
      r = time(*ready);
      h = time(hand);
    } else {
      h = time(hand);
      r = time(*ready);
    }
    ready_first = !ready_first;
    hand_ms.push_back(h);
    ready_ms.push_back(r);
    ratio.push_back(r / h);
  }
  state.counters["hand_min_ms"] = *std::min_element(hand_ms.begin(), hand_ms.end());
  state.counters["hand_median_ms"] = median(hand_ms);
  state.counters["ready_min_ms"] = *std::min_element(ready_ms.begin(), ready_ms.end());
  state.counters["ready_median_ms"] = median(ready_ms);
  state.counters["ratio_of_mins"] = state.counters["ready_min_ms"] / state.counters["hand_min_ms"];
  state.counters["ratio_median"] = median(ratio);
}
BENCHMARK(BM_RayCastSource_vs_HandWritten)->Arg(1)->Arg(4)->Iterations(10)->Unit(benchmark::kMillisecond);

}  // namespace
