// cluster/channel.hpp, orientation_channel.hpp, stretch_channel.hpp, visibility_channel.hpp
// against brute-force M×M references and analytic cases.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <vector>
#include <glm/gtc/matrix_transform.hpp>
#include "brute_tracer.hpp"
#include "infolerp/cluster/orientation_channel.hpp"
#include "infolerp/cluster/region_growing.hpp"
#include "infolerp/cluster/stretch_channel.hpp"
#include "infolerp/cluster/visibility_channel.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "support/procedural.hpp"

using namespace infolerp;

namespace {
std::vector<std::uint32_t> all_triangles(std::size_t n) {
  std::vector<std::uint32_t> v(n);
  std::iota(v.begin(), v.end(), 0u);
  return v;
}

// Full M×M direct channel from a per-pair kernel: rows p(t'|t), p(t) = 1/M.
template <class K>
std::vector<std::vector<double>> full_rows(std::size_t m, K kernel) {
  std::vector<std::vector<double>> rows(m, std::vector<double>(m));
  for (std::size_t a = 0; a < m; ++a) {
    double z = 0.0;
    for (std::size_t b = 0; b < m; ++b) z += rows[a][b] = kernel(a, b);
    for (std::size_t b = 0; b < m; ++b) rows[a][b] = z > 0.0 ? rows[a][b] / z : 1.0 / double(m);
  }
  return rows;
}
double full_mi(const std::vector<std::vector<double>>& rows, std::size_t a) {
  const std::size_t m = rows.size();
  double sum = 0.0;
  for (std::size_t y = 0; y < m; ++y) {
    double py = 0.0;
    for (std::size_t x = 0; x < m; ++x) py += rows[x][y] / double(m);
    if (rows[a][y] > 0.0) sum += rows[a][y] * std::log2(rows[a][y] / py);
  }
  return sum;
}

template <class State>
void compare_with_full(const State& s, const std::vector<std::vector<double>>& rows, double tol) {
  const std::size_t m = rows.size();
  for (std::uint32_t a = 0; a < m; a += 7)
    for (std::uint32_t b = 0; b < m; b += 3) {
      const double ref = js_divergence(std::span<const double>(rows[a]), std::span<const double>(rows[b]), 0.5);
      REQUIRE(s.divergence(s.class_of(a), s.class_of(b)) == Approx(ref).margin(tol));
    }
  for (std::uint32_t a = 0; a < m; a += 11) REQUIRE(s.mutual_information(s.class_of(a)) == Approx(full_mi(rows, a)).margin(tol));
}
}  // namespace

TEST_CASE("orientation exact rows equal the brute-force M x M channel", "[cluster][orientation]") {
  const auto m = support::make_torus(12, 8, 1.0f, 0.3f);
  const auto n = face_normals(m);
  const auto rows = full_rows(n.size(), [&](std::size_t a, std::size_t b) {
    return std::max(0.0, 1.0 - glm::dot(glm::dvec3(n[a]), glm::dvec3(n[b])));
  });
  const auto s = make_orientation_state(n, 0);
  compare_with_full(s, rows, 1e-9);
  // A batch column equals single evaluations.
  std::vector<float> col(s.class_count());
  s.divergences(3, 0, col);
  for (std::uint32_t c = 0; c < col.size(); ++c) REQUIRE(col[c] == static_cast<float>(s.divergence(3, c)));
}

TEST_CASE("orientation: identical normals share one class; a planar patch is all alike", "[cluster][orientation]") {
  const auto box = support::make_box({0, 0, 0}, {1, 2, 3});
  const auto s = make_orientation_state(face_normals(box), 0);
  REQUIRE(s.class_count() == 6);
  const auto plane = support::make_plane(8, 8, 2.0f);
  for (std::uint32_t bins : {0u, 256u}) {
    const auto p = make_orientation_state(face_normals(plane), bins);
    REQUIRE(p.class_count() == 1);
    REQUIRE(p.all_alike());
    REQUIRE(p.divergence(0, 0) == 0.0);
  }
}

