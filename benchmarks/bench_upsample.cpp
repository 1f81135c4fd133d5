// Cost of the I-Buffer upsampler's own work: interpolation, re-use, compatibility tests,
// shading into the frame buffer, with a cheap synthetic sample source so that evaluation costs
// almost nothing. Goal: at most 20 ns per interpolated pixel on one core. The cheap_probe_source
// rows add a probe per new sample (as cheap as the evaluation here); cheap_refining_source's
// probes leave out the light bits and are refined where needed (refine_probe); cheap_tolerant_source
// adds agree() (a tolerance on the sources' occlusion terms).
//   ns_per_interpolated = frame time / interpolated samples (all passes; conservative: the frame
//                         time also pays for the few evaluated and the re-used samples)
//   ns_per_pixel        = frame time / output pixels
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>
#include <glm/vec4.hpp>
#include "infolerp/upsample/upsampler.hpp"

namespace {

using sample = infolerp::surface_sample<2, true>;

// 1025x1025 frame with two clusters split by a diagonal and a shadow edge, attributes linear.
struct cheap_source {
  using sample_type = sample;
  sample evaluate(std::uint32_t xi, std::uint32_t yi) const {
    const float x = static_cast<float>(xi), y = static_cast<float>(yi);
    sample s;
    s.cluster = x + y > 1000.0f ? 1u : 0u;
    s.lights = 3.0f * x - y > 600.0f ? 0u : 1u;
    s.position = {x, y, 1.0f};
    s.normal = {0.0f, 0.0f, 1.0f};
    s.texcoord = {x * (1.0f / 1024.0f), y * (1.0f / 1024.0f)};
    s.occlusion = {0.75f, 0.5f};
    return s;
  }
  glm::vec4 shade(const sample& s, std::uint32_t, std::uint32_t) const {
    const float light = s.lights ? s.occlusion[1] : 0.0f;
    return {s.texcoord.x * s.occlusion[0] + light, s.texcoord.y * s.occlusion[0] + light, 0.5f * s.occlusion[0], 1.0f};
  }
};

// The same with probes: every new sample probes its pixel (here as cheap as evaluate) and is
// completed from the sources that match it.
struct cheap_probe_source : cheap_source {
  sample probe(std::uint32_t x, std::uint32_t y) const { return evaluate(x, y); }
};

// Probes that leave out the light bits, refined (refine_probe) where two agreeing sources that
// bracket the new sample do not suffice.
struct cheap_refining_source : cheap_source {
  sample probe(std::uint32_t x, std::uint32_t y) const {
    sample s = evaluate(x, y);
    s.lights = 0;
    return s;
  }
  bool probe_compatible(const sample& p, const sample& s) const { return p.cluster == s.cluster; }
  sample refine_probe(const sample&, std::uint32_t x, std::uint32_t y) const { return evaluate(x, y); }
};

// The refining source with agree() (sample_source.hpp): every chosen pair's occlusion terms
// tested against a tolerance (all agree here, so the frame is the refining source's).
struct cheap_tolerant_source : cheap_refining_source {
  bool agree(const sample& a, const sample& b) const { return infolerp::occlusion_within(a, b, 0.05f); }
};

template <class Source>
void BM_UpsampleInterpolatedPixel(benchmark::State& state) {
  const auto passes = static_cast<std::uint32_t>(state.range(0));
  constexpr std::uint32_t w = 1025, h = 1025;
  auto up = infolerp::upsampler<sample>::create(w, h, {.passes = passes, .max_passes = passes});
  if (!up) {
    state.SkipWithError(up.error().message().c_str());
    return;
  }
  std::vector<glm::vec4> frame(static_cast<std::size_t>(w) * h);
  const Source src;
  for (auto _ : state) {
    auto s = up->render(src, std::span<glm::vec4>(frame));
    benchmark::DoNotOptimize(frame.data());
    benchmark::ClobberMemory();
    if (!s) state.SkipWithError(s.message().c_str());
  }
  const auto& st = up->stats();
  const double frames = static_cast<double>(state.iterations());
  state.counters["interpolated"] = static_cast<double>(st.interpolated());
  state.counters["evaluated_fraction"] = st.evaluated_fraction();
  state.counters["ns_per_interpolated"] = benchmark::Counter(
      static_cast<double>(st.interpolated()) * frames, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["ns_per_pixel"] = benchmark::Counter(static_cast<double>(w) * h * frames,
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK_TEMPLATE(BM_UpsampleInterpolatedPixel, cheap_source)->Arg(2)->Arg(3)->Arg(4)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_UpsampleInterpolatedPixel, cheap_probe_source)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_UpsampleInterpolatedPixel, cheap_refining_source)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_UpsampleInterpolatedPixel, cheap_tolerant_source)->Arg(4)->Unit(benchmark::kMillisecond);

// Plain per-pixel evaluation of the same cheap source (passes = 1), for comparison.
void BM_UpsamplePlainEvaluation(benchmark::State& state) {
  constexpr std::uint32_t w = 1025, h = 1025;
  auto up = infolerp::upsampler<sample>::create(w, h, {.passes = 1, .max_passes = 1});
  std::vector<glm::vec4> frame(static_cast<std::size_t>(w) * h);
  const cheap_source src;
  for (auto _ : state) {
    auto s = up->render(src, std::span<glm::vec4>(frame));
    benchmark::DoNotOptimize(frame.data());
    benchmark::ClobberMemory();
    if (!s) state.SkipWithError(s.message().c_str());
  }
  state.counters["ns_per_pixel"] = benchmark::Counter(static_cast<double>(w) * h * static_cast<double>(state.iterations()),
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_UpsamplePlainEvaluation)->Unit(benchmark::kMillisecond);

}  // namespace
