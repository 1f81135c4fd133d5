#pragma once
// Cluster-local 16-bit indices (salient-clustering paper §IV.B–C): "vertex indices reference
// localized cluster vertex arrays", stored as unsigned shorts, which limits a cluster to 2^16
// vertices; §IV.C binds, per cluster, its vertex data and its portion of one index buffer.
//
// Built once (make_local_index_table): each hierarchy cluster is cut into parts small enough for
// 16-bit indices (cluster_split.hpp, a Morton walk of its triangles). A part's vertices are those
// its triangles can name at any budget: their corners and every vertex those corners contract
// to (the chain removed → target of vertex_contraction.hpp, which may leave the cluster). They
// are listed ascending by global id; a part's local index is the position in that list. A part
// whose closure exceeds the limit makes its cluster split again with a smaller limit.
// The closure does not depend on which contractions a frame applies: a corner's output vertex is
// always on its chain (it follows the chain up to the first contraction not applied). So one table
// serves every selection of view_dependent_lod (per-view stop points, the global-prefix fallback,
// the paper's eqs. 5–9) and any stop points handed to contract_indices.
//
// Per frame (localize_indices): the 32-bit buffer and per-cluster ranges of
// view_dependent_lod::frame() / contract_indices become 16-bit local indices with one range per
// part. A cluster of one part keeps its triangle order; a cluster of several parts is
// counting-sorted by part, each triangle going to the first part that holds its three corners
// (the part its original triangle came from always does). Most triangles find it in one read
// per corner (each vertex's first holder); the others merge the corners' holder lists.
// Allocation-free.
//
// What an engine binds for part p: the vertex attributes of vertices[vertex_offsets[p] ..
// vertex_offsets[p + 1]) (gathered once into one buffer: base vertex = vertex_offsets[p]; or
// into one buffer per part), and the 16-bit indices [part_ranges[p].first,
// + part_ranges[p].count).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/lod/cluster_split.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/vertex_contraction.hpp"

namespace infolerp {

inline constexpr std::uint32_t max_local_vertices = 65536;

struct local_index_table {
  std::vector<std::uint32_t> part_offsets;    // per hierarchy cluster + 1 (CSR): its parts
  std::vector<std::uint32_t> part_cluster;    // per part: its hierarchy cluster
  std::vector<std::uint32_t> vertex_offsets;  // per part + 1 (CSR): its slice of vertices
  std::vector<std::uint32_t> vertices;        // global vertex id of each local vertex, part by part
  // Per global vertex (CSR): the parts holding it, ascending, and its local index in each.
  std::vector<std::uint32_t> holder_offsets, holder_part;
  std::vector<std::uint16_t> holder_local;
  // Per global vertex: its first holder (lowest part, invalid_id if none) and its local index
  // there, one read instead of three for the common case of a triangle whose corners share it.
  struct holder {
    std::uint32_t part;
    std::uint16_t local;
  };
  std::vector<holder> first_holder;

