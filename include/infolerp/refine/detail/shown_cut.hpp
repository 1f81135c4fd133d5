#pragma once
// The shown set of progressive_refiner (refine/progressive_driver.hpp) and its deltas
// (Oliveira et al. §2's incremental add/delete protocol). A triangle is shown once its corners
// are shaded; a split one stays shown until its in-view children are ready, so the shown set is
// a non-overlapping cut of the hierarchy: walking down from a visible leaf's root, each ready
// triangle is shown and the walk goes on below it while it expands. A triangle's outcome depends
// on its ancestors alone, so after a change only the in-view subtrees under seed triangles (split
// leaves' parents, parents of triangles that got a corner delivered) are walked again, and the
// shown set follows per-triangle counts of the visible leaves showing it.
// Memory: about 30 bytes per triangle. Not thread-safe: one call at a time.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>
#include "infolerp/core/status.hpp"
#include "infolerp/refine/detail/id_set.hpp"
#include "infolerp/refine/detail/luminance_image.hpp"
#include "infolerp/refine/detail/shading_cache.hpp"
#include "infolerp/refine/refiner_types.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"

namespace infolerp::detail {

// What the cut reads of the rest of the refiner in one call.
struct cut_inputs {
  const subdivision_mesh& mesh;
  const shading_cache& cache;
  std::span<const std::uint32_t> in_view;  // per triangle: the view clock when it or a descendant is visible
  std::uint32_t clock;                     // the current view's
};

class shown_cut {
 public:
  void grow(std::size_t triangles, std::size_t vertices) {
    in_sent_.resize(triangles, 0);
    listed_.resize(triangles, 0);
    display_of_.resize(triangles, invalid_id);
    shown_count_.resize(triangles, 0);
    decided_.resize(triangles, 0);
    shown_mark_.resize(triangles, 0);
    decision_.resize(triangles);
    shown_.grow(triangles);
    waiter_head_.resize(vertices, invalid_id);
    waiter_clock_.resize(vertices, 0);
  }
  void reset() {
    in_sent_.clear();
    listed_.clear();
    changed_.clear();
    display_of_.clear();
    shown_count_.clear();
    waiters_.clear();
    waiter_head_.clear();
    waiter_clock_.clear();
    shown_.reset();
  }
  // A new view: Δ_total counts from zero, the waiting lists of the last view are dropped.
  void begin_view() {
    sent_total_ = 0;
    waiters_.clear();
  }

  // Triangle t of the view `clock` waits for vertex v (one list per vertex).
  void add_waiter(std::uint32_t v, std::uint32_t t, std::uint32_t clock) {
    if (waiter_clock_[v] != clock) waiter_clock_[v] = clock, waiter_head_[v] = invalid_id;
    waiters_.push_back({t, waiter_head_[v]});
    waiter_head_[v] = static_cast<std::uint32_t>(waiters_.size() - 1);
  }

  // The whole cut for the visible leaves (ascending). O(in-view triangles): each decided once.
  void rebuild(const cut_inputs& in, const id_set& visible, luminance_image& lum) {
    next_display_clock();
    merged_.clear();  // the new shown set: leaves shown themselves (ascending as visible is), then ancestors
    shown_above_.clear();
    for (std::uint32_t leaf : visible.sorted()) {
      path_.clear();
      std::uint32_t t = leaf;
      for (; t != invalid_id && decided_[t] != display_clock_; t = in.mesh.triangle(t).parent) path_.push_back(t);
      display_step above = t == invalid_id ? display_step{invalid_id, true} : decision_[t];
      for (auto it = path_.rbegin(); it != path_.rend(); ++it) {
        above = decide(in, *it, above);
        decided_[*it] = display_clock_;
        decision_[*it] = above;
      }
      if (display_of_[leaf] != above.shown) display_of_[leaf] = above.shown, lum.mark_dirty(leaf);
      if (above.shown == leaf) merged_.push_back(leaf);
      else if (above.shown != invalid_id && shown_mark_[above.shown] != display_clock_)
        shown_mark_[above.shown] = display_clock_, shown_above_.push_back(above.shown);
    }
    if (!shown_above_.empty()) {  // sorting only the ancestors: O(shown + ancestors · log)
      std::sort(shown_above_.begin(), shown_above_.end());
      scratch_.resize(merged_.size() + shown_above_.size());
      std::merge(merged_.begin(), merged_.end(), shown_above_.begin(), shown_above_.end(), scratch_.begin());
      merged_.swap(scratch_);
    }
    // Table 1's Δ_total: the triangles that entered the shown set (sent to the visualizer).
    std::size_t kept = 0;
    for (std::uint32_t t : merged_) kept += shown_.contains(t);
    sent_total_ += merged_.size() - kept;
    for (std::uint32_t t : shown_.unordered()) shown_count_[t] = 0, note_change(t);
    for (std::uint32_t t : merged_) note_change(t);
    shown_.assign(merged_);
    for (std::uint32_t leaf : visible.unordered())
      if (display_of_[leaf] != invalid_id) ++shown_count_[display_of_[leaf]];
  }

