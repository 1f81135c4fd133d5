// Weighting map, contraction hierarchy, per-view selection and vertex contraction
// (salient-clustering paper §III.C, §IV).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <span>
#include <tuple>
#include <vector>
#include <catch2/catch.hpp>
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/screen_error_selection.hpp"
#include "infolerp/lod/vertex_contraction.hpp"
#include "infolerp/lod/view_dependent_lod.hpp"
#include "infolerp/lod/view_selection.hpp"
#include "infolerp/lod/weighting_map.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"
#include "support/thread_pool.hpp"

using namespace infolerp;

namespace {

// Clusters by the octant of the triangle centroid (8 ids, some possibly empty).
std::vector<std::uint32_t> octant_clusters(const indexed_mesh& m) {
  std::vector<std::uint32_t> c(m.triangle_count());
  glm::dvec3 mid(0.0);
  for (const auto& p : m.positions) mid += glm::dvec3(p);
  mid /= static_cast<double>(m.positions.size());
  for (std::size_t t = 0; t < c.size(); ++t) {
    const glm::dvec3 x = triangle_centroid(corners(m, t)) - mid;
    c[t] = (x.x > 0 ? 1u : 0u) | (x.y > 0 ? 2u : 0u) | (x.z > 0 ? 4u : 0u);
  }
  return c;
}

// Every undirected edge of the output has exactly two triangles, used once in each direction,
// and no triangle repeats an index.
bool closed_and_manifold(std::span<const std::uint32_t> idx) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (std::size_t k = 0; k < idx.size(); k += 3) {
    if (idx[k] == idx[k + 1] || idx[k + 1] == idx[k + 2] || idx[k] == idx[k + 2]) return false;
    for (int j = 0; j < 3; ++j) ++directed[{idx[k + static_cast<std::size_t>(j)], idx[k + static_cast<std::size_t>((j + 1) % 3)]}];
  }
  for (const auto& [e, n] : directed) {
    if (n != 1) return false;
    auto it = directed.find({e.second, e.first});
    if (it == directed.end() || it->second != 1) return false;
  }
  return true;
}

bool applied(const contraction_hierarchy& h, std::span<const std::uint32_t> stop, std::uint32_t i) {
  return i < stop[h.owner[i]];
}

// Brute-force reference of one frame: apply the chosen contractions in global order to a
// per-vertex map, then remap the cluster-ordered triangles and drop degenerate ones.
std::vector<std::uint32_t> reference_indices(const contraction_hierarchy& h, std::span<const std::uint32_t> stop) {
  std::vector<std::uint32_t> to(h.vertex_count);
  for (std::uint32_t v = 0; v < h.vertex_count; ++v) to[v] = v;
  for (std::uint32_t i = 0; i < h.contraction_count(); ++i)
    if (applied(h, stop, i))
      for (auto& x : to)
        if (x == h.removed[i]) x = h.target[i];
  std::vector<std::uint32_t> out;
  for (std::size_t t = 0; t < h.triangle_count(); ++t) {
    const std::uint32_t a = to[h.indices[3 * t]], b = to[h.indices[3 * t + 1]], c = to[h.indices[3 * t + 2]];
    if (a != b && b != c && a != c) out.insert(out.end(), {a, b, c});
  }
  return out;
}

result<contraction_hierarchy> uniform_hierarchy(const indexed_mesh& m, std::span<const std::uint32_t> cl,
                                                std::uint32_t count, double backstop) {
  std::vector<double> w(3 * m.triangle_count(), 1.0);
  return make_contraction_hierarchy(m, w, cl, count, {.backstop = backstop});
}

}  // namespace

TEST_CASE("weighting map: amplification and smoothing on hand-made maps", "[lod]") {
  std::vector<double> hand{5, 0, 9, 1, 8, 2, 7, 3, 6, 4};
  amplify_weights(hand, 30.0, 100.0);  // 30th percentile of 0..9 (nearest rank 3) is 2
  CHECK(hand == std::vector<double>{500, 0, 900, 1, 800, 200, 700, 300, 600, 400});

  // Smoothing: one spike on a plane against the Gaussian ball average by brute force.
  const indexed_mesh m = support::make_plane(10, 10, 1.0f);
  std::vector<double> s(m.vertex_count(), 0.0);
  s[60] = 1.0, s[3] = 0.5;
  const double sigma = 0.08;
  const auto smoothed = smooth_vertex_values(m, std::span<const double>(s), sigma);
  REQUIRE(smoothed.ok());
  const std::vector<double>& g = *smoothed;
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    double num = 0.0, den = 0.0;
    for (std::size_t x = 0; x < m.vertex_count(); ++x) {
      const double d2 = glm::dot(glm::dvec3(m.positions[x] - m.positions[v]), glm::dvec3(m.positions[x] - m.positions[v]));
      if (d2 > 4.0 * sigma * sigma) continue;
      const double w = std::exp(-d2 / (2.0 * sigma * sigma));
      num += w * s[x], den += w;
    }
    CHECK(g[v] == Approx(num / den).margin(1e-12));
  }

  // Without smoothing and amplification the map is eq. 4 itself.
  const std::vector<std::uint32_t> cl = octant_clusters(m);
  std::vector<double> sal(m.vertex_count());
  for (std::size_t k = 0; k < sal.size(); ++k) sal[k] = static_cast<double>(k % 7);
  auto plain = weighting_map(m, sal, cl, 8, {.smoothing_scale = 0.0, .amplification = 1.0});
  auto eq4 = cluster_localized_saliency(m, sal, cl, 8);
  REQUIRE(plain.ok());
  REQUIRE(eq4.ok());
  CHECK(*plain == *eq4);
  // Lee's amplification: every corner is its smoothed eq. 4 value, ×100 at or above the 30th
  // percentile.
  auto full = weighting_map(m, sal, cl, 8, {.amplify_percentile = 30.0, .amplification = 100.0});
  REQUIRE(full.ok());
  const auto sm = smooth_vertex_values(m, std::span<const double>(sal), 3.0 * 0.003 * mesh_bounds(m).diagonal());
  REQUIRE(sm.ok());
  auto local = cluster_localized_saliency(m, std::span<const double>(*sm), cl, 8);
  REQUIRE(local.ok());
  std::vector<double> sorted = *local;
  std::sort(sorted.begin(), sorted.end());
  const double alpha = sorted[static_cast<std::size_t>(std::ceil(0.3 * static_cast<double>(sorted.size()))) - 1];
  for (std::size_t k = 0; k < sorted.size(); ++k) CHECK((*full)[k] == ((*local)[k] >= alpha ? 100.0 * (*local)[k] : (*local)[k]));
}

