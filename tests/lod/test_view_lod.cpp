// The default view-dependent selection (screen_error_selection.hpp through view_dependent_lod):
// any valid camera gets a crack-free LOD, bad cameras get a clear status, zero saliency keeps
// its planes (the weight floor of contraction_hierarchy.hpp).
#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <numbers>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <vector>
#include <catch2/catch.hpp>
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/lod_mesh.hpp"
#include "infolerp/lod/view_dependent_lod.hpp"
#include "infolerp/lod/weighting_map.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"

using namespace infolerp;

namespace {

// Every undirected edge used by exactly two triangles, once in each direction, no repeated index.
bool closed_and_manifold(std::span<const std::uint32_t> idx) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (std::size_t k = 0; k < idx.size(); k += 3) {
    if (idx[k] == idx[k + 1] || idx[k + 1] == idx[k + 2] || idx[k] == idx[k + 2]) return false;
    for (std::size_t j = 0; j < 3; ++j) ++directed[{idx[k + j], idx[k + (j + 1) % 3]}];
  }
  for (const auto& [e, n] : directed) {
    auto it = directed.find({e.second, e.first});
    if (n != 1 || it == directed.end() || it->second != 1) return false;
  }
  return true;
}

// Whether the triangles of a (as corner triples) are among those of b, counted with multiplicity.
bool is_sub_multiset(std::span<const std::uint32_t> a, std::span<const std::uint32_t> b) {
  std::map<std::array<std::uint32_t, 3>, int> count;
  for (std::size_t k = 0; k < b.size(); k += 3) ++count[{b[k], b[k + 1], b[k + 2]}];
  for (std::size_t k = 0; k < a.size(); k += 3)
    if (--count[{a[k], a[k + 1], a[k + 2]}] < 0) return false;
  return true;
}

std::vector<std::uint32_t> octants(const indexed_mesh& m) {
  std::vector<std::uint32_t> c(m.triangle_count());
  for (std::size_t t = 0; t < c.size(); ++t) {
    const glm::dvec3 x = triangle_centroid(corners(m, t));
    c[t] = (x.x > 0 ? 1u : 0u) | (x.y > 0 ? 2u : 0u) | (x.z > 0 ? 4u : 0u);
  }
  return c;
}

struct sphere_lod {
  indexed_mesh m = support::make_icosphere(3);
  std::vector<std::uint32_t> cl = octants(m);
  std::vector<double> sal;
  contraction_hierarchy h;
  cluster_table table;
  sphere_lod() {
    sal.resize(m.vertex_count());
    for (std::size_t v = 0; v < sal.size(); ++v) sal[v] = 1.0 + 0.5 * std::sin(3.0 * m.positions[v].x);
    auto w = weighting_map(m, sal, cl, 8);
    auto hh = make_contraction_hierarchy(m, *w, cl, 8, {.cluster_local_first = false});
    auto t = compute_cluster_attributes(m, sal, cl, 8);
    REQUIRE(hh.ok());
    REQUIRE(t.ok());
    h = std::move(*hh), table = std::move(*t);
  }
};

// Triangles of the coarsest cut (every contraction applied), counted from scratch: a triangle is
// kept when its three corners, each followed to the vertex it contracts to, stay distinct.
std::uint64_t coarsest_triangles(const contraction_hierarchy& h) {
  std::vector<std::uint32_t> to(h.vertex_count);
  for (std::uint32_t v = 0; v < h.vertex_count; ++v) to[v] = v;
  for (std::size_t i = h.contraction_count(); i-- > 0;) to[h.removed[i]] = to[h.target[i]];
  std::uint64_t n = 0;
  for (std::size_t k = 0; k < h.indices.size(); k += 3) {
    const std::uint32_t a = to[h.indices[k]], b = to[h.indices[k + 1]], c = to[h.indices[k + 2]];
    n += a != b && b != c && a != c;
  }
  return n;
}

lod_camera look_at(const glm::dvec3& eye, const glm::dvec3& at) { return {eye, at - eye, {0.0, 0.0, 1.0}, 0.8, 256, 256}; }

}  // namespace