TEST_CASE("direct channel: Pinsker MI bound and estimate where rows are stored, none where not", "[cluster][orientation]") {
  const auto m = support::make_icosphere(3);
  const auto n = face_normals(m);
  const auto binned = make_orientation_state(n, 256);  // rows stored (U·C <= 65,536)
  REQUIRE(binned.class_count() * binned.kernel().column_count() <= binned.max_stored_entries);
  REQUIRE(std::isfinite(binned.estimate_error()));
  double largest_bound = 0.0;
  for (std::uint32_t a = 0; a < binned.class_count(); ++a) {
    const double bound = binned.mutual_information_lower_bound(a);
    REQUIRE(bound <= binned.mutual_information(a) + 1e-12);
    largest_bound = std::max(largest_bound, bound);
    for (std::uint32_t b = 0; b < binned.class_count(); b += 7)
      REQUIRE(std::abs(binned.estimate(a, b) - binned.divergence(a, b)) <= binned.estimate_error());
  }
  REQUIRE(largest_bound > 0.0);  // the bound decides something
  const auto exact = make_orientation_state(n, 0);  // 1280 classes: rows not stored
  REQUIRE(exact.class_count() * exact.kernel().column_count() > exact.max_stored_entries);
  REQUIRE(exact.estimate_error() == std::numeric_limits<double>::infinity());
  REQUIRE(exact.mutual_information_lower_bound(0) == 0.0);
}

TEST_CASE("orientation binned rows approach exact rows as K grows", "[cluster][orientation]") {
  const auto m = support::make_icosphere(3);
  const auto n = face_normals(m);
  const auto exact = make_orientation_state(n, 0);
  double previous = 1.0;
  for (std::uint32_t bins : {64u, 1024u, 16384u}) {
    const auto binned = make_orientation_state(n, bins);
    double worst = 0.0;
    for (std::uint32_t a = 0; a < n.size(); a += 37)
      for (std::uint32_t b = 0; b < n.size(); b += 13)
        worst = std::max(worst, std::abs(binned.divergence(binned.class_of(a), binned.class_of(b)) -
                                         exact.divergence(exact.class_of(a), exact.class_of(b))));
    INFO("bins " << bins << " worst |ΔJS| " << worst);
    REQUIRE(worst < previous);
    previous = worst;
  }
  REQUIRE(previous < 0.02);
}

