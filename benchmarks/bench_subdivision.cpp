// Subdivision throughput (refine/subdivision_mesh.hpp) on CGAL's fandisk (12,946 triangles).
// Goal: at least 2 million child triangles per second on one core.
//  BM_Subdivision_Uniform:          every leaf selected, 3 levels (closure only) -> 64x the mesh
//  BM_Subdivision_RandomSelections: 20,000 random leaf selections with the default propagation
// Building the roots is excluded from the timing; `children_per_second` counts every triangle
// produced (1:4 and 1:2 children, retired ones included).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>
#include "infolerp/refine/subdivision_mesh.hpp"
#include "support/mesh_io.hpp"

namespace {
const infolerp::indexed_mesh* fandisk() {
  static const auto m = infolerp::support::load_mesh(infolerp::support::cgal_mesh("fandisk"));
  return m.ok() ? &*m : nullptr;
}
}  // namespace

static void BM_Subdivision_Uniform(benchmark::State& state) {
  const auto* m = fandisk();
  if (!m) return state.SkipWithError("fandisk not found");
  double children = 0.0;
  std::vector<std::uint32_t> leaves;
  for (auto _ : state) {
    state.PauseTiming();
    auto s = infolerp::subdivision_mesh::create(*m);
    state.ResumeTiming();
    for (int level = 0; level < 3; ++level) {
      leaves.clear();
      s->leaves(leaves);
      for (std::uint32_t t : leaves) (void)s->split(t, 0);
    }
    children += static_cast<double>(s->triangle_count() - s->original_triangle_count());
    benchmark::DoNotOptimize(s->leaf_count());
  }
  state.counters["children_per_second"] = benchmark::Counter(children, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Subdivision_Uniform)->Unit(benchmark::kMillisecond);

static void BM_Subdivision_RandomSelections(benchmark::State& state) {
  const auto* m = fandisk();
  if (!m) return state.SkipWithError("fandisk not found");
  double children = 0.0;
  std::vector<std::uint32_t> picks;
  for (auto _ : state) {
    state.PauseTiming();
    auto s = infolerp::subdivision_mesh::create(*m);
    std::mt19937 rng(1);
    state.ResumeTiming();
    for (int i = 0; i < 20000; ++i) {
      // A random leaf: random original triangle, random point, its leaf (as a pixel would).
      std::uniform_real_distribution<float> u01(0.0f, 1.0f);
      float u = u01(rng), v = u01(rng);
      if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
      const auto t = static_cast<std::uint32_t>(rng() % m->triangles.size());
      (void)s->split(s->locate(t, {u, v}).leaf);
    }
    children += static_cast<double>(s->triangle_count() - s->original_triangle_count());
    benchmark::DoNotOptimize(s->leaf_count());
  }
  state.counters["children_per_second"] = benchmark::Counter(children, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Subdivision_RandomSelections)->Unit(benchmark::kMillisecond);
