// Clustering (issue 3) on CGAL's refined_elephant (~89k triangles) and procedural meshes.
//   BM_Clustering_RefinedElephant   Algorithm 1: visibility → orientation → stretch, one core,
//                                   visibility rays precomputed outside the timed loop. Goal ≤ 150 ms.
//                                   Counters chN_{prepare,init,growth,smoothing}_ms: channel N's
//                                   stages in the last iteration (channel_report's stage times).
//   BM_OrientationChannel/K/rows (CGAL's fandisk), BM_OrientationChannel_Torus/K/rows,
//   BM_StretchChannel/K/rows (UV sphere)   one-channel clustering, K = 0 (exact) or bins, rows 0
//                                   per cell or 1 exact rows over the cells: time, JS abs error
//                                   vs exact, adjusted Rand index vs exact. Goal at K = 1024:
//                                   ARI >= 0.99 at >= 10x less time.
//   BM_VisibilityChannel_Total / BM_VisibilityChannel_RaysOnly   the channel against the raw time
//                                   of its own rays through the same tracer. Goal ≤ 1.3×.
//   BM_VisibilityChannel_Exact/S/H  the channel with coherent = true, through 16-ray packets
//                                   (S = 0) or Embree's coherent streams (S = 1), cull_hull = H;
//                                   counts checked equal to Total's. Goal ≤ 0.6× Total.
//                                   (Time against error of every option: infolerp_pareto visibility.)
//   BM_Clustering_RefinedElephant_Ordered   the same on the mesh reordered for locality
//                                   (triangles by Morton code, vertices by first use).
//   BM_Clustering_RefinedElephant_Counted/E   the same through support::counting_channel, with
//                                   the JS estimate (E = 1) or without (E = 0: the baseline, exact
//                                   JS for every comparison), counting exact JS per channel.
// Tracer: support::embree_scene (Embree 3, 16-ray packets), device with one thread.
//
// Measured 2026-12-03, stop 20 (the same AVX2-only EPYC VM, slower this day: the same code ran
// 340-470 ms in a loop of 20 calls; the benchmark now also reports the min of repetitions):
//   BM_Clustering_RefinedElephant   median 416 / 423 / 413 ms, min 364 / 419 / 398 (three runs
//     of 5 repetitions), clusters unchanged (cluster_of_fnv24 7619422). _Ordered in the same
//     runs: median 343 / 322 / 352, min 314 / 285 / 343. Goal <= 150 ms NOT met. Tried, not kept:
//     - the split as one breadth-first flood from all triangles on the path's edges, each its
//       own part, parts joined by union-find where floods meet, stopped once one part is closed
//       and the other sources are joined (A ∪ B is connected, so every part holds such a
//       triangle): identical results, visits 539k -> 356k (visibility) and 103k -> 60k
//       (orientation), but smoothing slower in an in-process A/B of 21 alternating
//       repetitions: visibility min 109.8 against 100.6 ms, orientation 25.8 against 22.1.
//     - fewer viewpoints as a shortcut: N = 32 ran min 256 against 378 ms for N = 64 (N = 16:
//       274), but its visibility clusters agree with N = 64's at ARI 0.32 (0.21 for N = 16;
//       0.50 / 0.41 after all three channels): not an approximation of the same clustering.
// Measured 2026-12-03, stop 19 (the same AVX2-only EPYC VM as stop 18, noisy: one binary ran
// 240-345 ms in a harness within minutes, so alternating runs and in-process A/B comparisons):
//   BM_Clustering_RefinedElephant   268 / 297 ms median (two runs of 4 repetitions), same
//     clusters (cluster_of_fnv24 7619422), peak RSS 86 MB. Goal <= 150 ms NOT met. Stage
//     medians from the new counters (the 268 ms run): visibility init 42, growth 50, smoothing
//     59; orientation prepare 1.1, init 2.8, growth 18, smoothing 22; stretch prepare 6.7, init
//     14, growth 23, smoothing 10. Tried and not kept (clusters identical in each):
//     - the split decided from pieces: flood only the parts left by cutting A and B along the
//       old and the new boundary (capped floods, one capped "bulk" per side, union-find over the
//       pieces); the split part of visibility smoothing 23.7 -> 19.8 ms, orientation's 3.6 ->
//       4.4, whole smoothing unchanged within noise. The pieces between the two boundaries hold
//       200k of the 539k triangles the full floods visit: most of the work is inherent.
//     - a byte per slot marking the path's crossings for the flood (the idea of stop 14 again):
//       visibility smoothing -2 to -4 ms, orientation +1 to +2.5 ms in an in-process A/B.
//     - byte-sized flood marks instead of 4-byte region ids: no difference measurable.
//     - each set ordered by its triangles' Morton codes inside the channel loop (the mesh left
//       as is): 248 against 236 ms; smoothing -9, but init reads the counts out of order (+7)
//       and ordering costs 11 ms. Reordering the whole mesh (triangles by Morton code, vertices
//       by first use) gives 216-219 against 240 ms in the harness; in this benchmark
//       BM_Clustering_RefinedElephant_Ordered took 252 against 301 ms median (one run of 4
//       repetitions, both in it; 37 / 2100 / 4586 clusters against 34 / 1960 / 4248).
//     - -march=native: no gain on this machine (min 253 against 246 ms).
// Measured 2026-12-03, stop 18 (CPU time, one core of a 2-core AMD EPYC VM with AVX2 and no
// AVX-512, idle, c1760c2; f355b86 only moves code):
//   BM_Clustering_RefinedElephant   256 / 264 ms median (two runs of 4 repetitions), same
//     clusters (cluster_of_fnv24 7619422), peak RSS 86 MB. Goal <= 150 ms NOT met here.
//     Per part (a harness mirroring cluster_mesh's channel loop, best of 6, ms): validation 0.8,
//     topology 7; visibility init 38 (denoising, representatives), growth 43 (first seed's MI
//     2.8, seed search 16, rings 22, sequential pass 4.3, merging 1.4), smoothing 51 (per-slot
//     mesh edges 1.9, pairs and member lists 1.7, boundaries 4, bands 13, band edges 4.7, A* 5.3,
//     the 81 split floods 24: 539k triangles visited, ~45 ns each, latency-bound); orientation
//     prepare 1, init 2.4, subset graphs 2.4, growth 14, smoothing 20 (5.4 of it per-set setup);
//     stretch prepare 6, init 12, subset graphs 4, growth 16.5, smoothing 9.5 over 1960 sets.
//   With refined_elephant's triangles sorted by the Morton code of their centroids (harness
//   only; different clusters, 4488), the same run takes 212 against 240 ms: visibility init
//   38 -> 35, growth 43 -> 35, smoothing 51 -> 43 (splits 24 -> 17). The mesh as shipped has
//   poor locality; an engine's cache-ordered mesh would be ~12% faster.
// Measured 2026-12-02, stop 15 (CPU time, one core of a 2-core AMD EPYC VM (Zen 4) with
// AVX-512, the noisiest yet: the same binary 171-280 ms from run to run; min and median over
// 72 alternating runs of 6 repetitions):
//   BM_Clustering_RefinedElephant   min 174.2 / median 205.3 ms against 179.1 / 208.6 for the
//     previous version (1c2357f), same clusters (cluster_of_fnv24 7619422). Goal <= 150 ms NOT
//     met here (-march=native builds: min 168 / median 179 in 18 runs). Peak RSS 85 MB (107
//     before). The steps (perf share of the whole process, each against the one before; the
//     clusters bit-identical after each): visibility init's own loops vectorised (p(t|v) from
//     integer count sums, p(v|t) = p(t|v)/S(t): 4.6% -> 2.1%), denoising summed in registers
//     (6.1% -> 5.1%), libm's hypot replaced where squares are safe in the stretch channel
//     (1.5% -> 0.2%), denoising from the visible counts so the raw M×N row buffer is gone
//     (time neutral, 22 MB less memory). Tried and not kept: the split flood reading 2-byte
//     filter bits per slot instead of the 8-byte edge keys (10.4% -> 10.2%, noise), the subset
//     graph written by index instead of push_back (no change). The three-channel run's biggest
//     parts now: visibility smoothing 12%, the JS estimates 10%, denoising 8%, visibility
//     growth 5% of all samples (the process includes the untimed rays, ~22%).
//   BM_VisibilityChannel_Total 1890 ms, BM_VisibilityChannel_RaysOnly 1803 ms wall (1864 CPU)
//     in one run: 1.05x (goal <= 1.3x; the previous version 1872 / 1776 in the same session).
//     Counted/0 322 ms, Counted/1 260 ms in one noisy run, exact JS counts unchanged.
// Measured 2026-12-02, later (CPU time, one core of another 2-core AMD EPYC VM, with AVX-512,
// ~25% steal time: single runs vary by +-15%, so min and median over alternating runs):
//   BM_Clustering_RefinedElephant   min 148.2 / median 155.7 ms over 36 runs against 171.1 /
//     188.2 for the previous version (22fc459), alternating, same clusters (cluster_of_fnv24
//     7619422). Goal <= 150 ms met in the quieter runs only. The steps, each measured against
//     the one before: large_buffer_allocator for the visibility rows (page faults 159k -> 32k
//     per process, 181-188 -> 161-162 ms), the AVX-512 copy of the JS estimate (64 float bins
//     24.4 -> 19.8-20.9 ns a pair), the radix key sort in boundary smoothing (std::sort had ~6%),
//     and the split's merged member list written in place (std::merge into a sized vector).
//     A flood stack sized once gave no measurable gain and was taken out again. Peak RSS 107 MB
//     (94 before: whole 2 MiB pages). Counted/0 184 ms, Counted/1 171 ms in one run (the exact
//     kernel is itself AVX-512 here). Tried and not kept (perf share, no gain): denoising in
//     place with delayed write-back (34k of 89k rows pending: the mesh order is not local;
//     slower), marking the path's graph slots for the split's flood instead of the edge-key
//     filter (smoothing 8.9% -> 10.8%), prefetching p(t) with the rows.
//   BM_VisibilityChannel_Total 1665 ms, BM_VisibilityChannel_RaysOnly 1540 ms wall (1590 CPU)
//     in one run: 1.08x (goal <= 1.3x).
// Measured 2026-12-02 (CPU time, g++ 12 -O3 portable flags, one core of the shared 2-core AMD
// EPYC VM: AVX2, no AVX-512, about 2x slower here than the Xeon VM of 2026-12-01):
//   BM_Clustering_RefinedElephant   402 / 409 ms (median of 3, two alternating idle runs) against
//     597 / 603 for the previous version (0604aaf) and 592 / 594 for Counted/0: -32%. Clusters
//     bit-identical (34 / 1960 / 4248, cluster_of_fnv24 7619422 in all three). Exact JS
//     evaluations per run, without -> with the estimate: visibility 274,125 -> 2,399,
//     orientation 50,636 -> 11,435, stretch 65,386 -> 2,685 (the rest decided by estimates,
//     6.2x cheaper than the exact kernel at 64 float bins, 3.7x at 257 double bins). Goal
//     <= 150 ms NOT met. Where the time goes now (perf, self time): the estimates 14% (seed
//     search 6%), boundary smoothing 16% (visibility 11%: mostly the split's flood fills, bound
//     by memory), visibility init + denoising 9%, growth 8%, sorting 3.5%, direct-channel
//     states 3%, topology and subset graphs 3%.
//   BM_VisibilityChannel_Total 3968 ms, BM_VisibilityChannel_RaysOnly 3808 ms (9.57 M rays) in
//     the same run: 1.04x (goal <= 1.3x). These two had been dropped by mistake in 7c583eb and
//     are back.
// Measured 2026-12-01 (Xeon VM, AVX-512, before the estimate):
//   BM_Clustering_RefinedElephant   280 / 282 / 287 ms CPU (median of 3 repetitions, 3 runs)
//     against 306 / 306 / 304 for the previous version (ed66263, which measured 258-266 at
//     load 0.4 earlier that day) in the same alternating runs at load 0.5-0.9: ~8% less;
//     ~1070 ms before the issue-3 speed work. CPU per part (a harness mirroring
//     cluster_mesh, median of 6, load 0.9, previous version in brackets): validation and
//     topology 8.4 (9.0); visibility 181 (204): init 53 (57, of which ~13 are page faults of
//     its two fresh M×N float buffers), seeds + growth 70 (81: seed search ~43, rings ~19,
//     sequential pass 5.8 (8.5)), smoothing 55 (63: band flood 23 with 73k JS, split floods
//     16.5, A* 6.7); orientation 44 (45: growth 17, smoothing 23); stretch 10 prepare + 48
//     run (init 9, growth 23, smoothing 11). Tried and not kept (measured): per-row tables of
//     log2 entries (one logarithm per bin: a 64-bin pair 189 -> 106 ns in cache, but the 35 MB
//     table cost ~30 ms of init, mostly page faults, and the seed search gained ~5 ms as the
//     rows then stream 3x the bytes; for the direct channels' rows it saved ~7 ms of growth and
//     cost ~4.5 ms of stretch init); the log-free lower bound of I(x;Y) for the direct
//     channels (no gain: stretch growth 22.6 -> 24.5 ms); the split of boundary smoothing by floods
//     racing from the path (1.6x fewer triangles visited, 1.7x slower).
//   Direct channels at K = 1024, 2026-12-02 on the EPYC VM (CPU, idle): orientation on fandisk
//     exact 5.15 s, exact rows 88.5 ms (58x, ARI 0.997); stretch on the UV sphere exact 716 ms,
//     exact rows 2.76 ms (259x, ARI 1).
//   Direct channels at K = 1024 (Xeon VM, CPU, load 3.5; every figure in orientation_channel.hpp and
//     stretch_channel.hpp): orientation on fandisk, exact rows ARI 0.997 at 52x less time than
//     exact (29 ms against 1.52 s; per-cell rows 0.954); stretch on the UV sphere, exact rows
//     ARI 1 at 187x (per-cell rows 0.66): goal met. The jittered torus (2304 triangles, 786
//     occupied cells) is no binning regime: exact rows ARI 0.83 at 3x; on bunny00 (a scan,
//     exact 803 s, not benchmarked) exact rows give ARI 0.49 at K = 1024, 0.85 at 4096. Exact
//     against exact at Th x 1.01: ARI 0.994 on fandisk, 0.72 on the torus, 0.48 on bunny00.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <numbers>
#include <numeric>
#include <type_traits>
#include <vector>
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/mesh/locality_order.hpp"
#include "support/counting_channel.hpp"
#include "support/adjusted_rand_index.hpp"
#include "support/embree_tracer.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"