TEST_CASE("Degener stretch of analytic Jacobians", "[cluster][stretch]") {
  const triangle_corners c{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  // J = diag(2, 1): σ1 = 2, σ2 = 1 → (2 + 1/2)·(2 + 1/2) = 6.25.
  REQUIRE(degener_stretch(c, {0, 0}, {2, 0}, {0, 1}, 1.0, 1.0) == Approx(6.25));
  // Isometry (a rotation in UV): the minimum, 4.
  const double r = std::sqrt(0.5);
  REQUIRE(degener_stretch(c, {0, 0}, {r, r}, {-r, r}, 1.0, 1.0) == Approx(4.0));
  // θ = 0 keeps only the angle term.
  REQUIRE(degener_stretch(c, {0, 0}, {2, 0}, {0, 1}, 1.0, 0.0) == Approx(2.5));
  // The angle term is scale-free, also where σ² would overflow or underflow a double.
  REQUIRE(degener_stretch(c, {0, 0}, {2, 0}, {0, 1}, 0x1p600, 0.0) == Approx(2.5));
  REQUIRE(degener_stretch(c, {0, 0}, {2, 0}, {0, 1}, 0x1p-600, 0.0) == Approx(2.5));
  // Zero-area UV image: the stated special case.
  REQUIRE(std::isinf(degener_stretch(c, {0, 0}, {1, 0}, {2, 0}, 1.0, 1.0)));
  const double raw[] = {5.0, 7.0, std::numeric_limits<double>::infinity(), 6.0};
  const auto s = make_stretch_state(raw, 0);
  REQUIRE(s.class_count() == 3);  // 7 and the special case both normalise to 1
  REQUIRE(s.kernel().reps[s.class_of(0)] == 0.0);
  REQUIRE(s.kernel().reps[s.class_of(1)] == 1.0);
  REQUIRE(s.kernel().reps[s.class_of(2)] == 1.0);  // special case: the set's largest, 1
  REQUIRE(s.kernel().reps[s.class_of(3)] == Approx(0.5));
}

TEST_CASE("stretch exact rows equal the brute-force M x M channel", "[cluster][stretch]") {
  const auto m = support::make_uv_sphere(10, 8);
  auto raw = texture_stretch(m);
  REQUIRE(raw.ok());
  const auto s = make_stretch_state(*raw, 0);
  double lo = 1e300, hi = -1e300;
  for (double v : *raw) lo = std::min(lo, v), hi = std::max(hi, v);
  std::vector<double> norm(raw->size());
  for (std::size_t i = 0; i < norm.size(); ++i) norm[i] = ((*raw)[i] - lo) / (hi - lo);
  const auto rows = full_rows(norm.size(), [&](std::size_t a, std::size_t b) { return 1.0 - std::abs(norm[a] - norm[b]); });
  compare_with_full(s, rows, 1e-9);
  // Stretch grows toward the poles: the polar cap is the most stretched, the equator the least.
  const double equator = (*raw)[2 * 10 * 3 + 1], pole = (*raw)[0];
  REQUIRE(pole > equator);
}

TEST_CASE("stretch channel is skipped on meshes without texcoords", "[cluster][stretch]") {
  const auto m = support::make_icosphere(1);
  serial_executor exec;
  auto topo = make_topology(m);
  REQUIRE(topo.ok());
  auto p = stretch_channel{}.prepare(m, *topo, 0, exec);
  REQUIRE(p.ok());
  REQUIRE(p->skip_reason() != nullptr);
  REQUIRE_FALSE(p->init(std::vector<std::uint32_t>{0, 1}).ok());
  auto bad = stretch_channel{.theta = -1.0}.prepare(support::make_uv_sphere(6, 4), *topo, 0, exec);
  REQUIRE_FALSE(bad.ok());
  REQUIRE(bad.error().code() == errc::bad_parameter);
}

TEST_CASE("visibility: Bayes inversion, occlusion and unseen triangles", "[cluster][visibility]") {
  // A floor plane with a small roof above its centre, and a triangle sealed inside a closed box.
  indexed_mesh scene = support::make_plane(6, 6, 2.0f);
  const std::size_t floor_count = scene.triangles.size();
  support::append(scene, support::make_plane(1, 1, 0.6f), glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 0.3f)));
  const std::size_t inner = scene.triangles.size();
  support::append(scene, support::make_plane(1, 1, 0.1f), glm::translate(glm::mat4(1.0f), glm::vec3(3, 3, 0)));
  support::append(scene, support::make_box({2.8f, 2.8f, -0.2f}, {3.2f, 3.2f, 0.2f}));
  test::brute_tracer tracer(scene);
  auto topo = make_topology(scene);
  REQUIRE(topo.ok());
  serial_executor exec;
  std::size_t calls = 0, last = 0;
  const visibility_channel opts{.viewpoints = 24, .denoise = false,
                                .progress = [&](std::size_t done, std::size_t total) {
                                  ++calls;
                                  REQUIRE(done >= last);
                                  REQUIRE(total == scene.triangles.size());
                                  last = done;
                                }};
  auto p = opts.prepare(scene, *topo, tracer, exec);
  REQUIRE(p.ok());
  REQUIRE(calls >= 1);
  REQUIRE(last == scene.triangles.size());
  // The roof's underside is back-facing from above and the floor below the roof is covered.
  const auto tris = all_triangles(scene.triangles.size());
  auto s = p->init(tris);
  REQUIRE(s.ok());
  // Rows are distributions, p(t) sums to 1 over the set.
  double total = 0.0;
  for (std::uint32_t t = 0; t < tris.size(); ++t) {
    total += s->input_probability(t);
    if (s->unseen(t)) continue;
    double row = 0.0;
    for (float x : s->row(t)) row += x;
    REQUIRE(row == Approx(1.0).epsilon(1e-5));
  }
  REQUIRE(total == Approx(1.0));
  // p(t|v) = OR(t,v) / Σ_t' OR(t',v), p(v) = 1/N_active, p(t) = Σ_v p(v) p(t|v) and
  // p(v|t) = p(v) p(t|v) / p(t), written out from occlusion_ratio: on the whole scene, and on
  // the floor alone, which the viewpoints below it do not see (N_active < N).
  auto check_bayes = [&](std::span<const std::uint32_t> set, bool all_active) {
    auto st = p->init(set);
    REQUIRE(st.ok());
    std::vector<double> weight(p->viewpoints, 0.0);
    for (std::uint32_t t : set)
      for (std::size_t v = 0; v < p->viewpoints; ++v) weight[v] += p->occlusion_ratio(t, v);
    const auto active = std::count_if(weight.begin(), weight.end(), [](double w) { return w > 0.0; });
    REQUIRE((static_cast<std::size_t>(active) == p->viewpoints) == all_active);
    for (std::uint32_t i = 0; i < set.size(); ++i) {
      double pt = 0.0;
      for (std::size_t v = 0; v < p->viewpoints; ++v)
        if (weight[v] > 0.0) pt += p->occlusion_ratio(set[i], v) / weight[v] / static_cast<double>(active);
      REQUIRE(st->input_probability(i) == Approx(pt).epsilon(1e-12).margin(1e-300));
      for (std::size_t v = 0; v < p->viewpoints; ++v) {
        const double want = pt > 0.0 && weight[v] > 0.0 ? p->occlusion_ratio(set[i], v) / weight[v] / static_cast<double>(active) / pt : 0.0;
        REQUIRE(static_cast<double>(st->row(i)[v]) == Approx(want).epsilon(1e-6).margin(1e-12));
      }
    }
  };
  check_bayes(tris, true);
  check_bayes(std::span<const std::uint32_t>(tris).first(floor_count), false);
  // The sealed triangles are unseen: their own class.
  REQUIRE(s->unseen(static_cast<std::uint32_t>(inner)));
  REQUIRE(s->unseen(static_cast<std::uint32_t>(inner + 1)));
  REQUIRE(s->divergence(static_cast<std::uint32_t>(inner), static_cast<std::uint32_t>(inner + 1)) == 0.0);
  REQUIRE(s->divergence(static_cast<std::uint32_t>(inner), 0) == 1.0);
  REQUIRE(std::isinf(s->mutual_information(static_cast<std::uint32_t>(inner))));
  // A floor triangle under the roof sees fewer viewpoints than one at the floor's edge.
  std::size_t under = 0, edge = 0;
  for (std::size_t t = 0; t < floor_count; ++t) {
    const auto c = triangle_centroid(corners(scene, t));
    if (std::abs(c.x) < 0.15 && std::abs(c.y) < 0.15) under = t;
    if (c.x > 0.8 && c.y > 0.8) edge = t;
  }
  std::size_t seen_under = 0, seen_edge = 0;
  for (std::size_t v = 0; v < p->viewpoints; ++v) {
    seen_under += p->occlusion_ratio(under, v) > 0.0;
    seen_edge += p->occlusion_ratio(edge, v) > 0.0;
  }
  REQUIRE(seen_under < seen_edge);
  // Deterministic for any executor.
  auto p2 = opts.prepare(scene, *topo, tracer, exec);
  REQUIRE(p2->visible == p->visible);
}

