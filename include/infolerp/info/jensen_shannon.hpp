#pragma once
// Jensen–Shannon divergence in bits (Lin 1991; clustering paper §3.1: JS(π₁..π_n; p₁..p_n) and
// the two-row shorthand JS(Y|a,b) with π = p(a)/(p(a)+p(b))).
//
// Evaluated per bin, never as H(Σπp) − ΣπH(p) (which cancels catastrophically and can go
// negative): JS = Σ_i [ π₁ p_i log₂(p_i/m_i) + π₂ q_i log₂(q_i/m_i) ],  m_i = π₁p_i + π₂q_i.
// Accumulated in double, clamped to [0, 1] (two-way) or [0, log₂ n] (n-ary); zero bins and bins
// with p_i == q_i contribute exactly 0 (so identical inputs give exactly 0); never NaN.
//
// Speed: the two-way kernel is branch-free (info/log2.hpp) and, under GCC/Clang, written with
// vector extensions: 2 doubles per SSE2 register, 4 per AVX register. On x86-64 a portable
// build also carries an AVX2 and an AVX-512F copy of the kernel (target attributes, no FMA:
// contraction is switched off, see js_kernel_avx512) chosen at run time by
// __builtin_cpu_supports; define INFOLERP_NO_RUNTIME_DISPATCH to keep the SSE2 one,
// INFOLERP_NO_AVX512 to stop at AVX2. Bins are processed in blocks in two stages (ratios and
// divisions, then polynomials) so that out-of-order cores overlap them; a bin takes two
// divisions (1/m, and one for both atanh arguments). Throughput beside std::log2 per bin:
// benchmarks/NOTES.md (BM_JensenShannon).
// Other compilers get the same arithmetic one bin at a time. Summation: bins are taken in
// chunks of 64; within a chunk four accumulators, combined as (a0+a1)+(a2+a3), bin i going to
// a_(i mod 4) (8-lane vectors add their two halves in turn); the chunk sums are added with
// compensated summation (core/detail/compensated_sum.hpp), one step per 64 bins. The result is
// bit-identical for every vector width, so the dispatch never changes a result
// (tests/core/test_info.cpp compares the SSE2, AVX2 and AVX-512 kernels bit for bit).
// Accuracy: every bin's term is >= 0, so the summation error is bounded by about 18 roundings
// of the result (16 additions per lane, the lane combination, the compensated total) whatever
// the bin count, plus the per-bin evaluation (a few 1e-16 absolute). Tested within 1e-15 of a
// closed form for one-hot against uniform with weights 0.9/0.1 up to 2^20 bins, for this
// kernel, the checked form on unnormalised input and the n-ary form; within 1e-12 of a
// long-double reference for subnormal entries, p ≈ q to the last bit and random rows.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>
#include <vector>
#include "infolerp/core/detail/compensated_sum.hpp"
#include "infolerp/core/detail/cpu.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/info/log2.hpp"