TEST_CASE("weighting map: smooth_vertex_values names what is out of range instead of overflowing its grid keys", "[lod]") {
  const indexed_mesh m = support::make_plane(10, 10, 1.0f);  // diagonal sqrt(2)
  const std::vector<double> s(m.vertex_count(), 1.0);
  const std::span<const double> values(s);
  // 2^21 cells per axis is the keys' limit: σ 1e-3 at 1,000 cells per σ asks for 1.4e6 cells
  // along the diagonal (fine), at 2,000 for 2.8e6 (too many).
  const auto fine = smooth_vertex_values(m, values, 1e-3, serial_executor{}, 1, 1000.0);
  REQUIRE(fine.ok());
  CHECK(*fine == s);  // a constant stays constant
  const auto too_fine = smooth_vertex_values(m, values, 1e-3, serial_executor{}, 1, 2000.0);
  REQUIRE_FALSE(too_fine.ok());
  CHECK(too_fine.error().message().find("proxy_cells_per_sigma") != std::string::npos);
  const auto too_small = smooth_vertex_values(m, values, 1e-9, serial_executor{}, 1, 4.0);
  REQUIRE_FALSE(too_small.ok());
  CHECK(too_small.error().message().find("proxy_cells_per_sigma") != std::string::npos);
  for (double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    INFO("sigma " << bad);
    const auto r = smooth_vertex_values(m, values, bad);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().message().find("sigma") != std::string::npos);
  }
  const auto negative = smooth_vertex_values(m, values, 0.1, serial_executor{}, 1, -1.0);
  REQUIRE_FALSE(negative.ok());
  CHECK(negative.error().message().find("proxy_cells_per_sigma") != std::string::npos);
  const auto short_values = smooth_vertex_values(m, values.first(5), 0.1);
  REQUIRE_FALSE(short_values.ok());
  CHECK(short_values.error().message().find("values") != std::string::npos);
}

TEST_CASE("weighting map: smoothing over the saliency proxy", "[lod]") {
  // A plane with a rough map: fine proxy cells (one vertex each) give exact's smoothing, the
  // automatic method switches at exact_below, any executor gives the same bits.
  const indexed_mesh m = support::make_plane(60, 60, 1.0f);
  std::vector<double> sal(m.vertex_count());
  for (std::size_t k = 0; k < sal.size(); ++k) sal[k] = static_cast<double>((k * 7919) % 13);
  const std::vector<std::uint32_t> cl = octant_clusters(m);
  const weighting_map_options exact{.epsilon = 0.02, .smoothing_method = saliency_method::exact};
  auto e = weighting_map(m, sal, cl, 8, exact);
  REQUIRE(e.ok());
  auto with = [&](saliency_method method, double cells, std::size_t exact_below = 200000) {
    weighting_map_options o = exact;
    o.smoothing_method = method, o.proxy_cells_per_sigma = cells, o.exact_below = exact_below;
    return o;
  };
  // σ_s = 3 · 0.02 · √2 = 0.085; the spacing is 1/60: at 32 cells per σ_s a cell is 0.0027 wide.
  auto fine = weighting_map(m, sal, cl, 8, with(saliency_method::proxy, 32.0));
  REQUIRE(fine.ok());
  double worst = 0.0;
  for (std::size_t k = 0; k < e->size(); ++k) worst = std::max(worst, std::abs((*fine)[k] - (*e)[k]));
  CHECK(worst < 1e-9);
  auto coarse = weighting_map(m, sal, cl, 8, with(saliency_method::proxy, 2.0));
  REQUIRE(coarse.ok());
  CHECK(*coarse != *e);  // cells of several vertices: an approximation
  auto below = weighting_map(m, sal, cl, 8, with(saliency_method::automatic, 2.0, m.vertex_count() + 1));
  auto at = weighting_map(m, sal, cl, 8, with(saliency_method::automatic, 2.0, m.vertex_count()));
  REQUIRE(below.ok());
  REQUIRE(at.ok());
  CHECK(*below == *e);
  CHECK(*at == *coarse);
  for (unsigned workers : {2u, 3u}) {
    auto par = weighting_map(m, sal, cl, 8, with(saliency_method::proxy, 2.0), support::thread_pool_executor(workers));
    REQUIRE(par.ok());
    CHECK(*par == *coarse);
  }
  // Bad options name themselves.
  for (double cells : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), 1e7}) {
    INFO("proxy_cells_per_sigma " << cells);
    auto r = weighting_map(m, sal, cl, 8, with(saliency_method::proxy, cells));
    REQUIRE(!r.ok());
    CHECK(r.error().code() == errc::bad_parameter);
    CHECK(r.error().message().find("proxy_cells_per_sigma") != std::string::npos);
  }
  CHECK(weighting_map(m, sal, cl, 8, with(saliency_method::exact, 1e7)).ok());  // unused by exact
  auto bad = weighting_map(m, sal, cl, 8, with(static_cast<saliency_method>(7), 2.0));
  REQUIRE(!bad.ok());
  CHECK(bad.error().message().find("smoothing_method") != std::string::npos);
}