// A UV sphere under a roof, 32 viewpoints: rows from alike to disjoint, symmetric rows, and
// unseen triangles under the cap; the state of the visibility channel on all of it.
struct sphere_under_roof {
  indexed_mesh scene;
  mesh_topology topo;
  prepared_visibility_channel channel;
};
static sphere_under_roof make_sphere_under_roof() {
  sphere_under_roof r{support::make_uv_sphere(16, 10), {}, {}};
  support::append(r.scene, support::make_plane(2, 2, 0.8f), glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 1.3f)));
  test::brute_tracer tracer(r.scene);
  auto topo = make_topology(r.scene);
  REQUIRE(topo.ok());
  r.topo = std::move(*topo);
  serial_executor exec;
  auto p = visibility_channel{.viewpoints = 32}.prepare(r.scene, r.topo, tracer, exec);
  REQUIRE(p.ok());
  r.channel = std::move(*p);
  return r;
}
static visibility_state sphere_under_roof_state() {
  const sphere_under_roof r = make_sphere_under_roof();
  auto s = r.channel.init(all_triangles(r.scene.triangles.size()));
  REQUIRE(s.ok());
  return std::move(*s);
}

TEST_CASE("visibility: denoising averages each row with its neighbours within Th", "[cluster][visibility]") {
  // §3.2.1 written out: the denoised row of t is the mean of the raw rows of t and of its edge
  // neighbours j (seen, in the set) with raw JS(t, j) <= Th; unseen rows stay 0.
  sphere_under_roof r = make_sphere_under_roof();
  prepared_visibility_channel* p = &r.channel;
  const mesh_topology* topo = &r.topo;
  const auto set = all_triangles(r.scene.triangles.size());
  const std::size_t n = p->viewpoints;
  std::size_t averaged = 0, alone = 0;
  for (const double th : {0.48, 0.01}) {  // the default, and one under which some rows stay alone
    p->threshold = th;
    p->denoise = true;
    auto denoised = p->init(set);
    p->denoise = false;
    auto raw = p->init(set);
    REQUIRE(denoised.ok());
    REQUIRE(raw.ok());
    for (std::uint32_t t = 0; t < set.size(); ++t) {
      REQUIRE(denoised->input_probability(t) == raw->input_probability(t));
      std::vector<double> sum(raw->row(t).begin(), raw->row(t).end());
      std::size_t count = 1;
      if (!raw->unseen(t))
        for (std::uint32_t j : topo->neighbours_of(t))
          if (!raw->unseen(j) && raw->divergence(t, j) <= th) {
            for (std::size_t v = 0; v < n; ++v) sum[v] += raw->row(j)[v];
            ++count;
          }
      (count > 1 ? averaged : alone) += 1;
      for (std::size_t v = 0; v < n; ++v)
        REQUIRE(static_cast<double>(denoised->row(t)[v]) ==
                Approx(sum[v] / static_cast<double>(count)).epsilon(1e-6).margin(1e-12));
    }
  }
  REQUIRE(averaged > set.size() / 2);  // the scene exercises both cases
  REQUIRE(alone > 0);
}

