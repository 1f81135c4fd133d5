#pragma once
// A cheap estimate of the two-way Jensen–Shannon divergence with a proven error bound, so that
// the clustering (cluster/region_growing.hpp, cluster/boundary_smoothing.hpp) decides most
// "JS < Th" and "JS_a < JS_b" questions without the exact kernel of info/jensen_shannon.hpp
// (a filter, then exact evaluation only where the estimate cannot decide: same results).
//
// Entropy form (Lin 1991, Eq. 4.1; clustering paper §3.1 JS(π₁,π₂; p,q)):
//   JS = H(m) − π₁H(p) − π₂H(q),  m = π₁p + π₂q,
// with H(p), H(q) estimated once per row (entropy_estimate) and H(m) per pair (one logarithm
// per bin, no division), all in float: log₂x = k + P(f − 1) for x = 2^k·f, f in [√½, √2),
// P a degree-8 polynomial (Chebyshev interpolant, truncation 5.7e-8, Estrin's scheme). Measured over every
// float f in [√½, √2) (tests/core/test_info.cpp, every compiled variant): |P(f − 1) − log₂f|
// <= 1.2e-7; the bound below uses log2_estimate_error = 2.5e-7. The exact kernel is evaluated
// per bin in double and cancels nothing; this one cancels (H(m) ~ log₂n against a JS that may
// be ~0), which is why it only screens.
//
// Error bound, for rows of n entries >= 0 summing to 1 (within 2⁻¹⁰) and weights summing to 1:
//   |js_estimate − JS| <= js_estimate_error(n) = 2·(δ + (n/8 + 16)·2⁻²⁴·(log₂n + 3)) + 1e-12.
// Each of the three entropies is within δ + (n/8 + 16)·2⁻²⁴·(log₂n + 3): the polynomial error
// δ weighted by Σx = 1; float rounding of the inputs (for double rows) and of m (4 roundings),
// of k + P and of x·(k + P) (2), all relative to |x·log₂x|, whose sum is H <= log₂n; and the
// float sums (at least 16 lanes of at most n/16 + 1 terms each, then their sum in double),
// relative to the same Σ. H(m) and π₁H(p) + π₂H(q) each contribute one such bound. For n = 64:
// 1.2e-5.
// Zero entries contribute exactly 0 (the logarithm of 0 comes out finite); subnormal entries
// less than 1e-36 each.
//
// Speed: the portable build runs 8-float GNU vectors on SSE2; on x86-64 an AVX2+FMA copy and a
// 16-float AVX-512F copy are chosen at run time (the bound holds for each, and each is tested;
// their bits may differ, which is why results never depend on an estimate's value, only on
// decisions it proves). The estimate pays off for float rows (the direct channels keep float
// copies of their rows for it); for double rows the conversion eats most of the gain
// (benchmarks/NOTES.md, BM_JensenShannon_Column).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include "infolerp/info/jensen_shannon.hpp"
#include "infolerp/info/log2.hpp"