namespace infolerp {

namespace detail {

#if defined(__GNUC__) && !defined(INFOLERP_NO_VECTOR_EXTENSIONS)
#define INFOLERP_JS_VECTOR 1
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"  // vectors only pass between inlined helpers
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF  // no a·b + c into FMA in the AVX-512 kernel (the same bits everywhere)
#endif
typedef double js_v2d __attribute__((vector_size(16)));
typedef std::uint64_t js_v2u __attribute__((vector_size(16)));
typedef double js_v4d __attribute__((vector_size(32)));
typedef std::uint64_t js_v4u __attribute__((vector_size(32)));
typedef double js_v8d __attribute__((vector_size(64)));
typedef std::uint64_t js_v8u __attribute__((vector_size(64)));
#if defined(__AVX__)
using js_vd = js_v4d;
using js_vu = js_v4u;
#else
using js_vd = js_v2d;
using js_vu = js_v2u;
#endif
#define INFOLERP_JS_UNROLL _Pragma("GCC unroll 2")
#else
#define INFOLERP_JS_VECTOR 0
using js_vd = double;
using js_vu = std::uint64_t;
#define INFOLERP_JS_UNROLL
#endif

// Helpers take and return vectors by reference: a 256-bit vector passed by value to or from a
// function compiled without AVX would trip GCC's -Wpsabi in the user's translation unit.

// Stage 1 of a bin (or a vector of bins): weights, ratio exponents, atanh arguments.
template <class D>
struct js_stage {
  D pa, pb, k, sa, sb;
};
template <class D, class U>
INFOLERP_FORCE_INLINE void js_prepare(js_stage<D>& s, const D& a, const D& b, double wp, double wq) noexcept {
  // All-ones where a != b: equal bins contribute exactly 0.
#if INFOLERP_JS_VECTOR
  const U keep = INFOLERP_BIT_CAST(U, a != b);
#else
  const U keep = std::uint64_t{0} - static_cast<std::uint64_t>(a != b);
#endif
  s.pa = INFOLERP_BIT_CAST(D, INFOLERP_BIT_CAST(U, wp * a) & keep);
  s.pb = INFOLERP_BIT_CAST(D, INFOLERP_BIT_CAST(U, wq * b) & keep);
  const D inv_m = 1.0 / (s.pa + s.pb);  // Inf where pa + pb == 0: the weights below are 0 there
  log2_split<D> ra, rb;
  log2_reduce<D, U>(ra, a * inv_m);
  log2_reduce<D, U>(rb, b * inv_m);
  s.k = s.pa * ra.k + s.pb * rb.k;
  // (f − 1)/(f + 1) for both with one division: d = 1/((f_a + 1)(f_b + 1)).
  const D va = ra.f + 1.0, vb = rb.f + 1.0;
  const D d = 1.0 / (va * vb);
  s.sa = ((ra.f - 1.0) * vb) * d;
  s.sb = ((rb.f - 1.0) * va) * d;
}
// Stage 2: acc += π₁p log₂(p/m) + π₂q log₂(q/m). The partial sums are 4 lanes (bin i to
// a_(i mod 4)): vectors of up to 4 lanes add into acc[v mod (4/lanes)], 8-lane vectors add
// their low then their high half into one 4-lane acc (the same additions in the same order).
template <class D, class A, std::size_t N>
INFOLERP_FORCE_INLINE void js_finish(A (&acc)[N], std::size_t v, const js_stage<D>& s) noexcept {
  D la, lb;
  log_atanh_series(la, s.sa);
  log_atanh_series(lb, s.sb);
  if constexpr (sizeof(D) == sizeof(A)) {
    acc[v % N] += s.k + (s.pa * la + s.pb * lb) * log2_e;
  } else {
    const D t = s.k + (s.pa * la + s.pb * lb) * log2_e;
    A half[sizeof(D) / sizeof(A)];
    std::memcpy(half, &t, sizeof t);
    for (const A& h : half) acc[0] += h;
  }
}

// Loads `count` (< lanes allowed: zero-padded) entries as doubles, times scale (pre, then inv).
template <bool Scaled, class D, class T>
INFOLERP_FORCE_INLINE void js_load(D& v, const T* x, std::size_t count, double pre, double inv) noexcept {
  constexpr std::size_t lanes = sizeof(D) / sizeof(double);
#if INFOLERP_JS_VECTOR
  if (count < lanes) {
    v = D{};
    for (std::size_t j = 0; j < count; ++j) v[j] = static_cast<double>(x[j]);
  } else if constexpr (std::is_same_v<T, double>) {
    std::memcpy(&v, x, sizeof v);
  } else {  // floats: one load, one conversion
    typedef float F __attribute__((vector_size(sizeof(D) / 2)));
    F f;
    std::memcpy(&f, x, sizeof f);
    v = __builtin_convertvector(f, D);
  }
#else
  static_assert(lanes == 1);
  v = count ? static_cast<double>(*x) : 0.0;
#endif
  if constexpr (Scaled) v = (v * pre) * inv;
}

// Bins per partial sum of the two-way kernel: each chunk of js_chunk bins (starting at a
// multiple of js_chunk) is summed in 4 lanes from zero, and the chunk sums are added with
// compensated summation, so the rounding error does not grow with the bin count.
inline constexpr std::size_t js_chunk = 64;

// The sum of the two-way kernel over one chunk p[0..n), q[0..n), n <= js_chunk, on vectors D
// of doubles (U: matching integers): four lanes, bin i to lane i mod 4, combined as
// (a0+a1)+(a2+a3). Scaled: entries are first multiplied by pre_* then inv_* (normalisation
// without overflow, see jensen_shannon).
template <class D, class U, bool Scaled, class T>
INFOLERP_FORCE_INLINE double js_chunk_sum(const T* p, const T* q, std::size_t n, double wp, double pre_p, double inv_p,
                                          double pre_q, double inv_q) noexcept {
  constexpr std::size_t lanes = sizeof(D) / sizeof(double);
  const double wq = 1.0 - wp;
  constexpr std::size_t block = lanes > 4 ? 4 : 8;  // vectors per stage
  static_assert(js_chunk % (block * lanes) == 0);
#if INFOLERP_JS_VECTOR
  using A = std::conditional_t<(lanes > 4), js_v4d, D>;  // partial sums: at most 4 lanes
#else
  using A = D;
#endif
  constexpr std::size_t accumulators = 4 / (sizeof(A) / sizeof(double));
  A acc[accumulators] = {};
  D a, b;
  std::size_t i = 0;
  for (; i + block * lanes <= n; i += block * lanes) {
    js_stage<D> stage[block];
    INFOLERP_JS_UNROLL
    for (std::size_t v = 0; v < block; ++v) {
      const std::size_t at = i + v * lanes;
      js_load<Scaled>(a, p + at, lanes, pre_p, inv_p);
      js_load<Scaled>(b, q + at, lanes, pre_q, inv_q);
      js_prepare<D, U>(stage[v], a, b, wp, wq);
    }
    INFOLERP_JS_UNROLL
    for (std::size_t v = 0; v < block; ++v) js_finish(acc, v, stage[v]);
  }
  if (i < n) {  // tail: one more stage, zero-padded (zero bins add exactly 0)
    const std::size_t vectors = (n - i + lanes - 1) / lanes;
    js_stage<D> stage[block];
    for (std::size_t v = 0; v < vectors; ++v) {
      const std::size_t at = i + v * lanes, count = std::min(lanes, n - at);
      js_load<Scaled>(a, p + at, count, pre_p, inv_p);
      js_load<Scaled>(b, q + at, count, pre_q, inv_q);
      js_prepare<D, U>(stage[v], a, b, wp, wq);
    }
    for (std::size_t v = 0; v < vectors; ++v) js_finish(acc, v, stage[v]);
  }
  double lane[4];
  static_assert(sizeof acc == sizeof lane);
  std::memcpy(lane, acc, sizeof lane);
  return (lane[0] + lane[1]) + (lane[2] + lane[3]);
}

// The two-way kernel over p[0..n), q[0..n): chunk sums (js_chunk_sum) added with compensated
// summation, clamped to [0, 1].
template <class D, class U, bool Scaled, class T>
INFOLERP_FORCE_INLINE double js_kernel_on(const T* p, const T* q, std::size_t n, double wp, double pre_p, double inv_p,
                                          double pre_q, double inv_q) noexcept {
  compensated_sum total;
  std::size_t i = 0;
  for (; i + js_chunk <= n; i += js_chunk)
    total.add(js_chunk_sum<D, U, Scaled>(p + i, q + i, js_chunk, wp, pre_p, inv_p, pre_q, inv_q));
  if (i < n) total.add(js_chunk_sum<D, U, Scaled>(p + i, q + i, n - i, wp, pre_p, inv_p, pre_q, inv_q));
  const double sum = total.value();
  return sum > 0.0 ? std::min(sum, 1.0) : 0.0;  // also maps NaN (broken preconditions) to 0
}
#undef INFOLERP_JS_UNROLL

// Runtime dispatch (x86-64, GCC/Clang, not already compiled for AVX2): the same kernel on
// 4-lane vectors in a function compiled for AVX2 (no FMA: the arithmetic, and so every bit of
// the result, is the portable kernel's). Define INFOLERP_NO_RUNTIME_DISPATCH to disable.
#if INFOLERP_JS_VECTOR && defined(INFOLERP_X86_DISPATCH) && !defined(__AVX2__)
#define INFOLERP_JS_AVX2 1
template <bool Scaled, class T>
__attribute__((target("avx2"))) double js_kernel_avx2(const T* p, const T* q, std::size_t n, double wp, double pre_p,
                                                      double inv_p, double pre_q, double inv_q) noexcept {
  return js_kernel_on<js_v4d, js_v4u, Scaled>(p, q, n, wp, pre_p, inv_p, pre_q, inv_q);
}
// And on 8-lane vectors where the CPU has AVX-512F (define INFOLERP_NO_AVX512 to disable).
// AVX-512F implies FMA, and GCC and Clang would contract a·b + c into it (other bits than the
// portable kernel): contraction is off in this function for GCC, and for the inlined helpers
// under Clang (#pragma STDC FP_CONTRACT, here and in log2.hpp).
#if !defined(INFOLERP_NO_AVX512)
#define INFOLERP_JS_AVX512 1
template <bool Scaled, class T>
#if defined(__clang__)
__attribute__((target("avx512f")))
#else
__attribute__((target("avx512f"), optimize("fp-contract=off")))
#endif
double js_kernel_avx512(const T* p, const T* q, std::size_t n, double wp, double pre_p, double inv_p, double pre_q,
                        double inv_q) noexcept {
  return js_kernel_on<js_v8d, js_v8u, Scaled>(p, q, n, wp, pre_p, inv_p, pre_q, inv_q);
}
#endif
#endif

template <bool Scaled, class T>
double js_kernel(const T* p, const T* q, std::size_t n, double wp, double pre_p = 1.0, double inv_p = 1.0,
                 double pre_q = 1.0, double inv_q = 1.0) noexcept {
#ifdef INFOLERP_JS_AVX512
  if (x86_vector_level() == 2) return js_kernel_avx512<Scaled>(p, q, n, wp, pre_p, inv_p, pre_q, inv_q);
#endif
#ifdef INFOLERP_JS_AVX2
  if (x86_vector_level() >= 1) return js_kernel_avx2<Scaled>(p, q, n, wp, pre_p, inv_p, pre_q, inv_q);
#endif
  return js_kernel_on<js_vd, js_vu, Scaled>(p, q, n, wp, pre_p, inv_p, pre_q, inv_q);
}

// Σ_i p_i log₂(p_i/q_i) over the bins with p_i > 0, q_i > 0 and p_i != q_i (the others
// contribute exactly 0), clamped at 0; each term as p·log2_accurate(p/q), summed like
// js_kernel_on (4 accumulators, bit-identical for every vector width). Used for I(x;Y).
template <class D, class U, class T>
INFOLERP_FORCE_INLINE double kl_kernel_on(const T* p, const double* q, std::size_t n) noexcept {
  constexpr std::size_t lanes = sizeof(D) / sizeof(double), accumulators = 4 / lanes;
  D acc[accumulators] = {};
  D a, b, one, ln;
  const double ones[4] = {1.0, 1.0, 1.0, 1.0};
  js_load<false>(one, ones, lanes, 1.0, 1.0);
  log2_split<D> x;
  for (std::size_t i = 0, v = 0; i < n; i += lanes, ++v) {  // tail zero-padded: p = 0 adds 0
    js_load<false>(a, p + i, n - i, 1.0, 1.0);
    js_load<false>(b, q + i, n - i, 1.0, 1.0);
#if INFOLERP_JS_VECTOR
    const U keep = INFOLERP_BIT_CAST(U, (a > 0.0) & (b > 0.0) & (a != b));
#else
    const U keep = std::uint64_t{0} - static_cast<std::uint64_t>(a > 0.0 && b > 0.0 && a != b);
#endif
    // p/q where kept, else 1 (log 0): no Inf or NaN reaches the logarithm.
    const D r = INFOLERP_BIT_CAST(D, (INFOLERP_BIT_CAST(U, a / b) & keep) | (INFOLERP_BIT_CAST(U, one) & ~keep));
    log2_reduce<D, U>(x, r);
    log_atanh_series(ln, (x.f - 1.0) / (x.f + 1.0));
    acc[v % accumulators] += INFOLERP_BIT_CAST(D, INFOLERP_BIT_CAST(U, a) & keep) * (x.k + ln * log2_e);
  }
  double lane[4];
  static_assert(sizeof acc == sizeof lane);
  std::memcpy(lane, acc, sizeof lane);
  const double sum = (lane[0] + lane[1]) + (lane[2] + lane[3]);
  return sum > 0.0 ? sum : 0.0;
}

// log₂e·Σ_i (p_i − q_i) over the bins with p_i > 0 and q_i > 0: a lower bound of kl_kernel
// without logarithms (p·ln(p/q) >= p − q), summed like kl_kernel_on.
template <class D, class U, class T>
INFOLERP_FORCE_INLINE double kl_lower_bound_on(const T* p, const double* q, std::size_t n) noexcept {
  constexpr std::size_t lanes = sizeof(D) / sizeof(double), accumulators = 4 / lanes;
  D acc[accumulators] = {};
  D a, b;
  for (std::size_t i = 0, v = 0; i < n; i += lanes, ++v) {  // tail zero-padded: p = 0 adds 0
    js_load<false>(a, p + i, n - i, 1.0, 1.0);
    js_load<false>(b, q + i, n - i, 1.0, 1.0);
#if INFOLERP_JS_VECTOR
    const U keep = INFOLERP_BIT_CAST(U, (a > 0.0) & (b > 0.0));
#else
    const U keep = std::uint64_t{0} - static_cast<std::uint64_t>(a > 0.0 && b > 0.0);
#endif
    acc[v % accumulators] += INFOLERP_BIT_CAST(D, INFOLERP_BIT_CAST(U, a - b) & keep);
  }
  double lane[4];
  static_assert(sizeof acc == sizeof lane);
  std::memcpy(lane, acc, sizeof lane);
  return log2_e * ((lane[0] + lane[1]) + (lane[2] + lane[3]));
}

// Both sums over (p, q) run as K::run<D, U>: the AVX2 lanes where the CPU has them, else the
// portable ones (bit-identical, the same summation order).
struct kl_sum {
  template <class D, class U, class T>
  INFOLERP_FORCE_INLINE static double run(const T* p, const double* q, std::size_t n) noexcept {
    return kl_kernel_on<D, U>(p, q, n);
  }
};
struct kl_bound {
  template <class D, class U, class T>
  INFOLERP_FORCE_INLINE static double run(const T* p, const double* q, std::size_t n) noexcept {
    return kl_lower_bound_on<D, U>(p, q, n);
  }
};
#ifdef INFOLERP_JS_AVX2
template <class K, class T>
__attribute__((target("avx2"))) double kl_dispatch_avx2(const T* p, const double* q, std::size_t n) noexcept {
  return K::template run<js_v4d, js_v4u>(p, q, n);
}
#endif
template <class K, class T>
double kl_dispatch(const T* p, const double* q, std::size_t n) noexcept {
#ifdef INFOLERP_JS_AVX2
  if (x86_vector_level() >= 1) return kl_dispatch_avx2<K>(p, q, n);
#endif
  return K::template run<js_vd, js_vu>(p, q, n);
}
template <class T>
double kl_kernel(const T* p, const double* q, std::size_t n) noexcept {
  return kl_dispatch<kl_sum>(p, q, n);
}
template <class T>
double kl_lower_bound(const T* p, const double* q, std::size_t n) noexcept {
  return kl_dispatch<kl_bound>(p, q, n);
}
#if INFOLERP_JS_VECTOR
#pragma GCC diagnostic pop
#if defined(__clang__)
#pragma STDC FP_CONTRACT DEFAULT
#endif
#endif

// Checks one user distribution and finds the factors that normalise it: x·pre·inv = x/Σx
// without overflow or underflow of the sum. Errors name the distribution and the bin.
struct distribution_scale {
  double pre = 1.0, inv = 1.0;
};
// `what` names the entry point in messages ("jensen_shannon", "entropy", ...).
template <class T>
result<distribution_scale> check_distribution(std::span<const T> x, const char* what, const char* name, std::size_t index) {
  const auto label = [&] { return index == no_element ? std::string(name) : std::string(name) + " " + std::to_string(index); };
  if (x.empty()) return make_error(errc::empty_input, no_element, what, ": ", label(), " has no bins");
  compensated_sum sum;  // the error of a plain running sum grows with the bin count
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double v = static_cast<double>(x[i]);
    if (!std::isfinite(v)) return make_error(errc::non_finite, i, what, ": ", label(), " bin ", i, ": non-finite entry");
    if (v < 0.0) return make_error(errc::bad_distribution, i, what, ": ", label(), " bin ", i, ": negative entry ", v);
    sum.add(v);
  }
  if (!(sum.sum > 0.0))
    return make_error(errc::bad_distribution, no_element, what, ": ", label(), ": all ", x.size(),
                      " bins are zero (no distribution to normalise)");
  distribution_scale s;
  if (!std::isfinite(sum.sum) || sum.sum < 0x1p-1000) {  // rescale by a power of two (exact) first
    s.pre = std::isfinite(sum.sum) ? 0x1p+64 : 0x1p-64;
    sum = {};
    for (const T& v : x) sum.add(static_cast<double>(v) * s.pre);
  }
  s.inv = 1.0 / sum.value();
  return s;
}

}  // namespace detail

