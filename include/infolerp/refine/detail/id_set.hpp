#pragma once
// A set of ids (triangles of the refiner's hierarchy) with O(1) insert and erase (the last id
// moves into the gap) and an ascending view sorted on demand. Per-id positions: 4 bytes per id.
// Preconditions: ids < the size given to grow(). Not thread-safe (sorted() sorts in place).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace infolerp::detail {

class id_set {
 public:
  static constexpr std::uint32_t none = 0xffffffffu;

  void grow(std::size_t n) { pos_.resize(n, none); }
  void reset() { ids_.clear(), pos_.clear(), sorted_ = true; }
  // Replaces the contents with `ascending` (sorted, distinct). O(old size + new size).
  void assign(std::span<const std::uint32_t> ascending) {
    for (std::uint32_t t : ids_) pos_[t] = none;
    ids_.assign(ascending.begin(), ascending.end());
    for (std::size_t i = 0; i < ids_.size(); ++i) pos_[ids_[i]] = static_cast<std::uint32_t>(i);
    sorted_ = true;
  }
  [[nodiscard]] bool contains(std::uint32_t t) const { return t < pos_.size() && pos_[t] != none; }
  void insert(std::uint32_t t) {
    sorted_ = sorted_ && (ids_.empty() || ids_.back() < t);
    pos_[t] = static_cast<std::uint32_t>(ids_.size());
    ids_.push_back(t);
  }
  void erase(std::uint32_t t) {
    const std::uint32_t i = pos_[t], last = ids_.back();
    ids_[i] = last;
    pos_[last] = i;
    ids_.pop_back();
    pos_[t] = none;
    sorted_ = sorted_ && i == ids_.size();
  }
  [[nodiscard]] std::size_t size() const noexcept { return ids_.size(); }
  [[nodiscard]] std::size_t memory_bytes() const noexcept { return (ids_.capacity() + pos_.capacity()) * sizeof(std::uint32_t); }
  [[nodiscard]] std::span<const std::uint32_t> unordered() const noexcept { return ids_; }
  // O(n log n) after a change that broke the order, O(1) otherwise.
  [[nodiscard]] std::span<const std::uint32_t> sorted() const {
    if (!sorted_) {
      std::sort(ids_.begin(), ids_.end());
      for (std::size_t i = 0; i < ids_.size(); ++i) pos_[ids_[i]] = static_cast<std::uint32_t>(i);
      sorted_ = true;
    }
    return ids_;
  }

 private:
  mutable std::vector<std::uint32_t> ids_, pos_;
  mutable bool sorted_ = true;
};

}  // namespace infolerp::detail
