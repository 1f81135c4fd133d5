#pragma once
// Distances between a mesh and a simplification of it over the same vertices, measured the same
// way for any simplifier (the LOD harness and the demo's LOD stage):
//   weighted = Σ_v S(v)·d(v) / Σ S, d(v) the distance from original vertex v to the simplified
//              surface, S a per-vertex weight (e.g. mesh saliency);
//   hausdorff = the larger of max_v d(v) and the largest distance from a simplified triangle's
//              vertices, edge midpoints and centroid to the original surface.
// Closest points come from a bounding-volume hierarchy of the triangles (exact); measure() costs
// O((V + 7·T') log T) for V original vertices and T' simplified triangles.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "infolerp/mesh/geometry.hpp"

namespace infolerp::support {

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection §5.1.5).
inline glm::dvec3 closest_on_triangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Exact point-to-surface distance through a bounding-volume hierarchy of the triangles: median
// splits of the centroids along the longest axis, four triangles a leaf, searched nearest box
// first and pruned by the best distance so far. Building costs O(T log T) time and O(T) memory
// (about 20 bytes a triangle); a query visits O(log T) boxes on a well-shaped mesh, whatever
// the distance from the point to the surface. Queries are const: one object serves any number of
// threads. An empty index list gives the largest double for every point.
class surface_distance {
 public:
  surface_distance(const std::vector<glm::vec3>& pos, std::span<const std::uint32_t> idx) : pos_(pos), idx_(idx) {
    const std::size_t nt = idx.size() / 3;
    order_.resize(nt);
    std::vector<glm::vec3> centroid(nt);
    for (std::uint32_t t = 0; t < nt; ++t) {
      order_[t] = t;
      centroid[t] = (pos[idx[3 * t]] + pos[idx[3 * t + 1]] + pos[idx[3 * t + 2]]) / 3.0f;
    }
    if (nt > 0) nodes_.reserve(2 * (nt / leaf_size) + 1);
    if (nt > 0) build(0, static_cast<std::uint32_t>(nt), centroid);
  }

  double operator()(const glm::dvec3& p) const {
    double best2 = std::numeric_limits<double>::max();
    if (nodes_.empty()) return best2;
    std::uint32_t stack[2 * max_depth];
    std::size_t top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const node& n = nodes_[stack[--top]];
      if (box_distance2(n, p) >= best2) continue;
      if (n.count > 0) {
        for (std::uint32_t k = n.first; k < n.first + n.count; ++k) {
          const std::size_t t = order_[k];
          const glm::dvec3 q = closest_on_triangle(p, glm::dvec3(pos_[idx_[3 * t]]), glm::dvec3(pos_[idx_[3 * t + 1]]),
                                                   glm::dvec3(pos_[idx_[3 * t + 2]]));
          const glm::dvec3 d = q - p;
          best2 = std::min(best2, glm::dot(d, d));
        }
        continue;
      }
      const auto self = static_cast<std::uint32_t>(&n - nodes_.data());
      std::uint32_t near = self + 1, far = n.first;
      const double dn = box_distance2(nodes_[near], p), df = box_distance2(nodes_[far], p);
      if (df < dn) std::swap(near, far);
      if (std::max(dn, df) < best2) stack[top++] = far;  // the nearer child is searched first
      if (std::min(dn, df) < best2) stack[top++] = near;
    }
    return std::sqrt(best2);
  }

 private:
  static constexpr std::uint32_t leaf_size = 4;
  static constexpr std::size_t max_depth = 64;  // median splits of < 2^32 triangles stay below 33 levels
  // A box; a leaf (count > 0) holds order_[first, first + count), an inner node's children are
  // the next node and nodes_[first].
  struct node {
    glm::vec3 lo, hi;
    std::uint32_t first = 0, count = 0;
  };

  static double box_distance2(const node& n, const glm::dvec3& p) {
    const glm::dvec3 d = glm::max(glm::max(glm::dvec3(n.lo) - p, p - glm::dvec3(n.hi)), glm::dvec3(0.0));
    return glm::dot(d, d);
  }

  void build(std::uint32_t begin, std::uint32_t end, const std::vector<glm::vec3>& centroid) {
    const auto self = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back({glm::vec3(std::numeric_limits<float>::max()), glm::vec3(-std::numeric_limits<float>::max()), begin, 0});
    glm::vec3 clo(std::numeric_limits<float>::max()), chi(-std::numeric_limits<float>::max());
    for (std::uint32_t k = begin; k < end; ++k) {
      const std::size_t t = order_[k];
      for (int j = 0; j < 3; ++j) {
        const glm::vec3& v = pos_[idx_[3 * t + static_cast<std::size_t>(j)]];
        nodes_[self].lo = glm::min(nodes_[self].lo, v);
        nodes_[self].hi = glm::max(nodes_[self].hi, v);
      }
      clo = glm::min(clo, centroid[t]);
      chi = glm::max(chi, centroid[t]);
    }
    if (end - begin <= leaf_size) {
      nodes_[self].count = end - begin;
      return;
    }
    const glm::vec3 e = chi - clo;
    const int axis = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                     [&](std::uint32_t a, std::uint32_t b) { return centroid[a][axis] < centroid[b][axis]; });
    build(begin, mid, centroid);
    nodes_[self].first = static_cast<std::uint32_t>(nodes_.size());
    build(mid, end, centroid);
  }

  const std::vector<glm::vec3>& pos_;
  std::span<const std::uint32_t> idx_;
  std::vector<std::uint32_t> order_;  // triangles in leaf order
  std::vector<node> nodes_;           // depth first, the root first
};

