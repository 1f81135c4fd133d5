#pragma once
// Triangles in the order of a Morton (Z-order) curve through their centroids, so that
// neighbouring triangles sit close together in memory. Mesh files often list faces in no
// spatial order, and the clustering and saliency loops are bound by memory latency, so the
// order alone changes their time (benchmarks/NOTES.md, BM_Clustering_RefinedElephant_Ordered).
// Salient clustering renumbers its faces with it internally; an engine can apply it to its own
// meshes before clustering (the clusters then differ only by tie-breaking).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>
#include <glm/common.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/mesh/geometry.hpp"

namespace infolerp {

// order[i] = the point placed at position i: points quantised to 21 bits per axis in their
// bounding box, sorted by interleaved code, ties by index (deterministic).
// Preconditions: finite points. Complexity O(P log P), allocation 16·P bytes.
inline std::vector<std::uint32_t> morton_order(std::span<const glm::dvec3> points) {
  bounding_box box;
  for (const glm::dvec3& p : points) box.extend(p);
  const glm::dvec3 ext = glm::max(box.hi - box.lo, glm::dvec3(1e-300));
  std::vector<std::pair<std::uint64_t, std::uint32_t>> key(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::uint64_t code = 0;
    for (int a = 0; a < 3; ++a) {
      const double x = (points[i][a] - box.lo[a]) / ext[a];  // NaN (an infinite extent) counts as 0
      const auto q = static_cast<std::uint64_t>((x > 0.0 ? std::min(x, 1.0) : 0.0) * 2097151.0);
      for (int bit = 0; bit < 21; ++bit) code |= (q >> bit & 1u) << (3 * bit + a);
    }
    key[i] = {code, static_cast<std::uint32_t>(i)};
  }
  std::sort(key.begin(), key.end());
  std::vector<std::uint32_t> order(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) order[i] = key[i].second;
  return order;
}

// The same for the triangles of m, by centroid: order[i] = the triangle placed at position i.
// Preconditions: finite positions (validate_mesh). Complexity O(T log T), allocation 40·T bytes.
template <class M>
std::vector<std::uint32_t> morton_triangle_order(const M& m) {
  static_assert(check_mesh<M>());
  std::vector<glm::dvec3> centroid(mesh_triangle_count(m));
  for (std::size_t t = 0; t < centroid.size(); ++t) centroid[t] = triangle_centroid(corners(m, t));
  return morton_order(centroid);
}

}  // namespace infolerp
