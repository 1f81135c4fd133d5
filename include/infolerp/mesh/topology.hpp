#pragma once
// Mesh topology: unique edges, the triangles around each edge, and the dual graph (triangles
// adjacent across an edge) that region growing walks. Non-manifold edges (more than two
// triangles) are kept, not assumed away: every triangle on such an edge is adjacent to every
// other one on it. Edges whose two ends are the same vertex (a degenerate triangle with a
// repeated index) are left out; that corner's edge id is invalid_id.
//
// Built with a counting sort on each edge's smaller vertex: O(V + T) time, no hashing, and
// deterministic (edges sorted by (v0, v1), faces and neighbours ascending).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/detail/csr.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"

namespace infolerp {

// Edges, edge-face incidence and the dual graph. Accessors: preconditions e < edge_count(),
// t < triangle_count() (unchecked); O(1), no allocation (spans view the vectors); safe for
// concurrent const calls.
struct mesh_topology {
  std::vector<glm::uvec2> edges;               // unique edges (v0 < v1), sorted
  std::vector<std::uint32_t> triangle_edges;   // 3 per triangle: edge from corner c to c+1
  std::vector<std::uint32_t> edge_face_offsets;  // edges.size()+1, CSR into edge_faces
  std::vector<std::uint32_t> edge_faces;         // triangles on each edge, ascending
  std::vector<std::uint32_t> neighbour_offsets;  // triangle_count()+1, CSR into neighbours
  std::vector<std::uint32_t> neighbours;         // dual graph, ascending, no self, no repeats

  std::size_t triangle_count() const { return neighbour_offsets.empty() ? 0 : neighbour_offsets.size() - 1; }
  std::size_t edge_count() const { return edges.size(); }
  std::span<const std::uint32_t> faces_of_edge(std::size_t e) const {
    return {edge_faces.data() + edge_face_offsets[e], edge_faces.data() + edge_face_offsets[e + 1]};
  }
  std::span<const std::uint32_t> neighbours_of(std::size_t t) const {
    return {neighbours.data() + neighbour_offsets[t], neighbours.data() + neighbour_offsets[t + 1]};
  }
  std::size_t edge_valence(std::size_t e) const { return edge_face_offsets[e + 1] - edge_face_offsets[e]; }
  bool is_boundary_edge(std::size_t e) const { return edge_valence(e) == 1; }
  bool is_non_manifold_edge(std::size_t e) const { return edge_valence(e) > 2; }
};

// Builds the topology of any infolerp::mesh.
// Errors: an index >= vertex_count (names the triangle and corner), more than 2^32/3-1 triangles.
// Complexity: O(V + T), plus a sort of each vertex's edge bucket (tiny except at poles).
// Allocation: the result, about 60 bytes per triangle, and temporaries freed on return (48
// bytes per triangle plus 4 per vertex).
template <class M>
result<mesh_topology> make_topology(const M& m) {
  static_assert(check_mesh<M>());
  const std::size_t nv = mesh_vertex_count(m);
  const std::size_t nt = mesh_triangle_count(m);
  if (nt >= (std::size_t{1} << 32) / 3)
    return make_error(errc::unsupported, nt, "mesh has ", nt, " triangles; at most 1431655764 are supported");
  if (nv >= invalid_id)
    return make_error(errc::unsupported, nv, "mesh has ", nv, " vertices; at most 4294967294 are supported");

  mesh_topology topo;
  // Each half-edge 3t + c as its two ends (corner c, corner c + 1 of triangle t).
  std::vector<glm::uvec2> half(3 * nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const glm::uvec3 tri = mesh_triangle(m, t);
    for (int c = 0; c < 3; ++c)
      if (tri[c] >= nv)
        return make_error(errc::index_out_of_range, t, "triangle ", t, " corner ", c, ": vertex index ", tri[c],
                          " out of range (vertex count ", nv, ")");
    half[3 * t] = {tri.x, tri.y}, half[3 * t + 1] = {tri.y, tri.z}, half[3 * t + 2] = {tri.z, tri.x};
  }

  // Half-edges bucketed by their smaller vertex: (larger vertex, half-edge id); a half-edge
  // (a, a) of a degenerate triangle is no edge.
  struct half_edge {
    std::uint32_t hi, id;
    bool operator<(const half_edge& o) const { return hi != o.hi ? hi < o.hi : id < o.id; }
  };
  std::vector<std::uint32_t> start;
  std::vector<half_edge> buckets;
  detail::group_by_key(
      nv, half.size(),
      [&](std::size_t h) { return half[h].x == half[h].y ? detail::no_bucket : std::min(half[h].x, half[h].y); },
      [&](std::size_t h) { return half_edge{std::max(half[h].x, half[h].y), static_cast<std::uint32_t>(h)}; },
      start, buckets);

  topo.triangle_edges.assign(3 * nt, invalid_id);
  topo.edge_faces.reserve(buckets.size());
  topo.edges.reserve(buckets.size() / 2 + 1);
  topo.edge_face_offsets.reserve(buckets.size() / 2 + 2);
  for (std::size_t v = 0; v < nv; ++v) {
    const auto first = buckets.begin() + start[v], last = buckets.begin() + start[v + 1];
    if (last - first > 1) std::sort(first, last);  // buckets hold ~3 entries on typical meshes
    for (auto run = first; run != last;) {
      const auto e = static_cast<std::uint32_t>(topo.edges.size());
      topo.edges.push_back({static_cast<std::uint32_t>(v), run->hi});
      topo.edge_face_offsets.push_back(static_cast<std::uint32_t>(topo.edge_faces.size()));
      auto end = run;
      for (; end != last && end->hi == run->hi; ++end) {
        topo.triangle_edges[end->id] = e;
        // A degenerate triangle (a, b, a) has edge (a, b) twice: list it once.
        if (topo.edge_faces.size() == topo.edge_face_offsets.back() || topo.edge_faces.back() != end->id / 3)
          topo.edge_faces.push_back(end->id / 3);
      }
      run = end;
    }
  }
  topo.edge_face_offsets.push_back(static_cast<std::uint32_t>(topo.edge_faces.size()));

  // Dual graph: the other triangles on each of a triangle's edges.
  topo.neighbour_offsets.resize(nt + 1);
  topo.neighbours.reserve(3 * nt);
  std::vector<std::uint32_t> local;
  for (std::size_t t = 0; t < nt; ++t) {
    topo.neighbour_offsets[t] = static_cast<std::uint32_t>(topo.neighbours.size());
    local.clear();
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t e = topo.triangle_edges[3 * t + static_cast<std::size_t>(c)];
      if (e == invalid_id) continue;
      for (std::uint32_t f : topo.faces_of_edge(e))
        if (f != t) local.push_back(f);
    }
    if (local.size() > 1) {
      std::sort(local.begin(), local.end());
      local.erase(std::unique(local.begin(), local.end()), local.end());
    }
    topo.neighbours.insert(topo.neighbours.end(), local.begin(), local.end());
  }
  topo.neighbour_offsets[nt] = static_cast<std::uint32_t>(topo.neighbours.size());
  return topo;
}

