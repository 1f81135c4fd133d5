#pragma once
// NLD_OS's selection (Oliveira, Santos, Proença, §4 and §4.1) kept between batches, so a batch
// costs what it selects and what it made visible, not the whole visible set. select() returns
// exactly what select_nld_os (criteria.hpp) returns on the same frame: the leaves above the
// always-refine fraction first (largest first, ties by id), then those with S > S_req and a
// size of at least min_pixels (criteria.hpp) by S (largest first, ties by id).
//
// How: within one view a visible leaf keeps its pixel count until it is split, and its corners
// are shaded (never evicted) whenever a selection runs, so its pair sum (nld.hpp, the numerator
// of equation (1)) is fixed. S is a non-decreasing function of the pair sum for the batch's
// L_max, so a max-heap on the pair sum yields leaves in non-increasing S; a selection pops until
// it has the batch and every leaf tied with the last one taken, then orders those by (S, id).
// Split leaves leave lazily (dropped when popped); a leaf that is too small never enters.
//
// Use: clear() with a new view, add() every leaf that becomes visible, select() per batch.
// Preconditions of select(): every visible leaf of the view was added since clear(), and the
// corners of every added leaf that is still a visible leaf are shaded.
// Complexity per select(): O((added since the last select + popped) · log heap + forced leaves ·
// log); allocation: the heap grows with the leaves added in the view.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>
#include "infolerp/refine/criteria.hpp"
#include "infolerp/refine/nld.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"

namespace infolerp {

class nld_os_queue {
 public:
  void clear() {
    pending_.clear();
    heap_.clear();
    forced_.clear();
  }
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    return (pending_.capacity() + forced_.capacity()) * sizeof(std::uint32_t) + heap_.capacity() * sizeof(entry) +
           taken_.capacity() * sizeof(scored);
  }
  // Leaf t gained pixels in the current view; its key is taken at the next select().
  void add(std::uint32_t t) { pending_.push_back(t); }

  // Appends up to `limit` ids to `out` (see the prologue).
  void select(const refinement_frame& f, const criteria_options& o, std::vector<std::uint32_t>& out,
              std::size_t limit) {
    const double image = double(f.width) * double(f.height);
    const std::size_t kept = heap_.size();
    for (std::uint32_t t : pending_) {
      if (!visible_leaf(f, t)) continue;
      const auto px = f.leaf_pixels[t];
      if (double(px) > o.always_refine_fraction * image) {
        forced_.push_back(t);
      } else if (detail::qualifies(f, o, t)) {  // fixed for the view: corners and projection do not change
        const glm::uvec3 v = f.mesh->triangle(t).vertices;
        const float L[3] = {f.vertex_luminance[v.x], f.vertex_luminance[v.y], f.vertex_luminance[v.z]};
        heap_.push_back({nld_pair_sum(L), t});
      }
    }
    pending_.clear();
    if (heap_.size() - kept > kept / 8) {  // many new candidates (a new view): O(heap) in one go
      std::make_heap(heap_.begin(), heap_.end(), below);
    } else {
      for (std::size_t i = kept; i < heap_.size(); ++i)
        std::push_heap(heap_.begin(), heap_.begin() + static_cast<std::ptrdiff_t>(i + 1), below);
    }
    const std::size_t forced = take_forced(f, out, limit);
    if (forced < limit) take_by_s(f, o, out, limit - forced);
  }

 private:
  struct entry {
    double pair_sum;
    std::uint32_t id;
  };
  // Heap order: larger pair sum first, ties by smaller id.
  static bool below(const entry& a, const entry& b) {
    if (a.pair_sum != b.pair_sum) return a.pair_sum < b.pair_sum;
    return a.id > b.id;
  }
  static bool visible_leaf(const refinement_frame& f, std::uint32_t t) {
    return f.mesh->is_leaf(t) && f.leaf_pixels[t] > 0;
  }

  // The forced leaves still visible, largest first (ties by id), up to limit. Returns how many.
  std::size_t take_forced(const refinement_frame& f, std::vector<std::uint32_t>& out, std::size_t limit) {
    forced_.erase(std::remove_if(forced_.begin(), forced_.end(), [&](std::uint32_t t) { return !visible_leaf(f, t); }),
                  forced_.end());
    std::sort(forced_.begin(), forced_.end(), [&](std::uint32_t a, std::uint32_t b) {
      return f.leaf_pixels[a] != f.leaf_pixels[b] ? f.leaf_pixels[a] > f.leaf_pixels[b] : a < b;
    });
    const std::size_t n = std::min(limit, forced_.size());
    out.insert(out.end(), forced_.begin(), forced_.begin() + static_cast<std::ptrdiff_t>(n));
    return n;
  }

  // Up to `need` leaves with S > S_req by (S, id): pops while S can still reach the cut; the
  // popped leaves not taken go back on the heap.
  void take_by_s(const refinement_frame& f, const criteria_options& o, std::vector<std::uint32_t>& out,
                 std::size_t need) {
    taken_.clear();
    while (!heap_.empty()) {
      const entry e = heap_.front();
      const bool stale = !visible_leaf(f, e.id);  // split since it was added
      const float s = stale ? 0.0f : nld_normalised(e.pair_sum, 3, f.l_max);
      if (!stale && (!(s > o.s_req) || (taken_.size() >= need && s != taken_.back().s))) break;
      std::pop_heap(heap_.begin(), heap_.end(), below);
      heap_.pop_back();
      if (!stale) taken_.push_back({s, e});
    }
    std::sort(taken_.begin(), taken_.end(),
              [](const scored& a, const scored& b) { return a.s != b.s ? a.s > b.s : a.e.id < b.e.id; });
    for (std::size_t i = 0; i < taken_.size(); ++i) {
      if (i < need) {
        out.push_back(taken_[i].e.id);
      } else {
        heap_.push_back(taken_[i].e);
        std::push_heap(heap_.begin(), heap_.end(), below);
      }
    }
  }

  struct scored {
    float s;
    entry e;
  };
  std::vector<std::uint32_t> pending_, forced_;
  std::vector<entry> heap_;
  std::vector<scored> taken_;
};

}  // namespace infolerp