TEST_CASE("visibility: within() gives exactly divergence() <= Th", "[cluster][visibility]") {
  const visibility_state s = sphere_under_roof_state();
  std::size_t checked = 0, below = 0;
  const auto m = static_cast<std::uint32_t>(s.element_count());
  for (std::uint32_t a = 0; a < m; ++a)
    for (std::uint32_t b = a; b < m; b += 7) {
      const double js = s.divergence(a, b);
      for (double th : {0.0, 0.01, 0.1, 0.48, 0.9, 1.0, js, std::nextafter(js, 0.0), std::nextafter(js, 2.0), js + 1e-10,
                        js - 1e-10, js + 2e-9}) {
        REQUIRE(s.within(a, b, th) == (js <= th));
        ++checked;
        below += js <= th;
      }
    }
  REQUIRE(checked > 10000);
  REQUIRE(below > checked / 4);
  REQUIRE(below < checked);
}

TEST_CASE("visibility: representatives have bit-identical rows and divergences; MI bound below MI", "[cluster][visibility]") {
  const visibility_state s = sphere_under_roof_state();  // symmetric rows and unseen triangles give groups
  const auto m = static_cast<std::uint32_t>(s.element_count());
  auto same = [&](std::uint32_t a, std::uint32_t b) {
    const auto ra = s.row(a), rb = s.row(b);
    return std::memcmp(ra.data(), rb.data(), ra.size_bytes()) == 0 && s.input_probability(a) == s.input_probability(b);
  };
  std::size_t shared = 0, positive_bounds = 0;
  for (std::uint32_t t = 0; t < m; ++t) {
    const std::uint32_t r = s.representative(t);
    REQUIRE(r <= t);
    REQUIRE(same(r, t));
    REQUIRE(s.representative(r) == r);
    shared += r != t;
    for (std::uint32_t b = 0; b < t; ++b)  // the smallest identical element, and only that
      if (same(b, t)) {
        REQUIRE(r <= b);
        break;
      }
    for (std::uint32_t b = 0; b < m; b += 5) {
      REQUIRE(s.divergence(t, b) == s.divergence(r, b));
      REQUIRE(s.divergence(b, t) == s.divergence(b, r));
    }
    const double bound = s.mutual_information_lower_bound(t), mi = s.mutual_information(t);
    REQUIRE(bound <= mi + 1e-12);
    positive_bounds += bound > 0.1;
  }
  REQUIRE(shared > 0);
  REQUIRE(shared < m);
  REQUIRE(positive_bounds > m / 4);
}