TEST_CASE("view LOD: random cameras, inside the mesh included, get crack-free LODs within budget", "[lod]") {
  const sphere_lod s;
  auto lod = view_dependent_lod::create(s.h, s.table);
  auto whole = view_dependent_lod::create(s.h, s.table, {.view = {}, .keep_hidden = true});
  REQUIRE(lod.ok());
  REQUIRE(whole.ok());
  std::vector<std::uint32_t> out(contracted_index_bound(s.h)), cut_out(out.size());
  std::vector<index_range> ranges(8), cut_ranges(8);
  contraction_workspace w = make_contraction_workspace(s.h);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-3.0, 3.0), unit(-1.0, 1.0);
  const std::uint64_t nt = s.m.triangle_count(), coarsest = coarsest_triangles(s.h);
  std::uniform_int_distribution<std::uint64_t> budget(0, nt);
  for (int k = 0; k < 40; ++k) {
    // Every fourth camera inside the sphere (and inside every cluster's bounding sphere).
    // One draw per statement: the order of a constructor's arguments differs between compilers.
    const auto draw3 = [&](std::uniform_real_distribution<double>& d) {
      glm::dvec3 v;
      for (int a = 0; a < 3; ++a) v[a] = d(rng);
      return v;
    };
    const glm::dvec3 eye = k % 4 == 0 ? 0.3 * draw3(unit) : draw3(pos);
    lod_camera cam = look_at(eye, draw3(unit));
    if (glm::length(glm::cross(cam.forward, cam.up)) < 1e-3) continue;
    const std::uint64_t r = k == 1 ? 0 : k == 2 ? nt : budget(rng);
    INFO("camera " << k << ", budget " << r << " of " << nt << " triangles (coarsest cut " << coarsest << ")");
    // The whole cut (keep_hidden): closed and manifold, counted exactly, so within the budget
    // (the coarsest cut when the budget is below it), and not below half of it (the selection
    // falls back to a global prefix before matching leaves less).
    auto all = whole->frame(cam, r, out, ranges);
    if (!all.ok()) FAIL(all.error().message());
    CHECK(closed_and_manifold(std::span<const std::uint32_t>(out.data(), all->indices)));
    CHECK(all->indices / 3 <= std::max(r, coarsest));
    CHECK(all->indices / 3 >= std::min(r, nt) / 2);
    CHECK(all->estimated == all->indices / 3);
    if (r >= nt) CHECK(all->indices == 3 * nt);
    // The default frame: a subset of its own cut, which is closed and manifold (no crack).
    auto st = lod->frame(cam, r, out, ranges);
    if (!st.ok()) FAIL(st.error().message());
    auto cut = contract_indices(s.h, lod->stop_points(), w, cut_out, cut_ranges);
    REQUIRE(cut.ok());
    const std::span<const std::uint32_t> cut_idx(cut_out.data(), *cut);
    CHECK(closed_and_manifold(cut_idx));
    CHECK(is_sub_multiset(std::span<const std::uint32_t>(out.data(), st->indices), cut_idx));
    // Inside the sphere every triangle faces away, and every one the frustum holds is drawn.
    if (k % 4 == 0) CHECK(st->indices > 0);
    // Within budget as estimated from the samples (128 per cluster: here nearly every triangle),
    // and what is drawn within the estimate's error of it.
    CHECK(st->estimated <= std::max(r, coarsest));
    CHECK(st->indices / 3 <= std::max(r, coarsest) + nt / 50);
    std::size_t sum = 0;
    for (const index_range& g : ranges) sum += g.count;
    CHECK(sum == st->indices);
  }
}

