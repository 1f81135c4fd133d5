#pragma once
// Neumaier's compensated summation (Neumaier 1974, the improved Kahan–Babuška sum): the
// rounding error of each addition is carried separately and added back once at the end, so the
// error of a long sum stays near one rounding of the result instead of growing with the
// number of terms. Four additions and a comparison per term; no allocation, no state beyond
// the object. Every operation is an addition (nothing an FMA could contract).
#include <cmath>
#include "infolerp/core/detail/cpu.hpp"

namespace infolerp::detail {

struct compensated_sum {
  double sum = 0.0, carry = 0.0;
  INFOLERP_FORCE_INLINE void add(double x) noexcept {
    const double t = sum + x;
    carry += std::fabs(sum) >= std::fabs(x) ? (sum - t) + x : (x - t) + sum;
    sum = t;
  }
  double value() const noexcept { return sum + carry; }
};

}  // namespace infolerp::detail
