// Culling in view_dependent_lod::frame (hidden_triangles.hpp): for the same cut, the culled
// output and the whole cut give the same primary hit at every pixel (Embree), on a closed mesh
// seen from outside and on open meshes seen from their back; what may be culled is decided per
// closed part.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <span>
#include <vector>
#include <catch2/catch.hpp>
#include "infolerp/lod/hidden_triangles.hpp"
#include "infolerp/lod/view_dependent_lod.hpp"
#include "infolerp/lod/weighting_map.hpp"
#include "support/embree_tracer.hpp"
#include "support/procedural.hpp"

using namespace infolerp;

namespace {

// The corner triple of the triangle each pixel's primary ray hits first ({invalid_id x 3} on a
// miss), n x n pixels of cam.
std::vector<std::array<std::uint32_t, 3>> hit_image(const support::embree_device& device, std::span<const glm::vec3> pos,
                                                    std::span<const std::uint32_t> idx, const lod_camera& cam, int n) {
  std::vector<std::array<std::uint32_t, 3>> img(static_cast<std::size_t>(n * n), {invalid_id, invalid_id, invalid_id});
  if (idx.empty()) return img;
  std::vector<glm::uvec3> tris(idx.size() / 3);
  for (std::size_t t = 0; t < tris.size(); ++t) tris[t] = {idx[3 * t], idx[3 * t + 1], idx[3 * t + 2]};
  support::embree_scene scene(device);
  REQUIRE(scene.add_triangles(pos, tris).ok());
  REQUIRE(scene.commit().ok());
  const camera_basis b = make_camera_basis(cam);
  const double tv = std::tan(0.5 * cam.vertical_fov), th = tv * cam.width / cam.height;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double sx = (2.0 * (x + 0.5) / n - 1.0) * th, sy = (1.0 - 2.0 * (y + 0.5) / n) * tv;
      ray r;
      r.origin = glm::vec3(cam.position);
      r.direction = glm::vec3(glm::normalize(b.forward + sx * b.right + sy * b.up));
      const hit h = scene.intersect(r);
      if (h.valid()) img[static_cast<std::size_t>(y * n + x)] = {tris[h.triangle].x, tris[h.triangle].y, tris[h.triangle].z};
    }
  return img;
}

struct lod_of {
  contraction_hierarchy h;
  cluster_table table;
  lod_of(const indexed_mesh& m, std::uint32_t clusters) {
    std::vector<std::uint32_t> cl(m.triangle_count());
    for (std::size_t t = 0; t < cl.size(); ++t)  // bands across x
      cl[t] = std::min(clusters - 1, static_cast<std::uint32_t>(t * clusters / cl.size()));
    std::vector<double> sal(m.vertex_count());
    for (std::size_t v = 0; v < sal.size(); ++v) sal[v] = 1.0 + 0.5 * std::sin(5.0 * m.positions[v].x);
    auto w = weighting_map(m, sal, cl, clusters);
    REQUIRE(w.ok());
    auto hh = make_contraction_hierarchy(m, *w, cl, clusters);
    auto t = compute_cluster_attributes(m, sal, cl, clusters);
    REQUIRE(hh.ok());
    REQUIRE(t.ok());
    h = std::move(*hh), table = std::move(*t);
  }
};

// For each camera and budget: the culled frame draws fewer triangles than its cut (when
// `culls`), and the same first hit at every pixel of a 96 x 96 image.
void check_same_picture(const indexed_mesh& m, const lod_of& s, std::span<const lod_camera> cams, bool culls,
                        const lod_options& opt = {}) {
  const support::embree_device device;
  auto lod = view_dependent_lod::create(s.h, s.table, opt);
  REQUIRE(lod.ok());
  std::vector<std::uint32_t> out(contracted_index_bound(s.h)), cut_out(out.size());
  std::vector<index_range> ranges(s.h.cluster_count);
  contraction_workspace w = make_contraction_workspace(s.h);
  std::size_t pixels_hit = 0;
  for (std::size_t k = 0; k < cams.size(); ++k)
    for (const double f : {0.0, 0.5, 0.9}) {
      INFO("camera " << k << ", budget " << 1.0 - f << " of the triangles");
      auto st = lod->frame(cams[k], static_cast<std::uint64_t>((1.0 - f) * static_cast<double>(s.h.triangle_count())), out, ranges);
      if (!st.ok()) FAIL(st.error().message());
      auto cut = contract_indices(s.h, lod->stop_points(), w, cut_out, ranges);
      REQUIRE(cut.ok());
      if (culls) CHECK(st->indices < *cut);
      const auto ours = hit_image(device, m.positions, std::span<const std::uint32_t>(out.data(), st->indices), cams[k], 96);
      const auto all = hit_image(device, m.positions, std::span<const std::uint32_t>(cut_out.data(), *cut), cams[k], 96);
      std::size_t differ = 0;
      for (std::size_t p = 0; p < ours.size(); ++p) {
        differ += ours[p] != all[p] ? 1 : 0;
        pixels_hit += all[p][0] != invalid_id ? 1 : 0;
      }
      CHECK(differ == 0);
    }
  CHECK(pixels_hit > cams.size() * 96 * 96 / 10);  // the cameras see the mesh
}

