#pragma once
// The support function of a point set, h(n) = max_p n·p: the offset of the plane with normal n
// that touches the set's convex hull. A plane n·y = h(n) separates the set (n·p <= h(n)) from
// every point with n·y > h(n), which is how the visibility channel proves that a ray cannot be
// occluded without tracing it.
//
// Points are kept in Morton order in blocks of 16 under superblocks of 16 blocks, each with its
// bounding box; a query scans only the boxes whose support exceeds the best value found so far
// (branch and bound), and stops as soon as the value exceeds a caller's limit, so "is this plane
// a supporting plane?" costs a handful of box tests for most planes.
// Exact: the value is the maximum of the same double dot products a linear scan takes.
// Preconditions: finite points. Construction O(P log P), allocation 16·P bytes + boxes;
// queries O(P) worst case, typically far fewer, no allocation, thread-safe (const).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/locality_order.hpp"

namespace infolerp {

class point_support {
 public:
  point_support() = default;
  explicit point_support(std::span<const glm::dvec3> points) {
    const std::vector<std::uint32_t> order = morton_order(points);
    points_.resize(points.size());
    for (std::size_t i = 0; i < order.size(); ++i) points_[i] = points[order[i]];
    for (std::size_t b = 0; b < points_.size(); b += block) {
      bounding_box box;
      for (std::size_t i = b; i < std::min(points_.size(), b + block); ++i) box.extend(points_[i]);
      blocks_.push_back(box);
    }
    for (std::size_t s = 0; s < blocks_.size(); s += block) {
      bounding_box box;
      for (std::size_t i = s; i < std::min(blocks_.size(), s + block); ++i) {
        box.extend(blocks_[i].lo);
        box.extend(blocks_[i].hi);
      }
      supers_.push_back(box);
    }
  }

  // h(n) when it is <= limit, else +inf (the scan stops at the first point above limit).
  // `start` is a known lower bound of h(n) (e.g. n·p of one of the points; -inf if none).
  double support_up_to(const glm::dvec3& n, double start, double limit) const {
    double best = start;
    if (best > limit) return std::numeric_limits<double>::infinity();
    for (std::size_t s = 0; s < supers_.size(); ++s) {
      if (!(box_support(supers_[s], n) > best)) continue;
      for (std::size_t b = s * block; b < std::min(blocks_.size(), (s + 1) * block); ++b) {
        if (!(box_support(blocks_[b], n) > best)) continue;
        for (std::size_t i = b * block; i < std::min(points_.size(), (b + 1) * block); ++i) {
          best = std::max(best, glm::dot(n, points_[i]));
          if (best > limit) return std::numeric_limits<double>::infinity();
        }
      }
    }
    return best;
  }

 private:
  static constexpr std::size_t block = 16;
  std::vector<glm::dvec3> points_;
  std::vector<bounding_box> blocks_, supers_;

  // An upper bound of the computed n·p over the box: the dot with its farthest corner along n,
  // raised by 2⁻⁵⁰·Σ|n_a|·max|coordinate|, more than the rounding of either dot product, so
  // that rounding never prunes a box holding the maximum.
  static double box_support(const bounding_box& b, const glm::dvec3& n) {
    const glm::dvec3 c(n.x > 0.0 ? b.hi.x : b.lo.x, n.y > 0.0 ? b.hi.y : b.lo.y, n.z > 0.0 ? b.hi.z : b.lo.z);
    const glm::dvec3 big = glm::max(glm::abs(b.lo), glm::abs(b.hi));
    return glm::dot(n, c) + glm::dot(glm::abs(n), big) * 0x1p-50;
  }
};

}  // namespace infolerp
