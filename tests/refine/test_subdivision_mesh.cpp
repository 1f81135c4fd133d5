// refine/subdivision_mesh.hpp: hand-checked small cases, then property tests over thousands of
// random selections on real meshes (conformity, area conservation, no duplicate vertices,
// valid hierarchy, shape bound) and point location against a brute-force search.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <tuple>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/matrix.hpp>
#include "infolerp/mesh/topology.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"

using infolerp::indexed_mesh;
using infolerp::invalid_id;
using infolerp::subdivision_mesh;

// Fast REQUIRE for invariants checked millions of times: one failure ends the test case.
#define VERIFY(...)                                \
  do {                                             \
    if (!(__VA_ARGS__)) FAIL("violated: " #__VA_ARGS__); \
  } while (0)

namespace {

double area(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) { return 0.5 * glm::length(glm::cross(b - a, c - a)); }

double min_angle(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  auto angle = [](glm::dvec3 p, glm::dvec3 q, glm::dvec3 r) {
    return std::acos(std::clamp(glm::dot(glm::normalize(q - p), glm::normalize(r - p)), -1.0, 1.0));
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

// Smallest angle any leaf may have: a leaf is similar to its original triangle (1:4 children
// are) or a 1:2 child of such a triangle.
double shape_bound(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  double bound = min_angle(a, b, c);
  const std::array<glm::dvec3, 3> p{a, b, c};
  for (std::size_t k = 0; k < 3; ++k) {
    const glm::dvec3 pa = p[k], pb = p[(k + 1) % 3], pc = p[(k + 2) % 3], m = 0.5 * (pa + pb);
    bound = std::min({bound, min_angle(pa, m, pc), min_angle(m, pb, pc)});
  }
  return bound;
}

double perimeter(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  return glm::distance(a, b) + glm::distance(b, c) + glm::distance(c, a);
}

// Every invariant the header promises, checked from the outside.
// Areas: vertices are floats, so every midpoint is rounded by up to half an ulp of the largest
// coordinate (|δ| <= sqrt(3)·max|p|·2^-24); moving a vertex by δ changes a triangle's area by at
// most half the opposite edge times δ, so a set of triangles can lose or gain at most
// (their total perimeter)·δ. That is the tolerance, no more (angles likewise: ~2δ/edge).
void check_invariants(const subdivision_mesh& s, const indexed_mesh& input) {
  const auto P = [&](std::uint32_t v) { return glm::dvec3(s.position(v)); };
  const auto tris = s.triangles();
  const std::size_t n_orig = input.triangles.size();
  VERIFY(s.original_triangle_count() == n_orig);
  double max_abs = 0.0;
  for (const glm::vec3& p : input.positions) max_abs = std::max({max_abs, double(std::abs(p.x)), double(std::abs(p.y)), double(std::abs(p.z))});
  const double delta = std::sqrt(3.0) * max_abs * std::ldexp(1.0, -24);

  // Hierarchy: links, levels, originals, children made of parent corners and edge midpoints,
  // children's areas summing to the parent's.
  std::size_t leaves = 0;
  std::set<std::uint32_t> used_vertices;  // vertices of triangles in use (coarsen() frees slots and vertices)
  for (std::uint32_t t = 0; t < tris.size(); ++t) {
    const auto& n = tris[t];
    if (n.retired == 3) {  // a slot coarsen() freed
      VERIFY(t >= n_orig);
      VERIFY(n.child_count == 0);
      continue;
    }
    for (int k = 0; k < 3; ++k) used_vertices.insert(n.vertices[k]);
    if (n.is_leaf()) ++leaves;
    if (t < n_orig) {
      VERIFY(n.parent == invalid_id);
      VERIFY(n.level == 0);
      VERIFY(n.original == t);
      VERIFY(n.retired == 0);
    } else {
      VERIFY(n.parent < tris.size());  // not always below t: coarsen() frees slots that later splits reuse
      VERIFY(tris[n.parent].retired != 3);
      const auto& p = tris[n.parent];
      VERIFY(n.level == p.level + 1);
      VERIFY(n.original == p.original);
      if (n.retired) VERIFY(p.child_count == 4);  // retired 1:2 children: the parent was re-split 1:4
      else VERIFY((t >= p.first_child && t < p.first_child + p.child_count));
    }
    if (n.child_count == 0) {
      VERIFY(n.first_child == invalid_id);
      continue;
    }
    VERIFY((n.child_count == 2 || n.child_count == 4));
    std::set<std::tuple<float, float, float>> allowed;
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 a = s.position(n.vertices[k]), b = s.position(n.vertices[(k + 1) % 3]);
      allowed.insert({a.x, a.y, a.z});
      const glm::vec3 m = 0.5f * (a + b);
      allowed.insert({m.x, m.y, m.z});
    }
    double child_area = 0.0, child_perimeter = 0.0;
    for (std::uint32_t c = n.first_child; c < n.first_child + n.child_count; ++c) {
      VERIFY(tris[c].parent == t);
      VERIFY(tris[c].retired == 0);
      for (int k = 0; k < 3; ++k) {
        const glm::vec3 q = s.position(tris[c].vertices[k]);
        VERIFY(allowed.count({q.x, q.y, q.z}) == 1);
      }
      child_area += area(P(tris[c].vertices.x), P(tris[c].vertices.y), P(tris[c].vertices.z));
      child_perimeter += perimeter(P(tris[c].vertices.x), P(tris[c].vertices.y), P(tris[c].vertices.z));
    }
    VERIFY(std::abs(child_area - area(P(n.vertices.x), P(n.vertices.y), P(n.vertices.z))) <= child_perimeter * delta);
  }
  VERIFY(leaves == s.leaf_count());

  // Area conservation per original triangle; orientation and shape of every leaf.
  std::vector<double> leaf_area(n_orig, 0.0), leaf_perimeter(n_orig, 0.0);
  for (const auto& n : tris) {
    if (!n.is_leaf()) continue;  // free slots are not leaves
    const glm::dvec3 a = P(n.vertices.x), b = P(n.vertices.y), c = P(n.vertices.z);
    leaf_area[n.original] += area(a, b, c);
    leaf_perimeter[n.original] += perimeter(a, b, c);
    const glm::uvec3 o = input.triangles[n.original];
    const glm::dvec3 oa(input.positions[o.x]), ob(input.positions[o.y]), oc(input.positions[o.z]);
    VERIFY(glm::dot(glm::cross(b - a, c - a), glm::cross(ob - oa, oc - oa)) > 0.0);
    // Rounded midpoints turn an angle by at most ~2δ over the shortest edge.
    const double shortest = std::min({glm::distance(a, b), glm::distance(b, c), glm::distance(c, a)});
    VERIFY(min_angle(a, b, c) >= shape_bound(oa, ob, oc) - 4.0 * delta / shortest);
  }
  for (std::size_t t = 0; t < n_orig; ++t) {
    const glm::uvec3 o = input.triangles[t];
    const double original_area = area(glm::dvec3(input.positions[o.x]), glm::dvec3(input.positions[o.y]),
                                      glm::dvec3(input.positions[o.z]));
    VERIFY(std::abs(leaf_area[t] - original_area) <= leaf_perimeter[t] * delta);
  }

  // No duplicate vertices: a new vertex never sits where another vertex already is.
  std::map<std::tuple<float, float, float>, std::uint32_t> where;
  for (std::uint32_t v : used_vertices) {
    const glm::vec3 p = s.position(v);
    const auto [it, fresh] = where.insert({{p.x, p.y, p.z}, v});
    if (!fresh) VERIFY(v < input.positions.size());  // only the input may repeat positions
  }

  // Conformity: each leaf edge is matched by the opposite half-edge of exactly one other leaf,
  // unless it lies on a boundary edge of the input; no leaf vertex sits in the middle of an
  // unmatched edge (a T-vertex).
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> half_edges;
  std::set<std::uint32_t> leaf_vertices;
  for (const auto& n : tris) {
    if (!n.is_leaf()) continue;
    for (int k = 0; k < 3; ++k) {
      ++half_edges[{n.vertices[k], n.vertices[(k + 1) % 3]}];
      leaf_vertices.insert(n.vertices[k]);
    }
  }
  auto in_topo = infolerp::make_topology(input);
  VERIFY(in_topo.ok());
  double input_boundary = 0.0, leaf_boundary = 0.0;
  for (std::uint32_t e : infolerp::boundary_edges(*in_topo))
    input_boundary += glm::distance(glm::dvec3(input.positions[in_topo->edges[e].x]),
                                    glm::dvec3(input.positions[in_topo->edges[e].y]));
  for (const auto& [he, count] : half_edges) {
    VERIFY(count == 1);  // no two leaves with the same directed edge
    if (half_edges.count({he.second, he.first})) continue;
    leaf_boundary += glm::distance(P(he.first), P(he.second));
    const glm::vec3 m = 0.5f * (s.position(he.first) + s.position(he.second));
    const auto it = where.find({m.x, m.y, m.z});
    VERIFY((it == where.end() || leaf_vertices.count(it->second) == 0));
  }
  VERIFY(leaf_boundary == Approx(input_boundary).epsilon(1e-5).margin(1e-9));
}

std::vector<std::uint32_t> leaf_ids(const subdivision_mesh& s) {
  std::vector<std::uint32_t> out;
  s.leaves(out);
  return out;
}

// Random selections: mostly current leaves, sometimes any id (split, retired or a 1:2 child).
void random_selections(subdivision_mesh& s, const indexed_mesh& input, int count, unsigned seed, int check_every) {
  std::mt19937 rng(seed);
  std::vector<std::uint32_t> leaves = leaf_ids(s);
  for (int i = 1; i <= count; ++i) {
    std::uint32_t t;
    if (rng() % 4 == 0) t = static_cast<std::uint32_t>(rng() % s.triangle_count());
    else t = leaves[rng() % leaves.size()];
    REQUIRE(s.split(t).ok());
    if (i % 50 == 0) leaves = leaf_ids(s);
    if (i % check_every == 0) check_invariants(s, input);
  }
  check_invariants(s, input);
}

}  // namespace

TEST_CASE("subdivision: two triangles of a square, by hand") {
  indexed_mesh sq;
  sq.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  sq.triangles = {{0, 1, 2}, {0, 2, 3}};  // shared diagonal (0,2): ratio 2·area/width² = 0.5 for both

  SECTION("flat neighbour: 1:2 closure") {
    auto s = subdivision_mesh::create(sq, {.bisect_ratio = 0.6f});
    REQUIRE(s.ok());
    REQUIRE(s->split(0u).ok());
    CHECK(s->triangle_count() == 2 + 4 + 2);
    CHECK(s->leaf_count() == 4 + 2);
    CHECK(s->vertex_count() == 4 + 3);
    CHECK(s->triangle(1).child_count == 2);
    CHECK(s->triangle(1).split_edge == 0);  // edge (0,2) is corner 0 -> 1 of triangle 1
    CHECK(s->edge_midpoint(0, 2) == s->edge_midpoint(2, 0));
    check_invariants(*s, sq);

    // Rule 3: selecting a 1:2 child re-splits its parent 1:4, reusing the diagonal midpoint.
    const std::uint32_t green = s->triangle(1).first_child;
    REQUIRE(s->split(green).ok());
    CHECK(s->triangle(1).child_count == 4);
    CHECK(s->triangle(green).retired == 1);
    CHECK(s->triangle(green + 1).retired == 2);
    CHECK(s->triangle_count() == 2 + 4 + 2 + 4);
    CHECK(s->leaf_count() == 8);
    CHECK(s->vertex_count() == 4 + 5);
    check_invariants(*s, sq);
    // Selecting the retired child or a split triangle again changes nothing.
    REQUIRE(s->split(green).ok());
    REQUIRE(s->split(0u).ok());
    CHECK(s->triangle_count() == 12);
  }
  SECTION("well-shaped neighbour: 1:4 propagation") {
    auto s = subdivision_mesh::create(sq, {.bisect_ratio = 0.5f});
    REQUIRE(s.ok());
    REQUIRE(s->split(0u).ok());
    CHECK(s->leaf_count() == 8);
    CHECK(s->vertex_count() == 9);
    CHECK(s->triangle(1).child_count == 4);
    check_invariants(*s, sq);
  }
  SECTION("deeper split on one side closes the other side") {
    auto s = subdivision_mesh::create(sq, {.bisect_ratio = 0.6f});
    REQUIRE(s.ok());
    REQUIRE(s->split(0u).ok());
    // child 0 of triangle 0 = (v0, m0, m2) has edge (m2, v0) on the diagonal.
    REQUIRE(s->split(s->triangle(0).first_child).ok());
    check_invariants(*s, sq);
    CHECK(s->triangle(1).child_count == 4);  // the 1:2 neighbour had to become 1:4
  }
  SECTION("errors name the element") {
    auto s = subdivision_mesh::create(sq);
    REQUIRE(s.ok());
    const auto st = s->split(99u);
    CHECK(st.code() == infolerp::errc::index_out_of_range);
    CHECK(st.element() == 99);
    indexed_mesh bad = sq;
    bad.triangles.push_back({1, 1, 2});
    CHECK(subdivision_mesh::create(bad).error().element() == 2);
    bad.triangles.back() = {0, 1, 7};
    CHECK(subdivision_mesh::create(bad).error().code() == infolerp::errc::index_out_of_range);
    bad.triangles.back() = {0, 1, 2};
    bad.triangles.push_back({0, 1, 2});
    CHECK(subdivision_mesh::create(bad).error().code() == infolerp::errc::non_manifold_edge);
    indexed_mesh flat = sq;
    flat.positions[2] = {0.5f, 0.5f, 0.0f};  // triangle 0 = (0,0) (1,0) (.5,.5) ok; make 1 collinear
    flat.positions[3] = {1.0f, 1.0f, 0.0f};
    CHECK(subdivision_mesh::create(flat).error().code() == infolerp::errc::degenerate_triangle);
    CHECK(subdivision_mesh::create(indexed_mesh{}).error().code() == infolerp::errc::empty_input);
    CHECK(subdivision_mesh::create(sq, {.bisect_ratio = -1.0f}).error().code() == infolerp::errc::bad_parameter);
  }
}

TEST_CASE("subdivision: midpoints of coordinates near FLT_MAX stay finite") {
  // Found by fuzz_subdivision: 0.5 * (a + b) overflowed to infinity when both were near FLT_MAX.
  const float big = std::numeric_limits<float>::max();
  indexed_mesh m;
  m.positions = {{big, big, 0}, {big, -big, 0}, {big, big, big}};
  m.triangles = {{0, 1, 2}};
  auto s = subdivision_mesh::create(m, {});
  REQUIRE(s.ok());
  REQUIRE(s->split(0u).ok());
  REQUIRE(s->vertex_count() == 6);
  for (std::size_t v = 0; v < s->vertex_count(); ++v) {
    const glm::vec3 p = s->position(v);
    CHECK((std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)));
  }
  CHECK(s->position(s->edge_midpoint(0, 2)) == glm::vec3(big, big, 0.5f * big));
  CHECK(s->position(s->edge_midpoint(0, 1)) == glm::vec3(big, 0, 0));
}

TEST_CASE("subdivision: thousands of random selections on fandisk keep every invariant") {
  auto mesh = infolerp::support::load_mesh(infolerp::support::cgal_mesh("fandisk"));
  REQUIRE(mesh.ok());
  for (std::uint32_t depth : {0u, 1u, 2u}) {
    auto s = subdivision_mesh::create(*mesh, {.bisect_ratio = 0.5f, .propagation_depth = depth});
    REQUIRE(s.ok());
    random_selections(*s, *mesh, 2000, 11 + depth, 1000);
    INFO("depth " << depth << ": " << s->leaf_count() << " leaves");
    CHECK(s->leaf_count() > mesh->triangles.size() + 2000 * 3);
  }
}

TEST_CASE("subdivision: random selections on bunny00 (open mesh with boundaries)") {
  auto mesh = infolerp::support::load_mesh(infolerp::support::cgal_mesh("bunny00"));
  REQUIRE(mesh.ok());
  auto s = subdivision_mesh::create(*mesh, {.bisect_ratio = 0.8f, .propagation_depth = 1});
  REQUIRE(s.ok());
  random_selections(*s, *mesh, 3000, 5, 1500);
}

TEST_CASE("subdivision: unbounded propagation and repeated deep selections on a small sphere") {
  const auto sphere = infolerp::support::make_icosphere(1);
  auto s = subdivision_mesh::create(sphere, {.bisect_ratio = 0.9f, .propagation_depth = 1000});
  REQUIRE(s.ok());
  random_selections(*s, sphere, 120, 3, 40);
  // Drill into one spot: select the leaf under a fixed point again and again; its level grows
  // by one per selection (a 1:2 leaf's parent re-splits 1:4 first), the closure holds.
  for (int i = 0; i < 14; ++i) REQUIRE(s->split(s->locate(0, {0.3f, 0.3f}).leaf).ok());
  check_invariants(*s, sphere);
  std::uint8_t deepest = 0;
  for (const auto& n : s->triangles()) deepest = std::max(deepest, n.level);
  INFO(s->leaf_count() << " leaves");
  CHECK(deepest >= 12);
  CHECK(s->triangle(s->locate(0, {0.3f, 0.3f}).leaf).level >= 12);
}

TEST_CASE("subdivision: point location matches brute force and follows splits") {
  auto mesh = infolerp::support::load_mesh(infolerp::support::cgal_mesh("fandisk"));
  REQUIRE(mesh.ok());
  auto s = subdivision_mesh::create(*mesh);
  REQUIRE(s.ok());
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  struct probe {
    std::uint32_t original;
    glm::vec2 uv;
    infolerp::point_location loc;
  };
  std::vector<probe> probes;
  for (int i = 0; i < 2000; ++i) {
    float u = u01(rng), v = u01(rng);
    if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
    const auto t = static_cast<std::uint32_t>(rng() % mesh->triangles.size());
    probes.push_back({t, {u, v}, s->locate(t, {u, v})});
  }
  random_selections(*s, *mesh, 1500, 21, 100000);
  // Brute force: leaves of each original.
  std::vector<std::vector<std::uint32_t>> by_original(mesh->triangles.size());
  for (std::uint32_t t : leaf_ids(*s)) by_original[s->triangle(t).original].push_back(t);
  for (const probe& p : probes) {
    const glm::uvec3 o = mesh->triangles[p.original];
    const glm::dvec3 q = (1.0 - p.uv.x - p.uv.y) * glm::dvec3(mesh->positions[o.x]) +
                         double(p.uv.x) * glm::dvec3(mesh->positions[o.y]) + double(p.uv.y) * glm::dvec3(mesh->positions[o.z]);
    const auto loc = s->locate(p.original, p.uv);
    REQUIRE(s->is_leaf(loc.leaf));
    REQUIRE(s->triangle(loc.leaf).original == p.original);
    REQUIRE(loc.weights.x + loc.weights.y + loc.weights.z == Approx(1.0f).margin(1e-5));
    REQUIRE(std::min({loc.weights.x, loc.weights.y, loc.weights.z}) >= -1e-5f);
    const glm::uvec3 lv = s->triangle(loc.leaf).vertices;
    const glm::dvec3 r = double(loc.weights.x) * glm::dvec3(s->position(lv.x)) +
                         double(loc.weights.y) * glm::dvec3(s->position(lv.y)) +
                         double(loc.weights.z) * glm::dvec3(s->position(lv.z));
    REQUIRE(glm::distance(q, r) < 1e-5);
    // The brute-force search finds the point in the located leaf (and nowhere with larger margin).
    double best = -1e9;
    std::uint32_t best_leaf = invalid_id;
    for (std::uint32_t t : by_original[p.original]) {
      const glm::uvec3 v = s->triangle(t).vertices;
      const glm::dvec3 a(s->position(v.x)), b(s->position(v.y)), c(s->position(v.z));
      const glm::dvec3 n = glm::cross(b - a, c - a);
      const double nn = glm::dot(n, n);
      const double w0 = glm::dot(glm::cross(c - b, q - b), n) / nn, w1 = glm::dot(glm::cross(a - c, q - c), n) / nn;
      const double margin = std::min({w0, w1, 1.0 - w0 - w1});
      if (margin > best) best = margin, best_leaf = t;
    }
    REQUIRE(best >= -1e-6);
    if (best > 1e-4) REQUIRE(best_leaf == loc.leaf);  // unambiguous (not on a leaf edge)
    // Following the stale location gives the same answer as a fresh one.
    const auto followed = s->locate_from(p.loc.leaf, p.loc.weights);
    REQUIRE(followed.leaf == loc.leaf);
    REQUIRE(glm::distance(followed.weights, loc.weights) < 1e-4f);
  }
}

TEST_CASE("subdivision: §4.1 tessellation to a screen fraction") {
  const auto plane = infolerp::support::make_plane(1, 1, 2.0f);  // covers NDC [-1,1]² under identity
  auto s = subdivision_mesh::create(plane);
  REQUIRE(s.ok());
  // Each half covers 1/2 of the screen; 1/2 · 4^-k <= 0.01 first at k = 3.
  s->tessellate(infolerp::screen_fraction_test{.view_projection = glm::mat4(1.0f), .max_fraction = 0.01f});
  CHECK(s->leaf_count() == 2 * 64);
  for (const auto& n : s->triangles())
    if (n.is_leaf()) CHECK(n.level == 3);
  check_invariants(*s, plane);
  // max_level bounds it.
  auto capped = subdivision_mesh::create(plane);
  REQUIRE(capped.ok());
  capped->tessellate(infolerp::screen_fraction_test{.max_fraction = 1e-9f}, 2);
  CHECK(capped->leaf_count() == 2 * 16);
}

namespace {
// Brute-force screen fraction: a ray from the eye through each cell centre of a grid over NDC,
// intersected with the triangle in world space; a hit counts when its view depth lies between
// the near and far planes (what the view volume keeps).
double ray_cast_screen_fraction(glm::vec3 eye, const glm::mat4& view, float fovy, float aspect, float znear,
                                float zfar, glm::vec3 a, glm::vec3 b, glm::vec3 c, int grid) {
  const glm::mat4 inv = glm::inverse(view);
  const double h = std::tan(0.5 * fovy);
  int hits = 0;
  for (int j = 0; j < grid; ++j)
    for (int i = 0; i < grid; ++i) {
      const double x = (2.0 * (i + 0.5) / grid - 1.0) * h * aspect, y = (2.0 * (j + 0.5) / grid - 1.0) * h;
      const glm::dvec3 d = glm::dvec3(glm::mat3(inv) * glm::vec3(float(x), float(y), -1.0f));  // view depth 1
      const glm::dvec3 o(eye), e1 = glm::dvec3(b) - glm::dvec3(a), e2 = glm::dvec3(c) - glm::dvec3(a);
      const glm::dvec3 pv = glm::cross(d, e2);
      const double det = glm::dot(e1, pv);
      if (std::abs(det) < 1e-12) continue;
      const glm::dvec3 tv = o - glm::dvec3(a);
      const double u = glm::dot(tv, pv) / det;
      const glm::dvec3 qv = glm::cross(tv, e1);
      const double v = glm::dot(d, qv) / det, t = glm::dot(e2, qv) / det;  // t = view depth (|d.z| = 1)
      if (u >= 0 && v >= 0 && u + v <= 1 && t >= znear && t <= zfar) ++hits;
    }
  return double(hits) / double(grid * grid);
}
}  // namespace

TEST_CASE("subdivision: the screen fraction is the on-screen area, clipped to the view volume") {
  const glm::vec3 eye{0.3f, 1.5f, 4.0f};
  const glm::mat4 view = glm::lookAt(eye, glm::vec3(0.0f, 0.0f, -2.0f), glm::vec3(0.0f, 1.0f, 0.0f));
  const float fovy = glm::radians(60.0f), aspect = 4.0f / 3.0f, znear = 0.1f, zfar = 100.0f;
  const infolerp::screen_fraction_test test{.view_projection = glm::perspective(fovy, aspect, znear, zfar) * view};
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-8.0f, 8.0f);
  int behind = 0, crossing = 0, outside = 0, inside = 0;
  for (int k = 0; k < 200; ++k) {
    const glm::vec3 a{u(rng), u(rng) * 0.5f, u(rng)}, b{u(rng), u(rng) * 0.5f, u(rng)}, c{u(rng), u(rng) * 0.5f, u(rng)};
    const double reference = ray_cast_screen_fraction(eye, view, fovy, aspect, znear, zfar, a, b, c, 160);
    const float fraction = test.screen_fraction(a, b, c);
    // One grid cell along the projected boundary: the reference's resolution.
    CHECK(std::abs(fraction - reference) <= 0.03 + 0.05 * reference);
    const auto depth = [&](glm::vec3 p) { return -(view * glm::vec4(p, 1.0f)).z; };
    const int in_front = (depth(a) > 0) + (depth(b) > 0) + (depth(c) > 0);
    if (in_front == 0) {
      ++behind;
      CHECK(fraction == 0.0f);
    } else if (in_front < 3) {
      ++crossing;
    } else if (reference == 0.0) {
      ++outside;
    } else {
      ++inside;
    }
  }
  // The random triangles cover every case.
  CHECK(behind > 0);
  CHECK(crossing > 0);
  CHECK(outside > 0);
  CHECK(inside > 0);
}

