#pragma once
// Per-vertex mean curvature from the cotangent Laplacian with Meyer's mixed Voronoi area
// (Meyer, Desbrun, Schröder, Barr, "Discrete differential-geometry operators for triangulated
// 2-manifolds", 2002, §3.3–3.5 and Fig. 4). Mesh saliency (Lee et al. 2005; salient-clustering
// paper §III.A, eq. 1) filters this curvature.
//
//   K(x_i) = 1/(2 A_mixed(i)) · Σ_j (cot α_ij + cot β_ij) (x_i − x_j)        (Meyer eq. 8)
//   H(i)   = ½ K(x_i) · n̂_i                                                    (signed)
//
// n̂_i is the area-weighted vertex normal. Taking the normal component (rather than |K|/2)
// gives the sign (positive where the surface bends away from its normal, e.g. +1/R on a
// sphere with outward winding) and stays meaningful on boundary vertices, where K also has an
// in-plane part. A_mixed is Meyer's mixed area: the Voronoi area inside non-obtuse triangles,
// half the triangle area at an obtuse corner, a quarter at the other corners of an obtuse one.
//
// Finite for every input: cotangents come from dot/|cross| of one triangle (large on slivers,
// never Inf), zero-area triangles are skipped, and a vertex with zero mixed area or zero normal
// (unreferenced, or only on zero-area triangles) gets H = 0.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"

namespace infolerp {

namespace detail {
// Input checks shared by the curvature and saliency entry points: at least one triangle,
// indices in range, finite positions on referenced vertices. O(T), no allocation.
template <class M>
status check_indices_and_positions(const M& m) {
  const std::size_t nv = mesh_vertex_count(m), nt = mesh_triangle_count(m);
  if (nt == 0 || nv == 0) return make_error(errc::empty_input, no_element, "mesh has no triangles");
  for (std::size_t t = 0; t < nt; ++t) {
    const glm::uvec3 tri = mesh_triangle(m, t);
    for (int c = 0; c < 3; ++c) {
      if (tri[c] >= nv)
        return make_error(errc::index_out_of_range, t, "triangle ", t, " corner ", c, ": vertex index ", tri[c],
                          " out of range (vertex count ", nv, ")");
      if (!all_finite(mesh_position(m, tri[c])))
        return make_error(errc::non_finite, tri[c], "vertex ", tri[c], " (triangle ", t, "): non-finite position");
    }
  }
  return {};
}
}  // namespace detail

namespace detail {
// The shared kernel: pos(v) -> glm::dvec3, tri(t) -> glm::uvec3, indices already checked.
template <class Pos, class Tri>
std::vector<double> mean_curvature_kernel(std::size_t nv, std::size_t nt, Pos&& pos, Tri&& tri_of) {
  struct vertex_sums {  // a vertex's sums side by side: one line per corner in the scatter below
    glm::dvec3 lap{0.0}, normal{0.0};
    double area = 0.0;
  };
  std::vector<vertex_sums> sum(nv);
  for (std::size_t t = 0; t < nt; ++t) {
    const glm::uvec3 tri = tri_of(t);
    const glm::dvec3 p[3] = {pos(tri.x), pos(tri.y), pos(tri.z)};
    const glm::dvec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
    const double twice_area = glm::length(n);
    if (!(twice_area > 0.0) || !std::isfinite(twice_area)) continue;  // zero area: no contribution
    double dots[3], cot[3];
    for (int c = 0; c < 3; ++c) {
      dots[c] = glm::dot(p[(c + 1) % 3] - p[c], p[(c + 2) % 3] - p[c]);
      cot[c] = dots[c] / twice_area;
    }
    const bool obtuse = dots[0] < 0.0 || dots[1] < 0.0 || dots[2] < 0.0;
    for (int c = 0; c < 3; ++c) {
      const int a = (c + 1) % 3, b = (c + 2) % 3;
      const glm::dvec3 ea = p[c] - p[a], eb = p[c] - p[b];  // edges to the other corners
      vertex_sums& v = sum[tri[c]];
      // Edge (c, a) is opposite corner b; edge (c, b) is opposite corner a.
      v.lap += cot[b] * ea + cot[a] * eb;
      v.normal += n;
      if (!obtuse)
        v.area += (glm::dot(ea, ea) * cot[b] + glm::dot(eb, eb) * cot[a]) / 8.0;
      else
        v.area += twice_area * (dots[c] < 0.0 ? 0.25 : 0.125);
    }
  }
  std::vector<double> h(nv, 0.0);
  for (std::size_t v = 0; v < nv; ++v) {
    const vertex_sums& a = sum[v];
    const double len = glm::length(a.normal);
    if (a.area > 0.0 && len > 0.0) h[v] = 0.25 * glm::dot(a.lap, a.normal / len) / a.area;
  }
  return h;
}
}  // namespace detail

// Signed mean curvature per vertex (see the top of this file), computed in double from the
// mesh's float positions. The Laplacian divides position differences by edge length squared,
// so float rounding of the input (~6e-8 relative) shows up as ~1e-5 relative curvature noise
// on a 2562-vertex unit sphere and grows 4x per halving of the edge length; pass double
// positions to the overload below when that matters.
// Errors: empty mesh, index out of range, non-finite position (names the vertex/triangle).
// Degenerate (zero-area) triangles are allowed and contribute nothing.
// Complexity O(V + T); allocation: the result plus 7 doubles per vertex of scratch. Serial.
template <class M>
result<std::vector<double>> mean_curvature(const M& m) {
  static_assert(check_mesh<M>());
  if (status s = detail::check_indices_and_positions(m); !s.ok()) return s;
  return detail::mean_curvature_kernel(
      mesh_vertex_count(m), mesh_triangle_count(m), [&](std::size_t v) { return glm::dvec3(mesh_position(m, v)); },
      [&](std::size_t t) { return mesh_triangle(m, t); });
}

// The same from double-precision positions (for engines that keep them, and for analytic tests).
// Errors, complexity and allocation as above.
inline result<std::vector<double>> mean_curvature(std::span<const glm::dvec3> positions,
                                                  std::span<const glm::uvec3> triangles) {
  if (triangles.empty() || positions.empty()) return make_error(errc::empty_input, no_element, "mesh has no triangles");
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t v = triangles[t][c];
      if (v >= positions.size())
        return make_error(errc::index_out_of_range, t, "triangle ", t, " corner ", c, ": vertex index ", v,
                          " out of range (vertex count ", positions.size(), ")");
      if (!all_finite(positions[v]))
        return make_error(errc::non_finite, v, "vertex ", v, " (triangle ", t, "): non-finite position");
    }
  return detail::mean_curvature_kernel(
      positions.size(), triangles.size(), [&](std::size_t v) { return positions[v]; },
      [&](std::size_t t) { return triangles[t]; });
}

}  // namespace infolerp
