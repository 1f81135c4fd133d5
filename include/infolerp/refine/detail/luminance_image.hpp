#pragma once
// The luminance image and L_max that the criteria read (Oliveira et al. §4), kept for
// progressive_refiner (refine/progressive_driver.hpp): the interpolated luminance of every pixel
// as the leaves of a max-tree (root at 1, pixel p at n + p), so L_max is the root. After a new
// view every pixel is computed; afterwards only the pixels of leaves marked dirty (split, or
// shown through another triangle), and only the tree nodes whose maximum changed.
// Criteria that read only L_max (NLD_OS, RND) skip the image (update_bounds()): a max-tree with
// one slot per visible leaf holds an upper bound of its pixels' luminances (its shown triangle's
// brightest corner) or, once evaluated, their exact maximum; L_max descends to the largest entry
// and evaluates leaves until that entry is exact.
// Memory: 8 bytes per pixel (image) or about 20 per visible leaf (bounds), 8 per triangle.
// Not thread-safe: one call at a time.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace infolerp::detail {

class luminance_image {
 public:
  void grow(std::size_t triangles) { dirty_mark_.resize(triangles, 0), slot_of_.resize(triangles, none); }
  void reset() {
    tree_.clear();
    dirty_.clear();
    dirty_mark_.clear();
    dirty_clock_ = 1;
    l_max_ = 0.0f;
    key_.clear(), exact_.clear(), slot_of_.clear(), leaf_of_.clear(), free_.clear(), cap_ = 0, bounds_ = false, all_dirty_ = true;
  }
  // A new view: every pixel is recomputed at the next update().
  void invalidate() { all_dirty_ = true; }
  // A leaf whose pixels' colours may have changed since the last update().
  void mark_dirty(std::uint32_t leaf) {
    if (all_dirty_ || dirty_mark_[leaf] == dirty_clock_) return;
    dirty_mark_[leaf] = dirty_clock_;
    dirty_.push_back(leaf);
  }
  // A triangle id freed by the hierarchy.
  void forget(std::uint32_t t) { dirty_mark_[t] = 0, slot_of_[t] = none; }

  // Brings the image of n pixels and L_max up to date: float luminance_of(p) per pixel,
  // for_each_pixel(leaf, f) calls f(p) for each pixel listed under a leaf. O(n) after
  // invalidate() (in parallel), else O(dirty pixels + tree nodes whose maximum changed).
  template <class E, class LuminanceOf, class ForEachPixel>
  void update(std::size_t n, E&& exec, std::size_t grain, LuminanceOf&& luminance_of, ForEachPixel&& for_each_pixel) {
    if (all_dirty_ || bounds_) {
      bounds_ = false;
      clear_slots();
      tree_.resize(2 * n);
      exec.parallel_for(n, grain, [&](std::size_t begin, std::size_t end) {
        for (std::size_t p = begin; p < end; ++p) tree_[n + p] = luminance_of(p);
      });
      for (std::size_t i = n; i-- > 1;) tree_[i] = std::max(tree_[2 * i], tree_[2 * i + 1]);
      all_dirty_ = false;
    } else {
      level_.clear();  // parents of the pixels whose value changed
      for (std::uint32_t leaf : dirty_)
        for_each_pixel(leaf, [&](std::uint32_t p) {
          const float l = luminance_of(p);
          if (tree_[n + p] == l) return;
          tree_[n + p] = l;
          const auto parent = static_cast<std::uint32_t>((n + p) / 2);
          if (level_.empty() || level_.back() != parent) level_.push_back(parent);
        });
      update_tree();
    }
    next_dirty_clock();
    l_max_ = n == 0 ? 0.0f : std::max(0.0f, tree_[1]);
  }

  // L_max without the image, the same value as update()'s: the largest of `floor` (the
  // background's luminance when a pixel missed the scene, else 0) and exact(leaf) (the largest
  // luminance of the leaf's pixels) over the visible leaves. bound(leaf) is an upper bound of
  // exact(leaf), -infinity for a leaf no longer visible. O(visible + the last view's visible)
  // after invalidate(), else O(dirty leaves · log visible) plus the leaves evaluated (each once
  // until marked dirty again) · (their pixels + log visible).
  template <class Bound, class Exact>
  void update_bounds(std::span<const std::uint32_t> visible, float floor, Bound&& bound, Exact&& exact) {
    if (all_dirty_ || !bounds_) {
      bounds_ = true, all_dirty_ = false;
      tree_.clear(), level_.clear();
      clear_slots();
      for (std::uint32_t leaf : visible) slot_of_[leaf] = static_cast<std::uint32_t>(leaf_of_.size()), leaf_of_.push_back(leaf);
      rebuild_keys(std::max<std::size_t>(leaf_of_.size(), 1), [&](std::size_t s) { return bound(leaf_of_[s]); });
    } else {
      for (std::uint32_t leaf : dirty_) set_bound(leaf, bound(leaf));
    }
    next_dirty_clock();
    for (;;) {  // best first: the largest entry, evaluated until it is exact
      std::size_t i = 1;
      while (i < cap_) i = key_[2 * i] >= key_[2 * i + 1] ? 2 * i : 2 * i + 1;
      const auto s = static_cast<std::uint32_t>(i - cap_);
      if (key_[i] == -std::numeric_limits<float>::infinity() || exact_[s]) break;
      exact_[s] = 1;
      set_key(s, exact(leaf_of_[s]));
    }
    l_max_ = std::max({0.0f, floor, key_[1]});
  }

