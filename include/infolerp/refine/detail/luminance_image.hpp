#pragma once
// The luminance image and L_max that the criteria read (Oliveira et al. §4), kept for
// progressive_refiner (refine/progressive_driver.hpp): the interpolated luminance of every pixel
// as the leaves of a max-tree (root at 1, pixel p at n + p), so L_max is the root. After a new
// view every pixel is computed; afterwards only the pixels of leaves marked dirty (split, or
// shown through another triangle), and only the tree nodes whose maximum changed.
// Memory: 8 bytes per pixel, 4 per triangle. Not thread-safe: one call at a time.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace infolerp::detail {

class luminance_image {
 public:
  void grow(std::size_t triangles) { dirty_mark_.resize(triangles, 0); }
  void reset() {
    tree_.clear();
    dirty_.clear();
    dirty_mark_.clear();
    dirty_clock_ = 1;
    l_max_ = 0.0f;
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
  void forget(std::uint32_t t) { dirty_mark_[t] = 0; }

  // Brings the image of n pixels and L_max up to date: float luminance_of(p) per pixel,
  // for_each_pixel(leaf, f) calls f(p) for each pixel listed under a leaf. O(n) after
  // invalidate() (in parallel), else O(dirty pixels + tree nodes whose maximum changed).
  template <class E, class LuminanceOf, class ForEachPixel>
  void update(std::size_t n, E&& exec, std::size_t grain, LuminanceOf&& luminance_of, ForEachPixel&& for_each_pixel) {
    if (all_dirty_) {
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
    dirty_.clear();
    if (++dirty_clock_ == 0) std::fill(dirty_mark_.begin(), dirty_mark_.end(), 0u), dirty_clock_ = 1;
    l_max_ = n == 0 ? 0.0f : std::max(0.0f, tree_[1]);
  }

  // The pixel luminances of the last update() for an image of n pixels, empty before one.
  [[nodiscard]] std::span<const float> pixels(std::size_t n) const {
    if (tree_.size() != 2 * n) return {};
    return std::span<const float>(tree_).subspan(n);
  }
  [[nodiscard]] float l_max() const noexcept { return l_max_; }
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    return tree_.capacity() * sizeof(float) + (level_.capacity() + next_.capacity() + dirty_.capacity() + dirty_mark_.capacity()) * 4;
  }

 private:
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
  std::vector<std::uint32_t> level_, next_;     // update_tree()'s nodes of one round and the next
  std::vector<std::uint32_t> dirty_, dirty_mark_;  // leaves to recompute, and their dirty_clock_ stamps
  std::uint32_t dirty_clock_ = 1;
  bool all_dirty_ = true;
  float l_max_ = 0.0f;
};

}  // namespace infolerp::detail