using namespace infolerp;

namespace {

// Spherical texcoords per corner (u unwrapped per triangle), so the stretch channel has work.
void add_spherical_texcoords(indexed_mesh& m) {
  const bounding_box box = mesh_bounds(m);
  const glm::dvec3 c = box.center();
  m.texcoords.clear();
  for (const auto& t : m.triangles) {
    glm::dvec2 uv[3];
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 d = glm::dvec3(m.positions[t[k]]) - c;
      uv[k] = {std::atan2(d.y, d.x) / (2.0 * std::numbers::pi) + 0.5, std::acos(std::clamp(d.z / glm::length(d), -1.0, 1.0)) / std::numbers::pi};
    }
    const double hi = std::max({uv[0].x, uv[1].x, uv[2].x});
    for (auto& x : uv)
      if (hi - x.x > 0.5) x.x += 1.0;
    for (auto& x : uv) m.texcoords.emplace_back(x);
  }
}

struct elephant_scene {
  indexed_mesh mesh;
  mesh_topology topo;
  std::unique_ptr<support::embree_device> device;
  std::unique_ptr<support::embree_scene> tracer;
  prepared_visibility_channel visibility;
  bool ok = false;
};

const visibility_channel elephant_visibility{.threshold = 0.48, .viewpoints = 64, .samples_per_side = 2};