TEST_CASE("stretch binned rows approach exact rows as K grows", "[cluster][stretch]") {
  const auto m = support::make_uv_sphere(24, 16);
  const auto raw = texture_stretch(m);
  REQUIRE(raw.ok());
  const auto exact = make_stretch_state(*raw, 0);
  double previous = 1.0;
  for (std::uint32_t bins : {64u, 1024u, 16384u, 1u << 20}) {
    const auto binned = make_stretch_state(*raw, bins);
    double worst = 0.0;
    for (std::uint32_t a = 0; a < raw->size(); a += 3)
      for (std::uint32_t b = 0; b < raw->size(); b += 5)
        worst = std::max(worst, std::abs(binned.divergence(binned.class_of(a), binned.class_of(b)) -
                                         exact.divergence(exact.class_of(a), exact.class_of(b))));
    INFO("bins " << bins << " worst |ΔJS| " << worst);
    REQUIRE(worst <= previous);
    previous = worst;
  }
  REQUIRE(previous < 1e-4);
}

namespace {
// Column of each element in a binned state: the rank of its cell among the occupied cells.
std::vector<std::uint32_t> columns_of(const std::vector<std::uint32_t>& cell) {
  std::vector<std::uint32_t> occupied(cell);
  std::sort(occupied.begin(), occupied.end());
  occupied.erase(std::unique(occupied.begin(), occupied.end()), occupied.end());
  std::vector<std::uint32_t> col(cell.size());
  for (std::size_t i = 0; i < cell.size(); ++i)
    col[i] = static_cast<std::uint32_t>(std::lower_bound(occupied.begin(), occupied.end(), cell[i]) - occupied.begin());
  return col;
}

// A binned state with exact rows against its definition: the row of element a over the columns
// is a's exact M-entry row summed per column; its JS never exceeds the exact JS (the channel to
// the cells processes the exact one) and is closer to it than per-cell rows are.
template <class State, class Kernel>
void check_exact_rows(const State& exact, const State& own, const State& cells, const std::vector<std::uint32_t>& col,
                      Kernel kernel) {
  const std::size_t m = col.size();
  REQUIRE(own.class_count() == exact.class_count());
  std::vector<double> row(own.kernel().column_count()), ref(row.size());
  for (std::uint32_t a = 0; a < m; a += 17) {
    std::fill(ref.begin(), ref.end(), 0.0);
    double z = 0.0;
    for (std::size_t t = 0; t < m; ++t) z += kernel(a, t), ref[col[t]] += kernel(a, t);
    own.row(own.class_of(a), row);
    // Margin: float normals are unit only to ~1e-7, and the reference clamps each 1 − n·n' at 0
    // (the own term can be −1e-7) where the per-column sum clamps once.
    for (std::size_t c = 0; c < row.size(); ++c) REQUIRE(row[c] == Approx(ref[c] / z).epsilon(0).margin(1e-9));
  }
  double worst_own = 0.0, worst_cells = 0.0;
  for (std::uint32_t a = 0; a < m; a += 37)
    for (std::uint32_t b = 0; b < m; b += 13) {
      const double e = exact.divergence(exact.class_of(a), exact.class_of(b));
      const double o = own.divergence(own.class_of(a), own.class_of(b));
      REQUIRE(o <= e + 1e-12);
      worst_own = std::max(worst_own, e - o);
      worst_cells = std::max(worst_cells, std::abs(e - cells.divergence(cells.class_of(a), cells.class_of(b))));
    }
  INFO("worst |ΔJS| exact rows " << worst_own << ", per-cell rows " << worst_cells);
  REQUIRE(worst_own < worst_cells);
}
}  // namespace