// Two-distribution JS with weights (weight_p, 1 − weight_p). Unchecked kernel for inner loops.
// Preconditions: p.size() == q.size(); entries finite and >= 0; each sums to 1 (not
// re-normalised); 0 <= weight_p <= 1. Result in [0, 1], exactly 0 for identical inputs, 1 for
// disjoint supports with equal weights. Complexity O(n), no allocation, thread-safe.
inline double js_divergence(std::span<const double> p, std::span<const double> q, double weight_p = 0.5) noexcept {
  return detail::js_kernel<false>(p.data(), q.data(), std::min(p.size(), q.size()), weight_p);
}
inline double js_divergence(std::span<const float> p, std::span<const float> q, double weight_p = 0.5) noexcept {
  return detail::js_kernel<false>(p.data(), q.data(), std::min(p.size(), q.size()), weight_p);
}

// JS(Y|a,b) of the clustering paper: rows p(Y|a), p(Y|b) weighted by the input probabilities
// p(a), p(b), normalised to π₁ = p(a)/(p(a)+p(b)); equal weights when both are 0.
// Preconditions as js_divergence, plus p_a, p_b finite and >= 0. Complexity O(n), no
// allocation, thread-safe.
inline double js_channel(std::span<const double> row_a, std::span<const double> row_b, double p_a, double p_b) noexcept {
  const double total = p_a + p_b;
  return js_divergence(row_a, row_b, total > 0.0 ? p_a / total : 0.5);
}
inline double js_channel(std::span<const float> row_a, std::span<const float> row_b, double p_a, double p_b) noexcept {
  const double total = p_a + p_b;
  return js_divergence(row_a, row_b, total > 0.0 ? p_a / total : 0.5);
}

