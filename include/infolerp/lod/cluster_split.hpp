#pragma once
// Splitting clusters for 16-bit indices (salient-clustering paper §IV.B: the shader works on
// unsigned shorts, which "limits clusters to a maximum of 2^16 vertices, a restriction which can
// be easily enforced during pre-processing").
// Each cluster's triangles are visited along a Morton curve of their centroids and cut into
// consecutive parts whenever the next triangle would bring the part above max_vertices distinct
// vertices (one limit for all clusters, or one per cluster: cluster_local_indices.hpp cuts again
// only the clusters whose parts overflow), so every part is spatially compact and at most its
// limit large. A cluster within its limit keeps one id. New ids: the parts of cluster 0 first,
// then those of cluster 1, and so on (an empty cluster gets none); first_part[c] is the first id
// of cluster c. Deterministic.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>
#include "infolerp/core/detail/csr.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/locality_order.hpp"

namespace infolerp {

struct split_clusters_result {
  std::vector<std::uint32_t> cluster;  // per triangle: its new cluster id
  std::vector<std::uint32_t> first_part;  // per old cluster + 1: its first new id (CSR offsets)
  std::uint32_t count = 0;             // new clusters
};

// Errors: mesh errors (empty, index out of range, non-finite position), cluster.size() != T
// (bad_size), a cluster id >= cluster_count (names the triangle), a limit < 3 (bad_parameter),
// max_vertices not one per cluster (bad_size). Complexity O(T log T); allocation O(V + T).
template <class M>
result<split_clusters_result> split_clusters(const M& m, std::span<const std::uint32_t> cluster,
                                             std::uint32_t cluster_count, std::span<const std::uint32_t> max_vertices) {
  static_assert(check_mesh<M>());
  if (max_vertices.size() != cluster_count)
    return make_error(errc::bad_size, max_vertices.size(), "max_vertices has ", max_vertices.size(), " limits for ",
                      cluster_count, " clusters");
  if (status s = detail::check_indices_and_positions(m); !s.ok()) return s;
  const std::size_t nt = mesh_triangle_count(m), nv = mesh_vertex_count(m);
  if (cluster.size() != nt)
    return make_error(errc::bad_size, cluster.size(), "cluster has ", cluster.size(), " ids for ", nt, " triangles");
  for (std::size_t t = 0; t < nt; ++t)
    if (cluster[t] >= cluster_count)
      return make_error(errc::index_out_of_range, t, "triangle ", t, ": cluster ", cluster[t], " >= cluster count ",
                        cluster_count);
  for (std::uint32_t c = 0; c < cluster_count; ++c)
    if (max_vertices[c] < 3)
      return make_error(errc::bad_parameter, c, "cluster ", c, ": max_vertices ", max_vertices[c], " must be at least 3");
  // Triangles grouped by cluster, Morton order inside each (a stable counting sort of the curve).
  const std::vector<std::uint32_t> curve = morton_triangle_order(m);
  std::vector<std::uint32_t> offsets, grouped;
  detail::group_by_key(
      cluster_count, nt, [&](std::size_t i) { return cluster[curve[i]]; }, [&](std::size_t i) { return curve[i]; },
      offsets, grouped);
  split_clusters_result out;
  out.cluster.resize(nt);
  out.first_part.assign(cluster_count + 1, 0);
  std::vector<std::uint32_t> seen(nv, invalid_id);  // per vertex: the last part that counted it
  std::uint32_t part = 0;
  for (std::uint32_t c = 0; c < cluster_count; ++c) {
    out.first_part[c] = part;
    std::uint32_t size = 0;
    bool open = false;
    for (std::uint32_t k = offsets[c]; k < offsets[c + 1]; ++k) {
      const glm::uvec3 f = mesh_triangle(m, grouped[k]);
      if (!open) open = true, size = 0;
      std::uint32_t fresh = 0;
      for (int j = 0; j < 3; ++j) {
        bool dup = seen[f[j]] == part;
        for (int i = 0; i < j; ++i) dup = dup || f[i] == f[j];
        fresh += dup ? 0u : 1u;
      }
      if (size + fresh > max_vertices[c]) {  // close this part, start the next with this triangle
        ++part;
        size = 0;
        fresh = 0;
        for (int j = 0; j < 3; ++j) {
          bool dup = false;
          for (int i = 0; i < j; ++i) dup = dup || f[i] == f[j];
          fresh += dup ? 0u : 1u;
        }
      }
      for (int j = 0; j < 3; ++j) seen[f[j]] = part;
      size += fresh;
      out.cluster[grouped[k]] = part;
    }
    if (open) ++part;
  }
  out.first_part[cluster_count] = part;
  out.count = part;
  return out;
}

// One limit for every cluster.
template <class M>
result<split_clusters_result> split_clusters(const M& m, std::span<const std::uint32_t> cluster,
                                             std::uint32_t cluster_count, std::uint32_t max_vertices = 65536) {
  const std::vector<std::uint32_t> limits(cluster_count, max_vertices);
  return split_clusters(m, cluster, cluster_count, std::span<const std::uint32_t>(limits));
}

}  // namespace infolerp
