// Clustering on CGAL's refined_elephant (~89k triangles) and procedural meshes.
//   BM_Clustering_RefinedElephant   Algorithm 1: visibility → orientation → stretch, one core,
//                                   visibility rays precomputed outside the timed loop (a regression
//                                   benchmark: cluster_of_fnv24 must equal the exact kernel run's,
//                                   BM_Clustering_RefinedElephant_Counted/0, in the same run).
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
//   BM_VisibilityChannel_Adaptive/P/N   adaptive_probes = P at n = 2 through coherent streams,
//                                   neighbour rule N; checked against Total's counts by the
//                                   documented bounds (every entry within n² − P of it; with the
//                                   neighbour rule, equal to it or to the probe rule's entry).
//   BM_VisibilityChannel_Images/R/M   images at resolution R, fallback under M pixels, through
//                                   coherent streams; checked deterministic (both iterations
//                                   give the same counts).
//                                   Counter mean_js (both): JS of the raw p(V|t) rows against Total's.
//                                   (Time against error of every option: infolerp_pareto visibility.)
//   BM_Clustering_RefinedElephant_Ordered   the same on the mesh reordered for locality
//                                   (triangles by Morton code, vertices by first use).
//   BM_Clustering_RefinedElephant_Counted/E   the same through support::counting_channel, with
//                                   the JS estimate (E = 1) or without (E = 0: the baseline, exact
//                                   JS for every comparison), counting exact JS per channel.
//   BM_Clustering_KnownAnswer       the same three channels and options on a mesh whose answer is
//                                   known from geometry alone: a cube of 6 faces of 16x16 quads,
//                                   welded, planar UVs of one scale. Every channel's row
//                                   is alike within a face (one normal, one stretch; a convex face
//                                   is seen from the same viewpoints everywhere) and differs
//                                   across faces, so the clusters are the faces. Counter
//                                   ari_vs_faces: adjusted Rand index against the face labels (the
//                                   clustering regression of report.sh: it shares neither the
//                                   rays nor the region growing with its reference).
// Tracer: support::embree_scene (Embree 3, 16-ray packets), device with one thread.
// Figures: benchmarks/NOTES.md.
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
  e.topo = std::move(*make_topology(e.mesh));
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
// repetition it slowed least. It is not steadier than the median (benchmarks/NOTES.md).
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

// The cube of BM_Clustering_KnownAnswer and its face of each triangle (0..5). Coordinates are
// multiples of 1/8 and texcoords of 1/16, exact in float, so a face's normals and stretch are
// equal to the last bit and the known answer does not rest on rounding.
struct known_answer_scene {
  indexed_mesh mesh;
  std::vector<std::uint32_t> face;
};
known_answer_scene make_known_answer() {
  constexpr std::uint32_t n = 16;  // quads per side
  known_answer_scene k;
  indexed_mesh cube;
  for (std::uint32_t f = 0; f < 6; ++f) {
    const int axis = static_cast<int>(f / 2), u = (axis + 1) % 3, v = (axis + 2) % 3;
    const float side = f % 2 ? -1.0f : 1.0f;
    const auto base = static_cast<std::uint32_t>(cube.positions.size());
    for (std::uint32_t j = 0; j <= n; ++j)
      for (std::uint32_t i = 0; i <= n; ++i) {
        glm::vec3 p;
        p[axis] = side, p[u] = -1.0f + 2.0f * float(i) / float(n), p[v] = -1.0f + 2.0f * float(j) / float(n);
        cube.positions.push_back(p);
      }
    for (std::uint32_t j = 0; j < n; ++j)
      for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t a = base + j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
        const float h = 1.0f / float(n);
        const glm::vec2 ta(float(i) * h, float(j) * h), tb(float(i + 1) * h, float(j) * h), tc(float(i) * h, float(j + 1) * h),
            td(float(i + 1) * h, float(j + 1) * h);
        // (u, v, axis) is right-handed: counter-clockwise in (u, v) faces +axis; flipped for -axis.
        if (side > 0) cube.triangles.insert(cube.triangles.end(), {{a, b, d}, {a, d, c}}), cube.texcoords.insert(cube.texcoords.end(), {ta, tb, td, ta, td, tc});
        else cube.triangles.insert(cube.triangles.end(), {{a, d, b}, {a, c, d}}), cube.texcoords.insert(cube.texcoords.end(), {ta, td, tb, ta, tc, td});
        k.face.insert(k.face.end(), 2, f);
      }
  }
  std::vector<std::uint32_t> remap;
  k.mesh = support::weld_positions(cube, remap);
  return k;
}

void BM_Clustering_KnownAnswer(benchmark::State& state) {
  static const known_answer_scene k = make_known_answer();
  const auto topo = make_topology(k.mesh);
  if (!topo) return state.SkipWithError(topo.error().message().c_str());
  support::embree_device device("threads=1");
  support::embree_scene tracer(device);
  if (!tracer.add_mesh(k.mesh) || !tracer.commit()) return state.SkipWithError("embree scene");
  serial_executor exec;
  mesh_clustering last;
  for (auto _ : state) {
    auto r = cluster_mesh(k.mesh, tracer, exec, cluster_options{}, elephant_visibility,
                          orientation_channel{.threshold = 0.02, .bins = 256}, stretch_channel{.threshold = 0.1, .bins = 256});
    if (!r) return state.SkipWithError(r.error().message().c_str());
    last = std::move(*r);
    benchmark::DoNotOptimize(last);
  }
  state.counters["triangles"] = static_cast<double>(k.mesh.triangles.size());
  state.counters["clusters"] = last.cluster_count;
  for (std::size_t i = 0; i < last.channels.size(); ++i) state.counters["after_ch" + std::to_string(i)] = last.channels[i].clusters_after;
  state.counters["ari_vs_faces"] = support::adjusted_rand_index(last.cluster_of, k.face);
}
BENCHMARK(BM_Clustering_KnownAnswer)->Unit(benchmark::kMillisecond);