TEST_CASE("a plane of many triangles simplifies to two with zero error", "[lod]") {
  const indexed_mesh m = support::make_plane(12, 9, 2.0f);
  const std::vector<std::uint32_t> cl(m.triangle_count(), 0);
  auto h = uniform_hierarchy(m, cl, 1, 0.0);
  REQUIRE(h.ok());
  std::uint32_t zero = 0;
  while (zero < h->contraction_count() && h->error[zero] == 0.0f) ++zero;
  const std::vector<std::uint32_t> stop{zero};
  const auto idx = reference_indices(*h, stop);
  REQUIRE(idx.size() == 6);
  double area = 0.0;
  for (std::size_t k = 0; k < idx.size(); k += 3) {
    const glm::dvec3 a(m.positions[idx[k]]), b(m.positions[idx[k + 1]]), c(m.positions[idx[k + 2]]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    CHECK(n.z > 0.0);
    area += 0.5 * glm::length(n);
  }
  CHECK(area == Approx(4.0).epsilon(1e-12));
  for (std::uint32_t v : idx) CHECK(std::abs(std::abs(m.positions[v].x) - 1.0f) + std::abs(std::abs(m.positions[v].y) - 1.0f) == 0.0f);
}

TEST_CASE("a closed mesh stays closed at every budget; dependencies and budgets hold", "[lod]") {
  const indexed_mesh m = support::make_torus(24, 12, 1.0f, 0.35f);
  const std::vector<std::uint32_t> cl = octant_clusters(m);
  auto h = uniform_hierarchy(m, cl, 8, 0.01);
  REQUIRE(h.ok());
  REQUIRE(h->contraction_count() > m.vertex_count() / 2);
  contraction_workspace w = make_contraction_workspace(*h, 16);
  std::vector<std::uint32_t> out(contracted_index_bound(*h));
  std::vector<index_range> ranges(8);
  std::vector<std::uint32_t> stop(8);

  SECTION("global prefixes from 0 to the backstop") {
    for (std::uint32_t k = 0; k <= h->contraction_count(); k += 7) {
      std::fill(stop.begin(), stop.end(), k);
      auto n = contract_indices(*h, stop, w, out, ranges);
      REQUIRE(n.ok());
      const std::span<const std::uint32_t> got(out.data(), *n);
      INFO("prefix " << k);
      CHECK(closed_and_manifold(got));
      std::size_t removed = 0;
      for (std::uint32_t i = 0; i < k; ++i) removed += h->faces_removed[i];
      CHECK(*n == 3 * (m.triangle_count() - removed));
    }
  }
  SECTION("clusters at very different budgets, with neighbour matching") {
    const neighbour_table table = make_neighbour_table(*h);
    std::mt19937 rng(7);
    for (int trial = 0; trial < 60; ++trial) {
      std::vector<std::uint64_t> budget(8);
      for (std::uint32_t c = 0; c < 8; ++c) {
        const auto cap = h->capacity(c);
        const int mode = static_cast<int>(rng() % 3);
        budget[c] = mode == 0 ? 0 : (mode == 1 ? cap : rng() % (cap + 1));
      }
      REQUIRE(stop_points_from_budgets(*h, budget, stop).ok());
      for (std::uint32_t c = 0; c < 8; ++c) CHECK(applied_count(*h, c, stop[c]) == budget[c]);
      match_neighbours(table, stop);
      for (std::uint32_t c = 0; c < 8; ++c) CHECK(applied_count(*h, c, stop[c]) >= budget[c]);
      // No contraction before its dependencies.
      for (std::uint32_t i = 0; i < h->contraction_count(); ++i)
        if (applied(*h, stop, i) && h->parent[i] != no_parent) REQUIRE(applied(*h, stop, h->parent[i]));
      auto n = contract_indices(*h, stop, w, out, ranges);
      REQUIRE(n.ok());
      const std::span<const std::uint32_t> got(out.data(), *n);
      CHECK(closed_and_manifold(got));
      // No contracted vertex referenced; the output equals the brute-force reference.
      for (std::uint32_t v : got) {
        const std::uint32_t i = h->removal_order[v];
        CHECK((i == invalid_id || !applied(*h, stop, i)));
      }
      CHECK(std::vector<std::uint32_t>(got.begin(), got.end()) == reference_indices(*h, stop));
      // Ranges tile the output in cluster order.
      std::size_t at = 0;
      for (std::uint32_t c = 0; c < 8; ++c) {
        if (ranges[c].count) CHECK(ranges[c].first == at);
        at += ranges[c].count;
      }
      CHECK(at == *n);
    }
  }
}

TEST_CASE("vertex contraction: the triangles a cluster keeps are prefixes of runs", "[lod]") {
  const indexed_mesh m = support::make_torus(24, 12, 1.0f, 0.35f);
  const std::vector<std::uint32_t> cl = octant_clusters(m);
  auto h = uniform_hierarchy(m, cl, 8, 0.01);
  REQUIRE(h.ok());
  // Inside a cluster: runs by the owner of the removing contraction (never removed: owner 0),
  // latest removal first, so that a stop point keeps a prefix of each run.
  auto run_of = [&](std::size_t t) { return h->killer[t] == invalid_id ? 0u : h->owner[h->killer[t]]; };
  std::size_t runs = 0;
  for (std::uint32_t c = 0; c < 8; ++c)
    for (std::size_t t = h->triangle_offsets[c]; t < h->triangle_offsets[c + 1]; ++t) {
      INFO("triangle " << t);
      if (t == h->triangle_offsets[c]) {
        ++runs;
      } else if (run_of(t) != run_of(t - 1)) {
        REQUIRE(run_of(t - 1) < run_of(t));
        ++runs;
      } else {
        REQUIRE(h->killer[t - 1] >= h->killer[t]);
      }
    }
  CHECK(runs > 8);  // triangles on cluster borders are removed by other clusters' contractions
  // Stop points that are not dependency-closed: triangles may be lost (their gaps closed), never
  // invented, reordered or degenerate.
  contraction_workspace w = make_contraction_workspace(*h, 5);
  std::vector<std::uint32_t> out(contracted_index_bound(*h)), stop(8);
  std::vector<index_range> ranges(8);
  std::mt19937 rng(11);
  std::size_t dropped = 0;  // kept by their runs, dropped as degenerate: gaps the pass closes
  for (int trial = 0; trial < 40; ++trial) {
    for (auto& s : stop) s = static_cast<std::uint32_t>(rng() % (h->contraction_count() + 1));
    auto n = contract_indices(*h, stop, w, out, ranges);
    REQUIRE(n.ok());
    const auto as_triangles = [](std::span<const std::uint32_t> idx) {
      std::vector<std::array<std::uint32_t, 3>> t(idx.size() / 3);
      for (std::size_t k = 0; k < t.size(); ++k) t[k] = {idx[3 * k], idx[3 * k + 1], idx[3 * k + 2]};
      return t;
    };
    const auto ref = as_triangles(reference_indices(*h, stop));
    auto next = ref.begin();  // each output triangle appears in the reference after the previous one
    for (const auto& tri : as_triangles(std::span<const std::uint32_t>(out.data(), *n))) {
      next = std::find(next, ref.end(), tri);
      REQUIRE(next != ref.end());
      ++next;
    }
    std::size_t kept = 0;
    for (std::size_t t = 0; t < h->triangle_count(); ++t) kept += h->killer[t] >= stop[run_of(t)] ? 1 : 0;
    dropped += kept - *n / 3;
    std::size_t at_range = 0;  // ranges tile the output in cluster order
    for (std::uint32_t c = 0; c < 8; ++c) {
      if (ranges[c].count) CHECK(ranges[c].first == at_range);
      at_range += ranges[c].count;
    }
    CHECK(at_range == *n);
  }
  CHECK(dropped > 0);
}

TEST_CASE("hierarchy on a bumpy plane with holes: no flip, boundary kept, manifold", "[lod]") {
  indexed_mesh m = support::make_plane(14, 11, 2.0f);
  for (auto& p : m.positions) p.z = 0.15f * std::sin(4.0f * p.x) * std::cos(3.0f * p.y);
  std::vector<glm::uvec3> kept;  // two holes and a notch in the rim
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    if (t % 37 != 5 && t % 53 != 20 && t != 1) kept.push_back(m.triangles[t]);
  m.triangles = kept;
  m.triangles.push_back({3, 3, 4});  // a repeated index draws nothing
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (const glm::uvec3& f : m.triangles)
    if (f.x != f.y && f.y != f.z && f.x != f.z)
      for (int j = 0; j < 3; ++j) ++uses[{std::min(f[j], f[(j + 1) % 3]), std::max(f[j], f[(j + 1) % 3])}];
  std::vector<char> on_boundary(m.vertex_count(), 0);
  for (const auto& [e, n] : uses)
    if (n == 1) on_boundary[e.first] = on_boundary[e.second] = 1;
  const std::vector<std::uint32_t> cl(m.triangle_count(), 0);
  const std::vector<double> w(3 * m.triangle_count(), 1.0);
  // No boundary planes: only the boundary rule keeps the rim.
  auto h = make_contraction_hierarchy(m, w, cl, 1, {.backstop = 0.0, .boundary_weight = 0.0});
  REQUIRE(h.ok());
  REQUIRE(h->contraction_count() > m.vertex_count() / 2);
  // Replay the contractions one by one on a vertex map.
  std::vector<std::uint32_t> to(m.vertex_count());
  for (std::uint32_t v = 0; v < to.size(); ++v) to[v] = v;
  auto normal = [&](std::size_t t) {
    const glm::dvec3 a(m.positions[to[h->indices[3 * t]]]), b(m.positions[to[h->indices[3 * t + 1]]]),
        c(m.positions[to[h->indices[3 * t + 2]]]);
    return glm::cross(b - a, c - a);
  };
  std::size_t flips = 0, off_boundary = 0, non_manifold = 0;
  for (std::uint32_t i = 0; i < h->contraction_count(); ++i) {
    const std::uint32_t u = h->removed[i], v = h->target[i];
    if (on_boundary[u] && !on_boundary[v]) ++off_boundary;
    std::vector<glm::dvec3> before(h->triangle_count());
    for (std::size_t t = 0; t < before.size(); ++t) before[t] = normal(t);
    for (auto& x : to)
      if (x == u) x = v;
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (std::size_t t = 0; t < before.size(); ++t) {
      const std::uint32_t a = to[h->indices[3 * t]], b = to[h->indices[3 * t + 1]], c = to[h->indices[3 * t + 2]];
      if (a == b || b == c || a == c) continue;
      if (!(glm::dot(before[t], normal(t)) > 0.0)) ++flips;
      for (auto [x, y] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) ++edges[{std::min(x, y), std::max(x, y)}];
    }
    for (const auto& [e, n] : edges) {
      if (n > 2) ++non_manifold;
      if (n == 1 && !(on_boundary[e.first] && on_boundary[e.second])) ++off_boundary;
    }
  }
  CHECK(flips == 0);
  CHECK(off_boundary == 0);
  CHECK(non_manifold == 0);
}

TEST_CASE("hierarchy: the vertex heap keeps the (cost, u, v) order of a std::set under updates", "[lod]") {
  // Few distinct costs, so that most entries tie on cost (as zero-cost coplanar contractions do).
  std::mt19937 rng(7);
  for (const std::uint32_t n : {1u, 5u, 64u, 3000u}) {
    detail::vertex_heap heap;
    heap.reset(n);
    std::vector<detail::collapse_entry> entry(n);
    std::vector<char> in(n, 0);
    auto same = [](const detail::collapse_entry& a, const detail::collapse_entry& b) { return !(a < b) && !(b < a); };
    std::set<std::tuple<double, std::uint32_t, std::uint32_t>> ref;
    for (int step = 0; step < 20000; ++step) {
      const auto u = static_cast<std::uint32_t>(rng() % n);
      if (in[u]) ref.erase({entry[u].cost, u, entry[u].v});
      if (const auto op = rng() % 8; op == 0) {
        heap.erase(u), in[u] = 0;
      } else if (op == 1 && !ref.empty()) {  // pop the top, as the build does
        if (in[u]) ref.insert({entry[u].cost, u, entry[u].v});
        const auto [c, top_u, top_v] = *ref.begin();
        REQUIRE(same(heap.top(), {c, top_u, top_v}));
        heap.erase(top_u), in[top_u] = 0, ref.erase(ref.begin());
      } else {
        entry[u] = {static_cast<double>(rng() % 4), u, static_cast<std::uint32_t>(rng() % 3)};
        heap.set(entry[u]), in[u] = 1, ref.insert({entry[u].cost, u, entry[u].v});
      }
      REQUIRE(heap.empty() == ref.empty());
      if (!ref.empty()) REQUIRE(same(heap.top(), {std::get<0>(*ref.begin()), std::get<1>(*ref.begin()), std::get<2>(*ref.begin())}));
      if (in[u]) REQUIRE((heap.find(u) && same(*heap.find(u), entry[u])));
      else REQUIRE(heap.find(u) == nullptr);
    }
  }
}

TEST_CASE("hierarchy: a non-manifold edge is refused and named", "[lod]") {
  indexed_mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {2, 2, 2}};
  m.triangles = {{5, 2, 4}, {0, 1, 2}, {1, 0, 3}, {0, 1, 4}};  // edge (0, 1) has three triangles
  const std::vector<double> w(3 * m.triangle_count(), 1.0);
  const std::vector<std::uint32_t> cl(m.triangle_count(), 0);
  auto h = make_contraction_hierarchy(m, w, cl, 1);
  REQUIRE(!h.ok());
  CHECK(h.error().code() == errc::non_manifold_edge);
  CHECK(h.error().element() == 0);
  m.triangles.pop_back();
  CHECK(make_contraction_hierarchy(m, std::span(w).first(9), std::span(cl).first(3), 1).ok());
}

TEST_CASE("vertex contraction: identical bits for any executor", "[lod]") {
  const indexed_mesh m = support::make_icosphere(3);
  const std::vector<std::uint32_t> cl = octant_clusters(m);
  auto h = uniform_hierarchy(m, cl, 8, 0.01);
  REQUIRE(h.ok());
  std::vector<std::uint32_t> stop{50, 400, 0, 90000, 200, 600, 10, 300};
  match_neighbours(make_neighbour_table(*h), stop);
  contraction_workspace w1 = make_contraction_workspace(*h, 7), w2 = make_contraction_workspace(*h, 7);
  std::vector<std::uint32_t> a(contracted_index_bound(*h)), b(a.size());
  std::vector<index_range> ra(8), rb(8);
  auto na = contract_indices(*h, stop, w1, a, ra);
  auto nb = contract_indices(*h, stop, w2, b, rb, support::thread_pool_executor(4));
  REQUIRE(na.ok());
  REQUIRE(nb.ok());
  CHECK(*na == *nb);
  CHECK(a == b);
  for (std::size_t c = 0; c < 8; ++c) CHECK((ra[c].first == rb[c].first && ra[c].count == rb[c].count));
}

TEST_CASE("per-frame entry point: budgets, closedness, bad input", "[lod]") {
  const indexed_mesh m = support::make_icosphere(3);
  const std::vector<std::uint32_t> cl = octant_clusters(m);
  std::vector<double> sal(m.vertex_count());
  for (std::size_t v = 0; v < sal.size(); ++v) sal[v] = 1.0 + 0.5 * std::sin(3.0 * m.positions[v].x);
  auto wm = weighting_map(m, sal, cl, 8);
  REQUIRE(wm.ok());
  auto h = make_contraction_hierarchy(m, *wm, cl, 8, {.cluster_local_first = true});
  REQUIRE(h.ok());
  auto table = compute_cluster_attributes(m, sal, cl, 8);
  REQUIRE(table.ok());
  // The whole cut (keep_hidden), to count its triangles and check that it is closed.
  auto lod = view_dependent_lod::create(*h, *table, {.selection = lod_selection::paper, .view = {}, .keep_hidden = true});
  REQUIRE(lod.ok());
  std::vector<std::uint32_t> out(contracted_index_bound(*h));
  std::vector<index_range> ranges(8);
  const auto looking_at_origin = [](const glm::dvec3& eye) { return lod_camera{eye, -eye, {0.0, 1.0, 0.0}, 0.8, 64, 64}; };
  REQUIRE(h->local_contractions > 100);
  REQUIRE(h->local_contractions < h->contraction_count());
  const std::uint64_t n = h->contraction_count();
  for (std::uint64_t r : {std::uint64_t{0}, std::uint64_t{100}, std::uint64_t{h->local_contractions}, n / 2, n - 3, n}) {
    // The budget in triangles that the global prefix of r contractions keeps: with keep_hidden
    // (nothing culled) eq. 9 then distributes exactly R_global = r.
    std::uint64_t kept = h->triangle_count();
    for (std::uint64_t i = 0; i < r; ++i) kept -= h->faces_removed[i];
    auto st = lod->frame(looking_at_origin({0.3, -2.0, 4.0}), kept, out, ranges);
    REQUIRE(st.ok());
    CHECK(st->budgeted == r);  // eq. 9 spends exactly R_global
    CHECK(st->applied == r);   // and the local phase needs no matching: budgets honoured exactly
    std::uint64_t sum = 0;
    for (std::uint32_t c = 0; c < 8; ++c) {
      CHECK(lod->budgets()[c] <= h->capacity(c));
      if (r <= h->local_contractions) CHECK(lod->budgets()[c] <= h->local_capacity(c));
      sum += lod->budgets()[c];
    }
    CHECK(sum == r);
    std::size_t removed = 0;  // the triangle count follows from the applied contractions
    for (std::uint32_t i = 0; i < h->contraction_count(); ++i)
      if (i < lod->stop_points()[h->owner[i]]) removed += h->faces_removed[i];
    CHECK(st->indices == 3 * (m.triangle_count() - removed));
    CHECK(closed_and_manifold(std::span<const std::uint32_t>(out.data(), st->indices)));
  }
  // Bad input.
  CHECK(lod->frame(looking_at_origin({std::nan(""), 0.0, 5.0}), 10, out, ranges).error().code() == errc::bad_parameter);
  std::vector<std::uint32_t> small(out.size() - 1);
  CHECK(lod->frame(looking_at_origin({0.0, 0.0, 5.0}), 10, small, ranges).error().code() == errc::bad_size);
  std::vector<std::uint64_t> over(8, 0);
  over[3] = h->capacity(3) + 1;
  std::vector<std::uint32_t> stop(8);
  const status s = stop_points_from_budgets(*h, over, stop);
  CHECK(s.code() == errc::bad_parameter);
  CHECK(s.element() == 3);
  std::vector<double> w(3 * m.triangle_count(), 1.0);
  w[5] = -1.0;
  CHECK(make_contraction_hierarchy(m, w, cl, 8).error().code() == errc::bad_parameter);  // finite but negative
  w[5] = std::numeric_limits<double>::infinity();
  CHECK(make_contraction_hierarchy(m, w, cl, 8).error().code() == errc::non_finite);
  w[5] = std::nan("");
  CHECK(make_contraction_hierarchy(m, w, cl, 8).error().element() == 5);
  w.pop_back();
  CHECK(make_contraction_hierarchy(m, w, cl, 8).error().code() == errc::bad_size);
  std::vector<double> bad_sal = sal;
  bad_sal[2] = -0.5;
  CHECK(weighting_map(m, bad_sal, cl, 8).error().code() == errc::bad_parameter);  // finite but negative
  CHECK(weighting_map(m, sal, cl, 8, {.amplify_percentile = 101.0}).error().code() == errc::bad_parameter);
}