TEST_CASE("subdivision: tessellation never splits triangles behind the eye or outside the frustum") {
  // A 64 x 64 ground plane (z = 0 in the mesh, rotated to y = 0) with the eye in its middle,
  // looking along -z: half the plane lies behind the eye, much of the rest outside the frustum.
  const auto plane = infolerp::support::make_plane(4, 4, 64.0f);
  indexed_mesh ground;
  infolerp::support::append(ground, plane, glm::rotate(glm::mat4(1.0f), glm::radians(-90.0f), glm::vec3(1, 0, 0)));
  auto s = subdivision_mesh::create(ground);
  REQUIRE(s.ok());
  const glm::vec3 eye{0.0f, 1.0f, 0.0f};
  const glm::mat4 view = glm::lookAt(eye, glm::vec3(0.0f, 0.8f, -5.0f), glm::vec3(0.0f, 1.0f, 0.0f));
  const infolerp::screen_fraction_test test{
      .view_projection = glm::perspective(glm::radians(60.0f), 4.0f / 3.0f, 0.1f, 100.0f) * view, .max_fraction = 0.01f};
  const std::size_t selections = s->tessellate(test, 8);
  CHECK(selections > 0);
  check_invariants(*s, ground);
  // No triangle wholly behind the eye is split 1:4 (1:2 closure splits next to split
  // neighbours are allowed: they keep the mesh conforming).
  std::size_t split_behind = 0, visible_leaves = 0;
  for (const auto& n : s->triangles()) {
    const glm::vec3 p[3] = {s->position(n.vertices.x), s->position(n.vertices.y), s->position(n.vertices.z)};
    bool all_behind = true;
    for (const glm::vec3& q : p) all_behind = all_behind && -(view * glm::vec4(q, 1.0f)).z <= 0.0f;
    if (n.child_count == 4 && all_behind) ++split_behind;
    if (n.is_leaf() && test.screen_fraction(p[0], p[1], p[2]) > 0.0f) {
      ++visible_leaves;
      CHECK((n.level == 8 || test.screen_fraction(p[0], p[1], p[2]) <= 0.01f));
    }
  }
  INFO("leaves " << s->leaf_count());
  CHECK(split_behind == 0);
  CHECK(visible_leaves > 0);
  CHECK(s->leaf_count() < 32 * 4096);
}