  // An update under seeds: begin_update(), then set_display() of leaves that left the visible
  // set, seed() / seed_waiters() for what changed, then finish_update(). O(seeded subtrees +
  // touched · 1); the same cut as rebuild().
  void begin_update() {
    next_display_clock();
    seeds_.clear();
    touched_.clear();
  }
  // The shown triangle over visible leaf `leaf` (invalid_id: none, or no longer a visible leaf).
  void set_display(std::uint32_t leaf, std::uint32_t shown, luminance_image& lum) {
    const std::uint32_t old = display_of_[leaf];
    if (old == shown) return;
    if (old != invalid_id) touch(old), --shown_count_[old];
    if (shown != invalid_id) touch(shown), ++shown_count_[shown];
    display_of_[leaf] = shown;
    lum.mark_dirty(leaf);
  }
  // The cut may change under t's parent (t itself when it is a root).
  void seed(const subdivision_mesh& mesh, std::uint32_t t) {
    const std::uint32_t parent = mesh.triangle(t).parent;
    seeds_.push_back(parent != invalid_id ? parent : t);
  }
  // A delivered vertex: the cut may change under the parents of the triangles waiting for it.
  void seed_waiters(const subdivision_mesh& mesh, std::uint32_t v, std::uint32_t clock) {
    if (waiter_clock_[v] != clock) return;
    for (std::uint32_t i = waiter_head_[v]; i != invalid_id; i = waiters_[i].next) seed(mesh, waiters_[i].triangle);
    waiter_head_[v] = invalid_id;
  }
  void finish_update(const cut_inputs& in, luminance_image& lum) {
    std::sort(seeds_.begin(), seeds_.end(), [&](std::uint32_t a, std::uint32_t b) {
      const auto la = in.mesh.triangle(a).level, lb = in.mesh.triangle(b).level;
      return la != lb ? la < lb : a < b;
    });
    for (std::uint32_t s : seeds_) {
      if (in.in_view[s] != in.clock || decided_[s] == display_clock_) continue;
      stack_.push_back(s);
      while (!stack_.empty()) {
        const std::uint32_t t = stack_.back();
        stack_.pop_back();
        decided_[t] = display_clock_;
        const subdivision_triangle& n = in.mesh.triangle(t);
        const display_step above = decide(in, t, n.parent == invalid_id ? display_step{invalid_id, true} : decision_[n.parent]);
        decision_[t] = above;
        if (n.is_leaf()) set_display(t, above.shown, lum);
        for (std::uint32_t c = n.first_child; c < n.first_child + n.child_count; ++c)
          if (in.in_view[c] == in.clock) stack_.push_back(c);
      }
    }
    std::size_t added = 0;
    for (const touched_triangle& x : touched_) {
      const bool now = shown_count_[x.triangle] > 0;
      if (now == x.was) continue;
      if (now) shown_.insert(x.triangle), ++added;
      else shown_.erase(x.triangle);
      note_change(x.triangle);
    }
    sent_total_ += added;
  }

  // The shown set's changes since the last delta, each list ascending; a triangle is newly
  // shaded when a corner was delivered in delta epoch `epoch`. O(c log c) for c changes.
  void take_delta(display_delta& out, const subdivision_mesh& mesh, const shading_cache& cache, std::uint32_t epoch) {
    out.clear();
    for (std::uint32_t t : changed_) {
      const bool now = shown_.contains(t), was = in_sent_[t] != 0;
      if (now && !was) (cache.delivered_in(mesh, t, epoch) ? out.newly_shaded : out.added_from_cache).push_back(t);
      if (!now && was) out.deleted.push_back(t);
      in_sent_[t] = now;
      listed_[t] = 0;
    }
    changed_.clear();
    std::sort(out.added_from_cache.begin(), out.added_from_cache.end());
    std::sort(out.deleted.begin(), out.deleted.end());
    std::sort(out.newly_shaded.begin(), out.newly_shaded.end());
  }