lod_camera look_at(const glm::dvec3& eye, const glm::dvec3& at, const glm::dvec3& up = {0.0, 0.0, 1.0}) {
  return {eye, at - eye, up, 0.9, 96, 96};
}

}  // namespace

TEST_CASE("culling: a closed torus seen from random cameras outside it gives the same picture as its cut", "[lod]") {
  const indexed_mesh m = support::make_torus(48, 24, 1.0f, 0.35f);
  const std::vector<std::uint8_t> closed = closed_part_triangles(
      std::span<const std::uint32_t>(&m.triangles[0].x, 3 * m.triangle_count()), m.positions);
  REQUIRE(std::count(closed.begin(), closed.end(), 1) == static_cast<long>(m.triangle_count()));
  const lod_of s(m, 6);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), dist(1.6, 4.0);
  std::vector<lod_camera> cams;
  while (cams.size() < 10) {  // outside the torus's bounding sphere, looking near its centre
    glm::dvec3 dir;
    for (int a = 0; a < 3; ++a) dir[a] = unit(rng);
    if (glm::length(dir) < 0.2) continue;
    const double d = dist(rng);
    glm::dvec3 at;
    for (int a = 0; a < 3; ++a) at[a] = 0.5 * unit(rng);
    cams.push_back(look_at(d * glm::normalize(dir), at, std::abs(dir.z) > 0.9 * glm::length(dir) ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 0, 1)));
  }
  check_same_picture(m, s, cams, true);
}

TEST_CASE("culling: open meshes seen from their back keep every face the camera sees", "[lod]") {
  SECTION("a single sheet seen from below") {
    indexed_mesh m = support::make_plane(24, 24, 2.0f);
    for (auto& p : m.positions) p.z = 0.1f * std::sin(3.0f * p.x) * std::cos(2.0f * p.y);
    const std::vector<std::uint8_t> closed = closed_part_triangles(
        std::span<const std::uint32_t>(&m.triangles[0].x, 3 * m.triangle_count()), m.positions);
    REQUIRE(std::count(closed.begin(), closed.end(), 1) == 0);
    const lod_of s(m, 4);
    const std::vector<lod_camera> cams{look_at({0.3, -0.2, -2.5}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}),
                                       look_at({2.0, 1.0, -1.0}, {0.0, 0.0, 0.0}),
                                       look_at({0.0, 0.0, 2.5}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0})};
    check_same_picture(m, s, cams, false);
    // Seen from straight below, the whole sheet in view: every triangle of the cut is drawn.
    auto lod = view_dependent_lod::create(s.h, s.table);
    REQUIRE(lod.ok());
    std::vector<std::uint32_t> out(contracted_index_bound(s.h)), cut_out(out.size());
    std::vector<index_range> ranges(s.h.cluster_count);
    contraction_workspace w = make_contraction_workspace(s.h);
    auto st = lod->frame(look_at({0.0, 0.0, -4.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}), s.h.triangle_count() / 2, out, ranges);
    REQUIRE(st.ok());
    auto cut = contract_indices(s.h, lod->stop_points(), w, cut_out, ranges);
    REQUIRE(cut.ok());
    CHECK(st->indices == *cut);
  }
  SECTION("a box without its lid, seen from above into it and from outside") {
    // A closed, welded grid box (subdivided so that it simplifies) with its top face removed.
    indexed_mesh box = support::subdivide_midpoint(support::subdivide_midpoint(support::make_box({-1, -1, -1}, {1, 1, 1})));
    std::vector<std::uint32_t> remap;
    box = support::weld_positions(box, remap);
    indexed_mesh m;
    m.positions = box.positions;
    for (const glm::uvec3& t : box.triangles)
      if (!(box.positions[t.x].z > 0.99f && box.positions[t.y].z > 0.99f && box.positions[t.z].z > 0.99f)) m.triangles.push_back(t);
    REQUIRE(m.triangles.size() < box.triangles.size());
    const lod_of s(m, 3);
    const std::vector<lod_camera> cams{look_at({0.2, -0.3, 3.0}, {0.0, 0.0, -1.0}, {0.0, 1.0, 0.0}),
                                       look_at({1.5, -1.2, 2.0}, {0.0, 0.0, -0.5}),
                                       look_at({3.0, 2.0, -1.5}, {0.0, 0.0, 0.0})};
    check_same_picture(m, s, cams, false);
  }
}

TEST_CASE("culling: closed parts are told apart from open, inconsistent and inside-out ones", "[lod]") {
  const indexed_mesh sphere = support::make_icosphere(1);
  std::vector<std::uint32_t> idx(&sphere.triangles[0].x, &sphere.triangles[0].x + 3 * sphere.triangle_count());
  const auto all_are = [&](std::span<const std::uint32_t> i, std::uint8_t v) {
    const auto c = closed_part_triangles(i, sphere.positions);
    return std::all_of(c.begin(), c.end(), [&](std::uint8_t x) { return x == v; });
  };
  CHECK(all_are(idx, 1));
  std::vector<std::uint32_t> inside_out = idx;  // every triangle flipped: negative volume
  for (std::size_t k = 0; k < inside_out.size(); k += 3) std::swap(inside_out[k + 1], inside_out[k + 2]);
  CHECK(all_are(inside_out, 0));
  std::vector<std::uint32_t> one_flipped = idx;  // inconsistent winding
  std::swap(one_flipped[1], one_flipped[2]);
  CHECK(all_are(one_flipped, 0));
  std::vector<std::uint32_t> open(idx.begin() + 3, idx.end());  // a hole
  CHECK(all_are(open, 0));
  // Two parts: a closed sphere beside an open one; only the closed one is one-sided.
  std::vector<std::uint32_t> two = idx;
  const auto n = static_cast<std::uint32_t>(sphere.vertex_count());
  std::vector<glm::vec3> pos = sphere.positions;
  for (const glm::vec3& p : sphere.positions) pos.push_back(p + glm::vec3(3.0f, 0.0f, 0.0f));
  for (std::size_t k = 3; k < idx.size(); ++k) two.push_back(idx[k] + n);
  const auto c = closed_part_triangles(two, pos);
  CHECK(std::count(c.begin(), c.begin() + static_cast<long>(sphere.triangle_count()), 1) == static_cast<long>(sphere.triangle_count()));
  CHECK(std::count(c.begin() + static_cast<long>(sphere.triangle_count()), c.end(), 1) == 0);
}

TEST_CASE("culling: keep_hidden and two-sided clusters draw the whole cut", "[lod]") {
  const indexed_mesh m = support::make_torus(32, 16, 1.0f, 0.35f);
  const lod_of s(m, 4);
  const lod_camera cam = look_at({0.0, -2.0, 0.8}, {0.3, 0.0, 0.0});  // part of the torus out of view
  std::vector<std::uint32_t> out(contracted_index_bound(s.h)), cut_out(out.size());
  std::vector<index_range> ranges(s.h.cluster_count);
  contraction_workspace w = make_contraction_workspace(s.h);
  const std::array<std::uint32_t, 4> every{0, 1, 2, 3};
  for (const lod_options& opt : {lod_options{.view = {}, .keep_hidden = true}, lod_options{.view = {}, .two_sided = every}}) {
    auto lod = view_dependent_lod::create(s.h, s.table, opt);
    REQUIRE(lod.ok());
    auto st = lod->frame(cam, s.h.triangle_count() / 2, out, ranges);
    REQUIRE(st.ok());
    auto cut = contract_indices(s.h, lod->stop_points(), w, cut_out, ranges);
    REQUIRE(cut.ok());
    // keep_hidden: the whole cut; two-sided clusters: the cut without what is outside the frustum.
    const view_frustum v = make_view_frustum(cam);
    std::size_t in_view = 0;
    for (std::size_t k = 0; k < *cut; k += 3)
      in_view += hidden_triangle(v, m.positions[cut_out[k]], m.positions[cut_out[k + 1]], m.positions[cut_out[k + 2]], false) ? 0 : 3;
    CHECK(st->indices == (opt.keep_hidden ? *cut : in_view));
  }
}

TEST_CASE("culling: blocks of triangles get hidden_triangle's answer bit for bit", "[lod]") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> coord(-2.0f, 2.0f), tiny(-1e-6f, 1e-6f);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::size_t hidden_seen = 0, back_seen = 0, outside_seen = 0, tested = 0;
  for (int round = 0; round < 200; ++round) {
    glm::dvec3 eye(3.0 * unit(rng), 3.0 * unit(rng), 3.0 * unit(rng)), fwd(unit(rng), unit(rng), unit(rng));
    if (round % 10 == 0) eye *= 1e4;  // far away: hidden_triangle's precision concern
    if (glm::length(fwd) < 0.1) continue;
    const lod_camera cam{eye, fwd, std::abs(fwd.z) > 0.9 * glm::length(fwd) ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 0, 1),
                         0.3 + 2.0 * std::abs(unit(rng)), 64, 48};
    REQUIRE(check_camera(cam).ok());
    const view_frustum v = make_view_frustum(cam);
    triangle_block b;
    const std::size_t n = 1 + static_cast<std::size_t>(rng() % hidden_block_size);
    std::vector<std::array<glm::vec3, 3>> tri(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (auto& p : tri[i]) p = {coord(rng), coord(rng), coord(rng)};
      if (i % 7 == 3) tri[i][2] = tri[i][0] + (tri[i][1] - tri[i][0]) * 0.5f + glm::vec3(tiny(rng), tiny(rng), tiny(rng));  // near edge-on
      if (i % 11 == 5) tri[i][1] = tri[i][0];                                                                     // degenerate
      for (std::size_t j = 0; j < 3; ++j) b.x[j][i] = tri[i][j].x, b.y[j][i] = tri[i][j].y, b.z[j][i] = tri[i][j].z;
      b.one_sided[i] = static_cast<std::int32_t>(rng() % 3 != 0);
    }
    std::int32_t with[hidden_block_size];
    hidden_block(v, b, n, with);
    for (std::size_t i = 0; i < n; ++i) {
      const auto& [p0, p1, p2] = tri[i];
      const bool expected = hidden_triangle(v, p0, p1, p2, b.one_sided[i] != 0);
      const bool back = hidden_triangle(v, p0, p1, p2, b.one_sided[i] != 0) && !hidden_triangle(v, p0, p1, p2, false);
      const bool outside = hidden_triangle(v, p0, p1, p2, false);
      CHECK(with[i] == (expected ? 1 : 0));
      // The frustum planes or the facing test (contract_visible_indices uses the latter alone
      // when box_inside_frustum).
      CHECK(expected == (outside || (b.one_sided[i] != 0 && facing_away(v, p0, p1, p2))));
      hidden_seen += expected, back_seen += back, outside_seen += outside, ++tested;
    }
  }
  CHECK(hidden_seen > tested / 4);  // both answers, both reasons
  CHECK(hidden_seen < tested);
  CHECK(back_seen > 0);
  CHECK(outside_seen > 0);
}

TEST_CASE("culling: a box inside the frustum holds no point outside a plane as hidden_triangle computes it", "[lod]") {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), in01(0.0, 1.0);
  int inside = 0, not_inside = 0;
  for (int round = 0; round < 400; ++round) {
    const glm::dvec3 eye(5.0 * unit(rng), 5.0 * unit(rng), 5.0 * unit(rng));
    const glm::dvec3 centre = eye + glm::dvec3(unit(rng), unit(rng), -4.0);  // mostly ahead of a camera looking along −z
    const glm::dvec3 half(in01(rng), in01(rng), in01(rng));
    const lod_camera cam{eye, {0.05 * unit(rng), 0.05 * unit(rng), -1.0}, {0.0, 1.0, 0.0}, 0.4 + 1.2 * in01(rng), 64, 64};
    const view_frustum v = make_view_frustum(cam);
    const glm::dvec3 lo = centre - half, hi = centre + half;
    if (!box_inside_frustum(v, lo, hi)) {
      ++not_inside;
      continue;
    }
    ++inside;
    for (int s = 0; s < 200; ++s) {  // corners and random points of the box, in single precision
      glm::dvec3 t(in01(rng), in01(rng), in01(rng));
      if (s < 8) t = glm::dvec3(s & 1, (s >> 1) & 1, (s >> 2) & 1);
      const glm::vec3 p(lo + t * (hi - lo));
      const glm::vec3 pa = glm::clamp(p, glm::vec3(lo), glm::vec3(hi)) - v.eye_f;
      for (const glm::vec3& n : v.inward_f) CHECK(glm::dot(n, pa) >= 0.0f);
    }
  }
  CHECK(inside > 20);
  CHECK(not_inside > 20);
  CHECK(box_inside_frustum(make_view_frustum(look_at({0, 0, 0}, {0, -1, 0})), {1, 1, 1}, {-1, -1, -1}));  // empty
}

TEST_CASE("culling: frame() draws exactly the cut's triangles that hidden_triangle finds seen, in order", "[lod]") {
  const indexed_mesh m = support::make_torus(48, 24, 1.0f, 0.35f);
  const lod_of s(m, 6);
  auto lod = view_dependent_lod::create(s.h, s.table);
  REQUIRE(lod.ok());
  const std::vector<std::uint8_t> one_sided = closed_part_triangles(s.h.indices, s.h.positions);
  std::vector<std::uint32_t> out(contracted_index_bound(s.h)), cut_out(out.size());
  std::vector<index_range> ranges(s.h.cluster_count), cut_ranges(s.h.cluster_count);
  contraction_workspace w = make_contraction_workspace(s.h, 100);
  // Far (the whole torus in view: no frustum plane tested), close (planes cut it), inside the tube.
  const std::vector<lod_camera> cams{look_at({0.5, -6.0, 3.0}, {0, 0, 0}), look_at({0.2, -1.6, 0.5}, {0.4, 0.0, 0.0}),
                                     look_at({1.5, 0.0, 0.3}, {1.5, 0.0, -1.0}, {0, 1, 0}), look_at({1.0, 0.0, 0.05}, {0.0, 1.0, 0.0})};
  for (std::size_t k = 0; k < cams.size(); ++k)
    for (const double f : {0.0, 0.5, 0.9}) {
      INFO("camera " << k << ", budget " << f);
      auto st = lod->frame(cams[k], static_cast<std::uint64_t>((1.0 - f) * static_cast<double>(s.h.triangle_count())), out, ranges);
      REQUIRE(st.ok());
      auto cut = contract_indices(s.h, lod->stop_points(), w, cut_out, cut_ranges);
      REQUIRE(cut.ok());
      const view_frustum v = make_view_frustum(cams[k]);
      CHECK(box_inside_frustum(v, w.lo, w.hi) == (k == 0));  // both of contract_visible_indices' paths
      // The cut triangle by triangle in index-buffer order (contract_indices' order; a triangle
      // it skips is degenerate), and back faces count as seen when a ray from the eye crosses
      // the cut's closed part unevenly (the eye inside it: camera 3, the torus's tube).
      contraction_workspace w2 = make_contraction_workspace(s.h, 100);
      resolve_vertex_map(s.h, lod->stop_points(), w2);
      auto corner = [&](std::size_t t, std::size_t j) { return w2.remap[s.h.indices[3 * t + j]]; };
      long winding = 0;
      for (std::size_t t = 0; t < s.h.triangle_count(); ++t)
        if (one_sided[t] && corner(t, 0) != corner(t, 1) && corner(t, 1) != corner(t, 2) && corner(t, 0) != corner(t, 2))
          winding += eye_ray_crossing(v, s.h.positions[corner(t, 0)], s.h.positions[corner(t, 1)], s.h.positions[corner(t, 2)]);
      if (k == 3 && f == 0.0) CHECK(winding != 0);
      std::vector<std::uint32_t> expected;
      std::size_t kept_seen = 0;
      for (std::size_t t = 0; t < s.h.triangle_count(); ++t) {
        const std::uint32_t a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
        if (a == b || b == c || a == c) continue;
        ++kept_seen;
        if (!hidden_triangle(v, s.h.positions[a], s.h.positions[b], s.h.positions[c], winding == 0 && one_sided[t] != 0))
          expected.insert(expected.end(), {a, b, c});
      }
      CHECK(kept_seen * 3 == *cut);
      CHECK(expected.size() < *cut);
      CHECK(st->indices == expected.size());
      CHECK(std::equal(expected.begin(), expected.end(), out.begin()));
    }
}

TEST_CASE("culling: a camera inside a closed part, and two-sided clusters, give the same picture as the cut", "[lod]") {
  const indexed_mesh m = support::make_torus(48, 24, 1.0f, 0.35f);
  const lod_of s(m, 6);
  // Inside the tube, looking along it and across it: the back faces around the eye are seen.
  const std::vector<lod_camera> inside{look_at({1.0, 0.0, 0.05}, {0.0, 1.0, 0.0}), look_at({0.0, -1.05, 0.0}, {1.0, -1.0, 0.2}),
                                       look_at({-0.9, 0.1, -0.1}, {-1.5, 0.0, 0.3})};
  check_same_picture(m, s, inside, false);
  // Two-sided clusters (0 and 3) are never back-face culled; the others are, seen from outside.
  const std::array<std::uint32_t, 2> two{0, 3};
  const std::vector<lod_camera> outside{look_at({0.5, -3.0, 1.5}, {0.0, 0.0, 0.0}), look_at({2.5, 1.0, -0.5}, {0.0, 0.0, 0.0}),
                                        look_at({1.0, 0.0, 0.05}, {0.0, 1.0, 0.0})};
  check_same_picture(m, s, outside, false, {.view = {}, .two_sided = two});
}

TEST_CASE("culling: the eye-inside test counts a ray through a shared edge or vertex of a closed grid once", "[lod]") {
  // A closed, welded box of 8 x 8 cells per face on [-1, 1]^3 (grid coordinates exact in float).
  indexed_mesh box = support::make_box({-1, -1, -1}, {1, 1, 1});
  for (int i = 0; i < 3; ++i) box = support::subdivide_midpoint(box);
  std::vector<std::uint32_t> remap;
  box = support::weld_positions(box, remap);
  const std::vector<std::uint8_t> closed = closed_part_triangles(
      std::span<const std::uint32_t>(&box.triangles[0].x, 3 * box.triangle_count()), box.positions);
  REQUIRE(std::count(closed.begin(), closed.end(), 1) == static_cast<long>(box.triangle_count()));
  // The fixed ray of eye_ray_crossing leaves the box through x = 1, y = 1 or z = 1; put the eye on
  // that ray behind every grid vertex and edge midpoint of those faces, inside (winding 1) and
  // outside (winding 0) the box.
  const glm::dvec3 d(0.7296190, 0.3022190, 0.5341045);
  std::size_t cases = 0, wrong = 0;
  for (const glm::vec3& p : box.positions) {
    if (!(p.x == 1.0f || p.y == 1.0f || p.z == 1.0f)) continue;
    for (const glm::vec3& q : box.positions) {
      const glm::vec3 mid = 0.5f * (p + q);
      const bool vertex = p == q;
      if (!vertex && glm::length(p - q) > 0.2501f) continue;  // grid neighbours: 0.25 apart
      const glm::dvec3 target(vertex ? p : mid);
      for (const double t : {0.01, 0.125, 0.3, 4.0}) {
        const glm::dvec3 eye = target - t * d;
        const bool inside = std::abs(eye.x) < 1.0 && std::abs(eye.y) < 1.0 && std::abs(eye.z) < 1.0;
        const bool outside = std::abs(eye.x) > 1.0 || std::abs(eye.y) > 1.0 || std::abs(eye.z) > 1.0;
        if (!inside && !outside) continue;
        const view_frustum v = make_view_frustum(look_at(eye, eye + glm::dvec3(0.3, -0.2, 1.0)));
        long winding = 0;
        for (const glm::uvec3& f : box.triangles)
          winding += eye_ray_crossing(v, box.positions[f.x], box.positions[f.y], box.positions[f.z]);
        wrong += winding != (inside ? 1 : 0);
        ++cases;
      }
    }
  }
  INFO(wrong << " wrong windings of " << cases);
  CHECK(cases > 1000);
  CHECK(wrong == 0);
}