TEST_CASE("real meshes: hierarchy to the backstop stays manifold", "[lod][real]") {
  for (const char* name : {"bunny00", "armadillo", "refined_elephant"}) {
    auto m = support::load_mesh(support::cgal_mesh(name));
    REQUIRE(m.ok());
    auto sal = compute_saliency(*m);
    REQUIRE(sal.ok());
    auto clusters = salient_clustering(*m, sal->saliency, {.clusters = 10});
    REQUIRE(clusters.ok());
    auto wm = weighting_map(*m, sal->saliency, clusters->cluster, clusters->count);
    REQUIRE(wm.ok());
    auto h = make_contraction_hierarchy(*m, *wm, clusters->cluster, clusters->count);
    REQUIRE(h.ok());
    INFO(name << ": " << h->contraction_count() << " contractions of " << m->vertex_count() << " vertices");
    CHECK(h->contraction_count() + static_cast<std::size_t>(0.02 * static_cast<double>(m->vertex_count())) >= m->vertex_count());
    auto table = compute_cluster_attributes(*m, sal->saliency, clusters->cluster, clusters->count);
    REQUIRE(table.ok());
    auto lod = view_dependent_lod::create(*h, *table);
    REQUIRE(lod.ok());
    std::vector<std::uint32_t> out(contracted_index_bound(*h));
    std::vector<index_range> ranges(clusters->count);
    const bounding_box box = mesh_bounds(*m);
    const glm::dvec3 eye = box.center() + glm::dvec3(0.0, 0.0, 2.0 * box.diagonal());
    auto st = lod->frame({eye, box.center() - eye, {0.0, 1.0, 0.0}, 0.8, 256, 256}, h->triangle_count() / 20, out, ranges);
    if (!st.ok()) FAIL(st.error().message());
    // Boundary edges of the input stay the only boundary edges: count edges used once.
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> und;
    for (std::size_t k = 0; k < st->indices; k += 3)
      for (int j = 0; j < 3; ++j) {
        std::uint32_t a = out[k + static_cast<std::size_t>(j)], b = out[k + static_cast<std::size_t>((j + 1) % 3)];
        ++und[{std::min(a, b), std::max(a, b)}];
      }
    std::size_t non_manifold = 0;
    for (const auto& [e, n] : und) non_manifold += n > 2 ? 1 : 0;
    CHECK(non_manifold == 0);
  }
}

