#pragma once
// An allocator for large, short-lived buffers (the visibility channel's M×N rows): on Linux,
// allocations of at least 4 MiB are aligned to 2 MiB and marked MADV_HUGEPAGE, so that their
// first touch costs one page fault per 2 MiB instead of one per 4 KiB where transparent huge
// pages are enabled ("always" or "madvise"); a hint only, without effect on values. Below 4 MiB,
// plain operator new; elsewhere than Linux, aligned operator new without the hint.
// The visibility channel's two row buffers faulted 4 KiB pages for about a tenth of the
// clustering run (benchmarks/NOTES.md, BM_Clustering_RefinedElephant).
//
//   std::vector<float, infolerp::large_buffer_allocator<float>> rows;
#include <cstddef>
#include <new>
#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace infolerp {

template <class T>
struct large_buffer_allocator {
  using value_type = T;
  static constexpr std::size_t huge_page = std::size_t{2} << 20;
  static constexpr std::size_t large = std::size_t{4} << 20;  // bytes from which the hint is given

  large_buffer_allocator() = default;
  template <class U>
  large_buffer_allocator(const large_buffer_allocator<U>&) noexcept {}

  // Preconditions: n·sizeof(T) does not overflow. O(1) plus the system's allocation; fails as
  // operator new does when memory is exhausted.
  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < large) return static_cast<T*>(::operator new(bytes));
    void* p = ::operator new(bytes, std::align_val_t{huge_page});
#if defined(__linux__)
    madvise(p, bytes, MADV_HUGEPAGE);  // a hint: fails harmlessly where THP is off
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < large) ::operator delete(p);
    else ::operator delete(p, std::align_val_t{huge_page});
  }
  friend bool operator==(const large_buffer_allocator&, const large_buffer_allocator&) { return true; }
};

}  // namespace infolerp