TEST_CASE("view LOD: a camera inside the mesh, at its surface or far away gets a LOD under either selection", "[lod]") {
  const sphere_lod s;
  auto local = make_contraction_hierarchy(s.m, *weighting_map(s.m, s.sal, s.cl, 8), s.cl, 8, {.cluster_local_first = true});
  REQUIRE(local.ok());
  const std::vector<lod_camera> cams{look_at({0.0, 0.0, 0.0}, {1.0, 0.2, 0.1}),     // inside
                                     look_at({0.0, -1.0001, 0.0}, {0.0, 0.0, 0.0}),  // at the surface
                                     look_at({0.0, -1e7, 3.0}, {0.0, 0.0, 0.0}),     // far away
                                     look_at({0.0, -1e300, 3.0}, {0.0, 0.0, 0.0})};  // beyond float and a length's range
  for (lod_selection sel : {lod_selection::screen_error, lod_selection::paper}) {
    const contraction_hierarchy& h = sel == lod_selection::paper ? *local : s.h;
    auto lod = view_dependent_lod::create(h, s.table, {.selection = sel, .view = {}});
    REQUIRE(lod.ok());
    std::vector<std::uint32_t> out(contracted_index_bound(h));
    std::vector<index_range> ranges(8);
    for (std::size_t k = 0; k < cams.size(); ++k) {
      INFO("selection " << static_cast<int>(sel) << ", camera " << k);
      auto st = lod->frame(cams[k], s.m.triangle_count() / 4, out, ranges);
      if (!st.ok()) FAIL(st.error().message());
      CHECK(st->indices < 3 * s.m.triangle_count());
      CHECK(st->indices > 0);
    }
  }
}

TEST_CASE("view LOD: bad cameras get a clear status, legal extremes a LOD", "[lod]") {
  const sphere_lod s;
  auto lod = view_dependent_lod::create(s.h, s.table);
  REQUIRE(lod.ok());
  std::vector<std::uint32_t> out(contracted_index_bound(s.h));
  std::vector<index_range> ranges(8);
  const lod_camera good = look_at({0.0, -4.0, 1.0}, {0.0, 0.0, 0.0});
  REQUIRE(lod->frame(good, 10, out, ranges).ok());
  auto bad = [&](lod_camera c) { return lod->frame(c, 10, out, ranges).error(); };
  lod_camera c = good;
  c.position.x = std::nan("");
  CHECK(bad(c).code() == errc::bad_parameter);
  CHECK_THAT(bad(c).message(), Catch::Contains("position"));
  c = good, c.width = 0;
  CHECK(bad(c).code() == errc::bad_size);
  CHECK_THAT(bad(c).message(), Catch::Contains("viewport"));
  c = good, c.height = 0;
  CHECK(bad(c).code() == errc::bad_size);
  c = good, c.forward = glm::dvec3(0.0);
  CHECK(bad(c).code() == errc::bad_parameter);
  CHECK_THAT(bad(c).message(), Catch::Contains("forward"));
  c = good, c.up = glm::dvec3(0.0);
  CHECK_THAT(bad(c).message(), Catch::Contains("up vector is zero"));
  c = good, c.up = c.forward;
  CHECK_THAT(bad(c).message(), Catch::Contains("parallel"));
  c = good, c.vertical_fov = 0.0;
  CHECK_THAT(bad(c).message(), Catch::Contains("vertical_fov"));
  c = good, c.vertical_fov = std::numbers::pi;
  CHECK_THAT(bad(c).message(), Catch::Contains("vertical_fov"));
  c = good, c.vertical_fov = std::nan("");
  CHECK(bad(c).code() == errc::bad_parameter);
  // Any finite length of forward and up, and any fov below π, is a camera: the same frame as
  // with unit vectors (the huge and tiny ones overflow or underflow a plain length).
  const std::uint64_t half = s.m.triangle_count() / 2;
  auto ref = lod->frame(good, half, out, ranges);
  REQUIRE(ref.ok());
  const std::vector<std::uint32_t> expected(out.begin(), out.begin() + static_cast<long>(ref->indices));
  for (const double scale : {1e160, 1e300, 1e-200, 1e-310}) {
    INFO("forward and up scaled by " << scale);
    c = good, c.forward *= scale, c.up *= scale;
    auto st = lod->frame(c, half, out, ranges);
    if (!st.ok()) FAIL(st.error().message());
    CHECK(std::vector<std::uint32_t>(out.begin(), out.begin() + static_cast<long>(st->indices)) == expected);
  }
  c = good, c.vertical_fov = std::nextafter(std::numbers::pi, 0.0);
  CHECK(lod->frame(c, half, out, ranges).ok());
  CHECK(view_dependent_lod::create(s.h, s.table, {.view = {.hidden_weight = 0.0}}).error().code() == errc::bad_parameter);
  CHECK(view_dependent_lod::create(s.h, s.table, {.view = {.silhouette_weight = 0.5}}).error().code() == errc::bad_parameter);
  const std::uint32_t nine = 9;
  CHECK(view_dependent_lod::create(s.h, s.table, {.view = {}, .two_sided = std::span<const std::uint32_t>(&nine, 1)}).error().code() ==
        errc::index_out_of_range);
  CHECK(make_contraction_hierarchy(s.m, std::vector<double>(3 * s.m.triangle_count(), 1.0), s.cl, 8, {.weight_floor = 2.0})
            .error()
            .code() == errc::bad_parameter);
  // lod_selection::paper on a hierarchy without the cluster-local phase would be one global
  // prefix whatever the camera: refused, naming what it needs.
  auto paper = view_dependent_lod::create(s.h, s.table, {.selection = lod_selection::paper, .view = {}});
  CHECK(paper.error().code() == errc::bad_parameter);
  CHECK_THAT(paper.error().message(), Catch::Contains("cluster_local_first"));
}