// One direct channel, exact (K = 0) against binned: time of init + clustering, JS error, ARI.
// Args: K (0 = exact), rows (0 = per cell, 1 = exact rows over the cells).
template <class Make>
void direct_channel_bench(benchmark::State& state, const indexed_mesh& m, Make make_state, double threshold) {
  const auto bins = static_cast<std::uint32_t>(state.range(0));
  const bool exact_rows = state.range(1) != 0;
  auto topo = make_topology(m);
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

const support::embree_scene& elephant_stream() {
  static support::embree_scene stream = [] {
    auto& e = elephant();
    support::embree_scene s(*e.device, {.coherent_streams = true});
    if (!s.add_mesh(e.mesh) || !s.commit()) std::abort();
    return s;
  }();
  return stream;
}

// Mean JS (bits) between the raw p(V|t) rows of a and b, 1 where only one of them is unseen.
double mean_row_js(prepared_visibility_channel a, prepared_visibility_channel b) {
  a.denoise = b.denoise = false;
  std::vector<std::uint32_t> all(a.visible.size() / a.viewpoints);
  std::iota(all.begin(), all.end(), 0u);
  const visibility_state ra = *a.init(all), rb = *b.init(all);
  double sum = 0.0;
  for (std::uint32_t t : all)
    sum += ra.unseen(t) || rb.unseen(t) ? (ra.unseen(t) == rb.unseen(t) ? 0.0 : 1.0) : js_divergence(ra.row(t), rb.row(t));
  return sum / static_cast<double>(all.size());
}

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

// Times c.prepare() on refined_elephant through 16-ray packets or Embree's coherent streams,
// keeping every iteration's result for the checks; empty when skipped.
std::vector<prepared_visibility_channel> time_visibility(benchmark::State& state, const visibility_channel& c, bool stream) {
  auto& e = elephant();
  if (!e.ok) {
    state.SkipWithError("refined_elephant not found");
    return {};
  }
  const support::embree_scene& tracer = stream ? elephant_stream() : *e.tracer;
  serial_executor exec;
  std::vector<prepared_visibility_channel> runs;
  for (auto _ : state) {
    auto p = c.prepare(e.mesh, e.topo, tracer, exec);
    if (!p) {
      state.SkipWithError(p.error().message().c_str());
      return {};
    }
    runs.push_back(std::move(*p));
  }
  return runs;
}

void BM_VisibilityChannel_Exact(benchmark::State& state) {
  visibility_channel c = elephant_visibility;
  c.coherent = true;
  c.cull_hull = state.range(1) != 0;
  const auto runs = time_visibility(state, c, state.range(0) != 0);
  if (!runs.empty() && runs.back().visible != elephant().visibility.visible)
    state.SkipWithError("counts differ from the plain tracing");
}
BENCHMARK(BM_VisibilityChannel_Exact)->Args({0, 0})->Args({1, 0})->Args({1, 1})->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_VisibilityChannel_Adaptive(benchmark::State& state) {
  visibility_channel c = elephant_visibility;
  c.coherent = true;
  c.adaptive_probes = static_cast<std::uint32_t>(state.range(0));
  c.adaptive_neighbours = state.range(1) != 0;
  const auto runs = time_visibility(state, c, true);
  if (runs.empty()) return;
  const prepared_visibility_channel& p = runs.back();
  auto& e = elephant();
  visibility_channel probes_alone = c;
  probes_alone.adaptive_neighbours = false;
  serial_executor exec;
  const std::vector<std::uint8_t> alone =
      c.adaptive_neighbours ? probes_alone.prepare(e.mesh, e.topo, elephant_stream(), exec)->visible : p.visible;
  const std::vector<std::uint8_t>& exact = e.visibility.visible;
  const int bound = static_cast<int>(p.samples) - static_cast<int>(c.adaptive_probes);
  for (std::size_t i = 0; i < exact.size(); ++i) {
    if (std::abs(int{p.visible[i]} - int{exact[i]}) > bound)
      return state.SkipWithError("an entry is off by more than n² - P samples");
    if (c.adaptive_neighbours && p.visible[i] != exact[i] && p.visible[i] != alone[i])
      return state.SkipWithError("neighbour rule: an entry equals neither the exact count nor the probe rule's");
  }
  state.counters["mean_js"] = mean_row_js(p, e.visibility);
}
BENCHMARK(BM_VisibilityChannel_Adaptive)->Args({1, 0})->Args({1, 1})->Args({2, 1})->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_VisibilityChannel_Images(benchmark::State& state) {
  visibility_channel c = elephant_visibility;
  c.images = true;
  c.image_resolution = static_cast<std::uint32_t>(state.range(0));
  c.image_min_pixels = static_cast<double>(state.range(1));
  const auto runs = time_visibility(state, c, true);
  if (runs.empty()) return;
  if (runs.front().visible != runs.back().visible) return state.SkipWithError("images: counts differ between runs");
  state.counters["mean_js"] = mean_row_js(runs.back(), elephant().visibility);
}
BENCHMARK(BM_VisibilityChannel_Images)->Args({256, 4})->Args({512, 16})->Unit(benchmark::kMillisecond)->Iterations(2);

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
      infolerp::detail::make_visibility_rays(e.mesh, su, first, std::min(nt, first + g), rays, slots);
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