TEST_CASE("orientation binned with exact rows: per-cell sums of the exact rows", "[cluster][orientation]") {
  const auto m = support::make_icosphere(3);
  const auto n = face_normals(m);
  const auto exact = make_orientation_state(n, 0);
  for (std::uint32_t bins : {64u, 1024u}) {
    const auto r = static_cast<std::uint32_t>(std::sqrt(double(bins)));
    std::vector<std::uint32_t> cell(n.size());
    for (std::size_t i = 0; i < n.size(); ++i) cell[i] = octahedral_cell(n[i], r);
    check_exact_rows(exact, make_orientation_state(n, bins, true), make_orientation_state(n, bins), columns_of(cell),
                     [&](std::size_t a, std::size_t b) { return std::max(0.0, 1.0 - glm::dot(glm::dvec3(n[a]), glm::dvec3(n[b]))); });
  }
}

TEST_CASE("stretch binned with exact rows: per-cell sums of the exact rows, exact clustering", "[cluster][stretch]") {
  const auto m = support::make_uv_sphere(24, 16);
  const auto raw = texture_stretch(m);
  REQUIRE(raw.ok());
  double lo = 1e300, hi = -1e300;
  for (double v : *raw) lo = std::min(lo, v), hi = std::max(hi, v);
  std::vector<double> norm(raw->size());
  for (std::size_t i = 0; i < norm.size(); ++i) norm[i] = std::clamp(((*raw)[i] - lo) / (hi - lo), 0.0, 1.0);
  const auto exact = make_stretch_state(*raw, 0);
  for (std::uint32_t bins : {64u, 1024u}) {
    std::vector<std::uint32_t> cell(norm.size());
    for (std::size_t i = 0; i < norm.size(); ++i) cell[i] = std::min(bins - 1, static_cast<std::uint32_t>(norm[i] * bins));
    check_exact_rows(exact, make_stretch_state(*raw, bins, true), make_stretch_state(*raw, bins), columns_of(cell),
                     [&](std::size_t a, std::size_t b) { return 1.0 - std::abs(norm[a] - norm[b]); });
  }
  // One distinct value per cell (200 values at least 0.003 apart after normalising, cells 1/1024
  // wide): the exact channel, bit for bit.
  std::vector<double> spread(200);
  for (std::size_t i = 0; i < spread.size(); ++i) spread[(i * 7) % spread.size()] = double(i) + 0.4 * double(i % 2);
  const auto fine = make_stretch_state(spread, 1024, true), fine_exact = make_stretch_state(spread, 0);
  REQUIRE(fine.kernel().column_count() == fine.class_count());
  for (std::uint32_t a = 0; a < spread.size(); ++a)
    for (std::uint32_t b = 0; b < spread.size(); b += 3)
      REQUIRE(fine.divergence(fine.class_of(a), fine.class_of(b)) ==
              fine_exact.divergence(fine_exact.class_of(a), fine_exact.class_of(b)));
  // Region growing on the 64 × 32 sphere at the benchmark's Th: exact rows over 256 cells give
  // exact's clusters (per-cell rows give 2 clusters against 42).
  const auto big = support::make_uv_sphere(64, 32);
  const auto big_raw = texture_stretch(big);
  REQUIRE(big_raw.ok());
  auto topo = make_topology(big);
  REQUIRE(topo.ok());
  const auto all = all_triangles(big.triangles.size());
  std::vector<std::uint32_t> scratch(all.size(), invalid_id);
  const element_graph g = subset_graph(*topo, all, scratch);
  serial_executor exec;
  const region_growing_options o{.threshold = 0.005, .min_cluster_fraction = 0.001};
  const auto ref = grow_regions(make_stretch_state(*big_raw, 0), g, o, exec);
  const auto own = grow_regions(make_stretch_state(*big_raw, 256, true), g, o, exec);
  REQUIRE(ref.ok());
  REQUIRE(own.ok());
  REQUIRE(own->cluster_of == ref->cluster_of);
}
