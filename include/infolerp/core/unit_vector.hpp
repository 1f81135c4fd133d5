#pragma once
// d / |d| for any finite d, with no overflow or underflow on the way: glm::normalize where d·d is a
// normal number (so ordinary vectors keep its bits), d scaled by its largest component first
// where it is not; (0,0,0) for a zero or non-finite d. O(1), no allocation.
#include <algorithm>
#include <cmath>
#include <limits>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace infolerp {

template <class T, glm::qualifier Q>
[[nodiscard]] glm::vec<3, T, Q> unit_or_zero(const glm::vec<3, T, Q>& d) {
  if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z)) return glm::vec<3, T, Q>(T(0));
  const T l2 = glm::dot(d, d);
  if (std::isfinite(l2) && l2 >= std::numeric_limits<T>::min()) return glm::normalize(d);
  const T scale = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
  return scale > T(0) ? glm::normalize(d / scale) : glm::vec<3, T, Q>(T(0));
}

}  // namespace infolerp