  // Triangle t is shown, or was at the last delta, or changed since.
  [[nodiscard]] bool holds(std::uint32_t t) const { return in_sent_[t] || listed_[t] || shown_.contains(t); }
  // Ids freed by the hierarchy: back to their initial values.
  void forget_triangle(std::uint32_t t) {
    in_sent_[t] = 0, listed_[t] = 0, display_of_[t] = invalid_id, shown_count_[t] = 0, decided_[t] = 0, shown_mark_[t] = 0;
    decision_[t] = display_step{};
  }
  void forget_vertex(std::uint32_t v) { waiter_head_[v] = invalid_id, waiter_clock_[v] = 0; }

  // The shown triangle over visible leaf `leaf`, invalid_id when none is.
  [[nodiscard]] std::uint32_t display_of(std::uint32_t leaf) const { return display_of_[leaf]; }
  [[nodiscard]] const id_set& shown() const noexcept { return shown_; }
  [[nodiscard]] std::size_t sent_total() const noexcept { return sent_total_; }
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    const auto b = [](const auto&... v) { return ((v.capacity() * sizeof(typename std::remove_cvref_t<decltype(v)>::value_type)) + ...); };
    return shown_.memory_bytes() + b(display_of_, decision_, decided_, shown_mark_, shown_above_, merged_, scratch_, shown_count_,
                                     waiters_, waiter_head_, waiter_clock_, touched_, seeds_, stack_, in_sent_, listed_, changed_, path_);
  }

 private:
  // The walk's outcome at a triangle: the triangle shown so far, and whether the walk goes on
  // below it.
  struct display_step {
    std::uint32_t shown = invalid_id;
    bool open = true;
  };
  struct waiter {
    std::uint32_t triangle, next;
  };
  struct touched_triangle {
    std::uint32_t triangle;
    bool was;  // shown before this update
  };

  // A shown split triangle gives way to its children once every child in view is ready.
  [[nodiscard]] static bool expands(const cut_inputs& in, std::uint32_t t) {
    const subdivision_triangle& n = in.mesh.triangle(t);
    for (std::uint32_t c = n.first_child; c < n.first_child + n.child_count; ++c)
      if (in.in_view[c] == in.clock && !in.cache.ready(in.mesh, c)) return false;
    return true;
  }
  // Triangle t's outcome from its parent's (`above`): the walk stops at a triangle not ready;
  // a ready one is shown and the walk goes on below it when it expands.
  [[nodiscard]] static display_step decide(const cut_inputs& in, std::uint32_t t, display_step above) {
    if (!above.open) return above;
    if (!in.cache.ready(in.mesh, t)) return {above.shown, false};
    return {t, !in.mesh.triangle(t).is_leaf() && expands(in, t)};
  }
  // A new stamp for decided_ and shown_mark_; on wrap-around both restart.
  void next_display_clock() {
    if (++display_clock_ != 0) return;
    std::fill(decided_.begin(), decided_.end(), 0u);
    std::fill(shown_mark_.begin(), shown_mark_.end(), 0u);
    display_clock_ = 1;
  }
  void touch(std::uint32_t t) {
    if (shown_mark_[t] == display_clock_) return;
    shown_mark_[t] = display_clock_;
    touched_.push_back({t, shown_count_[t] > 0});
  }
  // A triangle whose membership in the shown set may have changed since the last delta.
  void note_change(std::uint32_t t) {
    if (listed_[t]) return;
    listed_[t] = 1;
    changed_.push_back(t);
  }

  std::vector<std::uint32_t> display_of_;   // per visible leaf: the shown triangle over it
  std::vector<display_step> decision_;      // per triangle: the walk's outcome, stamped in decided_
  std::vector<std::uint32_t> decided_, shown_mark_;  // display_clock_ stamps: decided, touched or listed
  std::uint32_t display_clock_ = 0;
  std::vector<std::uint32_t> shown_above_, merged_, scratch_, path_;
  std::vector<std::uint32_t> shown_count_;  // per triangle: visible leaves showing it
  std::vector<waiter> waiters_;             // the current view's waiting lists
  std::vector<std::uint32_t> waiter_head_, waiter_clock_;  // per vertex: first waiter, its view's clock
  std::vector<touched_triangle> touched_;
  std::vector<std::uint32_t> seeds_, stack_;
  std::size_t sent_total_ = 0;              // triangles that entered the shown set since the view was set
  id_set shown_;                            // the shown set
  std::vector<std::uint8_t> in_sent_, listed_;  // per triangle: shown at the last delta; in changed_
  std::vector<std::uint32_t> changed_;      // triangles whose membership changed since the last delta
};

}  // namespace infolerp::detail