struct distances {
  double weighted = 0.0, hausdorff = 0.0;
};

namespace detail {

// A triangle's vertex indices in ascending order: the same triangle whatever its winding.
inline std::array<std::uint32_t, 3> sorted_corners(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  std::array<std::uint32_t, 3> t{a, b, c};
  std::sort(t.begin(), t.end());
  return t;
}

}  // namespace detail

// Both distances of a simplification over m's vertices. Exact shortcuts keep the cost to what
// the simplification changed: an original vertex the simplified mesh still uses has distance 0,
// and a simplified triangle that is one of m's (same three vertices) lies on m. The rest goes
// through the two hierarchies, in chunks through exec (sums per fixed chunk, combined in order:
// the same bits for any executor). O((V + T + T') log T) time, O(V + T) memory.
template <class E = serial_executor>
distances measure(const indexed_mesh& m, const std::vector<double>& saliency, std::span<const std::uint32_t> simplified,
                  E&& exec = E{}) {
  constexpr std::size_t grain = 2048;
  std::vector<char> used(m.vertex_count(), 0), kept(m.vertex_count(), 0);
  for (const auto& t : m.triangles) used[t.x] = used[t.y] = used[t.z] = 1;
  for (const std::uint32_t v : simplified) kept[v] = 1;
  struct partial {
    double num = 0.0, den = 0.0, max = 0.0;
  };
  // Each hierarchy is built only when some point needs it.
  bool all_kept = true;
  for (std::size_t v = 0; v < used.size() && all_kept; ++v) all_kept = !used[v] || kept[v];
  const surface_distance to_simplified(m.positions, all_kept ? std::span<const std::uint32_t>() : simplified);
  std::vector<partial> vertex_part(chunk_count(m.vertex_count(), grain));
  for_each_chunk(exec, m.vertex_count(), grain, [&](std::size_t c, std::size_t begin, std::size_t end) {
    partial& r = vertex_part[c];
    for (std::size_t v = begin; v < end; ++v) {
      if (!used[v]) continue;
      const double d = kept[v] ? 0.0 : to_simplified(glm::dvec3(m.positions[v]));
      r.num += saliency[v] * d, r.den += saliency[v];
      r.max = std::max(r.max, d);
    }
  });
  std::vector<std::array<std::uint32_t, 3>> original(m.triangle_count());
  for (std::size_t t = 0; t < original.size(); ++t)
    original[t] = detail::sorted_corners(m.triangles[t].x, m.triangles[t].y, m.triangles[t].z);
  std::sort(original.begin(), original.end());
  std::vector<std::uint32_t> changed;  // simplified triangles that are not m's
  for (std::size_t k = 0; k + 2 < simplified.size(); k += 3)
    if (!std::binary_search(original.begin(), original.end(), detail::sorted_corners(simplified[k], simplified[k + 1], simplified[k + 2])))
      changed.insert(changed.end(), {simplified[k], simplified[k + 1], simplified[k + 2]});
  original = {};
  const std::span<const std::uint32_t> all(reinterpret_cast<const std::uint32_t*>(m.triangles.data()), 3 * m.triangle_count());
  const surface_distance to_original(m.positions, changed.empty() ? std::span<const std::uint32_t>() : all);
  const std::size_t nt = changed.size() / 3;
  std::vector<double> triangle_max(chunk_count(nt, grain), 0.0);
  for_each_chunk(exec, nt, grain, [&](std::size_t c, std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t) {
      const glm::dvec3 a(m.positions[changed[3 * t]]), b(m.positions[changed[3 * t + 1]]), e(m.positions[changed[3 * t + 2]]);
      for (const glm::dvec3& p : {a, b, e, 0.5 * (a + b), 0.5 * (b + e), 0.5 * (e + a), (a + b + e) / 3.0})
        triangle_max[c] = std::max(triangle_max[c], to_original(p));
    }
  });
  distances out;
  double num = 0.0, den = 0.0;
  for (const partial& r : vertex_part) num += r.num, den += r.den, out.hausdorff = std::max(out.hausdorff, r.max);
  for (const double d : triangle_max) out.hausdorff = std::max(out.hausdorff, d);
  out.weighted = den > 0.0 ? num / den : 0.0;
  return out;
}

}  // namespace infolerp::support