namespace infolerp {

// |P(f − 1) − log₂f| over f in [√½, √2), with margin (measured 1.2e-7).
inline constexpr double log2_estimate_error = 2.5e-7;

// The bound of js_estimate (and half of it bounds entropy_estimate). O(1).
inline double js_estimate_error(std::size_t n) noexcept {
  const double bins = static_cast<double>(n < 1 ? 1 : n);
  return 2.0 * (log2_estimate_error + (bins / 8.0 + 16.0) * 0x1p-24 * (std::log2(bins) + 3.0)) + 1e-12;
}

namespace detail {

#if defined(__GNUC__) && !defined(INFOLERP_NO_VECTOR_EXTENSIONS)
#define INFOLERP_JSE_VECTOR 1
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"  // vectors only pass between inlined helpers
typedef float jse_vf __attribute__((vector_size(32)));
typedef std::int32_t jse_vi __attribute__((vector_size(32)));
typedef float jse_vf16 __attribute__((vector_size(64)));
typedef std::int32_t jse_vi16 __attribute__((vector_size(64)));
#else
#define INFOLERP_JSE_VECTOR 0
using jse_vf = float;
using jse_vi = std::int32_t;
#endif

// out = k + P(f − 1) ≈ log₂x (x = 2^k·f, f in [√½, √2)); finite for x = 0 (−127) and
// subnormal x (within 24 of log₂x); x·out is what callers use.
template <class V, class I>
INFOLERP_FORCE_INLINE void log2_estimate_on(V& out, const V& x) noexcept {
  const I bits = INFOLERP_BIT_CAST(I, x);
  const I t = bits - 0x3F3504F3;  // the bits of √½ (rounded down)
#if INFOLERP_JSE_VECTOR
  const V k = __builtin_convertvector(t >> 23, V);
#else
  const V k = static_cast<float>(t >> 23);
#endif
  const V z = INFOLERP_BIT_CAST(V, bits - (t & -8388608)) - 1.0f;  // -8388608: the exponent field and sign
  // Estrin's scheme (short dependency chains): c0..c8 from the Chebyshev interpolant.
  const V z2 = z * z, z4 = z2 * z2;
  const V p01 = z * 1.44269498f + 4.1502019e-8f, p23 = z * 0.48091991f + -0.72136132f;
  const V p45 = z * 0.28712272f + -0.35996649f, p67 = z * 0.23439478f + -0.25156397f;
  const V p = (p01 + z2 * p23) + z4 * ((p45 + z2 * p67) + z4 * -0.13865119f);
  out = k + p;
}

// Loads one vector of entries as floats.
template <class V, class T>
INFOLERP_FORCE_INLINE void jse_load(V& v, const T* x) noexcept {
  if constexpr (std::is_same_v<T, float>) {
    std::memcpy(&v, x, sizeof v);
#if INFOLERP_JSE_VECTOR
  } else if constexpr (std::is_same_v<T, double> && sizeof(V) % 16 == 0) {  // 4-lane conversions
    typedef double D4 __attribute__((vector_size(32)));
    typedef float F4 __attribute__((vector_size(16)));
    for (std::size_t c = 0; c < sizeof(V) / 16; ++c) {
      D4 d;
      std::memcpy(&d, x + 4 * c, sizeof d);
      const F4 f = __builtin_convertvector(d, F4);
      std::memcpy(reinterpret_cast<char*>(&v) + sizeof f * c, &f, sizeof f);
    }
#endif
  } else {
    float f[sizeof(V) / sizeof(float)];
    for (std::size_t j = 0; j < sizeof(V) / sizeof(float); ++j) f[j] = static_cast<float>(x[j]);
    std::memcpy(&v, f, sizeof v);
  }
}

// Σ_i x_i·log₂x_i (<= 0) over x_i = wp·p_i + wq·q_i (float), or x_i = p_i when q is null.
template <class V, class I, class T>
INFOLERP_FORCE_INLINE double xlogx_sum_on(const T* p, const T* q, std::size_t n, float wp, float wq) noexcept {
  constexpr std::size_t lanes = sizeof(V) / sizeof(float);
  V acc0 = {}, acc1 = {};
  auto term = [&](V& acc, const T* pi, const T* qi) {
    V a, b, l;
    jse_load(a, pi);
    if (qi) {
      jse_load(b, qi);
      a = a * wp + b * wq;
    }
    log2_estimate_on<V, I>(l, a);
    acc += a * l;
  };
  std::size_t i = 0;
  for (; i + 2 * lanes <= n; i += 2 * lanes) {  // two independent chains
    term(acc0, p + i, q ? q + i : nullptr);
    term(acc1, p + i + lanes, q ? q + i + lanes : nullptr);
  }
  for (; i < n; i += lanes) {  // the tail, zero-padded (zero entries add exactly 0)
    T pt[lanes] = {}, qt[lanes] = {};
    for (std::size_t j = 0; j < lanes && i + j < n; ++j) {
      pt[j] = p[i + j];
      if (q) qt[j] = q[i + j];
    }
    term(acc1, pt, q ? qt : nullptr);
  }
  const V both = acc0 + acc1;
  float lane[lanes];
  std::memcpy(lane, &both, sizeof lane);
  double sum[lanes];  // pairwise, in double
  for (std::size_t j = 0; j < lanes; ++j) sum[j] = static_cast<double>(lane[j]);
  for (std::size_t w = lanes; w > 1; w /= 2)
    for (std::size_t j = 0; j < w / 2; ++j) sum[j] = sum[2 * j] + sum[2 * j + 1];
  return sum[0];
}

// out[j] = log2_estimate_on(x[j]) for j from i, a vector at a time while one fits; returns
// where it stopped.
template <class V, class I>
INFOLERP_FORCE_INLINE std::size_t log2_estimate_from(const float* x, float* out, std::size_t i, std::size_t n) noexcept {
  for (; i + sizeof(V) / sizeof(float) <= n; i += sizeof(V) / sizeof(float)) {
    V v, l;
    std::memcpy(&v, x + i, sizeof v);
    log2_estimate_on<V, I>(l, v);
    std::memcpy(out + i, &l, sizeof l);
  }
  return i;
}

#if INFOLERP_JSE_VECTOR
#pragma GCC diagnostic pop
#endif

#if defined(INFOLERP_JS_AVX2)
#define INFOLERP_JSE_AVX2 1
template <class T>
__attribute__((target("avx2,fma"))) double xlogx_sum_avx2(const T* p, const T* q, std::size_t n, float wp,
                                                          float wq) noexcept {
  return xlogx_sum_on<jse_vf, jse_vi>(p, q, n, wp, wq);
}
__attribute__((target("avx2,fma"))) inline void log2_estimate_avx2(const float* x, float* out, std::size_t n) noexcept {
  log2_estimate_from<jse_vf, jse_vi>(x, out, 0, n);
}
#endif

// And on 16 lanes where the CPU has AVX-512F (INFOLERP_NO_AVX512 disables it): half the
// iterations at 64 bins.
#if defined(INFOLERP_JS_AVX512)
#define INFOLERP_JSE_AVX512 1
template <class T>
__attribute__((target("avx512f"))) double xlogx_sum_avx512(const T* p, const T* q, std::size_t n, float wp,
                                                           float wq) noexcept {
  return xlogx_sum_on<jse_vf16, jse_vi16>(p, q, n, wp, wq);
}
__attribute__((target("avx512f"))) inline void log2_estimate_avx512(const float* x, float* out, std::size_t n) noexcept {
  log2_estimate_from<jse_vf, jse_vi>(x, out, log2_estimate_from<jse_vf16, jse_vi16>(x, out, 0, n), n);
}
#endif

template <class T>
double xlogx_sum(const T* p, const T* q, std::size_t n, float wp, float wq) noexcept {
#ifdef INFOLERP_JSE_AVX512
  if (x86_vector_level() == 2) return xlogx_sum_avx512(p, q, n, wp, wq);
#endif
#ifdef INFOLERP_JSE_AVX2
  if (x86_vector_level() >= 1) return xlogx_sum_avx2(p, q, n, wp, wq);
#endif
  return xlogx_sum_on<jse_vf, jse_vi>(p, q, n, wp, wq);
}

// out[i] ≈ log₂x[i] as the estimates compute it (the dispatched variant; n a multiple of 8).
// For the exhaustive accuracy test. O(n), no allocation.
inline void log2_estimate(const float* x, float* out, std::size_t n) noexcept {
#ifdef INFOLERP_JSE_AVX512
  if (x86_vector_level() == 2) return log2_estimate_avx512(x, out, n);
#endif
#ifdef INFOLERP_JSE_AVX2
  if (x86_vector_level() >= 1) return log2_estimate_avx2(x, out, n);
#endif
  log2_estimate_from<jse_vf, jse_vi>(x, out, 0, n);
}

}  // namespace detail

// H(p) in bits, within js_estimate_error(n)/2 (rows as in the header comment).
// O(n), no allocation, thread-safe.
template <class T>
double entropy_estimate(const T* p, std::size_t n) noexcept {
  return -detail::xlogx_sum<T>(p, nullptr, n, 1.0f, 0.0f);
}

// JS with weights (wp, 1 − wp) from the rows and their entropy_estimate values hp, hq; within
// js_estimate_error(n) of js_divergence(p, q, wp), clamped to [0, 1]. Preconditions: rows of
// n entries >= 0 each summing to 1 within 2⁻¹⁰, 0 <= wp <= 1. O(n), no allocation, thread-safe.
template <class T>
double js_estimate(const T* p, const T* q, std::size_t n, double wp, double hp, double hq) noexcept {
  const double wq = 1.0 - wp;
  const double hm = -detail::xlogx_sum<T>(p, q, n, static_cast<float>(wp), static_cast<float>(wq));
  const double js = hm - (wp * hp + wq * hq);
  return js > 0.0 ? (js < 1.0 ? js : 1.0) : 0.0;
}

}  // namespace infolerp
