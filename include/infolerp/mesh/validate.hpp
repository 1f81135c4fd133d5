#pragma once
// Mesh validation: the checks every infolerp entry point relies on (DESIGN.md, "Errors"),
// reported with the offending index so that an engine can point at the bad triangle.
// Non-manifold edges are found with make_topology (mesh/topology.hpp), not re-derived here.
//
// Checks, in this order (the first failure is returned):
//   1. empty mesh                     errc::empty_input          element() = no_element
//   2. vertex index >= vertex count   errc::index_out_of_range   element() = triangle
//   3. NaN/Inf position               errc::non_finite           element() = vertex
//      (of vertices some triangle uses, found in triangle order; with check_unused_vertices,
//      of every vertex, found in vertex order)
//   4. repeated index or zero area    errc::degenerate_triangle  element() = triangle
//   5. edge on more than 2 distinct   errc::non_manifold_edge    element() = the edge's third
//      triangles                                                 triangle (ascending); the message
//                                                                names the edge's vertices and triangles
// Index counts that are not a multiple of 3 are caught where raw indices enter
// (make_strided_mesh_view); a mesh type always yields whole triangles.
#include <cmath>
#include <cstddef>
#include <string>
#include <glm/vec3.hpp>
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/topology.hpp"

namespace infolerp {

struct validate_options {
  bool allow_degenerate = false;       // accept zero-area and repeated-index triangles
  bool allow_non_manifold = false;     // accept edges shared by more than two triangles (skips the topology build)
  bool check_unused_vertices = false;  // also reject NaN/Inf positions of vertices no triangle uses
};

// Validates any infolerp::mesh. Never reads a position through an out-of-range index, so it is
// safe on garbage indices and positions.
// Complexity: O(T) for checks 1-4 (plus O(V) with check_unused_vertices); check 5 builds the
// topology, O(V + T). Allocation: none for checks 1-4; the topology (~60 bytes per triangle)
// for check 5, released before returning; the message on error. Serial; thread-safe for
// concurrent calls on the same mesh (const reads only).
template <class M>
status validate_mesh(const M& m, const validate_options& options = {}) {
  static_assert(check_mesh<M>());
  const std::size_t nv = mesh_vertex_count(m), nt = mesh_triangle_count(m);
  if (nv == 0 || nt == 0)
    return make_error(errc::empty_input, no_element, "validate_mesh: empty mesh (", nv, " vertices, ", nt, " triangles)");

  for (std::size_t t = 0; t < nt; ++t) {
    const glm::uvec3 tri = mesh_triangle(m, t);
    for (int c = 0; c < 3; ++c)
      if (tri[c] >= nv)
        return make_error(errc::index_out_of_range, t, "validate_mesh: triangle ", t, " corner ", c, ": vertex index ",
                          tri[c], " out of range (vertex count ", nv, ")");
  }

  if (options.check_unused_vertices) {
    for (std::size_t v = 0; v < nv; ++v)
      if (!all_finite(mesh_position(m, v)))
        return make_error(errc::non_finite, v, "validate_mesh: vertex ", v, ": non-finite position");
  } else {
    for (std::size_t t = 0; t < nt; ++t) {
      const glm::uvec3 tri = mesh_triangle(m, t);
      for (int c = 0; c < 3; ++c)
        if (!all_finite(mesh_position(m, tri[c])))
          return make_error(errc::non_finite, tri[c], "validate_mesh: vertex ", tri[c], " (triangle ", t, " corner ", c,
                            "): non-finite position");
    }
  }

  if (!options.allow_degenerate) {
    for (std::size_t t = 0; t < nt; ++t) {
      const glm::uvec3 tri = mesh_triangle(m, t);
      if (tri.x == tri.y || tri.y == tri.z || tri.z == tri.x)
        return make_error(errc::degenerate_triangle, t, "validate_mesh: triangle ", t, ": repeated vertex index (", tri.x,
                          ", ", tri.y, ", ", tri.z, ")");
      if (!(triangle_area(corners(m, t)) > 0.0))
        return make_error(errc::degenerate_triangle, t, "validate_mesh: triangle ", t, ": zero area");
    }
  }

  if (!options.allow_non_manifold) {
    auto topo = make_topology(m);
    if (!topo) return topo.error();
    for (std::size_t e = 0; e < topo->edge_count(); ++e) {
      if (!topo->is_non_manifold_edge(e)) continue;
      const auto faces = topo->faces_of_edge(e);  // ascending, each triangle once
      std::string list;
      for (std::size_t i = 0; i < faces.size(); ++i) list += (i > 0 ? ", " : "") + std::to_string(faces[i]);
      const std::size_t third = faces[2], distinct = faces.size();
      return make_error(errc::non_manifold_edge, third, "validate_mesh: triangle ", third, ": edge (", topo->edges[e].x,
                        ", ", topo->edges[e].y, ") is shared by ", distinct, " triangles (", list, ")");
    }
  }
  return {};
}

}  // namespace infolerp