TEST_CASE("view LOD: a flat L-shaped sheet, half of it of zero saliency, keeps its area at 50%", "[lod]") {
  // 40 x 40 unit cells without the quadrant x, y >= 20: 1,200 units of area, two clusters.
  indexed_mesh m;
  std::map<std::pair<int, int>, std::uint32_t> id;
  auto vertex = [&](int x, int y) {
    auto [it, fresh] = id.try_emplace({x, y}, static_cast<std::uint32_t>(m.positions.size()));
    if (fresh) m.positions.emplace_back(static_cast<float>(x), static_cast<float>(y), 0.0f);
    return it->second;
  };
  std::vector<std::uint32_t> cl;
  for (int x = 0; x < 40; ++x)
    for (int y = 0; y < 40; ++y) {
      if (x >= 20 && y >= 20) continue;
      const std::uint32_t a = vertex(x, y), b = vertex(x + 1, y), c = vertex(x + 1, y + 1), d = vertex(x, y + 1);
      m.triangles.push_back({a, b, c});
      m.triangles.push_back({a, c, d});
      cl.insert(cl.end(), 2, x < 20 ? 0u : 1u);
    }
  // Saliency 0 on cluster 0's vertices (x <= 20), 1 beyond; without smoothing cluster 0's
  // weights are all 0, so only the floor keeps its corners and borders.
  std::vector<double> sal(m.vertex_count(), 0.0);
  for (std::size_t v = 0; v < sal.size(); ++v) sal[v] = m.positions[v].x > 20.5f ? 1.0 : 0.0;
  auto w = weighting_map(m, sal, cl, 2, {.smoothing_scale = 0.0});
  REQUIRE(w.ok());
  auto h = make_contraction_hierarchy(m, *w, cl, 2, {.cluster_local_first = false});
  auto table = compute_cluster_attributes(m, sal, cl, 2);
  REQUIRE(h.ok());
  REQUIRE(table.ok());
  auto lod = view_dependent_lod::create(*h, *table);
  REQUIRE(lod.ok());
  std::vector<std::uint32_t> out(contracted_index_bound(*h));
  std::vector<index_range> ranges(2);
  auto st = lod->frame(look_at({20.0, -30.0, 40.0}, {20.0, 20.0, 0.0}), 1200, out, ranges);
  if (!st.ok()) FAIL(st.error().message());
  REQUIRE(st->indices <= 3 * 1200);  // half of the 2,400 triangles
  REQUIRE(st->indices >= 3 * 600);
  double area = 0.0;
  bool flipped = false, outside = false;
  for (std::size_t k = 0; k < st->indices; k += 3) {
    const glm::dvec3 a(m.positions[out[k]]), b(m.positions[out[k + 1]]), c(m.positions[out[k + 2]]);
    const double z = 0.5 * glm::cross(b - a, c - a).z;
    flipped = flipped || z <= 0.0;
    area += z;
    const glm::dvec3 g = (a + b + c) / 3.0;
    outside = outside || (g.x > 20.0 && g.y > 20.0);
  }
  // With every triangle upright and inside the L, the covered area equals 1,200 only if the
  // boundary is kept: Hausdorff distance 0 up to rounding.
  CHECK_FALSE(flipped);
  CHECK_FALSE(outside);
  CHECK(std::abs(area - 1200.0) <= 1e-6 * std::sqrt(2.0) * 40.0);
}

