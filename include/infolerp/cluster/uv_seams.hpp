#pragma once
// Splits clusters at UV seams, so that no cluster crosses an edge between two texture charts.
// The I-Buffer interpolates texcoords between samples of one cluster (clustering paper §4),
// which is wrong across a seam (u = 0.99 and u = 0.01 average to 0.5); the paper avoids it
// with texture padding and per-chart parameterisations [41]. This step works after any
// clustering (cluster_mesh, salient clustering, the engine's own ids).
//
// A seam edge: two triangles share an edge by position (vertex indices may differ, as where
// an exporter duplicates seam vertices) and their texcoords differ at either end of it.
// Steps:
//   1. join triangles that share an edge by position, have the same input id, and are not
//      across a seam; the joined pieces are the new clusters;
//   2. a piece that still has a seam edge inside it (its chart reaches around the seam, as a
//      UV sphere's single chart does) is cut in two by growing from the edge's two triangles
//      breadth-first at once (each triangle goes to the nearer one, ties to the first); repeated
//      until no seam edge has one id on both sides.
// The result refines the input (triangles with different input ids never share an id), every
// cluster is edge-connected, and ids are numbered by their smallest triangle. A mesh without
// texcoords has no seams: its clusters are only split into edge-connected pieces.
// Errors: cluster_of.size() != triangle count (bad_size), an index out of range (names the
// triangle), a non-finite position or texcoord (names the vertex or triangle and corner).
// Complexity: O(V log V + T) for step 1; each cut of step 2 is O(size of the piece) (a UV
// sphere needs one). Allocation: O(V + T). Deterministic; serial.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <span>
#include <vector>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/detail/csr.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/topology.hpp"

