// mesh/geometry.hpp: finite normals and areas for degenerate and badly scaled triangles,
// analytic areas, bounds and diagonal.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <numeric>
#include "infolerp/mesh/geometry.hpp"
#include "support/procedural.hpp"

namespace {
bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
infolerp::triangle_corners tri(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) { return {a, b, c}; }
}  // namespace

TEST_CASE("degenerate triangles give a finite zero normal and zero area") {
  const glm::dvec3 o(1, 2, 3);
  for (const auto& c : {tri(o, o, o), tri(o, o, o + glm::dvec3(1, 0, 0)),
                        tri(o, o + glm::dvec3(1, 1, 1), o + glm::dvec3(2, 2, 2))}) {  // point, repeated, collinear
    CHECK(infolerp::triangle_area(c) == 0.0);
    CHECK(infolerp::triangle_normal(c) == glm::vec3(0.0f));
  }
  infolerp::indexed_mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  m.triangles = {{0, 1, 2}, {0, 0, 1}};
  for (const auto& n : infolerp::face_normals(m)) CHECK(n == glm::vec3(0.0f));
  for (double a : infolerp::face_areas(m)) CHECK(a == 0.0);
}

TEST_CASE("coordinates scaled by 1e±30 stay finite and keep their normal") {
  for (double scale : {1e-30, 1e30, 1e-38, 1e38}) {
    const auto c = tri(glm::dvec3(0, 0, 0), glm::dvec3(scale, 0, 0), glm::dvec3(0, scale, 0));
    const glm::vec3 n = infolerp::triangle_normal(c);
    CHECK(finite(n));
    CHECK(n.z == Approx(1.0f).margin(1e-6));
    CHECK(infolerp::triangle_area(c) == Approx(0.5 * scale * scale).epsilon(1e-12));
    // Through a float mesh too (the usual engine storage).
    infolerp::indexed_mesh m;
    const auto s = static_cast<float>(scale);
    m.positions = {{0, 0, 0}, {0, s, 0}, {0, 0, s}};
    m.triangles = {{0, 1, 2}};
    const glm::vec3 nm = infolerp::face_normals(m)[0];
    CHECK(finite(nm));
    CHECK(nm.x == Approx(1.0f).margin(1e-6));
    CHECK(std::isfinite(infolerp::face_areas(m)[0]));
    CHECK(infolerp::face_areas(m)[0] > 0.0);
  }
}

TEST_CASE("areas, normals and centroids match closed forms") {
  const auto c = tri(glm::dvec3(0, 0, 0), glm::dvec3(3, 0, 0), glm::dvec3(0, 4, 0));
  CHECK(infolerp::triangle_area(c) == 6.0);
  CHECK(infolerp::triangle_normal(c) == glm::vec3(0, 0, 1));
  CHECK(infolerp::triangle_centroid(c) == glm::dvec3(1, 4.0 / 3.0, 0));
  // Box 1×2×3: area 22, outward normals.
  const auto box = infolerp::support::make_box({0, 0, 0}, {1, 2, 3});
  const auto areas = infolerp::face_areas(box);
  CHECK(std::accumulate(areas.begin(), areas.end(), 0.0) == Approx(22.0).epsilon(1e-12));
  const auto normals = infolerp::face_normals(box);
  for (std::size_t t = 0; t < box.triangles.size(); ++t) {
    const glm::dvec3 outward = infolerp::triangle_centroid(infolerp::corners(box, t)) - glm::dvec3(0.5, 1.0, 1.5);
    CHECK(glm::dot(glm::dvec3(normals[t]), outward) > 0.0);
    CHECK(glm::length(normals[t]) == Approx(1.0f).margin(1e-6));
  }
  // Icosphere area approaches 4π from below.
  const auto sphere = infolerp::support::make_icosphere(4);
  const auto sa = infolerp::face_areas(sphere);
  const double total = std::accumulate(sa.begin(), sa.end(), 0.0);
  CHECK(total < 4 * std::numbers::pi);
  CHECK(total == Approx(4 * std::numbers::pi).epsilon(5e-3));
}

TEST_CASE("bounds and diagonal of a box; unused vertices do not count; empty mesh") {
  auto box = infolerp::support::make_box({-1, 2, 0}, {3, 5, 12});
  auto b = infolerp::mesh_bounds(box);
  CHECK(b.lo == glm::dvec3(-1, 2, 0));
  CHECK(b.hi == glm::dvec3(3, 5, 12));
  CHECK(b.diagonal() == Approx(13.0).epsilon(1e-15));  // sqrt(16 + 9 + 144)
  CHECK(b.center() == glm::dvec3(1, 3.5, 6));
  box.positions.push_back({100, 100, 100});  // unused
  CHECK(infolerp::mesh_bounds(box).hi == glm::dvec3(3, 5, 12));
  infolerp::indexed_mesh empty;
  const auto e = infolerp::mesh_bounds(empty);
  CHECK(e.empty());
  CHECK(e.diagonal() == 0.0);
  CHECK(e.center() == glm::dvec3(0.0));
}