TEST_CASE("subdivision: tessellation leaves a mesh behind the eye or beside the frustum alone") {
  const auto plane = infolerp::support::make_plane(4, 4, 8.0f);  // z = 0, facing +z
  const glm::mat4 projection = glm::perspective(glm::radians(60.0f), 4.0f / 3.0f, 0.1f, 100.0f);
  const glm::vec3 looks[] = {glm::vec3(0.0f, 0.0f, 10.0f),    // behind the eye (looking away)
                             glm::vec3(40.0f, 0.0f, -5.0f),   // far to the side
                             glm::vec3(0.0f, -40.0f, -5.0f)};  // far below
  for (const glm::vec3 look : looks) {
    INFO("looking along " << look.x << " " << look.y << " " << look.z);
    auto s = subdivision_mesh::create(plane);
    REQUIRE(s.ok());
    const glm::mat4 view = glm::lookAt(glm::vec3(0.0f, 0.0f, 5.0f), glm::vec3(0.0f, 0.0f, 5.0f) + look, glm::vec3(0, 1, 0));
    CHECK(s->tessellate(infolerp::screen_fraction_test{.view_projection = projection * view, .max_fraction = 1e-6f}) == 0);
    CHECK(s->triangle_count() == plane.triangles.size());
  }
}

namespace {
// Collapses every split triangle allow() admits, deepest first, until a round collapses nothing.
std::size_t coarsen_all(subdivision_mesh& s, const std::function<bool(std::uint32_t)>& allow,
                        std::vector<std::uint32_t>& freed_t, std::vector<std::uint32_t>& freed_v) {
  std::size_t collapsed = 0;
  for (bool progress = true; progress;) {
    progress = false;
    for (std::uint32_t t = 0; t < s.triangle_count(); ++t)
      if (s.triangle(t).child_count > 0 && s.coarsen(t, allow, [](std::uint32_t) { return true; }, freed_t, freed_v))
        progress = true, ++collapsed;
  }
  return collapsed;
}
}  // namespace

namespace {
// Random splits, then coarsen() of the originals left of x = 0 (whatever a split edge ties to
// the right half stays), then of everything, then splits again: the invariants and conformity
// (check_invariants) hold after each step.
void check_coarsen(const indexed_mesh& input) {
  auto s = subdivision_mesh::create(input, {.propagation_depth = 2});
  REQUIRE(s.ok());
  random_selections(*s, input, 600, 5, 100);
  const std::size_t storage = s->triangle_count(), vertices = s->vertex_count();
  std::vector<std::uint32_t> freed_t, freed_v;

  // Only the hierarchies of the left half's originals may go: whatever is tied to the right
  // half through a split edge stays, and the mesh stays conforming.
  const auto left = [&](std::uint32_t t) { return s->position(s->triangle(s->triangle(t).original).vertices.x).x < 0.0f; };
  const std::size_t some = coarsen_all(*s, left, freed_t, freed_v);
  CHECK(some > 0);
  check_invariants(*s, input);
  CHECK(s->live_triangle_count() == storage - freed_t.size());
  for (std::uint32_t t : freed_t) CHECK_FALSE(s->is_leaf(t));
  std::set<std::uint32_t> distinct_t(freed_t.begin(), freed_t.end()), distinct_v(freed_v.begin(), freed_v.end());
  CHECK(distinct_t.size() == freed_t.size());  // each slot freed once
  CHECK(distinct_v.size() == freed_v.size());
  for (std::uint32_t v : freed_v) CHECK(v >= input.positions.size());  // input vertices are never freed

  // Everything: back to the input, leaf for leaf.
  coarsen_all(*s, [](std::uint32_t) { return true; }, freed_t, freed_v);
  check_invariants(*s, input);
  CHECK(s->leaf_count() == input.triangles.size());
  CHECK(s->live_triangle_count() == input.triangles.size());
  for (std::uint32_t t = 0; t < input.triangles.size(); ++t) {
    CHECK(s->is_leaf(t));
    CHECK(s->triangle(t).vertices == input.triangles[t]);
  }
  for (std::uint32_t t = 0; t < input.triangles.size(); ++t)  // no midpoint is left on an input edge
    for (int k = 0; k < 3; ++k) CHECK(s->edge_midpoint(input.triangles[t][k], input.triangles[t][(k + 1) % 3]) == invalid_id);

  // Splitting again reuses the freed slots and vertices before growing, and keeps every invariant.
  random_selections(*s, input, 300, 9, 100);
  CHECK(s->triangle_count() <= storage);
  CHECK(s->vertex_count() <= vertices);
  REQUIRE(s->split(leaf_ids(*s).front()).ok());
  for (std::uint32_t c : s->created()) CHECK(s->triangle(c).parent != invalid_id);
  CHECK_FALSE(s->created().empty());
  check_invariants(*s, input);
}

// The icosphere's triangles whose corners all lie above z = -0.4: a curved mesh with one
// boundary loop, its vertices renumbered.
indexed_mesh open_cap() {
  const indexed_mesh sphere = infolerp::support::make_icosphere(2);
  indexed_mesh cap;
  std::vector<std::uint32_t> index(sphere.positions.size(), invalid_id);
  for (const glm::uvec3& t : sphere.triangles) {
    if (!(sphere.positions[t.x].z > -0.4f && sphere.positions[t.y].z > -0.4f && sphere.positions[t.z].z > -0.4f)) continue;
    glm::uvec3 u;
    for (int k = 0; k < 3; ++k) {
      if (index[t[k]] == invalid_id) index[t[k]] = static_cast<std::uint32_t>(cap.positions.size()), cap.positions.push_back(sphere.positions[t[k]]);
      u[k] = index[t[k]];
    }
    cap.triangles.push_back(u);
  }
  return cap;
}
}  // namespace

TEST_CASE("subdivision: coarsen undoes splits, keeps the mesh conforming, and splits reuse what it freed") {
  SECTION("a flat grid") { check_coarsen(infolerp::support::make_plane(6, 6, 2.0f)); }
  SECTION("a closed curved mesh (icosphere)") { check_coarsen(infolerp::support::make_icosphere(2)); }
  SECTION("an open curved mesh (icosphere cap)") {
    const indexed_mesh cap = open_cap();
    auto topo = infolerp::make_topology(cap);
    REQUIRE(topo.ok());
    REQUIRE_FALSE(infolerp::boundary_edges(*topo).empty());
    check_coarsen(cap);
  }
}

TEST_CASE("subdivision: coarsen collapses whole subtrees, and nothing when a predicate refuses") {
  const indexed_mesh input = infolerp::support::make_plane(2, 2, 2.0f);
  auto s = subdivision_mesh::create(input);
  REQUIRE(s.ok());
  REQUIRE(s->split(0).ok());
  const std::uint32_t child = s->triangle(0).first_child + 3;
  REQUIRE(s->split(child).ok());
  std::vector<std::uint32_t> ft, fv;
  const auto yes = [](std::uint32_t) { return true; };
  const auto no = [](std::uint32_t) { return false; };
  CHECK_FALSE(s->coarsen(child, no, yes, ft, fv));  // refused by a triangle
  CHECK_FALSE(s->coarsen(child, yes, no, ft, fv));  // refused by a vertex it created
  CHECK_FALSE(s->coarsen(s->triangle(child).first_child, yes, yes, ft, fv));  // a leaf: nothing to collapse
  CHECK(ft.empty());
  CHECK(fv.empty());
  CHECK(s->coarsen(0, yes, yes, ft, fv));  // the whole subtree, the split child's included
  CHECK(s->triangle(child).retired == 3);
  check_invariants(*s, input);
  CHECK(s->leaf_count() == input.triangles.size());
}
