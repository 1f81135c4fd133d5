#pragma once
// Jensen–Shannon divergence in bits (Lin 1991; clustering paper §3.1, JS and JS(Y|a,b)).
//
// Evaluated per bin, never as H(Σπp) − ΣπH(p) (which cancels catastrophically and can go
// negative): JS = Σ_i [ π₁ p_i log₂(p_i/m_i) + π₂ q_i log₂(q_i/m_i) ],  m_i = π₁p_i + π₂q_i.
// Accumulated in double, clamped to [0, 1]; zero bins contribute 0; never NaN.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>

namespace infolerp {

namespace detail {
template <class T>
double js_divergence_impl(std::span<const T> p, std::span<const T> q, double weight_p) noexcept {
  const double wp = weight_p, wq = 1.0 - weight_p;
  double sum = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double a = static_cast<double>(p[i]), b = static_cast<double>(q[i]);
    const double m = wp * a + wq * b;
    if (a > 0.0) sum += wp * a * std::log2(a / m);
    if (b > 0.0) sum += wq * b * std::log2(b / m);
  }
  return std::clamp(sum, 0.0, 1.0);
}
}  // namespace detail

// Two-distribution JS with weights (weight_p, 1 − weight_p). Unchecked kernel for inner loops.
// Preconditions: p.size() == q.size(); entries finite and >= 0; each sums to 1 (not
// re-normalised); 0 <= weight_p <= 1. Result in [0, 1], 0 for identical inputs, 1 for disjoint
// supports with equal weights. Complexity O(n), no allocation, thread-safe.
inline double js_divergence(std::span<const double> p, std::span<const double> q, double weight_p = 0.5) noexcept {
  return detail::js_divergence_impl(p, q, weight_p);
}
inline double js_divergence(std::span<const float> p, std::span<const float> q, double weight_p = 0.5) noexcept {
  return detail::js_divergence_impl(p, q, weight_p);
}

// JS(Y|a,b) of the clustering paper: rows p(Y|a), p(Y|b) weighted by the input probabilities
// p(a), p(b), normalised to π₁ = p(a)/(p(a)+p(b)); equal weights when both are 0.
// Preconditions as js_divergence, plus p_a, p_b finite and >= 0.
inline double js_channel(std::span<const double> row_a, std::span<const double> row_b, double p_a, double p_b) noexcept {
  const double total = p_a + p_b;
  return js_divergence(row_a, row_b, total > 0.0 ? p_a / total : 0.5);
}
inline double js_channel(std::span<const float> row_a, std::span<const float> row_b, double p_a, double p_b) noexcept {
  const double total = p_a + p_b;
  return js_divergence(row_a, row_b, total > 0.0 ? p_a / total : 0.5);
}

}  // namespace infolerp