namespace detail {
template <class T>
result<double> jensen_shannon_checked(std::span<const T> p, std::span<const T> q, double weight_p) {
  if (!(weight_p >= 0.0 && weight_p <= 1.0))
    return make_error(errc::bad_parameter, no_element, "jensen_shannon: weight_p ", weight_p, " outside [0, 1]");
  if (p.size() != q.size())
    return make_error(errc::bad_distribution, no_element, "jensen_shannon: p has ", p.size(), " bins but q has ", q.size());
  auto sp = check_distribution(p, "jensen_shannon", "p", no_element);
  if (!sp) return sp.error();
  auto sq = check_distribution(q, "jensen_shannon", "q", no_element);
  if (!sq) return sq.error();
  return js_kernel<true>(p.data(), q.data(), p.size(), weight_p, sp->pre, sp->inv, sq->pre, sq->inv);
}
}  // namespace detail

// Checked two-way JS for user data: each distribution is normalised by its sum first, so
// proportional inputs give ~0 (identical ones exactly 0).
// Errors: weight_p outside [0, 1] or NaN (bad_parameter); different sizes (bad_distribution);
// no bins (empty_input); a NaN/Inf entry (non_finite) or a negative entry (bad_distribution),
// element() = the bin; all bins zero (bad_distribution). Complexity O(n), no allocation
// (except the message on error), thread-safe.
inline result<double> jensen_shannon(std::span<const double> p, std::span<const double> q, double weight_p = 0.5) {
  return detail::jensen_shannon_checked(p, q, weight_p);
}
inline result<double> jensen_shannon(std::span<const float> p, std::span<const float> q, double weight_p = 0.5) {
  return detail::jensen_shannon_checked(p, q, weight_p);
}