// The mesh with its triangles in Morton order (mesh/locality_order.hpp) and its vertices
// renumbered by first use: what an engine's locality-ordered copy would look like.
void reorder_for_locality(indexed_mesh& m) {
  const std::vector<std::uint32_t> order = morton_triangle_order(m);
  std::vector<glm::uvec3> tris(order.size());
  std::vector<std::uint32_t> vertex(m.positions.size(), invalid_id);
  std::vector<glm::vec3> pos;
  pos.reserve(m.positions.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    glm::uvec3 t = m.triangles[order[i]];
    for (int k = 0; k < 3; ++k) {
      if (vertex[t[k]] == invalid_id) {
        vertex[t[k]] = static_cast<std::uint32_t>(pos.size());
        pos.push_back(m.positions[t[k]]);
      }
      t[k] = vertex[t[k]];
    }
    tris[i] = t;
  }
  m.triangles = std::move(tris);
  m.positions = std::move(pos);
}

elephant_scene make_elephant(bool ordered) {
  elephant_scene e;
  auto m = support::load_mesh(support::cgal_mesh("refined_elephant"));
  if (!m) return e;
  e.mesh = std::move(*m);
  if (ordered) reorder_for_locality(e.mesh);
  add_spherical_texcoords(e.mesh);
  e.topo = std::move(*build_topology(e.mesh));
  e.device = std::make_unique<support::embree_device>("threads=1");
  e.tracer = std::make_unique<support::embree_scene>(*e.device);
  if (!e.tracer->add_mesh(e.mesh) || !e.tracer->commit()) return e;
  serial_executor exec;
  e.visibility = std::move(*elephant_visibility.prepare(e.mesh, e.topo, *e.tracer, exec));
  e.ok = true;
  return e;
}