TEST_CASE("view LOD: four cameras around armadillo give four different crack-free sets within budget", "[lod][real]") {
  auto m = support::load_mesh(support::cgal_mesh("armadillo"));
  REQUIRE(m.ok());
  auto sal = compute_saliency(*m);
  REQUIRE(sal.ok());
  auto cl = salient_clustering(*m, sal->saliency, {.clusters = 10});
  REQUIRE(cl.ok());
  auto w = weighting_map(*m, sal->saliency, cl->cluster, cl->count);
  REQUIRE(w.ok());
  auto h = make_contraction_hierarchy(*m, *w, cl->cluster, cl->count, {.cluster_local_first = false});
  auto table = compute_cluster_attributes(*m, sal->saliency, cl->cluster, cl->count);
  REQUIRE(h.ok());
  REQUIRE(table.ok());
  auto lod = view_dependent_lod::create(*h, *table);
  REQUIRE(lod.ok());
  const bounding_box box = mesh_bounds(*m);
  const std::size_t nt = m->triangle_count();
  const std::uint64_t budget = nt / 10;
  std::vector<std::uint32_t> out(contracted_index_bound(*h)), cut_out(out.size());
  std::vector<index_range> ranges(cl->count), cut_ranges(cl->count);
  contraction_workspace work = make_contraction_workspace(*h);
  std::vector<std::vector<std::uint32_t>> sets;
  for (const glm::dvec3 dir : {glm::dvec3(1, 0, 0), glm::dvec3(-1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0, 0, -1)}) {
    const glm::dvec3 eye = box.center() + 1.5 * box.diagonal() * dir;
    auto st = lod->frame({eye, box.center() - eye, {0.0, 1.0, 0.0}, 0.7, 512, 512}, budget, out, ranges);
    if (!st.ok()) FAIL(st.error().message());
    INFO("camera direction " << dir.x << " " << dir.y << " " << dir.z << ": " << st->indices / 3 << " triangles drawn, "
                             << st->estimated << " estimated, budget " << budget);
    // The budget counts the triangles drawn: the selection's estimate meets it from below, and
    // the count drawn is within the estimate's error (a sample of 128 triangles per cluster).
    CHECK(st->estimated <= budget);
    CHECK(st->estimated >= budget - nt / 100);
    CHECK(st->indices / 3 >= budget * 8 / 10);
    CHECK(st->indices / 3 <= budget * 12 / 10);
    // What is drawn is part of the frame's cut, which is closed and manifold (no crack).
    auto cut = contract_indices(*h, lod->stop_points(), work, cut_out, cut_ranges);
    REQUIRE(cut.ok());
    const std::span<const std::uint32_t> cut_idx(cut_out.data(), *cut), ours(out.data(), st->indices);
    CHECK(closed_and_manifold(cut_idx));
    CHECK(is_sub_multiset(ours, cut_idx));
    CHECK(st->indices < *cut);
    std::vector<std::uint32_t> sorted(ours.begin(), ours.end());
    std::sort(sorted.begin(), sorted.end());
    for (const auto& other : sets) CHECK(other != sorted);
    sets.push_back(std::move(sorted));
  }
}

TEST_CASE("view LOD: weights of any finite scale give the hierarchy of weight 1 and honour the budget", "[lod]") {
  const sphere_lod s;
  const std::size_t nt = s.m.triangle_count();
  auto unit = make_contraction_hierarchy(s.m, std::vector<double>(3 * nt, 1.0), s.cl, 8);
  REQUIRE(unit.ok());
  const lod_camera cam = look_at({0.5, -3.0, 1.0}, {0.0, 0.0, 0.0});
  for (const double w : {1e-300, 1e-30, 1e30, 1e300, std::numeric_limits<double>::max()}) {
    INFO("every weight " << w);
    auto h = make_contraction_hierarchy(s.m, std::vector<double>(3 * nt, w), s.cl, 8);
    REQUIRE(h.ok());
    CHECK(h->removed == unit->removed);  // the same order: only the weights' ratios count
    CHECK(h->target == unit->target);
    for (const bool keep : {true, false}) {
      auto lod = view_dependent_lod::create(*h, s.table, {.view = {}, .keep_hidden = keep});
      REQUIRE(lod.ok());
      std::vector<std::uint32_t> out(contracted_index_bound(*h));
      std::vector<index_range> ranges(8);
      auto full = lod->frame(cam, nt, out, ranges);
      REQUIRE(full.ok());
      CHECK(full->applied == 0);  // the full mesh: nothing contracted
      if (keep) CHECK(full->indices == 3 * nt);
      auto half = lod->frame(cam, nt / 2, out, ranges);
      REQUIRE(half.ok());
      CHECK(half->indices / 3 <= nt / 2);
      if (keep) CHECK(half->indices / 3 >= nt / 4);
    }
  }
  // A mix of extremes: the largest double beside 1e-300 is finite and refused nowhere.
  std::vector<double> mixed(3 * nt);
  for (std::size_t i = 0; i < mixed.size(); ++i) mixed[i] = i % 2 ? std::numeric_limits<double>::max() : 1e-300;
  auto h = make_contraction_hierarchy(s.m, mixed, s.cl, 8);
  REQUIRE(h.ok());
  auto lod = view_dependent_lod::create(*h, s.table, {.view = {}, .keep_hidden = true});
  REQUIRE(lod.ok());
  std::vector<std::uint32_t> out(contracted_index_bound(*h));
  std::vector<index_range> ranges(8);
  auto st = lod->frame(cam, nt / 3, out, ranges);
  REQUIRE(st.ok());
  CHECK(st->indices / 3 <= nt / 3);
  CHECK(st->indices / 3 >= nt / 6);
}