namespace {

// Neighbour matching one dependency at a time (the reference for the table's binary searches).
std::uint32_t reference_match(const contraction_hierarchy& h, std::span<std::uint32_t> stop) {
  std::uint32_t sweeps = 0;
  for (bool changed = true; changed;) {
    changed = false;
    ++sweeps;
    for (std::uint32_t c = 0; c < h.cluster_count; ++c)
      for (std::uint32_t k = h.cross_offsets[c]; k < h.cross_offsets[c + 1] && h.cross[k].order < stop[c]; ++k) {
        std::uint32_t& s = stop[h.cross[k].cluster];
        if (s <= h.cross[k].needs) s = h.cross[k].needs + 1, changed = true;
      }
  }
  return sweeps;
}

// budgets_for_removal as first written: 64 steps over the bits of τ, each summing budget_at
// over every cluster's whole range (the reference for the narrowed search).
double reference_budgets(const contraction_hierarchy& h, std::span<const float> maxima, std::span<const std::uint32_t> faces,
                         std::span<const double> k, std::span<const double> share, double goal, std::span<std::uint64_t> budget) {
  auto seen = [&](std::uint32_t c, std::uint64_t b) { return share[c] * static_cast<double>(removed_at(h, faces, c, b)); };
  auto sum_at = [&](double tau) {
    double s = 0.0;
    for (std::uint32_t c = 0; c < h.cluster_count; ++c) s += seen(c, budget_at(h, maxima, c, k[c], tau));
    return s;
  };
  constexpr double inf = std::numeric_limits<double>::infinity();
  const std::uint64_t top = std::bit_cast<std::uint64_t>(inf);
  std::uint64_t lo = 0, hi = top;
  bool below_zero = false;
  if (sum_at(inf) <= goal) lo = top;
  else if (sum_at(0.0) > goal) below_zero = true, hi = 0;
  while (!below_zero && lo != top && hi - lo > 1) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    (sum_at(std::bit_cast<double>(mid)) <= goal ? lo : hi) = mid;
  }
  double sum = 0.0;
  for (std::uint32_t c = 0; c < h.cluster_count; ++c)
    sum += seen(c, budget[c] = below_zero ? 0 : budget_at(h, maxima, c, k[c], std::bit_cast<double>(lo)));
  if (lo == top) return sum;
  for (std::uint32_t c = 0; c < h.cluster_count; ++c) {
    const std::uint64_t more = budget_at(h, maxima, c, k[c], std::bit_cast<double>(hi));
    if (more <= budget[c]) continue;
    if (share[c] <= 0.0) {
      budget[c] = more;
      continue;
    }
    const double room = static_cast<double>(removed_at(h, faces, c, budget[c])) + (goal - sum) / share[c];
    const auto b = faces.begin() + h.cluster_offsets[c];
    const auto at = std::upper_bound(b + static_cast<long>(budget[c]), b + static_cast<long>(more), room,
                                     [](double r, std::uint32_t f) { return r < static_cast<double>(f); });
    const auto nb = static_cast<std::uint64_t>(at - b);
    sum += seen(c, nb) - seen(c, budget[c]);
    budget[c] = nb;
  }
  return sum;
}

}  // namespace

TEST_CASE("selection: matching through the neighbour table and the narrowed bisection give the plain results", "[lod]") {
  const indexed_mesh m = support::subdivide_midpoint(support::make_icosphere(3));
  const std::vector<std::uint32_t> cl = octant_clusters(m);
  std::vector<double> wt(3 * m.triangle_count());
  for (std::size_t i = 0; i < wt.size(); ++i) wt[i] = 1.0 + 0.8 * std::sin(0.37 * static_cast<double>(i));
  auto h = make_contraction_hierarchy(m, wt, cl, 8, {.backstop = 0.01});
  REQUIRE(h.ok());
  REQUIRE(h->cross.size() > 50);
  const neighbour_table table = make_neighbour_table(*h);
  const std::vector<float> maxima = cluster_error_maxima(*h);
  const std::vector<std::uint32_t> faces = cluster_removed_faces(*h);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> in01(0.0, 1.0);
  std::size_t raised = 0;
  for (int round = 0; round < 300; ++round) {
    std::vector<std::uint32_t> stop(8), plain;
    for (auto& s : stop) s = static_cast<std::uint32_t>(rng() % (h->contraction_count() + 1));
    plain = stop;
    const std::uint32_t a = reference_match(*h, plain), b = match_neighbours(table, stop);
    CHECK(a == b);
    CHECK(plain == stop);
    raised += a > 1;
    std::vector<double> k(8), share(8);
    for (std::uint32_t c = 0; c < 8; ++c) k[c] = std::exp(6.0 * in01(rng) - 3.0), share[c] = round % 5 == 0 ? 1.0 : in01(rng);
    if (round % 7 == 0) share[rng() % 8] = 0.0;
    const double goal = (1.2 * in01(rng) - 0.1) * static_cast<double>(h->triangle_count());
    std::vector<std::uint64_t> budget(8), ref(8);
    const double sb = budgets_for_removal(*h, table.active, maxima, faces, k, share, goal, budget);
    const double sr = reference_budgets(*h, maxima, faces, k, share, goal, ref);
    CHECK(sb == sr);
    CHECK(budget == ref);
  }
  CHECK(raised > 10);
}