elephant_scene& elephant() {
  static elephant_scene s = make_elephant(false);
  return s;
}

elephant_scene& elephant_ordered() {
  static elephant_scene s = make_elephant(true);
  return s;
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

// FNV-1a of cluster_of, 24 bits (exact in a counter): speed work must leave it unchanged.
double fnv24(const std::vector<std::uint32_t>& labels) {
  std::uint32_t h = 2166136261u;
  for (std::uint32_t l : labels) h = (h ^ l) * 16777619u;
  return static_cast<double>(h >> 8);
}

void run_elephant(benchmark::State& state, elephant_scene& e) {
  if (!e.ok) return state.SkipWithError("refined_elephant not found");
  serial_executor exec;
  mesh_clustering last;
  for (auto _ : state) {
    auto r = cluster_mesh(e.mesh, *e.tracer, exec, cluster_options{}, e.visibility,
                          orientation_channel{.threshold = 0.02, .bins = 256}, stretch_channel{.threshold = 0.1, .bins = 256});
    if (!r) return state.SkipWithError(r.error().message().c_str());
    last = std::move(*r);
    benchmark::DoNotOptimize(last);
  }
  state.counters["triangles"] = static_cast<double>(e.mesh.triangles.size());
  state.counters["clusters"] = last.cluster_count;
  for (std::size_t i = 0; i < last.channels.size(); ++i) {
    const channel_report& c = last.channels[i];
    const std::string ch = "ch" + std::to_string(i);
    state.counters["after_" + ch] = c.clusters_after;
    // Where the last iteration's time went, in ms (visibility's prepare is outside the loop).
    state.counters[ch + "_prepare_ms"] = 1e3 * c.prepare_seconds;
    state.counters[ch + "_init_ms"] = 1e3 * c.init_seconds;
    state.counters[ch + "_growth_ms"] = 1e3 * c.growth_seconds;
    state.counters[ch + "_smoothing_ms"] = 1e3 * c.smoothing_seconds;
  }
  state.counters["peak_rss_MB"] = peak_rss_mb();
  state.counters["cluster_of_fnv24"] = fnv24(last.cluster_of);
}

// With --benchmark_repetitions, the minimum too: on a shared VM every repetition is slowed by
// the neighbours' load (the same binary 340-470 ms within minutes), and the minimum is the
// repetition it slowed least. It is not steadier than the median: three runs of stop 20 gave
// medians 413-423 ms and minimums 364-419.
double minimum(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

void BM_Clustering_RefinedElephant(benchmark::State& state) { run_elephant(state, elephant()); }
BENCHMARK(BM_Clustering_RefinedElephant)->Unit(benchmark::kMillisecond)->ComputeStatistics("min", minimum);

// The same mesh in locality order (reorder_for_locality): what mesh order costs. Different
// clusters (ties fall differently), the same channels and thresholds.
void BM_Clustering_RefinedElephant_Ordered(benchmark::State& state) { run_elephant(state, elephant_ordered()); }
BENCHMARK(BM_Clustering_RefinedElephant_Ordered)->Unit(benchmark::kMillisecond)->ComputeStatistics("min", minimum);

// The same clustering through support::counting_channel: with the JS estimate (1) or without it
// (0, the exact kernel for every comparison, the baseline), counting the exact divergences per
// channel. The cluster_of hash must equal BM_Clustering_RefinedElephant's in both.
void BM_Clustering_RefinedElephant_Counted(benchmark::State& state) {
  auto& e = elephant();
  if (!e.ok) return state.SkipWithError("refined_elephant not found");
  serial_executor exec;
  mesh_clustering last;
  std::size_t evaluated[3] = {};
  auto run = [&](auto estimate) {
    constexpr bool with = decltype(estimate)::value;
    auto po = orientation_channel{.threshold = 0.02, .bins = 256}.prepare(e.mesh, e.topo, *e.tracer, exec);
    auto ps = stretch_channel{.threshold = 0.1, .bins = 256}.prepare(e.mesh, e.topo, *e.tracer, exec);
    return cluster_mesh(e.mesh, *e.tracer, exec, cluster_options{},
                        support::counting_channel<prepared_visibility_channel, with>{&e.visibility, e.visibility.threshold, &evaluated[0]},
                        support::counting_channel<prepared_orientation_channel, with>{&*po, 0.02, &evaluated[1]},
                        support::counting_channel<prepared_stretch_channel, with>{&*ps, 0.1, &evaluated[2]});
  };
  for (auto _ : state) {
    auto r = state.range(0) ? run(std::true_type{}) : run(std::false_type{});
    if (!r) return state.SkipWithError(r.error().message().c_str());
    last = std::move(*r);
    benchmark::DoNotOptimize(last);
  }
  const auto per_run = [&](std::size_t n) { return static_cast<double>(n) / static_cast<double>(state.iterations()); };
  state.counters["exact_js_visibility"] = per_run(evaluated[0]);
  state.counters["exact_js_orientation"] = per_run(evaluated[1]);
  state.counters["exact_js_stretch"] = per_run(evaluated[2]);
  state.counters["clusters"] = last.cluster_count;
  state.counters["cluster_of_fnv24"] = fnv24(last.cluster_of);
}
BENCHMARK(BM_Clustering_RefinedElephant_Counted)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// One direct channel, exact (K = 0) against binned: time of init + clustering, JS error, ARI.
// Args: K (0 = exact), rows (0 = per cell, 1 = exact rows over the cells).
template <class Make>
void direct_channel_bench(benchmark::State& state, const indexed_mesh& m, Make make_state, double threshold) {
  const auto bins = static_cast<std::uint32_t>(state.range(0));
  const bool exact_rows = state.range(1) != 0;
  auto topo = build_topology(m);
  std::vector<std::uint32_t> all(m.triangles.size()), scratch(m.triangles.size(), invalid_id);
  std::iota(all.begin(), all.end(), 0u);
  const element_graph g = subset_graph(*topo, all, scratch);
  serial_executor exec;
  const region_growing_options o{.threshold = threshold, .min_cluster_fraction = 0.001};
  std::vector<std::uint32_t> labels;
  for (auto _ : state) {
    const auto s = make_state(bins, exact_rows);
    auto r = grow_regions(s, g, o, exec);
    labels = r->cluster_of;
    benchmark::DoNotOptimize(labels);
  }
  // Reference: exact rows and their clustering (computed once per K, outside the timing).
  const auto exact = make_state(0u, false);
  const auto binned = make_state(bins, exact_rows);
  double err_sum = 0.0, err_max = 0.0;
  std::size_t pairs = 0;
  for (std::uint32_t a = 0; a < all.size(); a += 97)
    for (std::uint32_t b = 0; b < all.size(); b += 89) {
      const double d = std::abs(binned.divergence(binned.class_of(a), binned.class_of(b)) -
                                exact.divergence(exact.class_of(a), exact.class_of(b)));
      err_sum += d;
      err_max = std::max(err_max, d);
      ++pairs;
    }
  static std::map<const void*, std::vector<std::uint32_t>> exact_labels;
  auto& ref = exact_labels[&m];
  if (ref.empty()) ref = grow_regions(exact, g, o, exec)->cluster_of;
  state.counters["triangles"] = static_cast<double>(m.triangles.size());
  state.counters["classes"] = static_cast<double>(binned.class_count());
  state.counters["columns"] = static_cast<double>(binned.kernel().column_count());
  state.counters["js_err_mean"] = err_sum / static_cast<double>(pairs);
  state.counters["js_err_max"] = err_max;
  state.counters["clusters"] = static_cast<double>(*std::max_element(labels.begin(), labels.end()) + 1);
  state.counters["ari_vs_exact"] = support::adjusted_rand_index(labels, ref);
}

const indexed_mesh& torus() {
  // Jittered deterministically so that no two normals tie (a symmetric torus makes seed choice
  // among exactly tied candidates arbitrary, which says nothing about binning).
  static const indexed_mesh m = [] {
    auto t = support::make_torus(48, 24, 1.0f, 0.4f);
    for (std::size_t v = 0; v < t.positions.size(); ++v) {
      std::uint64_t h = (v + 1) * 0x9E3779B97F4A7C15ull;
      h ^= h >> 31;
      h *= 0xBF58476D1CE4E5B9ull;
      h ^= h >> 29;
      t.positions[v] *= 1.0f + 0.01f * (static_cast<float>(h % 2001) / 1000.0f - 1.0f);
    }
    return t;
  }();
  return m;
}
const indexed_mesh& uv_sphere() {
  static const indexed_mesh m = support::make_uv_sphere(64, 32);
  return m;
}

void direct_channel_args(benchmark::internal::Benchmark* b) {
  b->Args({0, 0});
  for (int rows : {0, 1})
    for (int k : {64, 256, 1024, 4096}) b->Args({k, rows});
  b->Unit(benchmark::kMillisecond);
}

// CGAL's fandisk (12,946 triangles, a CAD part: flat and curved patches).
void BM_OrientationChannel(benchmark::State& state) {
  static const auto m = support::load_mesh(support::cgal_mesh("fandisk"));
  if (!m) return state.SkipWithError("fandisk not found");
  static const auto normals = face_normals(*m);
  direct_channel_bench(
      state, *m, [&](std::uint32_t bins, bool rows) { return make_orientation_state(normals, bins, rows); }, 0.02);
}
BENCHMARK(BM_OrientationChannel)->Apply(direct_channel_args);

void BM_OrientationChannel_Torus(benchmark::State& state) {
  const auto& m = torus();
  static const auto normals = face_normals(m);
  direct_channel_bench(
      state, m, [&](std::uint32_t bins, bool rows) { return make_orientation_state(normals, bins, rows); }, 0.02);
}
BENCHMARK(BM_OrientationChannel_Torus)->Apply(direct_channel_args);

void BM_StretchChannel(benchmark::State& state) {
  const auto& m = uv_sphere();
  static const auto raw = *texture_stretch(m);
  direct_channel_bench(state, m, [&](std::uint32_t bins, bool rows) { return make_stretch_state(raw, bins, rows); },
                       0.005);
}
BENCHMARK(BM_StretchChannel)->Apply(direct_channel_args);

void BM_VisibilityChannel_Total(benchmark::State& state) {
  auto& e = elephant();
  if (!e.ok) return state.SkipWithError("refined_elephant not found");
  serial_executor exec;
  for (auto _ : state) {
    auto p = elephant_visibility.prepare(e.mesh, e.topo, *e.tracer, exec);
    benchmark::DoNotOptimize(p);
  }
  state.counters["triangles"] = static_cast<double>(e.mesh.triangles.size());
}
BENCHMARK(BM_VisibilityChannel_Total)->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_VisibilityChannel_Exact(benchmark::State& state) {
  auto& e = elephant();
  if (!e.ok) return state.SkipWithError("refined_elephant not found");
  static support::embree_scene stream = [&] {
    support::embree_scene s(*e.device, {.coherent_streams = true});
    if (!s.add_mesh(e.mesh) || !s.commit()) std::abort();
    return s;
  }();
  visibility_channel c = elephant_visibility;
  c.coherent = true;
  c.cull_hull = state.range(1) != 0;
  serial_executor exec;
  prepared_visibility_channel p;
  for (auto _ : state) {
    p = std::move(*(state.range(0) != 0 ? c.prepare(e.mesh, e.topo, stream, exec) : c.prepare(e.mesh, e.topo, *e.tracer, exec)));
    benchmark::DoNotOptimize(p);
  }
  if (p.visible != e.visibility.visible) state.SkipWithError("counts differ from the plain tracing");
}
BENCHMARK(BM_VisibilityChannel_Exact)->Args({0, 0})->Args({1, 0})->Args({1, 1})->Unit(benchmark::kMillisecond)->Iterations(2);

// The same rays, same chunks, same tracer: only the trace_occluded calls are timed.
void BM_VisibilityChannel_RaysOnly(benchmark::State& state) {
  auto& e = elephant();
  if (!e.ok) return state.SkipWithError("refined_elephant not found");
  const visibility_setup su = elephant_visibility.setup(e.mesh);
  const std::size_t nt = e.mesh.triangles.size(), g = elephant_visibility.grain;
  std::vector<ray> rays;
  std::vector<std::uint32_t> slots;
  std::vector<std::uint8_t> out;
  std::size_t count = 0;
  for (auto _ : state) {
    double seconds = 0.0;
    count = 0;
    for (std::size_t first = 0; first < nt; first += g) {
      rays.clear();
      slots.clear();
      make_visibility_rays(e.mesh, su, first, std::min(nt, first + g), rays, slots);
      out.resize(rays.size());
      const auto t0 = std::chrono::steady_clock::now();
      trace_occluded(*e.tracer, std::span<const ray>(rays), std::span<std::uint8_t>(out));
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      count += rays.size();
      benchmark::DoNotOptimize(out.data());
    }
    state.SetIterationTime(seconds);
  }
  state.counters["rays"] = static_cast<double>(count);
}
BENCHMARK(BM_VisibilityChannel_RaysOnly)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace
