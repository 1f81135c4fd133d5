#pragma once
// splitmix64 (Steele, Lea, Flood 2014, "Fast splittable pseudorandom number generators"):
// the same sequence on every platform and standard library, unlike std:: distributions, so
// seeded results (salient clustering's seeds, RND refinement points) are reproducible anywhere.
#include <cstdint>

namespace infolerp {

struct splitmix64 {
  std::uint64_t state = 0;
  // Next 64 random bits. O(1), no allocation; not thread-safe (one generator per thread).
  std::uint64_t next() noexcept {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  // Uniform integer in [0, n), unbiased (rejection). Precondition: n > 0.
  std::uint64_t uniform(std::uint64_t n) noexcept {
    const std::uint64_t threshold = (0 - n) % n;  // 2^64 mod n
    for (;;)
      if (const std::uint64_t x = next(); x >= threshold) return x % n;
  }
};

}  // namespace infolerp
