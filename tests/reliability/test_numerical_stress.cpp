// Numerical stress: coordinates scaled by 1e±30, float against double inputs,
// slivers with angles near 0 and 180 degrees, distributions of a million bins, thresholds at
// exactly 0 and 1. Results must be finite and within the tolerances stated next to each check
// (derived from float rounding, 2^-24 ≈ 6e-8 relative, and the figures the headers document).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <span>
#include <vector>
#include "infolerp/info/entropy.hpp"
#include "infolerp/info/jensen_shannon.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/validate.hpp"
#include "infolerp/refine/nld.hpp"
#include "infolerp/refine/progressive_driver.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"
#include "infolerp/saliency/cluster_importance.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"
#include "infolerp/upsample/pass_controller.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "reliability/reliability_support.hpp"
#include "support/brute_force_tracer.hpp"
#include "support/procedural.hpp"

namespace {

using infolerp::indexed_mesh;

indexed_mesh bumpy_sphere(unsigned level) {
  auto m = infolerp::support::make_icosphere(level);
  for (auto& p : m.positions)
    p *= 1.0f + 0.06f * std::sin(9.0f * p.x) * std::sin(7.0f * p.y + 1.0f) * std::cos(5.0f * p.z);
  return m;
}

bool all_finite(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}
double max_abs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}
// ||a − b|| / ||b||.
double relative_l2(const std::vector<double>& a, const std::vector<double>& b) {
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) num += (a[i] - b[i]) * (a[i] - b[i]), den += b[i] * b[i];
  return den > 0.0 ? std::sqrt(num / den) : std::sqrt(num);
}

// JS in long double, per bin, from normalised inputs: the reference for the double kernel.
long double js_reference(const std::vector<double>& p, const std::vector<double>& q, long double w = 0.5L) {
  long double sp = 0, sq = 0, sum = 0;
  for (double x : p) sp += x;
  for (double x : q) sq += x;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const long double a = p[i] / sp, b = q[i] / sq, m = w * a + (1 - w) * b;
    if (a > 0 && w > 0) sum += w * a * std::log2(a / m);
    if (b > 0 && w < 1) sum += (1 - w) * b * std::log2(b / m);
  }
  return sum;
}

}  // namespace

TEST_CASE("stress: coordinates scaled by 1e30 and 1e-30", "[reliability][stress]") {
  const indexed_mesh m = bumpy_sphere(2);
  const auto h = *infolerp::mean_curvature(m);
  const auto normals = infolerp::face_normals(m);
  const auto areas = infolerp::face_areas(m);
  const infolerp::saliency_options opt{.epsilon = 0.02};
  const auto sal = *infolerp::compute_saliency(m, opt);
  for (const float s : {1e30f, 1e-30f}) {
    INFO("scale " << s);
    indexed_mesh ms = m;
    for (auto& p : ms.positions) p *= s;
    REQUIRE(infolerp::validate_mesh(ms).ok());
    const double sd = static_cast<double>(s);

    // Normals are scale-free; areas scale by s². Float rounding of the scaled positions
    // (6e-8 relative) moves a unit normal by well under 1e-5 on these triangles.
    const auto ns = infolerp::face_normals(ms);
    const auto as = infolerp::face_areas(ms);
    for (std::size_t t = 0; t < ns.size(); ++t) {
      CHECK(glm::length(ns[t] - normals[t]) < 1e-5f);
      CHECK(as[t] / (sd * sd) == Approx(areas[t]).epsilon(1e-5));
    }

    // Curvature scales by 1/s; the rounding noise stays below 1e-4 of the largest |H|
    // (mean_curvature documents ~1e-5 relative on a finer, 2562-vertex sphere).
    const auto hs = *infolerp::mean_curvature(ms);
    REQUIRE(all_finite(hs));
    for (std::size_t v = 0; v < h.size(); ++v) CHECK(std::abs(hs[v] * sd - h[v]) <= 1e-4 * max_abs(h));

    // Saliency is dimensionless: the same map at any scale (levels scale by 1/s).
    {
      const auto ss = *infolerp::compute_saliency(ms, opt);
      const infolerp::mesh_saliency& ref = sal;
      REQUIRE(all_finite(ss.saliency));
      CHECK(ss.epsilon / sd == Approx(ref.epsilon).epsilon(1e-6));
      for (std::size_t i = 0; i < ss.levels.size(); ++i) {
        std::vector<double> scaled = ss.levels[i];
        for (double& x : scaled) x *= sd;
        CHECK(relative_l2(scaled, ref.levels[i]) < 1e-3);
      }
      // The final map too (Lee's normalisation is discontinuous at ties, but this mesh has none
      // at rounding level: measured ~1e-6).
      CHECK(relative_l2(ss.saliency, ref.saliency) < 1e-3);

      // Clustering and per-cluster attributes on the scaled mesh stay finite.
      auto c = infolerp::salient_clustering(ms, ss.saliency, {.clusters = 6});
      REQUIRE(c.ok());
      auto table = infolerp::compute_cluster_attributes(ms, ss.saliency, c->cluster, c->count);
      REQUIRE(table.ok());
      for (const auto& a : table->clusters) {
        CHECK(std::isfinite(a.area / (sd * sd)));
        CHECK(a.area > 0.0);
        CHECK(std::isfinite(a.radius));
        CHECK(std::isfinite(a.peak_normal_deviation));
      }
      auto view = infolerp::estimate_view_importance(*table, glm::dvec3(3.0 * sd, 0.0, 0.0));
      REQUIRE(view.ok());
      for (double x : view->area_estimate) CHECK(std::isfinite(x));
    }

    // Subdivision at scale: midpoints are the scaled midpoints (one float rounding each).
    auto sub = infolerp::subdivision_mesh::create(ms);
    REQUIRE(sub.ok());
    for (std::uint32_t t = 0; t < 40; t += 3) REQUIRE(sub->split(t).ok());
    for (const auto& p : sub->positions()) CHECK((std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)));
    const auto loc = sub->locate(0, {0.3f, 0.3f});
    CHECK(sub->is_leaf(loc.leaf));
    CHECK(std::isfinite(loc.weights.x + loc.weights.y + loc.weights.z));
  }
}