// Gives every element whose label is invalid_id the label of its connected component among the
// still-unlabelled elements, numbering new components next, next+1, ... in order of their
// smallest element; on_new(first_element) is called once per new component. neighbours_of(e)
// returns the element's neighbours (any range of uint32). Returns the next unused label.
// Complexity O(elements + adjacency); allocation: a stack of at most the elements. Deterministic.
template <class Neighbours, class OnNew>
std::uint32_t label_unlabelled_components(std::span<std::uint32_t> label, std::uint32_t next,
                                          Neighbours&& neighbours_of, OnNew&& on_new) {
  std::vector<std::uint32_t> stack;
  for (std::size_t seed = 0; seed < label.size(); ++seed) {
    if (label[seed] != invalid_id) continue;
    const std::uint32_t id = next++;
    label[seed] = id;
    on_new(static_cast<std::uint32_t>(seed));
    stack.push_back(static_cast<std::uint32_t>(seed));
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      for (std::uint32_t n : neighbours_of(t))
        if (label[n] == invalid_id) {
          label[n] = id;
          stack.push_back(n);
        }
    }
  }
  return next;
}

// Connected components of the dual graph (triangles joined across shared edges).
struct components {
  std::vector<std::uint32_t> label;  // per triangle, 0..count-1, numbered by smallest triangle
  std::uint32_t count = 0;
};

// Complexity O(T + neighbours), allocation O(T). Deterministic.
inline components connected_components(const mesh_topology& topo) {
  components out;
  out.label.assign(topo.triangle_count(), invalid_id);
  out.count = label_unlabelled_components(
      out.label, 0, [&](std::uint32_t t) { return topo.neighbours_of(t); }, [](std::uint32_t) {});
  return out;
}

// Indices of the edges with exactly one triangle, ascending. O(E); allocates the result.
// Thread-safe (reads topo only).
inline std::vector<std::uint32_t> boundary_edges(const mesh_topology& topo) {
  std::vector<std::uint32_t> out;
  for (std::size_t e = 0; e < topo.edge_count(); ++e)
    if (topo.is_boundary_edge(e)) out.push_back(static_cast<std::uint32_t>(e));
  return out;
}

}  // namespace infolerp
