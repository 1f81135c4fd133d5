#pragma once
// Per-triangle geometry (normals, areas, centroids) and bounding boxes, finite for every input:
// a degenerate (zero-area) triangle has area 0 and normal (0,0,0), never NaN.
// Computed in double and returned in float (normals) or double (areas).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/mesh_traits.hpp"

namespace infolerp {

struct triangle_corners {
  glm::dvec3 p0, p1, p2;
};

// Preconditions: t < triangle count, indices in range (see validate_mesh). O(1), no allocation.
template <class M>
triangle_corners corners(const M& m, std::size_t t) {
  static_assert(check_mesh<M>());
  const glm::uvec3 tri = mesh_triangle(m, t);
  return {glm::dvec3(mesh_position(m, tri.x)), glm::dvec3(mesh_position(m, tri.y)), glm::dvec3(mesh_position(m, tri.z))};
}

// Per-triangle helpers below: O(1), no allocation, pure (thread-safe).
// Unnormalised normal (p1-p0)×(p2-p0); its length is twice the area.
inline glm::dvec3 area_vector(const triangle_corners& c) { return glm::cross(c.p1 - c.p0, c.p2 - c.p0); }

inline double triangle_area(const triangle_corners& c) { return 0.5 * glm::length(area_vector(c)); }

// Unit normal, or (0,0,0) when the triangle has no area (or its area underflows).
inline glm::vec3 triangle_normal(const triangle_corners& c) {
  const glm::dvec3 n = area_vector(c);
  const double len = glm::length(n);
  if (!(len > 0.0) || !std::isfinite(len)) {
    // Rescale before giving up: tiny or huge coordinates can underflow/overflow the product.
    const double scale = std::max({glm::length(c.p1 - c.p0), glm::length(c.p2 - c.p0), 0.0});
    if (!(scale > 0.0) || !std::isfinite(scale)) return glm::vec3(0.0f);
    const glm::dvec3 ns = glm::cross((c.p1 - c.p0) / scale, (c.p2 - c.p0) / scale);
    const double ls = glm::length(ns);
    return ls > 0.0 && std::isfinite(ls) ? glm::vec3(ns / ls) : glm::vec3(0.0f);
  }
  return glm::vec3(n / len);
}

inline glm::dvec3 triangle_centroid(const triangle_corners& c) { return (c.p0 + c.p1 + c.p2) / 3.0; }

// All face normals at once. O(T) time, allocates T normals.
template <class M>
std::vector<glm::vec3> face_normals(const M& m) {
  static_assert(check_mesh<M>());
  std::vector<glm::vec3> out(mesh_triangle_count(m));
  for (std::size_t t = 0; t < out.size(); ++t) out[t] = triangle_normal(corners(m, t));
  return out;
}

// All face areas at once. O(T) time, allocates T doubles.
template <class M>
std::vector<double> face_areas(const M& m) {
  static_assert(check_mesh<M>());
  std::vector<double> out(mesh_triangle_count(m));
  for (std::size_t t = 0; t < out.size(); ++t) out[t] = triangle_area(corners(m, t));
  return out;
}

// Axis-aligned box, empty until extended. Members O(1), no allocation.
struct bounding_box {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()};
  glm::dvec3 hi{-std::numeric_limits<double>::infinity()};
  [[nodiscard]] bool empty() const { return !(lo.x <= hi.x); }
  [[nodiscard]] double diagonal() const { return empty() ? 0.0 : glm::length(hi - lo); }
  [[nodiscard]] glm::dvec3 center() const { return empty() ? glm::dvec3(0.0) : 0.5 * (lo + hi); }
  void extend(const glm::dvec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
};

// Box of the vertices that triangles use (unused vertices do not count). O(T), no allocation.
template <class M>
bounding_box mesh_bounds(const M& m) {
  static_assert(check_mesh<M>());
  bounding_box box;
  for (std::size_t t = 0; t < mesh_triangle_count(m); ++t) {
    const auto c = corners(m, t);
    box.extend(c.p0);
    box.extend(c.p1);
    box.extend(c.p2);
  }
  return box;
}

}  // namespace infolerp