  [[nodiscard]] std::uint32_t part_count() const { return static_cast<std::uint32_t>(part_cluster.size()); }
  [[nodiscard]] std::uint32_t vertex_count(std::uint32_t part) const {
    return vertex_offsets[part + 1] - vertex_offsets[part];
  }
};

namespace detail {

// The hierarchy's triangles (cluster order) over the user's positions, for split_clusters.
template <class M>
struct hierarchy_triangles {
  const M* mesh;
  const contraction_hierarchy* h;
  [[nodiscard]] std::size_t vertex_count() const { return mesh_vertex_count(*mesh); }
  [[nodiscard]] std::size_t triangle_count() const { return h->triangle_count(); }
  [[nodiscard]] glm::vec3 position(std::size_t v) const { return mesh_position(*mesh, v); }
  [[nodiscard]] glm::uvec3 triangle(std::size_t t) const {
    return {h->indices[3 * t], h->indices[3 * t + 1], h->indices[3 * t + 2]};
  }
};

// Vertices of each part: triangle corners closed under v → target of the contraction removing v.
// Returns the largest part size per cluster. stamp: per vertex, scratch.
inline std::vector<std::uint32_t> close_parts(const contraction_hierarchy& h, const split_clusters_result& s,
                                              std::span<const std::uint32_t> tri_cluster, local_index_table& t) {
  std::vector<std::uint32_t> offsets, grouped, stamp(h.vertex_count, invalid_id), largest(h.cluster_count, 0);
  group_by_key(
      s.count, h.triangle_count(), [&](std::size_t i) { return s.cluster[i]; },
      [](std::size_t i) { return static_cast<std::uint32_t>(i); }, offsets, grouped);
  t.vertex_offsets.assign(1, 0);
  t.vertices.clear();
  for (std::uint32_t p = 0; p < s.count; ++p) {
    const std::size_t begin = t.vertices.size();
    for (std::uint32_t k = offsets[p]; k < offsets[p + 1]; ++k)
      for (int j = 0; j < 3; ++j)
        for (std::uint32_t v = h.indices[3 * std::size_t{grouped[k]} + static_cast<std::size_t>(j)]; stamp[v] != p;) {
          stamp[v] = p;
          t.vertices.push_back(v);
          const std::uint32_t r = h.removal_order[v];
          if (r == invalid_id) break;
          v = h.target[r];
        }
    std::sort(t.vertices.begin() + static_cast<std::ptrdiff_t>(begin), t.vertices.end());
    t.vertex_offsets.push_back(static_cast<std::uint32_t>(t.vertices.size()));
    if (offsets[p] < offsets[p + 1]) {
      const std::uint32_t c = tri_cluster[grouped[offsets[p]]];
      largest[c] = std::max(largest[c], static_cast<std::uint32_t>(t.vertices.size() - begin));
    }
  }
  return largest;
}

}  // namespace detail

// The parts and their vertex lists for hierarchy h built from mesh m (the same mesh: its
// positions order the split). max_vertices in [3, 65536] bounds every part. Errors: mesh errors,
// a hierarchy naming vertices m does not have (bad_size), max_vertices out of range
// (bad_parameter), a cluster whose single triangles already reach more than max_vertices
// vertices through their contraction chains (bad_parameter, names the cluster). Complexity
// O(rounds · T log T + Σ part sizes · log), where rounds is 1 unless a closure overflows;
// allocation O(V + T + Σ part sizes).
template <class M>
result<local_index_table> make_local_index_table(const M& m, const contraction_hierarchy& h,
                                                 std::uint32_t max_vertices = max_local_vertices) {
  static_assert(check_mesh<M>());
  if (max_vertices < 3 || max_vertices > max_local_vertices)
    return make_error(errc::bad_parameter, no_element, "max_vertices ", max_vertices, " must be in [3, ",
                      max_local_vertices, "]");
  if (mesh_vertex_count(m) != h.vertex_count)
    return make_error(errc::bad_size, mesh_vertex_count(m), "mesh has ", mesh_vertex_count(m),
                      " vertices, the hierarchy ", h.vertex_count);
  std::vector<std::uint32_t> tri_cluster(h.triangle_count());
  for (std::uint32_t c = 0; c < h.cluster_count; ++c)
    std::fill(tri_cluster.begin() + h.triangle_offsets[c], tri_cluster.begin() + h.triangle_offsets[c + 1], c);
  const detail::hierarchy_triangles<M> view{&m, &h};
  std::vector<std::uint32_t> limit(h.cluster_count, max_vertices);
  local_index_table t;
  split_clusters_result s;
  for (bool over = true; over;) {
    auto split = split_clusters(view, tri_cluster, h.cluster_count, std::span<const std::uint32_t>(limit));
    if (!split.ok()) return split.error();
    s = std::move(*split);
    const std::vector<std::uint32_t> largest = detail::close_parts(h, s, tri_cluster, t);
    over = false;
    for (std::uint32_t c = 0; c < h.cluster_count; ++c) {
      if (largest[c] <= max_vertices) continue;
      // The closure grows with the part: shrink the limit in proportion, by at least one.
      const auto scaled = static_cast<std::uint32_t>(std::uint64_t{limit[c]} * max_vertices / largest[c]);
      limit[c] = std::min(limit[c] - 1, scaled);
      if (limit[c] < 3)
        return make_error(errc::bad_parameter, c, "cluster ", c, ": a triangle's contraction chains reach more than ",
                          max_vertices, " vertices");
      over = true;
    }
  }
  t.part_offsets = s.first_part;
  t.part_cluster.resize(s.count);
  for (std::uint32_t c = 0; c < h.cluster_count; ++c)
    std::fill(t.part_cluster.begin() + t.part_offsets[c], t.part_cluster.begin() + t.part_offsets[c + 1], c);
  // Holders per vertex: positions in vertices, ascending, so their parts ascend too.
  detail::group_by_key(
      h.vertex_count, t.vertices.size(), [&](std::size_t i) { return t.vertices[i]; },
      [](std::size_t i) { return static_cast<std::uint32_t>(i); }, t.holder_offsets, t.holder_part);
  t.holder_local.resize(t.holder_part.size());
  for (std::size_t a = 0; a < t.holder_part.size(); ++a) {
    const std::uint32_t i = t.holder_part[a];
    const auto p = static_cast<std::uint32_t>(
        std::upper_bound(t.vertex_offsets.begin(), t.vertex_offsets.end(), i) - t.vertex_offsets.begin() - 1);
    t.holder_part[a] = p;
    t.holder_local[a] = static_cast<std::uint16_t>(i - t.vertex_offsets[p]);
  }
  t.first_holder.assign(h.vertex_count, {invalid_id, 0});
  for (std::uint32_t v = 0; v < h.vertex_count; ++v)
    if (const std::uint32_t a = t.holder_offsets[v]; a < t.holder_offsets[v + 1])
      t.first_holder[v] = {t.holder_part[a], t.holder_local[a]};
  return t;
}

namespace detail {

// The first part in [p0, p1) holding all three vertices, and their local indices; false if none.
inline bool common_part(const local_index_table& t, const std::uint32_t (&v)[3], std::uint32_t p0, std::uint32_t p1,
                        std::uint32_t& part, std::uint16_t (&local)[3]) {
  const std::uint32_t* parts = t.holder_part.data();
  std::uint32_t at[3];
  for (int j = 0; j < 3; ++j) {
    const std::uint32_t* b = parts + t.holder_offsets[v[j]];
    const std::uint32_t* e = parts + t.holder_offsets[v[j] + 1];
    at[j] = static_cast<std::uint32_t>(std::lower_bound(b, e, p0) - parts);
  }
  // Advance the three sorted lists to a common part (a three-way merge).
  while (true) {
    std::uint32_t hi = 0;
    for (int j = 0; j < 3; ++j) {
      if (at[j] == t.holder_offsets[v[j] + 1] || parts[at[j]] >= p1) return false;
      hi = std::max(hi, parts[at[j]]);
    }
    bool same = true;
    for (int j = 0; j < 3; ++j)
      for (const std::uint32_t end = t.holder_offsets[v[j] + 1]; at[j] < end && parts[at[j]] < hi;) ++at[j];
    for (int j = 0; j < 3; ++j) same = same && at[j] < t.holder_offsets[v[j] + 1] && parts[at[j]] == hi;
    if (same) {
      part = hi;
      for (int j = 0; j < 3; ++j) local[j] = t.holder_local[at[j]];
      return true;
    }
  }
}

}  // namespace detail

// One frame's 32-bit indices (in, with one range per hierarchy cluster, as frame() writes them)
// into 16-bit local indices (out) and one range per part (part_ranges, in 16-bit indices of out).
// Errors: ranges not one per cluster, part_ranges not one per part, out smaller than the indices
// the ranges cover (bad_size); a range outside in or not a multiple of 3 (bad_index_count, names
// the cluster); an index that its cluster's parts do not hold, i.e. input not from this table's
// hierarchy (index_out_of_range, names the position in in). On error out and part_ranges are
// partly written. Complexity O(indices) where corners share their first holder, O(indices · h)
// otherwise, h the longest holder list (typically 1–3); no allocation.
inline result<std::size_t> localize_indices(const local_index_table& t, std::span<const std::uint32_t> in,
                                            std::span<const index_range> ranges, std::span<std::uint16_t> out,
                                            std::span<index_range> part_ranges) {
  const std::size_t clusters = t.part_offsets.empty() ? 0 : t.part_offsets.size() - 1;
  if (ranges.size() != clusters || part_ranges.size() != t.part_count())
    return make_error(errc::bad_size, ranges.size(), "ranges and part_ranges hold ", ranges.size(), " and ",
                      part_ranges.size(), " entries for ", clusters, " clusters and ", t.part_count(), " parts");
  std::size_t total = 0;
  for (std::size_t c = 0; c < clusters; ++c) {
    if (ranges[c].count % 3 != 0 || std::size_t{ranges[c].first} + ranges[c].count > in.size())
      return make_error(errc::bad_index_count, c, "cluster ", c, ": range [", ranges[c].first, ", +", ranges[c].count,
                        ") is not whole triangles inside the ", in.size(), " indices");
    total += ranges[c].count;
  }
  if (out.size() < total)
    return make_error(errc::bad_size, out.size(), "16-bit buffer holds ", out.size(), " indices; ", total, " needed");
  const auto missing = [&](std::size_t k, std::uint32_t c) {
    return make_error(errc::index_out_of_range, k, "index ", k, " (vertex ", in[k], ") is not a vertex of cluster ", c,
                      "'s parts");
  };
  const std::size_t nv = t.holder_offsets.empty() ? 0 : t.holder_offsets.size() - 1;
  std::uint32_t at = 0;
  for (std::uint32_t c = 0; c < clusters; ++c) {
    const std::uint32_t p0 = t.part_offsets[c], p1 = t.part_offsets[c + 1];
    const std::size_t b = ranges[c].first, e = b + ranges[c].count;
    for (std::uint32_t p = p0; p < p1; ++p) part_ranges[p] = {at, 0};
    if (e == b) continue;
    if (p1 == p0) return missing(b, c);
    // Count per part (a one-part cluster skips to the write), then place.
    for (int pass = p1 - p0 == 1 ? 1 : 0; pass < 2; ++pass) {
      for (std::size_t k = b; k < e; k += 3) {
        std::uint32_t v[3] = {in[k], in[k + 1], in[k + 2]}, part = 0;
        std::uint16_t local[3];
        if (v[0] >= nv || v[1] >= nv || v[2] >= nv) return missing(k, c);
        // The corners' first holders agree and lie in this cluster: that part is the first
        // common one (no lower part holds any corner); otherwise merge the holder lists.
        const local_index_table::holder h0 = t.first_holder[v[0]], h1 = t.first_holder[v[1]], h2 = t.first_holder[v[2]];
        if (h0.part == h1.part && h0.part == h2.part && h0.part - p0 < p1 - p0) {
          part = h0.part, local[0] = h0.local, local[1] = h1.local, local[2] = h2.local;
        } else if (!detail::common_part(t, v, p0, p1, part, local)) {
          return missing(k, c);
        }
        index_range& r = part_ranges[part];
        if (pass == 0) {
          r.count += 3;
          continue;
        }
        std::uint16_t* o = out.data() + r.first + r.count;
        o[0] = local[0], o[1] = local[1], o[2] = local[2];
        r.count += 3;
      }
      if (pass == 0)  // starts from the counts; the placing pass counts again
        for (std::uint32_t p = p0, next = at; p < p1; ++p) {
          part_ranges[p].first = next;
          next += part_ranges[p].count;
          part_ranges[p].count = 0;
        }
    }
    at += ranges[c].count;
  }
  return std::size_t{at};
}

}  // namespace infolerp
