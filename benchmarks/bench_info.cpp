// Jensen–Shannon throughput (goal: at least 200 million bins/s per core for double) next
// to a naive std::log2 baseline, and validate_mesh throughput on refined_elephant.
//   build/benchmarks/infolerp_bench --benchmark_filter='JensenShannon|ValidateMesh'
// BM_JensenShannon_Column/<bins>/<estimate>: one row against 4096 rows (a seed's JS column, as
// the clustering evaluates it), exact kernel (0) or js_estimate (1), with the estimate's worst
// error over the column against its bound. 64 float bins are the visibility channel's rows,
// 257 double bins the binned direct channels'. Figures: benchmarks/NOTES.md.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>
#include "infolerp/info/jensen_shannon.hpp"
#include "infolerp/info/js_estimate.hpp"
#include "infolerp/mesh/validate.hpp"
#include "support/mesh_io.hpp"

namespace {
template <class T>
std::vector<T> random_distribution(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> p(n);
  double sum = 0.0;
  for (auto& x : p) sum += (x = u(rng) * u(rng));
  std::vector<T> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<T>(p[i] / sum);
  return out;
}
// What the kernel replaced: std::log2 per bin, with branches for zero bins.
template <class T>
double js_naive(const std::vector<T>& p, const std::vector<T>& q, double wp) {
  const double wq = 1.0 - wp;
  double sum = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double a = static_cast<double>(p[i]), b = static_cast<double>(q[i]), m = wp * a + wq * b;
    if (a > 0.0) sum += wp * a * std::log2(a / m);
    if (b > 0.0) sum += wq * b * std::log2(b / m);
  }
  return std::clamp(sum, 0.0, 1.0);
}
template <class T, bool Naive>
void run_js(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const auto p = random_distribution<T>(n, 1), q = random_distribution<T>(n, 2);
  for (auto _ : state) {
    benchmark::DoNotOptimize(p.data());
    benchmark::DoNotOptimize(q.data());
    double js = Naive ? js_naive(p, q, 0.5) : infolerp::js_divergence(p, q, 0.5);
    benchmark::DoNotOptimize(js);
  }
  state.counters["bins_per_second"] =
      benchmark::Counter(static_cast<double>(n) * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
}  // namespace

static void BM_JensenShannon(benchmark::State& state) { run_js<double, false>(state); }
static void BM_JensenShannon_Float(benchmark::State& state) { run_js<float, false>(state); }
static void BM_JensenShannon_Naive(benchmark::State& state) { run_js<double, true>(state); }
BENCHMARK(BM_JensenShannon)->Arg(1 << 10)->Arg(1 << 16)->Arg(1 << 20);
BENCHMARK(BM_JensenShannon_Naive)->Arg(1 << 10)->Arg(1 << 16)->Arg(1 << 20);
BENCHMARK(BM_JensenShannon_Float)->Arg(1 << 10)->Arg(1 << 16)->Arg(1 << 20);

template <class T>
void run_js_column(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const bool estimate = state.range(1) != 0;
  constexpr std::size_t rows = 4096;
  std::vector<T> table;
  std::vector<double> h(rows);
  for (std::size_t r = 0; r < rows; ++r) {
    const auto p = random_distribution<T>(n, r + 10);
    table.insert(table.end(), p.begin(), p.end());
    h[r] = infolerp::entropy_estimate(table.data() + r * n, n);
  }
  std::vector<double> col(rows);
  auto column = [&](bool est) {
    for (std::size_t r = 1; r < rows; ++r)
      col[r] = est ? infolerp::js_estimate(table.data(), table.data() + r * n, n, 0.4, h[0], h[r])
                   : infolerp::js_divergence(std::span<const T>(table.data(), n), std::span<const T>(table.data() + r * n, n), 0.4);
  };
  for (auto _ : state) {
    column(estimate);
    benchmark::DoNotOptimize(col.data());
  }
  std::vector<double> exact(rows);
  column(false);
  exact = col;
  column(true);
  double worst = 0.0;
  for (std::size_t r = 1; r < rows; ++r) worst = std::max(worst, std::abs(col[r] - exact[r]));
  state.counters["ns_per_pair"] = benchmark::Counter(static_cast<double>(rows - 1) * static_cast<double>(state.iterations()),
                                                     benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["estimate_worst_error"] = worst;
  state.counters["estimate_bound"] = infolerp::js_estimate_error(n);
}
static void BM_JensenShannon_Column_Float(benchmark::State& state) { run_js_column<float>(state); }
static void BM_JensenShannon_Column_Double(benchmark::State& state) { run_js_column<double>(state); }
BENCHMARK(BM_JensenShannon_Column_Float)->Args({64, 0})->Args({64, 1});
BENCHMARK(BM_JensenShannon_Column_Double)->Args({257, 0})->Args({257, 1});

static void BM_ValidateMesh(benchmark::State& state) {
  auto m = infolerp::support::load_mesh(infolerp::support::cgal_mesh("refined_elephant"));
  if (!m.ok()) {
    state.SkipWithError(m.error().message().c_str());
    return;
  }
  for (auto _ : state) {
    auto s = infolerp::validate_mesh(*m);
    benchmark::DoNotOptimize(s);
    if (!s.ok()) state.SkipWithError(s.message().c_str());
  }
  state.counters["triangles"] = static_cast<double>(m->triangles.size());
  state.counters["triangles_per_second"] = benchmark::Counter(
      static_cast<double>(m->triangles.size()) * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ValidateMesh)->Unit(benchmark::kMillisecond);
