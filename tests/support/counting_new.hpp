#pragma once
// Counts heap allocations of a test executable (allocation_counter.hpp's counters): replaces the
// global operator new (plain and nothrow) and the operator delete they pair with. Include it in
// exactly one translation unit of an executable. Both new forms are replaced so that every
// free() below meets a malloc(): Catch2 and std::stable_sort allocate with the nothrow form, and
// under ASan the runtime's own nothrow new would otherwise pair with this free()
// (alloc-dealloc-mismatch).
#include <cstdlib>
#include <new>
#include "support/allocation_counter.hpp"

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
