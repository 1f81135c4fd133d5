#pragma once
// CPU dispatch for the vector kernels, in one place (info/jensen_shannon.hpp,
// info/js_estimate.hpp, saliency/mesh_saliency.hpp).
//
// On x86-64 under GCC or Clang a portable build also carries AVX2 and AVX-512F copies of its
// kernels (target attributes) and picks one at run time with x86_vector_level(); define
// INFOLERP_NO_RUNTIME_DISPATCH to keep the portable copy everywhere, INFOLERP_NO_AVX512 to stop
// at AVX2. The copies give the same results (each kernel's header says how), so the choice
// changes speed only. __builtin_cpu_supports reads flags the runtime sets at start-up: O(1), no
// state of ours, thread-safe.
//
// INFOLERP_FORCE_INLINE marks helpers that must be inlined into each ISA copy of their caller
// (an out-of-line helper would be compiled once, for the baseline ISA).
#if defined(__GNUC__) || defined(__clang__)
#define INFOLERP_FORCE_INLINE __attribute__((always_inline)) inline
#else
#define INFOLERP_FORCE_INLINE inline
#endif

#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__) && !defined(INFOLERP_NO_RUNTIME_DISPATCH)
#define INFOLERP_X86_DISPATCH 1
#endif

namespace infolerp::detail {

#ifdef INFOLERP_X86_DISPATCH
// 2: AVX-512F (with FMA), 1: AVX2 and FMA, 0: neither. INFOLERP_NO_AVX512 caps it at 1.
inline int x86_vector_level() noexcept {
#ifndef INFOLERP_NO_AVX512
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("fma")) return 2;
#endif
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") ? 1 : 0;
}
#endif

}  // namespace infolerp::detail