namespace infolerp {

struct seam_clustering {
  std::vector<std::uint32_t> cluster_of;  // per triangle, 0..cluster_count-1
  std::uint32_t cluster_count = 0;
  std::size_t seam_edges = 0;  // edges found to be seams
  std::size_t cuts = 0;        // pieces cut by step 2
};

namespace detail {

// Triangles over position-welded vertex ids (vertices at bit-identical positions share an id).
struct welded_triangles {
  std::size_t vertices = 0;
  std::vector<glm::uvec3> tris;
  std::size_t vertex_count() const { return vertices; }
  std::size_t triangle_count() const { return tris.size(); }
  glm::vec3 position(std::size_t) const { return glm::vec3(0.0f); }
  glm::uvec3 triangle(std::size_t t) const { return tris[t]; }
};

template <class M>
welded_triangles weld_by_position(const M& m) {
  const std::size_t nv = mesh_vertex_count(m);
  std::vector<std::uint32_t> order(nv);
  std::iota(order.begin(), order.end(), 0u);
  const auto less = [&](std::uint32_t a, std::uint32_t b) {
    const glm::vec3 p = mesh_position(m, a), q = mesh_position(m, b);
    return p.x != q.x ? p.x < q.x : p.y != q.y ? p.y < q.y : p.z != q.z ? p.z < q.z : a < b;
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<std::uint32_t> canonical(nv);
  for (std::size_t i = 0; i < nv; ++i)
    canonical[order[i]] = i > 0 && mesh_position(m, order[i]) == mesh_position(m, order[i - 1]) ? canonical[order[i - 1]] : order[i];
  welded_triangles w{nv, std::vector<glm::uvec3>(mesh_triangle_count(m))};
  for (std::size_t t = 0; t < w.tris.size(); ++t) {
    const glm::uvec3 tri = mesh_triangle(m, t);
    w.tris[t] = {canonical[tri.x], canonical[tri.y], canonical[tri.z]};
  }
  return w;
}

// The corner of welded triangle `tri` at welded vertex v (precondition: v is one of its corners).
inline unsigned corner_at(const glm::uvec3& tri, std::uint32_t v) { return tri.x == v ? 0u : tri.y == v ? 1u : 2u; }

// Two-seed breadth-first cut of the piece holding a and b: triangles nearer b get `fresh`.
// Walks only `joined` edges inside the piece (label == old). Allocation: the queue and marks.
inline void cut_piece(std::span<std::uint32_t> label, std::span<const std::uint32_t> joined_offsets,
                      std::span<const std::uint32_t> joined, std::uint32_t a, std::uint32_t b, std::uint32_t fresh,
                      std::vector<std::uint8_t>& side, std::vector<std::uint32_t>& queue) {
  const std::uint32_t old = label[a];
  queue.assign({a, b});
  side[a] = 1;
  side[b] = 2;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::uint32_t t = queue[head];
    for (std::uint32_t i = joined_offsets[t]; i < joined_offsets[t + 1]; ++i) {
      const std::uint32_t n = joined[i];
      if (side[n] != 0 || label[n] != old) continue;
      side[n] = side[t];
      queue.push_back(n);
    }
  }
  for (std::uint32_t t : queue) {
    if (side[t] == 2) label[t] = fresh;
    side[t] = 0;
  }
}

}  // namespace detail

template <class M>
result<seam_clustering> split_at_uv_seams(const M& m, std::span<const std::uint32_t> cluster_of) {
  static_assert(check_mesh<M>());
  const std::size_t nt = mesh_triangle_count(m), nv = mesh_vertex_count(m);
  if (cluster_of.size() != nt)
    return make_error(errc::bad_size, cluster_of.size(), "split_at_uv_seams: ", cluster_of.size(), " cluster ids for ",
                      nt, " triangles");
  for (std::size_t v = 0; v < nv; ++v) {
    if (!all_finite(mesh_position(m, v)))
      return make_error(errc::non_finite, v, "split_at_uv_seams: vertex ", v, " has a non-finite position");
  }
  for (std::size_t t = 0; t < nt; ++t) {
    const glm::uvec3 tri = mesh_triangle(m, t);
    for (unsigned c = 0; c < 3; ++c)
      if (tri[static_cast<int>(c)] >= nv)
        return make_error(errc::index_out_of_range, t, "split_at_uv_seams: triangle ", t, " corner ", c, ": vertex ",
                          tri[static_cast<int>(c)], " out of range");
  }
  const bool uv = mesh_has_texcoords(m);
  const auto texcoord = [&](std::size_t t, unsigned c) {
    if constexpr (textured_mesh<M>) return mesh_traits<M>::texcoord(m, t, c);
    else return glm::vec2(0.0f);
  };
  if (uv)
    for (std::size_t t = 0; t < nt; ++t)
      for (unsigned c = 0; c < 3; ++c)
        if (!all_finite(texcoord(t, c)))
          return make_error(errc::non_finite, t, "split_at_uv_seams: triangle ", t, " corner ", c, " has a non-finite texcoord");

  const detail::welded_triangles welded = detail::weld_by_position(m);
  auto topo = make_topology(welded);
  if (!topo) return topo.error();

  // Step 1: the joined dual graph (CSR) and the seam edges.
  seam_clustering out;
  std::vector<glm::uvec2> seams;  // triangle pairs across a seam
  std::vector<glm::uvec2> pairs;  // joined triangle pairs, both directions
  for (std::size_t e = 0; e < topo->edge_count(); ++e) {
    const auto faces = topo->faces_of_edge(e);
    const glm::uvec2 ends = topo->edges[e];
    bool seam_edge = false;
    for (std::size_t i = 0; i < faces.size(); ++i)
      for (std::size_t j = i + 1; j < faces.size(); ++j) {
        const std::uint32_t a = faces[i], b = faces[j];
        bool seam = false;
        for (int k = 0; k < 2 && uv; ++k)
          seam = seam || texcoord(a, detail::corner_at(welded.tris[a], ends[k])) !=
                             texcoord(b, detail::corner_at(welded.tris[b], ends[k]));
        if (seam) {
          seams.push_back({a, b});
          seam_edge = true;
        } else if (cluster_of[a] == cluster_of[b]) {
          pairs.push_back({a, b});
          pairs.push_back({b, a});
        }
      }
    out.seam_edges += seam_edge ? 1 : 0;
  }
  std::vector<std::uint32_t> offsets, joined;
  detail::group_by_key(
      nt, pairs.size(), [&](std::size_t i) { return pairs[i].x; }, [&](std::size_t i) { return pairs[i].y; }, offsets,
      joined);
  std::vector<std::uint32_t> label(nt, invalid_id);
  std::uint32_t count = label_unlabelled_components(
      label, 0, [&](std::uint32_t t) { return std::span<const std::uint32_t>(joined.data() + offsets[t], joined.data() + offsets[t + 1]); },
      [](std::uint32_t) {});

  // Step 2: cut pieces that reach around a seam. Cuts only refine, so one pass over the seams
  // in order leaves every seam with two ids.
  std::vector<std::uint8_t> side(nt, 0);
  std::vector<std::uint32_t> queue;
  for (const auto& s : seams)
    if (label[s.x] == label[s.y]) {
      detail::cut_piece(label, offsets, joined, s.x, s.y, count++, side, queue);
      ++out.cuts;
    }

  // Ids numbered by their smallest triangle.
  std::vector<std::uint32_t> renumber(count, invalid_id);
  out.cluster_of.resize(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    if (renumber[label[t]] == invalid_id) renumber[label[t]] = out.cluster_count++;
    out.cluster_of[t] = renumber[label[t]];
  }
  return out;
}

}  // namespace infolerp