TEST_CASE("stress: float against double inputs", "[reliability][stress]") {
  SECTION("Jensen-Shannon: float input gives the bits of the same values in double") {
    std::vector<float> pf(4097), qf(4097);
    for (std::size_t i = 0; i < pf.size(); ++i) {
      pf[i] = static_cast<float>(i % 7 == 0 ? 0.0 : 1.0 + std::sin(0.3 * static_cast<double>(i)));
      qf[i] = static_cast<float>(1e-30 * (1.0 + std::cos(0.7 * static_cast<double>(i))));  // tiny but normal
    }
    const std::vector<double> pd(pf.begin(), pf.end()), qd(qf.begin(), qf.end());
    for (double w : {0.0, 0.25, 0.5, 1.0}) {
      const double jf = *infolerp::jensen_shannon(std::span<const float>(pf), std::span<const float>(qf), w);
      const double jd = *infolerp::jensen_shannon(std::span<const double>(pd), std::span<const double>(qd), w);
      CHECK(std::memcmp(&jf, &jd, sizeof jf) == 0);
      CHECK(std::abs(static_cast<long double>(jd) - js_reference(pd, qd, w)) < 1e-14L);
    }
  }
  SECTION("curvature: a float mesh gives the bits of the double overload on the same values") {
    const indexed_mesh m = bumpy_sphere(3);
    const std::vector<glm::dvec3> dp(m.positions.begin(), m.positions.end());
    const auto hf = *infolerp::mean_curvature(m);
    const auto hd = *infolerp::mean_curvature(std::span<const glm::dvec3>(dp), std::span<const glm::uvec3>(m.triangles));
    CHECK(std::memcmp(hf.data(), hd.data(), hf.size() * sizeof(double)) == 0);
  }
  SECTION("curvature: float rounding of positions costs < 1e-4 on a 2562-vertex unit sphere") {
    // Double positions exactly on the sphere against their float roundings: mean_curvature
    // documents ~1e-5 relative noise from float input at this resolution.
    const indexed_mesh m = infolerp::support::make_icosphere(4);
    std::vector<glm::dvec3> dp;
    for (const auto& p : m.positions) dp.push_back(glm::normalize(glm::dvec3(p)));
    const auto hd = *infolerp::mean_curvature(std::span<const glm::dvec3>(dp), std::span<const glm::uvec3>(m.triangles));
    const auto hf = *infolerp::mean_curvature(m);
    for (std::size_t v = 0; v < hd.size(); ++v) {
      CHECK(std::abs(hf[v] - hd[v]) < 1e-4);
      CHECK(std::abs(hd[v] - 1.0) < 2e-2);  // discretisation of a unit sphere at this resolution
    }
  }
  SECTION("upsampler: a double-precision frame holds the float frame's values") {
    const std::uint32_t ids[3] = {0, 1, infolerp::invalid_id};
    const infolerp::reliability::table_source src{ids, 5};
    std::vector<glm::vec3> f(40 * 30);
    std::vector<glm::dvec3> d(40 * 30);
    REQUIRE(infolerp::upsample(src, 40, 30, std::span<glm::vec3>(f)).ok());
    REQUIRE(infolerp::upsample(src, 40, 30, std::span<glm::dvec3>(d)).ok());
    for (std::size_t i = 0; i < f.size(); ++i) CHECK(glm::dvec3(f[i]) == d[i]);
  }
}

