#pragma once
// Normalized Luminance Differences (NLD): Oliveira, Santos, Proença, "Refinement Criteria for
// High Fidelity Interactive Walkthroughs", §4, equation (1):
//
//   S = sqrt( Σ_{i<j} (L_i − L_j)²  /  ((n² div 4) · L_max²) )
//
// The denominator is the largest value the pair sum can take when every L_i lies in
// [0, L_max] (half of the points at 0, half at L_max gives ⌊n/2⌋·⌈n/2⌉ = n² div 4 pairs of
// difference L_max), so S lies in [0, 1]: 0 for equal luminances, 1 for a half-black,
// half-L_max set.
//
// Defined special cases (the paper leaves them open):
//   n < 2                    S = 0 (no pair differs)
//   L_max <= 0 or not finite S = 0 (an all-black image has no luminance differences to normalise)
//   a non-finite L_i         S = 1 (an invalid sample is the most suspicious one: refine it)
//   L_i outside [0, L_max]   S is clamped to 1
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <glm/vec3.hpp>

namespace infolerp {

// Rec. 709 luminance of a linear RGB colour (the weights the paper's Drago tone mapper uses).
// O(1), no allocation, pure.
inline constexpr float luminance(glm::vec3 rgb) noexcept {
  return 0.2126f * rgb.r + 0.7152f * rgb.g + 0.0722f * rgb.b;
}

// The numerator of equation (1), Σ_{i<j}(L_i − L_j)², accumulated in double with the
// mean-shifted identity Σ_{i<j}(L_i − L_j)² = n·Σ_i (L_i − mean)², which cannot go negative and
// does not cancel; +infinity when an L_i is not finite. For a fixed L_max, S (nld_normalised) is a
// non-decreasing function of it, so it orders triangles as S does for any L_max.
// Complexity O(n), two passes; no allocation; thread-safe.
inline double nld_pair_sum(std::span<const float> L) noexcept {
  const std::size_t n = L.size();
  double mean = 0.0;
  for (float l : L) {
    if (!std::isfinite(l)) return std::numeric_limits<double>::infinity();
    mean += static_cast<double>(l);
  }
  mean /= static_cast<double>(n);
  double squares = 0.0;
  for (float l : L) {
    const double d = static_cast<double>(l) - mean;
    squares += d * d;
  }
  return static_cast<double>(n) * squares;
}

// S of equation (1) from the pair sum of n luminances, with the special cases above. O(1).
inline float nld_normalised(double pair_sum, std::size_t n, float L_max) noexcept {
  if (n < 2 || !(L_max > 0.0f) || !std::isfinite(L_max)) return 0.0f;
  if (!std::isfinite(pair_sum)) return 1.0f;  // an invalid sample
  const double pairs = static_cast<double>((n * n) / 4);  // n² div 4
  const double lmax = static_cast<double>(L_max);
  const double s = std::sqrt(pair_sum / (pairs * lmax * lmax));
  return static_cast<float>(std::min(s, 1.0));
}

// S of equation (1) over the luminances L. Complexity O(n); no allocation; thread-safe.
inline float nld(std::span<const float> L, float L_max) noexcept {
  if (L.size() < 2) return 0.0f;
  return nld_normalised(nld_pair_sum(L), L.size(), L_max);
}
inline float nld(float a, float b, float c, float L_max) noexcept {
  const float L[3] = {a, b, c};
  return nld(std::span<const float>(L), L_max);
}
inline float nld(float a, float b, float c, float d, float L_max) noexcept {
  const float L[4] = {a, b, c, d};
  return nld(std::span<const float>(L), L_max);
}

}  // namespace infolerp
