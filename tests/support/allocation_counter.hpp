#pragma once
// The heap allocation counters of a test executable, to show that a per-frame path allocates
// nothing. Any file may include this; the counting itself is counting_new.hpp's, which exactly
// one translation unit of the executable includes.
#include <atomic>
#include <cstddef>

namespace infolerp::support {
inline std::atomic<std::size_t> heap_allocations{0};
// The largest single request seen (reset it to 0 before a measured call), and a cap: a request
// above heap_refuse_above fails (std::bad_alloc, or nullptr for the nothrow form) without asking
// malloc, so a runaway allocation shows up as a test failure instead of exhausting the machine.
inline std::atomic<std::size_t> heap_largest{0};
inline std::atomic<std::size_t> heap_refuse_above{~std::size_t{0}};
inline bool note_allocation(std::size_t n) {
  heap_allocations.fetch_add(1, std::memory_order_relaxed);
  std::size_t seen = heap_largest.load(std::memory_order_relaxed);
  while (n > seen && !heap_largest.compare_exchange_weak(seen, n, std::memory_order_relaxed)) {
  }
  return n <= heap_refuse_above.load(std::memory_order_relaxed);
}
}  // namespace infolerp::support
