#pragma once
// Counts heap allocations of a test executable, to show that a per-frame path allocates nothing:
// it replaces the global operator new (plain and nothrow) and the operator delete they pair with.
// Include it in exactly one translation unit of an executable. Both new forms are replaced so
// that every free() below meets a malloc(): Catch2 and std::stable_sort allocate with the nothrow
// form, and under ASan the runtime's own nothrow new would otherwise pair with this free()
// (alloc-dealloc-mismatch).
#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

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

// GCC pairs the replaced operator new with std::free below and warns of a mismatch; both are
// this file's own replacements, so the pair is consistent.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void* operator new(std::size_t n) {
  if (!infolerp::support::note_allocation(n)) throw std::bad_alloc();
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  if (!infolerp::support::note_allocation(n)) return nullptr;
  return std::malloc(n == 0 ? 1 : n);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
