// Mesh saliency and salient clustering.
// Goals: BM_Saliency_Exact on refined_elephant subdivided once 1:4 (~178k vertices) <= 1.0 s
// wall on 2 cores;
// BM_SalientClustering on bunny00 with C = 10 <= 0.5 s.
// Figures: benchmarks/NOTES.md.
// Google Benchmark's CPU column counts the main thread only: with 2 threads, compare wall times.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <utility>
#include <vector>
#include "infolerp/core/executor.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"

namespace {

const infolerp::indexed_mesh* elephant_subdivided() {
  static std::optional<infolerp::indexed_mesh> mesh = [] {
    auto m = infolerp::support::load_mesh(infolerp::support::cgal_mesh("refined_elephant"));
    return m.ok() ? std::optional(infolerp::support::subdivide_midpoint(*m)) : std::nullopt;
  }();
  return mesh ? &*mesh : nullptr;
}

void BM_Saliency_Exact(benchmark::State& state) {
  const auto* m = elephant_subdivided();
  if (!m) return state.SkipWithError("refined_elephant not found");
  for (auto _ : state) {
    auto s = infolerp::compute_saliency(*m, {.method = infolerp::saliency_method::exact},
                                        infolerp::openmp_executor{static_cast<int>(state.range(0))});
    if (!s.ok()) return state.SkipWithError(s.error().message().c_str());
    benchmark::DoNotOptimize(s->saliency.data());
  }
  state.counters["vertices"] = static_cast<double>(m->positions.size());
}
BENCHMARK(BM_Saliency_Exact)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

// bunny00 and the same mesh plus one triangle reaching a vertex `far` bounding-box diagonals
// away. Arg 0: bunny00 alone (the reference). Arg 1: the stray vertex 1e6 diagonals away with
// epsilon scaled down so that sigma is bunny00's: the same pairs as bunny00, so the time shows
// what the neighbour grid costs. Arg 2: the stray vertex 100 diagonals away with the default
// epsilon: sigma grows with the diagonal, every ball holds the whole bunny and the pairs are all
// pairs, by the definition (epsilon relative to the bounding box), not by the grid.
void BM_Saliency_StrayVertex(benchmark::State& state) {
  static std::optional<infolerp::indexed_mesh> bunny = [] {
    auto m = infolerp::support::load_mesh(infolerp::support::cgal_mesh("bunny00"));
    return m.ok() ? std::optional(std::move(*m)) : std::nullopt;
  }();
  if (!bunny) return state.SkipWithError("bunny00 not found");
  infolerp::indexed_mesh m = *bunny;
  infolerp::saliency_options opt;
  if (state.range(0) > 0) {
    const auto box = infolerp::mesh_bounds(m);
    const double far = state.range(0) == 1 ? 1e6 : 100.0;
    m.positions.push_back(glm::vec3(box.hi) + glm::vec3(static_cast<float>(far * box.diagonal()), 0.0f, 0.0f));
    m.triangles.push_back({0u, 1u, static_cast<unsigned>(m.positions.size() - 1)});
    if (state.range(0) == 1) opt.epsilon *= box.diagonal() / infolerp::mesh_bounds(m).diagonal();
  }
  for (auto _ : state) {
    auto s = infolerp::compute_saliency(m, opt, infolerp::openmp_executor{2});
    if (!s.ok()) return state.SkipWithError(s.error().message().c_str());
    benchmark::DoNotOptimize(s->saliency.data());
  }
  state.counters["vertices"] = static_cast<double>(m.positions.size());
}
BENCHMARK(BM_Saliency_StrayVertex)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

#include "infolerp/saliency/salient_clustering.hpp"

namespace {
void BM_SalientClustering(benchmark::State& state) {
  static std::optional<std::pair<infolerp::indexed_mesh, std::vector<double>>> data = []()
      -> std::optional<std::pair<infolerp::indexed_mesh, std::vector<double>>> {
    auto m = infolerp::support::load_mesh(infolerp::support::cgal_mesh("bunny00"));
    if (!m.ok()) return std::nullopt;
    auto s = infolerp::compute_saliency(*m, {}, infolerp::openmp_executor{2});
    if (!s.ok()) return std::nullopt;
    return std::pair{std::move(*m), std::move(s->saliency)};
  }();
  if (!data) return state.SkipWithError("bunny00 not found");
  std::uint32_t iterations = 0;
  bool converged = false;
  for (auto _ : state) {
    auto c = infolerp::salient_clustering(data->first, data->second, {.clusters = 10, .seed = 1});
    if (!c.ok()) return state.SkipWithError(c.error().message().c_str());
    iterations = c->iterations;
    converged = c->converged;
  }
  state.counters["triangles"] = static_cast<double>(data->first.triangles.size());
  state.counters["rounds"] = iterations;
  state.counters["converged"] = converged ? 1.0 : 0.0;
}
BENCHMARK(BM_SalientClustering)->Unit(benchmark::kMillisecond)->UseRealTime();

// bunny00 split 1:4 once (/1, 301,632 triangles) and twice (/2, 1,206,528): how a round's cost
// grows with the mesh. The rounds are fixed at 8 (max_iterations), since how many rounds the
// seeds take to repeat is chance, not size; saliency is computed once per mesh. Compare /2 with
// /1 in the same run (n log n: 4.4×).
void BM_SalientClustering_Subdivided(benchmark::State& state) {
  using data = std::optional<std::pair<infolerp::indexed_mesh, std::vector<double>>>;
  static std::map<std::int64_t, data> cache;
  const std::int64_t times = state.range(0);
  if (!cache.contains(times)) {
    auto m = infolerp::support::load_mesh(infolerp::support::cgal_mesh("bunny00"));
    data d;
    if (m.ok()) {
      infolerp::indexed_mesh mesh = std::move(*m);
      for (std::int64_t i = 0; i < times; ++i) mesh = infolerp::support::subdivide_midpoint(mesh);
      if (auto s = infolerp::compute_saliency(mesh, {}, infolerp::openmp_executor{2}); s.ok())
        d = std::pair{std::move(mesh), std::move(s->saliency)};
    }
    cache.emplace(times, std::move(d));
  }
  const data& d = cache.at(times);
  if (!d) return state.SkipWithError("bunny00 not found");
  for (auto _ : state) {
    auto c = infolerp::salient_clustering(d->first, d->second, {.clusters = 10, .seed = 1, .max_iterations = 8});
    if (!c.ok()) return state.SkipWithError(c.error().message().c_str());
    benchmark::DoNotOptimize(c->cluster.data());
  }
  state.counters["triangles"] = static_cast<double>(d->first.triangles.size());
}
BENCHMARK(BM_SalientClustering_Subdivided)->DenseRange(1, 2)->Unit(benchmark::kMillisecond)->UseRealTime();
}  // namespace
