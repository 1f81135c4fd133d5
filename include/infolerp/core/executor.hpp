#pragma once
// How infolerp runs work in parallel: through the user's job system. The library creates no
// threads and holds no global state.
//
// An executor offers  parallel_for(n, grain, fn)  which calls fn(begin, end) on disjoint ranges
// that together cover [0, n), from any number of threads, each range at most `grain` long
// unless the executor chooses to run everything on one thread. Results never depend on how the
// executor splits: algorithms reduce per fixed chunk (for_each_chunk) and combine in order.
#include <algorithm>
#include <concepts>
#include <cstddef>
#include <type_traits>
#ifdef _OPENMP
#include <omp.h>
#endif

namespace infolerp {

namespace detail {
struct range_fn_archetype {
  void operator()(std::size_t, std::size_t) const {}
};
}  // namespace detail

template <class E>
concept executor = requires(E& e, std::size_t n, std::size_t grain, detail::range_fn_archetype fn) {
  e.parallel_for(n, grain, fn);
};

// For `static_assert(check_executor<E>())` at entry points: one readable message when E is not an
// executor. Compile time only.
template <class E>
constexpr bool check_executor() {
  static_assert(executor<E>,
                "infolerp: executor type needs `void parallel_for(size_t n, size_t grain, F fn)` calling "
                "fn(begin, end) over ranges that cover [0, n)");
  return executor<E>;
}

// Runs everything on the calling thread, in order. The default executor. No allocation;
// stateless, so one object may be shared by any number of threads.
struct serial_executor {
  template <class F>
  void parallel_for(std::size_t n, std::size_t /*grain*/, F&& fn) const {
    if (n != 0) fn(std::size_t{0}, n);
  }
};

// Fixed chunking, the one place that turns (n, grain) into ranges: every chunked loop of the
// library (and an executor that splits by grain) goes through these, so no grain, however large,
// can wrap a chunk bound. Grain 0 counts as 1; a grain above n gives one chunk. O(1), no
// allocation.
// Number of fixed chunks of `grain` elements covering n elements.
constexpr std::size_t chunk_count(std::size_t n, std::size_t grain) noexcept {
  grain = grain == 0 ? 1 : grain;
  return n / grain + (n % grain != 0 ? 1 : 0);
}

struct chunk_bounds {
  std::size_t begin = 0, end = 0;
};

// Chunk c: [c·grain, min(n, (c+1)·grain)), computed without overflow. Precondition:
// c < chunk_count(n, grain) (then c·grain < n).
constexpr chunk_bounds chunk_at(std::size_t n, std::size_t grain, std::size_t c) noexcept {
  grain = grain == 0 ? 1 : grain;
  const std::size_t begin = c * grain;
  return {begin, begin + std::min(grain, n - begin)};
}

#ifdef _OPENMP
// OpenMP worksharing over chunks of `grain` (dynamic schedule). Offered only when the
// translation unit is compiled with OpenMP. threads = 0 uses OpenMP's default.
// Preconditions: not called from inside another OpenMP parallel region if nested parallelism is
// off (the call then runs on one thread). O(n / grain) scheduling; allocation is OpenMP's own.
struct openmp_executor {
  int threads = 0;
  template <class F>
  void parallel_for(std::size_t n, std::size_t grain, F&& fn) const {
    if (n == 0) return;
    const auto chunks = static_cast<long long>(chunk_count(n, grain));
    const int nthreads = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(nthreads)
    for (long long c = 0; c < chunks; ++c) {
      const chunk_bounds r = chunk_at(n, grain, static_cast<std::size_t>(c));
      fn(r.begin, r.end);
    }
  }
};
#endif

// Calls fn(chunk, begin, end) for each fixed chunk [chunk·grain, min(n, (chunk+1)·grain)),
// in parallel through the executor. Chunk boundaries depend only on n and grain, so a per-chunk
// reduction combined in chunk order gives the same bits for any executor and thread count.
// Preconditions: fn is safe to call concurrently for different chunks. O(chunks) scheduling,
// no allocation of its own (the executor's only).
template <class E, class F>
  requires executor<std::remove_cvref_t<E>>
void for_each_chunk(E&& exec, std::size_t n, std::size_t grain, F&& fn) {
  exec.parallel_for(chunk_count(n, grain), 1, [&](std::size_t cb, std::size_t ce) {
    for (std::size_t c = cb; c < ce; ++c) {
      const chunk_bounds r = chunk_at(n, grain, c);
      fn(c, r.begin, r.end);
    }
  });
}

}  // namespace infolerp