TEST_CASE("vertex contraction: the map updated between frames equals the map resolved anew", "[lod]") {
  const indexed_mesh m = support::subdivide_midpoint(support::make_icosphere(3));
  const std::vector<std::uint32_t> cl = octant_clusters(m);
  auto h = uniform_hierarchy(m, cl, 8, 0.01);
  REQUIRE(h.ok());
  const neighbour_table table = make_neighbour_table(*h);
  const auto n = static_cast<std::uint32_t>(h->contraction_count());
  contraction_workspace kept_between = make_contraction_workspace(*h);
  REQUIRE(kept_between.toggled.size() > 10);
  std::mt19937 rng(17);
  std::vector<std::uint32_t> stop(8, n / 2);
  std::size_t small_steps = 0;
  for (int frame = 0; frame < 400; ++frame) {
    // Mostly small moves of a few stop points (a moving camera), sometimes a jump of all of them.
    if (frame % 25 == 0) {
      for (auto& s : stop) s = static_cast<std::uint32_t>(rng() % (n + 1));
    } else {
      for (int moves = 0; moves < 3; ++moves) {
        std::uint32_t& s = stop[rng() % 8];
        const auto step = static_cast<std::int64_t>(rng() % 41) - 20;
        s = static_cast<std::uint32_t>(std::clamp<std::int64_t>(s + step, 0, n));
      }
      ++small_steps;
    }
    if (frame % 3 == 0) match_neighbours(table, stop);
    resolve_vertex_map(*h, stop, kept_between);
    contraction_workspace fresh = make_contraction_workspace(*h);
    resolve_vertex_map(*h, stop, fresh);
    REQUIRE(kept_between.remap == fresh.remap);
  }
  CHECK(small_steps > 300);
}