TEST_CASE("view LOD: a frame's cost follows the clusters that hold triangles, not the cluster ids allocated", "[lod]") {
  // The octants of sphere_lod as clusters k * 2^17 + 5 of 2^20: the same frames as with 8 ids.
  const sphere_lod s;
  constexpr std::uint32_t many = 1u << 20;
  std::vector<std::uint32_t> sparse(s.cl.size());
  for (std::size_t t = 0; t < sparse.size(); ++t) sparse[t] = s.cl[t] * (many / 8) + 5;
  auto w = weighting_map(s.m, s.sal, s.cl, 8);
  REQUIRE(w.ok());
  auto h = make_contraction_hierarchy(s.m, *w, sparse, many, {.cluster_local_first = false});
  auto table = compute_cluster_attributes(s.m, s.sal, sparse, many);
  REQUIRE(h.ok());
  REQUIRE(table.ok());
  auto lod = view_dependent_lod::create(*h, *table);
  auto dense = view_dependent_lod::create(s.h, s.table);
  REQUIRE(lod.ok());
  REQUIRE(dense.ok());
  std::vector<std::uint32_t> out(contracted_index_bound(*h)), out_dense(out.size());
  std::vector<index_range> ranges(many), ranges_dense(8);
  double frame_s = 1e30, fill_s = 1e30;
  for (int k = 0; k < 6; ++k) {
    const lod_camera cam = look_at({3.0 * std::cos(k), 3.0 * std::sin(k), 0.5 * k - 1.0}, {0.0, 0.0, 0.0});
    const auto budget = static_cast<std::uint64_t>(100 * (k + 1));
    const auto t0 = std::chrono::steady_clock::now();
    auto st = lod->frame(cam, budget, out, ranges);
    frame_s = std::min(frame_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    auto ref = dense->frame(cam, budget, out_dense, ranges_dense);
    REQUIRE(st.ok());
    REQUIRE(ref.ok());
    CHECK(st->indices == ref->indices);
    CHECK(std::equal(out.begin(), out.begin() + static_cast<long>(st->indices), out_dense.begin()));
    // The unavoidable per-id work, measured beside it: writing one range per cluster id.
    const auto t1 = std::chrono::steady_clock::now();
    std::fill(ranges.begin(), ranges.end(), index_range{static_cast<std::uint32_t>(k), 0});
    fill_s = std::min(fill_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
  }
  INFO("frame " << frame_s << " s, one pass over the ranges " << fill_s << " s");
  // A selection visiting every id in each of its bisection steps costs thousands of passes.
  CHECK(frame_s < 100.0 * fill_s);
}

TEST_CASE("lod_mesh: one call from a mesh to frames within a triangle budget, the chain's output", "[lod]") {
  const indexed_mesh m = support::make_icosphere(4);
  auto lod = make_lod_mesh(m);  // saliency computed inside
  if (!lod.ok()) FAIL(lod.error().message());
  REQUIRE(lod->triangle_count() == m.triangle_count());
  std::vector<std::uint32_t> indices(lod->index_bound());
  std::vector<index_range> ranges(lod->range_count());
  const lod_camera cam = look_at({0.4, -3.0, 1.2}, {0.0, 0.0, 0.0});
  auto st = lod->frame(cam, 500, indices, ranges);
  REQUIRE(st.ok());
  CHECK(st->indices / 3 <= 500);
  CHECK(st->indices / 3 >= 250);
  // The same frame from the chain of steps, each called as the README shows them.
  auto sal = compute_saliency(m);
  REQUIRE(sal.ok());
  auto cl = salient_clustering(m, sal->saliency);
  REQUIRE(cl.ok());
  auto w = weighting_map(m, sal->saliency, cl->cluster, cl->count);
  REQUIRE(w.ok());
  auto h = make_contraction_hierarchy(m, *w, cl->cluster, cl->count);
  auto table = compute_cluster_attributes(m, sal->saliency, cl->cluster, cl->count);
  REQUIRE(h.ok());
  REQUIRE(table.ok());
  auto chain = view_dependent_lod::create(*h, *table);
  REQUIRE(chain.ok());
  std::vector<std::uint32_t> expected(contracted_index_bound(*h));
  std::vector<index_range> chain_ranges(cl->count);
  auto ref = chain->frame(cam, 500, expected, chain_ranges);
  REQUIRE(ref.ok());
  CHECK(std::vector<std::uint32_t>(indices.begin(), indices.begin() + static_cast<long>(st->indices)) ==
        std::vector<std::uint32_t>(expected.begin(), expected.begin() + static_cast<long>(ref->indices)));
  // A moved lod_mesh keeps working (it owns what its view_dependent_lod points at).
  lod_mesh moved = std::move(*lod);
  auto again = moved.frame(cam, 500, indices, ranges);
  REQUIRE(again.ok());
  CHECK(again->indices == st->indices);
  // Errors of the steps come back named.
  const std::vector<double> short_saliency(m.vertex_count() - 1, 1.0);
  auto bad = make_lod_mesh(m, short_saliency);
  CHECK(bad.error().code() == errc::bad_size);
  std::vector<double> negative(m.vertex_count(), 1.0);
  negative[7] = -1.0;
  CHECK_FALSE(make_lod_mesh(m, negative).ok());
}
