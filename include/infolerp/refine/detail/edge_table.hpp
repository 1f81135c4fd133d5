#pragma once
// subdivision_mesh's edge table: an open-addressing map from an undirected edge (a, b) to its
// midpoint vertex and the (at most two) current leaves that have exactly this edge. Linear
// probing on a Fibonacci hash, load factor at most 1/2; erase() (used when coarsening) shifts
// later members of a probe chain back, so no tombstones accumulate. O(1) expected per call;
// memory 24 bytes per slot. Not thread-safe for modification.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>
#include "infolerp/core/status.hpp"

namespace infolerp::detail {

class edge_table {
 public:
  struct entry {
    std::uint64_t key;
    std::uint32_t midpoint;
    std::uint32_t face[2];
  };
  static constexpr std::uint64_t empty_key = ~std::uint64_t{0};

  void reserve(std::size_t n) {
    std::size_t cap = 16;
    while (cap < 2 * n) cap *= 2;
    if (cap > slots_.size()) rehash(cap);
  }
  [[nodiscard]] std::size_t size() const noexcept { return count_; }
  [[nodiscard]] std::size_t memory_bytes() const noexcept { return slots_.capacity() * sizeof(entry); }

  [[nodiscard]] const entry* find(std::uint32_t a, std::uint32_t b) const noexcept {
    if (slots_.empty()) return nullptr;
    const std::uint64_t k = key(a, b);
    for (std::size_t i = slot(k);; i = (i + 1) & mask_) {
      if (slots_[i].key == k) return &slots_[i];
      if (slots_[i].key == empty_key) return nullptr;
    }
  }
  [[nodiscard]] std::uint32_t midpoint(std::uint32_t a, std::uint32_t b) const noexcept {
    const entry* e = find(a, b);
    return e ? e->midpoint : invalid_id;
  }
  // The entry of (a, b), inserted (no midpoint, no faces) when absent. The reference is valid
  // until the next call of get().
  entry& get(std::uint32_t a, std::uint32_t b) {
    if (2 * (count_ + 1) > slots_.size()) rehash(std::max<std::size_t>(16, 2 * slots_.size()));
    const std::uint64_t k = key(a, b);
    std::size_t i = slot(k);
    for (; slots_[i].key != k; i = (i + 1) & mask_) {
      if (slots_[i].key == empty_key) {
        slots_[i] = {k, invalid_id, {invalid_id, invalid_id}};
        ++count_;
        break;
      }
    }
    return slots_[i];
  }
  // Removes the entry of (a, b) if present (backward-shift deletion keeps every probe chain
  // intact). Invalidates references from get().
  void erase(std::uint32_t a, std::uint32_t b) noexcept {
    if (slots_.empty()) return;
    const std::uint64_t k = key(a, b);
    std::size_t i = slot(k);
    for (; slots_[i].key != k; i = (i + 1) & mask_)
      if (slots_[i].key == empty_key) return;
    for (std::size_t j = i;;) {  // shift later members of the chain back into the hole at i
      j = (j + 1) & mask_;
      if (slots_[j].key == empty_key) break;
      const std::size_t home = slot(slots_[j].key);
      const bool between = i <= j ? (i < home && home <= j) : (i < home || home <= j);  // home in (i, j]: stays
      if (between) continue;
      slots_[i] = slots_[j];
      i = j;
    }
    slots_[i].key = empty_key;
    --count_;
  }
  // Adds a leaf to the edge; false when the edge already has two (a non-manifold edge).
  static bool add_face(entry& e, std::uint32_t t) noexcept {
    if (e.face[0] == invalid_id) e.face[0] = t;
    else if (e.face[1] == invalid_id) e.face[1] = t;
    else return false;
    return true;
  }
  static void remove_face(entry& e, std::uint32_t t) noexcept {
    if (e.face[0] == t) {
      e.face[0] = e.face[1];
      e.face[1] = invalid_id;
    } else if (e.face[1] == t) {
      e.face[1] = invalid_id;
    }
  }
  static std::uint32_t other_face(const entry& e, std::uint32_t t) noexcept {
    return e.face[0] == t ? e.face[1] : e.face[0];
  }

 private:
  static std::uint64_t key(std::uint32_t a, std::uint32_t b) noexcept {
    return a < b ? (std::uint64_t{a} << 32 | b) : (std::uint64_t{b} << 32 | a);
  }
  [[nodiscard]] std::size_t slot(std::uint64_t k) const noexcept {
    return static_cast<std::size_t>((k * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  void rehash(std::size_t cap) {
    std::vector<entry> old(cap, entry{empty_key, invalid_id, {invalid_id, invalid_id}});
    old.swap(slots_);
    mask_ = cap - 1;
    shift_ = 64;
    for (std::size_t c = cap; c > 1; c >>= 1) --shift_;
    for (const entry& e : old) {
      if (e.key == empty_key) continue;
      std::size_t i = slot(e.key);
      while (slots_[i].key != empty_key) i = (i + 1) & mask_;
      slots_[i] = e;
    }
  }
  std::vector<entry> slots_;
  std::size_t count_ = 0;
  std::size_t mask_ = 0;
  unsigned shift_ = 64;
};

}  // namespace infolerp::detail