TEST_CASE("stress: slivers with angles near 0 and 180 degrees", "[reliability][stress]") {
  for (const float h : {1e-3f, 1e-5f, 1e-7f}) {
    INFO("sliver height " << h);
    // Apex angle ~180° − 4h rad, base angles ~2h rad; and a needle with a 1e-7-ish angle.
    const infolerp::triangle_corners flat{{0, 0, 0}, {1, 0, 0}, {0.5, static_cast<double>(h), 0}};
    CHECK(infolerp::triangle_area(flat) == Approx(0.5 * static_cast<double>(h)).epsilon(1e-12));
    CHECK(glm::length(infolerp::triangle_normal(flat)) == Approx(1.0f).epsilon(1e-6));

    // A folded strip of slivers: a surface with curvature, so every term is exercised.
    indexed_mesh m = infolerp::support::make_plane(6, 6, 2.0f);
    for (auto& p : m.positions) p.z = 0.3f * p.x * p.x - 0.2f * p.y * p.y;
    const auto a = static_cast<std::uint32_t>(m.positions.size());
    m.positions.push_back({1.2f, 1.2f, 0.0f});
    m.positions.push_back({2.2f, 1.2f, 0.0f});
    m.positions.push_back({1.7f, 1.2f + h, 0.0f});        // near 180 at the apex
    m.positions.push_back({2.2f, 1.2f + 2.0f * h, 0.1f});  // needle: angle ~h at a
    m.triangles.push_back({a, a + 1, a + 2});
    m.triangles.push_back({a, a + 2, a + 3});
    m.triangles.push_back({a + 2, a + 1, a + 3});
    REQUIRE(infolerp::validate_mesh(m, {.allow_non_manifold = false}).ok());
    const auto curv = infolerp::mean_curvature(m);
    REQUIRE(curv.ok());
    CHECK(all_finite(*curv));
    {
      auto s = infolerp::compute_saliency(m, {.epsilon = 0.02});
      REQUIRE(s.ok());
      CHECK(all_finite(s->saliency));
      auto c = infolerp::salient_clustering(m, s->saliency, {.clusters = 3});
      REQUIRE(c.ok());
      auto table = infolerp::compute_cluster_attributes(m, s->saliency, c->cluster, c->count);
      REQUIRE(table.ok());
      for (const auto& at : table->clusters) CHECK(std::isfinite(at.peak_normal_deviation));
    }
    // Subdivision of the slivers: children finite, the mesh stays conforming.
    auto sub = infolerp::subdivision_mesh::create(m, {.bisect_ratio = 0.0f});
    REQUIRE(sub.ok());
    const auto first = static_cast<std::uint32_t>(m.triangles.size() - 3);
    for (int round = 0; round < 6; ++round) REQUIRE(sub->split(static_cast<std::uint32_t>(sub->triangle_count() - 1)).ok());
    REQUIRE(sub->split(first).ok());
    for (const auto& p : sub->positions()) CHECK((std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)));
    const auto leaves = sub->leaf_mesh();
    auto topo = infolerp::make_topology(leaves);
    REQUIRE(topo.ok());
    for (std::size_t e = 0; e < topo->edge_count(); ++e) CHECK(topo->edge_valence(e) <= 2);
    const auto loc = sub->locate(first, {0.4f, 0.3f});
    CHECK(sub->is_leaf(loc.leaf));
    CHECK(std::abs(loc.weights.x + loc.weights.y + loc.weights.z - 1.0f) < 1e-5f);
  }
}