  // The pixel luminances of the last update() for an image of n pixels, empty before one.
  [[nodiscard]] std::span<const float> pixels(std::size_t n) const {
    if (bounds_ || tree_.size() != 2 * n) return {};
    return std::span<const float>(tree_).subspan(n);
  }
  [[nodiscard]] float l_max() const noexcept { return l_max_; }
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    return (tree_.capacity() + key_.capacity()) * sizeof(float) + exact_.capacity() +
           (level_.capacity() + next_.capacity() + dirty_.capacity() + dirty_mark_.capacity() + slot_of_.capacity() +
            leaf_of_.capacity() + free_.capacity()) * 4;
  }

 private:
  static constexpr std::uint32_t none = 0xffffffffu;

  void clear_slots() {
    for (std::uint32_t leaf : leaf_of_)
      if (leaf != none) slot_of_[leaf] = none;
    leaf_of_.clear(), free_.clear(), key_.clear(), exact_.clear(), cap_ = 0;
  }
  // key_ for `capacity` slots (rounded up to a power of two), slot s's entry key_of(s).
  template <class KeyOf>
  void rebuild_keys(std::size_t capacity, KeyOf&& key_of) {
    cap_ = std::bit_ceil(capacity);
    key_.assign(2 * cap_, -std::numeric_limits<float>::infinity());
    exact_.resize(cap_, 0);
    for (std::size_t s = 0; s < leaf_of_.size(); ++s) key_[cap_ + s] = key_of(s);
    for (std::size_t i = cap_; i-- > 1;) key_[i] = std::max(key_[2 * i], key_[2 * i + 1]);
  }
  // A dirty leaf's bound: its slot freed when it is no longer visible, one taken when it is new.
  void set_bound(std::uint32_t leaf, float b) {
    std::uint32_t s = slot_of_[leaf];
    if (b == -std::numeric_limits<float>::infinity()) {
      if (s == none) return;
      set_key(s, b), slot_of_[leaf] = none, leaf_of_[s] = none, free_.push_back(s);
      return;
    }
    if (s == none) {
      if (!free_.empty()) s = free_.back(), free_.pop_back();
      else {
        if (leaf_of_.size() == cap_) {  // doubled: O(slots), once per doubling
          std::vector<float> old(key_.begin() + std::ptrdiff_t(cap_), key_.end());
          rebuild_keys(2 * cap_, [&](std::size_t x) { return old[x]; });
        }
        s = static_cast<std::uint32_t>(leaf_of_.size());
        leaf_of_.push_back(none);
      }
      slot_of_[leaf] = s, leaf_of_[s] = leaf;
    }
    exact_[s] = 0;
    set_key(s, b);
  }
  void next_dirty_clock() {
    dirty_.clear();
    if (++dirty_clock_ == 0) std::fill(dirty_mark_.begin(), dirty_mark_.end(), 0u), dirty_clock_ = 1;
  }
  // A slot's entry in the bounds' tree, and its ancestors' maxima up to the first unchanged.
  void set_key(std::uint32_t s, float v) {
    std::size_t i = cap_ + s;
    key_[i] = v;
    for (i /= 2; i >= 1; i /= 2) {
      const float m = std::max(key_[2 * i], key_[2 * i + 1]);
      if (key_[i] == m) break;
      key_[i] = m;
    }
  }
  // The max-tree's nodes above changed pixels, one round at a time: each queued node is
  // recomputed from its children and queues its parent only when its own value changed, so the
  // rounds end once no maximum changes, and a node whose child changed later (pixels sit at two
  // depths when the pixel count is not a power of two) is queued again and recomputed after it.
  // O(changed nodes + repeats), no sorting.
  void update_tree() {
    while (!level_.empty()) {
      next_.clear();
      for (std::uint32_t i : level_) {
        if (i == 0) continue;  // a one-pixel image: its pixel is the root
        const float v = std::max(tree_[2 * std::size_t(i)], tree_[2 * std::size_t(i) + 1]);
        if (tree_[i] == v) continue;
        tree_[i] = v;
        if (i > 1 && (next_.empty() || next_.back() != i / 2)) next_.push_back(i / 2);
      }
      level_.swap(next_);
    }
  }

  std::vector<float> tree_;                     // the max-tree; its leaves are the pixel luminances
  std::vector<float> key_;                      // update_bounds()'s max-tree over slots (slot s at cap_ + s)
  std::vector<std::uint8_t> exact_;             // per slot: key_ holds the exact maximum, not the bound
  std::vector<std::uint32_t> slot_of_, leaf_of_, free_;  // per triangle its slot; per slot its leaf; free slots
  std::size_t cap_ = 0;                         // key_'s slot count, a power of two
  bool bounds_ = false;                         // the last update was update_bounds()
  std::vector<std::uint32_t> level_, next_;     // update_tree()'s nodes of one round and the next
  std::vector<std::uint32_t> dirty_, dirty_mark_;  // leaves to recompute, and their dirty_clock_ stamps
  std::uint32_t dirty_clock_ = 1;
  bool all_dirty_ = true;
  float l_max_ = 0.0f;
};

}  // namespace infolerp::detail
