#pragma once
// Distances between a mesh and a simplification of it over the same vertices, measured the same
// way for any simplifier (the LOD harness and the demo's LOD stage):
//   weighted = Σ_v S(v)·d(v) / Σ S, d(v) the distance from original vertex v to the simplified
//              surface, S a per-vertex weight (e.g. mesh saliency);
//   hausdorff = the larger of max_v d(v) and the largest distance from a simplified triangle's
//              vertices, edge midpoints and centroid to the original surface.
// Closest points come from a uniform grid of triangle boxes searched in growing shells (exact).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
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

// Exact point-to-surface distance through a uniform grid of triangle boxes.
class surface_distance {
 public:
  surface_distance(const std::vector<glm::vec3>& pos, std::span<const std::uint32_t> idx) : pos_(pos), idx_(idx) {
    bounding_box box;
    for (std::uint32_t v : idx) box.extend(glm::dvec3(pos[v]));
    lo_ = box.lo;
    const std::size_t nt = idx.size() / 3;
    const glm::dvec3 ext = box.hi - box.lo;
    // About one triangle per cell: the cell side from the box's volume, or from its largest face
    // or longest side where the mesh is flat or a line (a zero volume must not give tiny cells).
    const double n = std::max<double>(1.0, static_cast<double>(nt));
    glm::dvec3 e = ext;
    if (e.x < e.y) std::swap(e.x, e.y);
    if (e.y < e.z) std::swap(e.y, e.z);
    if (e.x < e.y) std::swap(e.x, e.y);
    h_ = std::max({std::cbrt(e.x * e.y * e.z / n), std::sqrt(e.x * e.y / n), e.x / n, 1e-9 * box.diagonal()});
    for (int a = 0; a < 3; ++a) n_[a] = std::max(1, static_cast<int>(std::ceil(ext[a] / h_)));
    cells_.resize(static_cast<std::size_t>(n_[0]) * static_cast<std::size_t>(n_[1]) * static_cast<std::size_t>(n_[2]));
    for (std::size_t t = 0; t < nt; ++t) {
      glm::dvec3 l(std::numeric_limits<double>::max()), u(-std::numeric_limits<double>::max());
      for (int j = 0; j < 3; ++j) {
        l = glm::min(l, glm::dvec3(pos[idx[3 * t + static_cast<std::size_t>(j)]]));
        u = glm::max(u, glm::dvec3(pos[idx[3 * t + static_cast<std::size_t>(j)]]));
      }
      const glm::ivec3 cl = cell(l), cu = cell(u);
      for (int x = cl.x; x <= cu.x; ++x)
        for (int y = cl.y; y <= cu.y; ++y)
          for (int z = cl.z; z <= cu.z; ++z) cells_[index(x, y, z)].push_back(static_cast<std::uint32_t>(t));
    }
    seen_.assign(nt, 0);
  }
  double operator()(const glm::dvec3& p) {
    const glm::ivec3 c = cell(p);
    double best = std::numeric_limits<double>::max();
    ++stamp_;
    const int rmax = std::max({n_[0], n_[1], n_[2]});
    for (int r = 0; r <= rmax; ++r) {
      for (int x = c.x - r; x <= c.x + r; ++x)
        for (int y = c.y - r; y <= c.y + r; ++y)
          for (int z = c.z - r; z <= c.z + r; ++z) {
            if (std::max({std::abs(x - c.x), std::abs(y - c.y), std::abs(z - c.z)}) != r) continue;
            if (x < 0 || y < 0 || z < 0 || x >= n_[0] || y >= n_[1] || z >= n_[2]) continue;
            for (std::uint32_t t : cells_[index(x, y, z)]) {
              if (seen_[t] == stamp_) continue;
              seen_[t] = stamp_;
              const glm::dvec3 q = closest_on_triangle(p, glm::dvec3(pos_[idx_[3 * t]]), glm::dvec3(pos_[idx_[3 * t + 1]]),
                                                       glm::dvec3(pos_[idx_[3 * t + 2]]));
              best = std::min(best, glm::length(q - p));
            }
          }
      if (best <= static_cast<double>(r) * h_) break;  // unsearched cells are at least r·h away
    }
    return best;
  }

 private:
  glm::ivec3 cell(const glm::dvec3& p) const {
    glm::ivec3 c;
    for (int a = 0; a < 3; ++a) c[a] = std::clamp(static_cast<int>(std::floor((p[a] - lo_[a]) / h_)), 0, n_[a] - 1);
    return c;
  }
  std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(x) * static_cast<std::size_t>(n_[1]) + static_cast<std::size_t>(y)) * static_cast<std::size_t>(n_[2]) +
           static_cast<std::size_t>(z);
  }
  const std::vector<glm::vec3>& pos_;
  std::span<const std::uint32_t> idx_;
  glm::dvec3 lo_{0.0};
  double h_ = 1.0;
  int n_[3] = {1, 1, 1};
  std::vector<std::vector<std::uint32_t>> cells_;
  std::vector<std::uint32_t> seen_;
  std::uint32_t stamp_ = 0;
};

struct distances {
  double weighted = 0.0, hausdorff = 0.0;
};

inline distances measure(const indexed_mesh& m, const std::vector<double>& saliency, std::span<const std::uint32_t> simplified) {
  distances out;
  surface_distance to_simplified(m.positions, simplified);
  std::vector<char> used(m.vertex_count(), 0);
  for (const auto& t : m.triangles) used[t.x] = used[t.y] = used[t.z] = 1;
  double num = 0.0, den = 0.0;
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    if (!used[v]) continue;
    const double d = to_simplified(glm::dvec3(m.positions[v]));
    num += saliency[v] * d, den += saliency[v];
    out.hausdorff = std::max(out.hausdorff, d);
  }
  out.weighted = den > 0.0 ? num / den : 0.0;
  const std::span<const std::uint32_t> original(reinterpret_cast<const std::uint32_t*>(m.triangles.data()), 3 * m.triangle_count());
  surface_distance to_original(m.positions, original);
  for (std::size_t k = 0; k < simplified.size(); k += 3) {
    const glm::dvec3 a(m.positions[simplified[k]]), b(m.positions[simplified[k + 1]]), c(m.positions[simplified[k + 2]]);
    for (const glm::dvec3& p : {a, b, c, 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a), (a + b + c) / 3.0})
      out.hausdorff = std::max(out.hausdorff, to_original(p));
  }
  return out;
}


}  // namespace infolerp::support