TEST_CASE("stress: 300 nested selections (deeper than the 255 levels a triangle counts)", "[reliability][stress]") {
  // Selecting a child of the last split again and again: float midpoints stop moving after
  // ~30 levels, yet the hierarchy must stay a conforming triangulation and the level count
  // must saturate (it used to assert, or wrap to 0 without assertions).
  const indexed_mesh m = infolerp::support::make_plane(1, 1, 1.0f);
  auto s = infolerp::subdivision_mesh::create(m);
  REQUIRE(s.ok());
  std::uint32_t t = 0;
  for (int i = 0; i < 300; ++i) {
    REQUIRE(s->split(t).ok());
    const auto& n = s->triangle(t);
    REQUIRE(n.child_count > 0);
    t = n.first_child + (n.child_count == 4 ? 3u : 0u);
  }
  int deepest = 0;
  for (const auto& n : s->triangles()) {
    if (n.parent != infolerp::invalid_id) CHECK(int(n.level) >= int(s->triangle(n.parent).level));
    deepest = std::max<int>(deepest, n.level);
  }
  CHECK(deepest == 255);
  const auto topo = infolerp::make_topology(s->leaf_mesh());
  REQUIRE(topo.ok());
  for (std::size_t e = 0; e < topo->edge_count(); ++e) CHECK(topo->edge_valence(e) <= 2);
  const auto loc = s->locate(0, {0.3f, 0.3f});
  CHECK(s->is_leaf(loc.leaf));
  CHECK(std::isfinite(loc.weights.x + loc.weights.y + loc.weights.z));
}

TEST_CASE("stress: distributions of a million bins", "[reliability][stress]") {
  constexpr std::size_t n = 1000000;
  std::vector<double> p(n), q(n);
  std::uint64_t state = 12345;
  for (std::size_t i = 0; i < n; ++i) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    p[i] = static_cast<double>(state >> 11) * 0x1p-53;
    q[i] = i % 3 == 0 ? 0.0 : p[i] * (1.0 + 1e-3 * static_cast<double>((state >> 7) % 17));
  }
  // jensen_shannon documents "within a few 1e-16 of a long-double reference" at this size.
  const double js = *infolerp::jensen_shannon(std::span<const double>(p), std::span<const double>(q));
  CHECK(std::abs(static_cast<long double>(js) - js_reference(p, q)) < 1e-14L);
  CHECK(*infolerp::jensen_shannon(std::span<const double>(p), std::span<const double>(p)) == 0.0);

  std::vector<double> disjoint_a(n, 0.0), disjoint_b(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) (i % 2 ? disjoint_a : disjoint_b)[i] = 1.0 + static_cast<double>(i % 5);
  CHECK(*infolerp::jensen_shannon(std::span<const double>(disjoint_a), std::span<const double>(disjoint_b)) ==
        Approx(1.0).margin(1e-12));

  const std::vector<double> uniform(std::size_t{1} << 20, 3.0);  // H = 20 bits exactly
  CHECK(*infolerp::checked_entropy(uniform) == Approx(20.0).margin(1e-9));

  const std::span<const double> three[3] = {p, q, disjoint_a};
  const std::vector<double> w{1.0, 2.0, 1.0};
  const double nary = *infolerp::jensen_shannon(std::span<const std::span<const double>>(three), std::span<const double>(w));
  CHECK(std::isfinite(nary));
  CHECK(nary >= 0.0);
  CHECK(nary <= std::log2(3.0));
}