// n-ary weighted JS: Σ_i π_i Σ_y p_i(y) log₂(p_i(y)/m(y)), m = Σ_i π_i p_i, in [0, log₂ n].
// Each distribution is normalised by its sum and the weights by theirs (any finite weights:
// when their sum overflows they are scaled by a power of two first).
// Errors: no distributions (empty_input); weights.size() != distributions.size() (bad_size);
// a negative, NaN or Inf weight, or all weights 0 (bad_parameter, element() = the weight);
// distributions of different sizes (bad_distribution, element() = the distribution); bad
// entries as in the two-way form (element() = the bin; the message names distribution and bin).
// Complexity O(n·bins), scalar (not the vectorised kernel), no allocation except on error.
inline result<double> jensen_shannon(std::span<const std::span<const double>> distributions, std::span<const double> weights) {
  const std::size_t k = distributions.size();
  if (k == 0) return make_error(errc::empty_input, no_element, "jensen_shannon: no distributions");
  if (weights.size() != k)
    return make_error(errc::bad_size, no_element, "jensen_shannon: ", weights.size(), " weights for ", k, " distributions");
  double weight_sum = 0.0, weight_scale = 1.0;
  for (std::size_t i = 0; i < k; ++i) {
    if (!std::isfinite(weights[i]) || weights[i] < 0.0)
      return make_error(errc::bad_parameter, i, "jensen_shannon: weight ", i, " is ", weights[i], " (must be finite and >= 0)");
    weight_sum += weights[i];
  }
  if (!std::isfinite(weight_sum)) {  // finite weights whose sum overflows: scale by 2^-64 (exact)
    weight_scale = 0x1p-64;
    weight_sum = 0.0;
    for (const double w : weights) weight_sum += w * weight_scale;
  }
  if (!(weight_sum > 0.0))
    return make_error(errc::bad_parameter, no_element, "jensen_shannon: weights sum to 0 (all ", k, " are 0)");
  const std::size_t bins = distributions[0].size();
  struct input {
    detail::distribution_scale scale;
    double weight = 0.0;
  };
  constexpr std::size_t small = 16;  // up to 16 distributions without allocating
  input inputs_small[small];
  std::vector<input> inputs_large(k > small ? k : 0);
  input* inputs = k > small ? inputs_large.data() : inputs_small;
  for (std::size_t i = 0; i < k; ++i) {
    if (distributions[i].size() != bins)
      return make_error(errc::bad_distribution, i, "jensen_shannon: distribution ", i, " has ", distributions[i].size(),
                        " bins, distribution 0 has ", bins);
    auto s = detail::check_distribution(distributions[i], "jensen_shannon", "distribution", i);
    if (!s) return s.error();
    inputs[i] = {*s, weights[i] * weight_scale / weight_sum};
  }
  const auto entry = [&](std::size_t i, std::size_t y) { return distributions[i][y] * inputs[i].scale.pre * inputs[i].scale.inv; };
  detail::compensated_sum sum;  // bins add up without the error growing with their count
  for (std::size_t y = 0; y < bins; ++y) {
    double m = 0.0, lo = entry(0, y), hi = lo;
    for (std::size_t i = 0; i < k; ++i) {
      m += inputs[i].weight * entry(i, y);
      lo = std::min(lo, entry(i, y));
      hi = std::max(hi, entry(i, y));
    }
    if (lo == hi) continue;  // all alike: contributes exactly 0 (identical inputs give 0)
    for (std::size_t i = 0; i < k; ++i) {
      const double x = entry(i, y);
      if (x > 0.0 && inputs[i].weight > 0.0 && x != m) sum.add(inputs[i].weight * x * detail::log2_accurate(x / m));
    }
  }
  return std::clamp(sum.value(), 0.0, std::log2(static_cast<double>(k)));
}

}  // namespace infolerp
