#pragma once
// Branch-free log2 for the information-theory kernels (info/jensen_shannon.hpp), written so that
// GCC and Clang vectorise it with portable flags (SSE2 baseline, no -ffast-math).
//
// Range reduction by bit manipulation (as in musl's log): r = 2^k · f with f in [√½, √2), then
// ln f = 2·atanh(s), s = (f−1)/(f+1), |s| <= 0.1716, evaluated with fdlibm's e_log.c minimax
// coefficients (error below 2^-58 on that interval) in Estrin form for short dependency chains.
// Accuracy: within 3 ulp of log2(r) for normal positive r (measured: 4.6e-16 relative worst case
// against long double). Zero, subnormal, Inf and NaN inputs give a finite, meaningless value
// (never NaN, never a trap); callers multiply it by a weight that is 0 (or below 1e-300) there.
#include <bit>
#include <cstdint>
#include "infolerp/core/detail/cpu.hpp"

namespace infolerp::detail {

// The helpers are always inlined (so each ISA version of a caller gets its own copy), take and
// return vectors by reference and reinterpret bits with the builtin, not std::bit_cast: a
// 256-bit vector passed by value to or from a function compiled without AVX would trip GCC's
// -Wpsabi in the user's translation unit.
#if defined(__GNUC__)
#define INFOLERP_BIT_CAST(To, x) __builtin_bit_cast(To, x)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"  // 256-bit vectors only pass between inlined helpers
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF  // the same bits in the AVX-512 (FMA) kernels, see jensen_shannon.hpp
#endif
#else
#define INFOLERP_BIT_CAST(To, x) std::bit_cast<To>(x)
#endif

// out = ln((1+s)/(1-s)) for |s| <= 0.1716. D is double or a GNU vector of doubles.
template <class D>
INFOLERP_FORCE_INLINE void log_atanh_series(D& out, const D& s) noexcept {
  constexpr double c1 = 6.666666666666735130e-01, c2 = 3.999999999940941908e-01, c3 = 2.857142874366239149e-01,
                   c4 = 2.222219843214978396e-01, c5 = 1.818357216161805012e-01, c6 = 1.531383769920937332e-01,
                   c7 = 1.479819860511658591e-01;
  const D z = s * s, w = z * z, w2 = w * w;
  const D poly = (c1 + z * c2) + w * (c3 + z * c4) + w2 * ((c5 + z * c6) + w * c7);
  out = (s + s) + (s * z) * poly;
}

// r = 2^k · f with f in [√½, √2). U is the unsigned 64-bit integer type matching D.
template <class D>
struct log2_split {
  D k, f;
};
template <class D, class U>
INFOLERP_FORCE_INLINE void log2_reduce(log2_split<D>& out, const D& r) noexcept {
  constexpr std::uint64_t sqrt_half = 0x3FE6A09E667F3BCDull, exponent = 0xFFF0000000000000ull;
  constexpr std::uint64_t sign = 0x8000000000000000ull;  // flipping it adds 2048 to k (mod 4096)
  constexpr std::uint64_t magic = 0x4330000000000000ull;  // 2^52: a 12-bit integer to double exactly
  const U bits = INFOLERP_BIT_CAST(U, r);
  const U t = bits - sqrt_half;  // k = t >> 52 (arithmetic), f = r / 2^k
  out.k = INFOLERP_BIT_CAST(D, ((t ^ sign) >> 52) | magic) - (4503599627370496.0 + 2048.0);
  out.f = INFOLERP_BIT_CAST(D, bits - (t & exponent));
}

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#if defined(__clang__)
#pragma STDC FP_CONTRACT DEFAULT
#endif
#endif

inline constexpr double log2_e = 1.4426950408889634074;

// log2(r) for a finite positive normal double; see the header comment for other inputs.
inline double log2_accurate(double r) noexcept {
  log2_split<double> x;
  log2_reduce<double, std::uint64_t>(x, r);
  double ln_f;
  log_atanh_series(ln_f, (x.f - 1.0) / (x.f + 1.0));
  return x.k + ln_f * log2_e;
}

}  // namespace infolerp::detail