TEST_CASE("stress: thresholds at exactly 0 and 1", "[reliability][stress]") {
  SECTION("Jensen-Shannon weights 0 and 1: one distribution carries all weight, JS = 0") {
    const std::vector<double> p{0.0, 0.25, 0.75, 0.0}, q{0.5, 0.0, 0.25, 0.25};
    for (double w : {0.0, 1.0}) {
      const double js = *infolerp::jensen_shannon(std::span<const double>(p), std::span<const double>(q), w);
      CHECK(js == 0.0);
    }
    // Disjoint supports at equal weight: exactly the maximum, 1.
    const std::vector<double> a{1.0, 0.0}, b{0.0, 1.0};
    CHECK(*infolerp::jensen_shannon(std::span<const double>(a), std::span<const double>(b)) == 1.0);
  }
  SECTION("NLD: 0 for equal luminances, 1 for half black and half L_max") {
    CHECK(infolerp::nld(0.4f, 0.4f, 0.4f, 1.0f) == 0.0f);
    CHECK(infolerp::nld(0.0f, 2.0f, 0.0f, 2.0f, 2.0f) == 1.0f);
  }
  SECTION("refinement criteria with s_req 0 and 1") {
    const indexed_mesh m = infolerp::support::make_plane(2, 2, 2.0f);
    const infolerp::pinhole_camera cam{.eye = {0, 0, 1.8f}, .target = {0, 0, 0}, .up = {0, 1, 0},
                                       .vertical_fov_degrees = 60.0f, .width = 32, .height = 32};
    auto shade = [](const infolerp::shading_point& sp) { return glm::vec3(sp.position.x > 0.1f ? 1.0f : 0.0f); };
    for (auto criterion : {infolerp::refinement_criterion::nld_os, infolerp::refinement_criterion::nld_is}) {
      for (float s_req : {0.0f, 1.0f}) {
        INFO(infolerp::to_string(criterion) << " s_req " << s_req);
        auto r = infolerp::progressive_refiner::create(
            *infolerp::subdivision_mesh::create(m),
            {.criteria = {.criterion = criterion, .s_req = s_req, .min_pixels = 1.0f, .always_refine_fraction = 1.0f},
             .max_batches = 20});
        REQUIRE(r.ok());
        auto rep = r->run(infolerp::support::brute_force_tracer{&m}, cam, shade, infolerp::serial_executor{});
        REQUIRE(rep.ok());
        if (s_req == 1.0f) CHECK(rep->batches == 0);  // S never exceeds 1
        else CHECK(rep->batches > 0);                 // the shadow edge has S > 0
        std::vector<glm::vec3> img(32 * 32);
        r->reconstruct(img);
        float lo = 0.0f, hi = 0.0f;
        for (const auto& c : img) {
          CHECK(std::isfinite(c.x));
          lo = std::min(lo, c.x), hi = std::max(hi, c.x);
        }
        INFO("image range [" << double(lo) << ", " << double(hi) - 1.0 << " + 1]");
        // Pixel weights are stored as floats and re-derived (in double, stored as float) by
        // every batch that splits the pixel's leaf (20 batches here), each time rounding the
        // weights' sum by up to ~4 ulps (2.4e-7): interpolated 0/1 colours may leave [0, 1]
        // by up to 20 × 2.4e-7 ≈ 5e-6 (measured 1.9e-6).
        CHECK(lo >= -5e-6f);
        CHECK(hi <= 1.0f + 5e-6f);
      }
    }
  }
  SECTION("other parameters at the ends of their ranges") {
    const indexed_mesh m = bumpy_sphere(2);
    for (double flat : {0.0, 1.0}) {
      auto s = infolerp::compute_saliency(m, {.flat_level_threshold = flat});
      REQUIRE(s.ok());
      CHECK(all_finite(s->saliency));
      auto c = infolerp::salient_clustering(m, s->saliency, {.clusters = 4, .pool_multiplier = 1.0, .normal_weight = 1.0});
      REQUIRE(c.ok());
    }
    const std::vector<double> prio{3.0, 1.0, 2.0};
    const std::vector<std::uint64_t> cap{4, 4, 4};
    auto d = infolerp::distribute_contractions(prio, cap, 10, 1.0);
    REQUIRE(d.ok());
    CHECK(std::accumulate(d->begin(), d->end(), std::uint64_t{0}) == 10);
    auto sub = infolerp::subdivision_mesh::create(infolerp::support::make_plane(3, 3, 1.0f), {.bisect_ratio = 0.0f});
    REQUIRE(sub.ok());
    REQUIRE(sub->split(4u).ok());
    CHECK(infolerp::pass_controller::create({.min_frame_seconds = 0.02, .max_frame_seconds = 0.02, .smoothing = 1.0}).ok());
    const std::uint32_t ids[1] = {0};
    const infolerp::reliability::table_source src{ids, 1};
    std::vector<glm::vec3> px(1);
    CHECK(infolerp::upsample(src, 1, 1, std::span<glm::vec3>(px),
                             {.passes = infolerp::max_upsample_passes, .max_passes = infolerp::max_upsample_passes})
              .ok());
  }
}
