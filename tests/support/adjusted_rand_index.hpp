#pragma once
// Adjusted Rand index of two labelings of the same elements (Hubert & Arabie 1985): 1 for the
// same partition, about 0 for independent ones. For benchmarks comparing clusterings.
// O(n log n), allocation O(n).
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace infolerp::support {

inline double adjusted_rand_index(const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, double> joint;
  std::map<std::uint32_t, double> ra, rb;
  for (std::size_t i = 0; i < a.size(); ++i) {
    joint[{a[i], b[i]}] += 1.0;
    ra[a[i]] += 1.0;
    rb[b[i]] += 1.0;
  }
  auto c2 = [](double n) { return n * (n - 1.0) / 2.0; };
  double sij = 0.0, sa = 0.0, sb = 0.0;
  for (auto& [k, n] : joint) sij += c2(n);
  for (auto& [k, n] : ra) sa += c2(n);
  for (auto& [k, n] : rb) sb += c2(n);
  const double expected = sa * sb / c2(static_cast<double>(a.size()));
  const double maximum = 0.5 * (sa + sb);
  return maximum == expected ? 1.0 : (sij - expected) / (maximum - expected);
}

}  // namespace infolerp::support
