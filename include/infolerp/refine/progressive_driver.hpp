#pragma once
// Progressive refinement along a walkthrough: Oliveira, Santos, Proença, "Refinement Criteria
// for High Fidelity Interactive Walkthroughs", §2 (the Shading Management Agent: visibility, an
// object-space shading cache, asynchronous shading, the incremental add/delete protocol), §4.1
// (refinement interrupted after every R selections) and §5 (Table 1: Δ, Δ_total, samples, time).
//
// Views: set_view() traces one primary ray per pixel (core/tracer.hpp); the hit's barycentrics
// locate the pixel in the subdivision hierarchy, so later (planar) splits re-locate pixels
// without tracing. Hierarchy and cache survive view changes; only leaves shown now are refined,
// requested or displayed. start() is a full restart.
// Cache: one colour per hierarchy vertex (object space, the paper's Lambertian restriction),
// 20 bytes per vertex plus 40 per hierarchy triangle. With max_cached_samples, vertices outside
// the view are evicted least recently visible first; the current view's are never evicted, and
// refinement stops (cache_full) once they alone reach the bound.
// Hierarchy: with max_hierarchy_triangles, a new view prunes (subdivision_mesh::coarsen) subtrees
// none of whose triangles is in view, shown or awaiting a delta and none of whose vertices is
// cached or requested, least recently in view first, down to bound − bound/8; ids are reused.
// Shading: each vertex of a shown leaf and of its ancestors is requested once; take_requests()
// hands out shading_points, deliver() takes colours for any subset in any order, from any thread
// or machine (calls on one refiner must not overlap). shade_requests() is the synchronous adaptor.
// A batch runs only when nothing is outstanding, so results are bit-identical for any executor
// and delivery order.
// L_max (§4): the largest luminance of the current image, recomputed before every selection;
// Rec. 709 luminance of the linear colour stands in for Drago et al.'s tone mapper (S is
// scale-free under it).
// Display: a triangle is shown once its corners are shaded; a split one stays shown until its
// children are ready, so the shown set is always a non-overlapping cut of the hierarchy.
// take_delta() gives the changes in the paper's order: added from the cache, deleted, newly shaded.
// Figures: stage 1 shades every visible leaf's vertices; stage 2 runs batches (criteria.hpp)
// until the criterion selects nothing, the budget is reached (checked per batch) or max_batches
// ran. Δ: triangles shown now; Δ_total: triangles sent to the visualizer since the view was set
// (those that entered the shown set; a new view sends only what the previous one did not show).
// Work: a batch touches the pixels of the leaves it split (each pixel is listed under its leaf),
// never the whole image, visible set or hierarchy: NLD_OS's candidates wait in a heap the splits
// update (nld_os_queue.hpp), sets change in O(1) per member, deltas, the shown cut, the luminance
// image and L_max follow what a batch split or a delivery made ready. A new view is O(pixels).
//
// The tracer models infolerp::tracer with the mesh's triangle ids; the synchronous callback
// glm::vec3 shade(const shading_point&) is called once per request, concurrently.
#include <algorithm>
#include <array>
#include <chrono>
#include <concepts>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/refine/criteria.hpp"
#include "infolerp/refine/nld.hpp"
#include "infolerp/refine/nld_os_queue.hpp"
#include "infolerp/refine/pinhole_camera.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"

namespace infolerp {

// What the shading callback gets for one vertex.
struct shading_point {
  std::uint32_t vertex = invalid_id;     // vertex id in the subdivision mesh
  glm::vec3 position{0.0f};              // its world position
  glm::vec3 normal{0.0f};                // unit geometric normal of `triangle`
  std::uint32_t triangle = invalid_id;   // an original triangle it lies in
  glm::vec2 barycentric{0.0f};           // Embree-style (u, v) of the position in that triangle
};

struct stage_figures {
  std::size_t triangles = 0;           // Δ: leaves shown
  std::size_t triangles_total = 0;     // Δ_total: triangles sent to the visualizer since the view was set (Table 1)
  std::size_t triangles_produced = 0;  // every triangle the hierarchy holds
  std::size_t shading_samples = 0;     // vertices shaded so far
  double seconds = 0.0;                // wall time since the run started
};

struct refinement_report {
  stage_figures stage1, stage2;
  std::size_t batches = 0;      // batches of R run in stage 2
  std::size_t selections = 0;   // triangles the criterion selected
  bool budget_reached = false;  // stage 2 stopped on the shading budget or max_batches
};

struct driver_options {
  criteria_options criteria{};                                              // which criterion and its settings
  std::size_t max_shading_samples = std::numeric_limits<std::size_t>::max();  // stop once this many vertices are shaded
  std::size_t max_batches = std::numeric_limits<std::size_t>::max();          // stop after this many batches
  std::size_t max_cached_samples = std::numeric_limits<std::size_t>::max();  // cache bound (>= 1), see the prologue
  std::size_t max_hierarchy_triangles = std::numeric_limits<std::size_t>::max();  // hierarchy bound (>= 1), see the prologue
  glm::vec3 background{0.0f};                                              // colour of pixels without a hit or shown triangle
  std::size_t grain = 4096;                                                // executor grain (pixels, vertices)
};

// What one call of refine() did.
enum class refine_progress : std::uint8_t {
  refined,     // selected and split at least one batch; new requests may be waiting
  waiting,     // requests are outstanding: deliver them first
  finished,    // the criterion selects nothing more in this view
  cache_full,  // the cache holds max_cached_samples: no further refinement in this view
};

// How much one refine() call may do (§4.1: control returns to the caller after R selections).
struct refine_budget {
  std::size_t batches = 1;                                         // batches of R selections
  std::size_t samples = std::numeric_limits<std::size_t>::max();   // shading samples to request
  double seconds = std::numeric_limits<double>::infinity();        // wall time, checked between batches
};

// The incremental protocol of §2: how the shown set changed, in the paper's order.
struct display_delta {
  std::vector<std::uint32_t> added_from_cache;  // shown now, every corner shaded before the last delta
  std::vector<std::uint32_t> deleted;           // shown at the last delta, not now
  std::vector<std::uint32_t> newly_shaded;      // shown now, a corner delivered since the last delta
  void clear() {
    added_from_cache.clear();
    deleted.clear();
    newly_shaded.clear();
  }
};

// A set of triangle ids with O(1) insert and erase (the last id moves into the gap) and an
// ascending view sorted on demand. Per-id positions: 4 bytes per triangle.
class id_set {
 public:
  void grow(std::size_t n) { pos_.resize(n, invalid_id); }
  void reset() { ids_.clear(), pos_.clear(), sorted_ = true; }
  // Replaces the contents with `ascending` (sorted, distinct). O(old size + new size).
  void assign(std::span<const std::uint32_t> ascending) {
    for (std::uint32_t t : ids_) pos_[t] = invalid_id;
    ids_.assign(ascending.begin(), ascending.end());
    for (std::size_t i = 0; i < ids_.size(); ++i) pos_[ids_[i]] = static_cast<std::uint32_t>(i);
    sorted_ = true;
  }
  [[nodiscard]] bool contains(std::uint32_t t) const { return t < pos_.size() && pos_[t] != invalid_id; }
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
    pos_[t] = invalid_id;
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

// Not thread-safe: one call at a time per object (each call runs in parallel through the
// executor). Accessors below are O(1) and allocate nothing, but visible_leaves() and
// shown_triangles() sort in place on their first call after a change.
class progressive_refiner {
 public:
  // Largest image a view may have (width · height): 2^25 pixels (8192 x 4096, above 8K UHD);
  // the agent keeps about 60 bytes per pixel, so a view stays under 2 GB.
  static constexpr std::size_t max_view_pixels = std::size_t{1} << 25;

  // Takes over a subdivision mesh (possibly already tessellated, §4.1 of the clustering paper);
  // start() returns to it, so a copy is kept. Errors: options out of range (names the member).
  // O(mesh) for the copy.
  static result<progressive_refiner> create(subdivision_mesh mesh, driver_options options = {}) {
    if (auto st = validate(options.criteria); !st) return st;
    if (options.grain == 0) return make_error(errc::bad_parameter, no_element, "driver_options.grain must be >= 1");
    if (options.max_cached_samples == 0)
      return make_error(errc::bad_parameter, no_element, "driver_options.max_cached_samples must be >= 1");
    if (options.max_hierarchy_triangles == 0)
      return make_error(errc::bad_parameter, no_element, "driver_options.max_hierarchy_triangles must be >= 1");
    progressive_refiner r;
    r.initial_mesh_ = mesh;
    r.mesh_ = std::move(mesh);
    r.options_ = options;
    r.state_.rng = splitmix64{options.criteria.seed};
    r.index_green_splits();
    return r;
  }

  // Full restart, then stage 1 in one call: set_view() on the mesh given to create() with an
  // empty cache, and the requests shaded synchronously (shade_requests). Camera: any type with
  // width, height and primary_ray(x, y) -> ray (checked further when it has eye/target/up).
  // Errors: those of set_view(); on error the refiner is unchanged.
  // Complexity O(pixels · (trace + level)); allocation O(pixels + triangles + vertices).
  template <class T, class Camera, class Shade, class E>
  status start(const T& tracer, const Camera& camera, Shade&& shade, E&& exec) {
    static_assert(check_shade<Shade>());
    if (auto st = start(tracer, camera, exec); !st) return st;
    shade_requests(shade, exec);
    record_stage1();
    return {};
  }

  // Full restart with asynchronous shading: as start() above, but stage 1's requests are left
  // outstanding for take_requests()/deliver(). Errors: those of set_view(); on error the
  // refiner is unchanged.
  template <class T, class Camera, class E>
  status start(const T& tracer, const Camera& camera, E&& exec) {
    return view(tracer, camera, exec, true);
  }

  // A new view: visibility recomputed, hierarchy and cache kept, requests issued for the newly
  // visible unshaded vertices, the criterion's per-view state (RND's draws) and the report
  // restarted. May be called at any time, with requests outstanding (they stay valid).
  // Errors: an empty image or one of more than max_view_pixels; a camera with non-finite eye/target/up, eye == target, up parallel
  // to the view direction or a field of view outside (0, 180); a hit naming a triangle the
  // mesh does not have or with a non-finite distance or barycentric (names the pixel). On error
  // the refiner is unchanged. Complexity O(pixels · (trace + level) + visible · level), not
  // the hierarchy's size; allocation O(pixels), per-triangle arrays grow with the hierarchy.
  template <class T, class Camera, class E = serial_executor>
  status set_view(const T& tracer, const Camera& camera, E&& exec = E{}) {
    return view(tracer, camera, exec, false);
  }

  // Appends up to max_count outstanding requests, oldest first, and hands them out (each is
  // handed out once). Returns how many. O(returned); allocation: growth of out.
  std::size_t take_requests(std::vector<shading_point>& out,
                            std::size_t max_count = std::numeric_limits<std::size_t>::max()) {
    const std::size_t n = std::min(max_count, to_issue_.size() - issued_);
    for (std::size_t i = 0; i < n; ++i) out.push_back(point_of(to_issue_[issued_ + i]));
    issued_ += n;
    if (issued_ == to_issue_.size()) to_issue_.clear(), issued_ = 0;
    return n;
  }
  // Requests not yet delivered (handed out or not).
  [[nodiscard]] std::size_t outstanding_requests() const noexcept { return outstanding_; }

  // Accepts the colours of requested vertices, in any order and any grouping. Errors: sizes
  // differ; a vertex out of range, never requested, already delivered, or named twice; a
  // non-finite colour (names the entry). On error nothing is stored.
  // Complexity O(n + the in-view subtrees under the parents of the triangles waiting for these
  // vertices) (the shown set is brought up to date), plus O(V) when
  // the cache bound evicts (once per bound/8 deliveries); allocation: the eviction's candidates.
  status deliver(std::span<const std::uint32_t> vertices, std::span<const glm::vec3> colours) {
    if (vertices.size() != colours.size())
      return make_error(errc::bad_size, no_element, "deliver: ", vertices.size(), " vertices but ", colours.size(), " colours");
    std::size_t bad = no_index;
    bool named_twice = false;
    for (std::size_t i = 0; i < vertices.size() && bad == no_index; ++i) {
      const std::uint32_t v = vertices[i];
      if (v >= vstate_.size() || vstate_[v] != requested) bad = i, named_twice = v < vstate_.size() && vstate_[v] == delivering;
      else vstate_[v] = delivering;
    }
    for (std::size_t i = 0; i < vertices.size(); ++i)  // undo the marks (duplicates stay detectable above)
      if (vertices[i] < vstate_.size() && vstate_[vertices[i]] == delivering) vstate_[vertices[i]] = requested;
    if (bad != no_index) {
      const std::uint32_t v = vertices[bad];
      if (v >= vstate_.size())
        return make_error(errc::index_out_of_range, bad, "deliver: entry ", bad, ": vertex ", v, " out of range (",
                          vstate_.size(), " vertices)");
      if (named_twice)
        return make_error(errc::bad_parameter, bad, "deliver: entry ", bad, ": vertex ", v, " is named twice (first at entry ",
                          std::find(vertices.begin(), vertices.end(), v) - vertices.begin(), ")");
      return make_error(errc::bad_parameter, bad, "deliver: entry ", bad, ": vertex ", v,
                        vstate_[v] == shaded ? " was already delivered" : " has no outstanding request");
    }
    for (std::size_t i = 0; i < colours.size(); ++i)
      if (!std::isfinite(colours[i].x) || !std::isfinite(colours[i].y) || !std::isfinite(colours[i].z))
        return make_error(errc::non_finite, i, "deliver: entry ", i, ": colour of vertex ", vertices[i], " is not finite");
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      const std::uint32_t v = vertices[i];
      vstate_[v] = shaded;
      colour_[v] = colours[i];
      luminance_[v] = luminance(colours[i]);
      delivered_epoch_[v] = delta_epoch_;
    }
    outstanding_ -= vertices.size();
    samples_ += vertices.size();
    shaded_count_ += vertices.size();
    enforce_cache_bound();
    begin_display_update();
    for (std::uint32_t v : vertices) seed_waiters(v);
    finish_display_update();
    return {};
  }

  // Synchronous adaptor: hands out every outstanding request, shades it with
  // glm::vec3 shade(const shading_point&) on the executor and delivers the results.
  // Returns the number shaded. Allocation: the requests and colours.
  template <class Shade, class E>
  std::size_t shade_requests(Shade&& shade, E&& exec) {
    static_assert(check_shade<Shade>());
    static_assert(check_executor<std::remove_cvref_t<E>>());
    std::vector<shading_point> points;
    take_requests(points);
    std::vector<std::uint32_t> ids(points.size());
    std::vector<glm::vec3> colours(points.size());
    exec.parallel_for(points.size(), 256, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        ids[i] = points[i].vertex;
        colours[i] = shade(static_cast<const shading_point&>(points[i]));
      }
    });
    [[maybe_unused]] const status st = deliver(ids, colours);
    INFOLERP_ASSERT(st.ok() || points.empty());
    return points.size();
  }

  // Interruptible refinement (§4.1): up to budget.batches batches of R selections in the
  // current view, each split and followed by requests for the new visible vertices. A batch
  // needs every earlier request delivered, so without a renderer behind the call (this
  // overload) one batch runs and the next call returns `waiting` until deliveries arrive.
  // Preconditions: a view was set. Complexity per batch: the criterion's selection (NLD_OS:
  // nld_os_queue.hpp; NLD_IS and RND: criteria.hpp) + O(R) splits + O(new triangles · log)
  // (finding the split leaves) + O(pixels of the split leaves · level) for the re-location +
  // O(subtrees under the split leaves' parents) for the shown cut + O(pixels whose shown
  // triangle changed + max-tree nodes that changed); the view's first batch also builds its
  // luminance image, O(pixels).
  template <class E = serial_executor>
  refine_progress refine(refine_budget budget = {}, E&& exec = E{}) {
    return refine_impl(exec, budget, [](auto&) {});
  }
  // As above with a synchronous renderer: each batch's requests are shaded at once, so the
  // budget's batches, samples and seconds all apply.
  template <class Shade, class E = serial_executor>
  refine_progress refine(Shade&& shade, refine_budget budget = {}, E&& exec = E{}) {
    static_assert(check_shade<Shade>());
    return refine_impl(exec, budget, [&](E& ex) { shade_requests(shade, ex); });
  }

  // One batch of stage 2 with the synchronous renderer. Returns false when nothing was
  // selected, the shading budget is reached, max_batches ran or the cache is full (then stage
  // 2's figures are final). Preconditions: start() or set_view() succeeded.
  template <class Shade, class E = serial_executor>
  bool refine_batch(Shade&& shade, E&& exec = E{}) {
    if (done()) {
      report_.budget_reached = !finished_;
      return false;
    }
    const refine_progress p = refine(shade, refine_budget{.batches = 1}, exec);
    if (p != refine_progress::refined) {
      report_.budget_reached = p == refine_progress::cache_full;
      return false;
    }
    if (done()) {
      report_.budget_reached = true;
      return false;
    }
    return true;
  }

  // start() then batches until done. Returns the Table 1 figures. Errors, complexity and
  // allocation: those of start() plus every refine_batch().
  template <class T, class Camera, class Shade, class E = serial_executor>
  result<refinement_report> run(const T& tracer, const Camera& camera, Shade&& shade, E&& exec = E{}) {
    if (auto st = start(tracer, camera, shade, exec); !st) return st;
    while (refine_batch(shade, exec)) {
    }
    return report_;
  }

  // Moves the shown set forward and reports the change (§2's incremental protocol), each list
  // ascending. Replaying every delta into a set reproduces shown_triangles(). O(c log c) for the
  // c triangles whose membership changed since the last delta; allocation: growth of out.
  void take_delta(display_delta& out) {
    out.clear();
    for (std::uint32_t t : changed_) {
      const bool now = shown_.contains(t), was = in_sent_[t] != 0;
      if (now && !was) (newly_delivered(t) ? out.newly_shaded : out.added_from_cache).push_back(t);
      if (!now && was) out.deleted.push_back(t);
      in_sent_[t] = now;
      listed_[t] = 0;
    }
    changed_.clear();
    std::sort(out.added_from_cache.begin(), out.added_from_cache.end());
    std::sort(out.deleted.begin(), out.deleted.end());
    std::sort(out.newly_shaded.begin(), out.newly_shaded.end());
    ++delta_epoch_;
  }

  // Bounds the cache (see the prologue). Errors: a bound of 0; then nothing changes.
  status set_cache_bound(std::size_t max_cached_samples) {
    if (max_cached_samples == 0) return make_error(errc::bad_parameter, no_element, "cache bound must be >= 1");
    options_.max_cached_samples = max_cached_samples;
    enforce_cache_bound();
    return {};
  }

  // Bounds the hierarchy (see the prologue), applied at the next view. Errors: a bound of 0;
  // then nothing changes.
  status set_hierarchy_bound(std::size_t max_hierarchy_triangles) {
    if (max_hierarchy_triangles == 0) return make_error(errc::bad_parameter, no_element, "hierarchy bound must be >= 1");
    options_.max_hierarchy_triangles = max_hierarchy_triangles;
    prune_retry_ = 0;
    return {};
  }

  // The current image: per pixel the colours of the shown triangle over it interpolated (each
  // channel kept within its corners' range, so inside the range of what was delivered), or the
  // background. Preconditions: image.size() == width·height, a view was set. O(pixels), no
  // allocation.
  void reconstruct(std::span<glm::vec3> image) const {
    for (std::size_t p = 0; p < pixel_leaf_.size() && p < image.size(); ++p) image[p] = pixel_colour(p);
  }

  [[nodiscard]] const refinement_report& report() const noexcept { return report_; }
  [[nodiscard]] const subdivision_mesh& mesh() const noexcept { return mesh_; }
  [[nodiscard]] std::span<const std::uint32_t> pixel_leaves() const noexcept { return pixel_leaf_; }
  // The visible leaves (ascending; sorted on the first call after a batch changed them).
  [[nodiscard]] std::span<const std::uint32_t> visible_leaves() const { return visible_.sorted(); }
  [[nodiscard]] std::span<const std::uint32_t> leaf_pixels() const noexcept { return leaf_pixels_; }
  // The triangles the criterion selected in the last batch.
  [[nodiscard]] std::span<const std::uint32_t> last_selection() const noexcept { return selected_; }
  // The shown set (ascending; sorted on the first call after it changed): equals
  // visible_leaves() once every request is delivered.
  [[nodiscard]] std::span<const std::uint32_t> shown_triangles() const { return shown_.sorted(); }
  // Shaded colour of a vertex (meaningful when vertex_shaded(v)).
  [[nodiscard]] glm::vec3 vertex_colour(std::size_t v) const { return colour_[v]; }
  [[nodiscard]] bool vertex_shaded(std::size_t v) const { return v < vstate_.size() && vstate_[v] == shaded; }
  // Shaded values held now, and samples delivered since start() (evicted ones shaded again count twice).
  [[nodiscard]] std::size_t cached_samples() const noexcept { return shaded_count_; }
  [[nodiscard]] std::size_t samples_delivered() const noexcept { return samples_; }
  // Bytes the refiner holds: the hierarchy (and the copy start() returns to), the cache and the
  // per-triangle, per-vertex and per-view buffers, by capacity. O(1).
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    const auto b = [](const auto&... v) { return ((v.capacity() * sizeof(typename std::remove_cvref_t<decltype(v)>::value_type)) + ...); };
    return initial_mesh_.memory_bytes() + mesh_.memory_bytes() + nld_os_.memory_bytes() + visible_.memory_bytes() +
           shown_.memory_bytes() +
           b(pixel_leaf_, pixel_weights_, leaf_pixels_, in_view_, display_of_, decision_, decided_, shown_mark_, leaf_head_,
             pixel_next_, fresh_, split_, green_first_, lum_tree_, tree_level_, tree_next_, dirty_, dirty_mark_, shown_above_,
             merged_, scratch_, shown_count_, waiters_, waiter_head_, waiter_clock_, touched_, seeds_, stack_, vstate_,
             colour_, luminance_, last_seen_, delivered_epoch_, to_issue_, in_sent_, listed_, changed_, path_, evict_,
             selected_, freed_triangles_, freed_vertices_);
  }
  // The frame the criteria see (pixel luminances filled only for NLD_IS).
  [[nodiscard]] refinement_frame frame() const {
    refinement_frame f;
    f.width = width_;
    f.height = height_;
    f.mesh = &mesh_;
    f.pixel_leaf = pixel_leaf_;
    const std::size_t n = pixel_leaf_.size();  // the max-tree's leaves are the pixel luminances
    if (lum_tree_.size() == 2 * n) f.pixel_luminance = std::span<const float>(lum_tree_).subspan(n);
    f.leaf_pixels = leaf_pixels_;
    f.visible = visible_.unordered();
    f.vertex_luminance = luminance_;
    f.l_max = l_max_;
    f.view_samples = view_requests_;
    f.projection = has_projection_ ? &projection_ : nullptr;
    return f;
  }

 private:
  static constexpr std::size_t primary_block = 256;  // primary rays made and traced together
  enum : std::uint8_t { unshaded = 0, requested = 1, shaded = 2, delivering = 3 };
  static constexpr std::size_t no_index = std::numeric_limits<std::size_t>::max();

  template <class Shade>
  static constexpr bool check_shade() {
    static_assert(std::is_invocable_r_v<glm::vec3, Shade&, const shading_point&>,
                  "infolerp: shading callback needs `glm::vec3 shade(const infolerp::shading_point&)`");
    return true;
  }

  template <class Camera>
  static status check_camera(const Camera& camera) {
    const std::uint32_t width = camera.width, height = camera.height;
    const std::uint64_t pixels = std::uint64_t(width) * height;
    if (pixels == 0) return make_error(errc::empty_input, no_element, "camera image is ", width, "x", height);
    if (pixels > max_view_pixels)
      return make_error(errc::bad_parameter, no_element, "camera image ", width, "x", height, " has ", pixels,
                        " pixels, more than max_view_pixels (", max_view_pixels, ")");
    if constexpr (requires { camera.eye; camera.target; camera.up; camera.vertical_fov_degrees; }) {
      const glm::vec3 e = camera.eye, t = camera.target, u = camera.up;
      if (!all_finite(e) || !all_finite(t) || !all_finite(u))
        return make_error(errc::non_finite, no_element, "camera eye, target or up is not finite");
      if (e == t) return make_error(errc::bad_parameter, no_element, "camera eye equals target: no view direction");
      const glm::vec3 f = pinhole_camera::forward(e, t);
      if (f == glm::vec3(0.0f))
        return make_error(errc::bad_parameter, no_element, "camera eye and target are too far apart: target - eye overflows float");
      if (!(glm::length(glm::cross(f, pinhole_camera::unit(u))) > 1e-6f))
        return make_error(errc::bad_parameter, no_element, "camera up is zero or parallel to the view direction");
      const float fov = camera.vertical_fov_degrees;
      if (!(fov > 0.0f && fov < 180.0f))
        return make_error(errc::bad_parameter, no_element, "camera vertical_fov_degrees ", fov, " outside (0, 180)");
    }
    return {};
  }

  // The rays a camera makes: its frame computed once (pinhole_camera::frame()) when it has one,
  // else the camera itself.
  template <class Camera>
  static decltype(auto) rays_of(const Camera& camera) {
    if constexpr (requires { camera.frame(); }) return camera.frame();
    else return (camera);
  }

  // Traces and checks the view; only then (optionally) restarts and takes the view.
  template <class T, class Camera, class E>
  status view(const T& tracer, const Camera& camera, E&& exec, bool restart) {
    const auto began = std::chrono::steady_clock::now();
    std::vector<hit> hits;
    if (auto st = trace_view(tracer, camera, exec, hits); !st) return st;
    if (restart) reset();
    apply_view(camera, hits, exec, began);
    return {};
  }

  // Traces and checks a view without changing any state.
  template <class T, class Camera, class E>
  status trace_view(const T& tracer, const Camera& camera, E&& exec, std::vector<hit>& hits) const {
    static_assert(check_tracer<T>());
    static_assert(check_executor<std::remove_cvref_t<E>>());
    if (auto st = check_camera(camera); !st) return st;
    const std::uint32_t width = camera.width;
    const std::size_t n = std::size_t(width) * camera.height;
    hits.resize(n);
    for_each_chunk(exec, n, options_.grain, [&](std::size_t, std::size_t begin, std::size_t end) {
      std::array<ray, primary_block> rays;  // on the stack: no allocation per chunk
      const auto& cam = rays_of(camera);
      for (std::size_t b = begin; b < end; b += primary_block) {
        const std::size_t m = std::min(primary_block, end - b);
        for (std::size_t i = 0; i < m; ++i)
          rays[i] = cam.primary_ray(static_cast<std::uint32_t>((b + i) % width), static_cast<std::uint32_t>((b + i) / width));
        trace_intersect(tracer, std::span<const ray>(rays.data(), m), std::span<hit>(hits.data() + b, m));
      }
    });
    for (std::size_t p = 0; p < n; ++p) {
      const hit& h = hits[p];
      if (!h.valid()) continue;
      if (h.triangle >= mesh_.original_triangle_count())
        return make_error(errc::index_out_of_range, p, "pixel ", p, ": hit triangle ", h.triangle,
                          " is not in the mesh (", mesh_.original_triangle_count(), " triangles)");
      if (!std::isfinite(h.distance) || !std::isfinite(h.barycentric.x) || !std::isfinite(h.barycentric.y))
        return make_error(errc::non_finite, p, "pixel ", p, ": hit on triangle ", h.triangle,
                          " has a non-finite distance or barycentric");
      if (!h.barycentric_inside())
        return make_error(errc::bad_parameter, p, "pixel ", p, ": hit on triangle ", h.triangle, " has barycentric (",
                          h.barycentric.x, ", ", h.barycentric.y, ") outside the triangle");
    }
    return {};
  }

  void reset() {
    mesh_ = initial_mesh_;
    index_green_splits();
    selected_.clear();
    state_ = criterion_state{};
    state_.rng = splitmix64{options_.criteria.seed};
    lum_tree_.clear();
    in_view_.clear();
    visible_.reset();
    in_sent_.clear();
    listed_.clear();
    changed_.clear();
    leaf_pixels_.clear();
    leaf_head_.clear();
    display_of_.clear();
    dirty_.clear();
    dirty_mark_.clear();
    dirty_clock_ = 1;
    shown_count_.clear();
    waiters_.clear();
    waiter_head_.clear();
    waiter_clock_.clear();
    vstate_.clear();
    colour_.clear();
    luminance_.clear();
    last_seen_.clear();
    delivered_epoch_.clear();
    to_issue_.clear();
    issued_ = 0;
    outstanding_ = 0;
    shaded_count_ = 0;
    in_view_vertices_ = 0;
    samples_ = 0;
    l_max_ = 0.0f;
    clock_ = 0;
    view_requests_ = 0;
    delta_epoch_ = 0;
    prune_retry_ = 0;
    shown_.reset();
  }

  template <class Camera, class E>
  void apply_view(const Camera& camera, const std::vector<hit>& hits, E&& exec,
                  std::chrono::steady_clock::time_point began) {
    started_ = began;
    if constexpr (requires { { camera.frame() } -> std::convertible_to<pinhole_frame>; }) projection_ = camera.frame(), has_projection_ = true;
    else has_projection_ = false;
    width_ = camera.width;
    height_ = camera.height;
    finished_ = false;
    stage1_recorded_ = false;
    view_requests_ = 0;
    state_.points_drawn = 0;
    state_.exhausted = false;
    report_ = {};
    sent_total_ = 0;
    view_leaves(hits, exec);
  }

  [[nodiscard]] bool done() const {
    return finished_ || report_.stage2.shading_samples >= options_.max_shading_samples ||
           report_.batches >= options_.max_batches || cache_full();
  }

  void record_stage1() {
    if (stage1_recorded_) return;
    stage1_recorded_ = true;
    report_.stage1 = figures();
    report_.stage2 = report_.stage1;
  }

  template <class E, class Render>
  refine_progress refine_impl(E& exec, refine_budget budget, Render&& render) {
    const auto began = std::chrono::steady_clock::now();
    const std::size_t samples_before = samples_ + outstanding_;
    // Stops early return the reason unless a batch ran in this call (the next call reports it).
    for (std::size_t b = 0; b < budget.batches; ++b) {
      if (b > 0 && (samples_ + outstanding_ - samples_before >= budget.samples ||
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count() >= budget.seconds))
        break;
      if (outstanding_ > 0) return b == 0 ? refine_progress::waiting : refine_progress::refined;
      record_stage1();
      if (finished_) return b == 0 ? refine_progress::finished : refine_progress::refined;
      if (cache_full()) return b == 0 ? refine_progress::cache_full : refine_progress::refined;
      luminance_image(exec);  // also L_max
      selected_.clear();
      const refinement_frame f = frame();
      select_for_refinement(f, options_.criteria, state_, selected_, [&](std::vector<std::uint32_t>& ids, std::size_t limit) {
        nld_os_.select(f, options_.criteria, ids, limit);
      });
      if (selected_.empty()) {
        finished_ = true;
        report_.stage2 = figures();
        return b == 0 ? refine_progress::finished : refine_progress::refined;
      }
      [[maybe_unused]] const status st = mesh_.split(selected_);  // in order, as split(t) one by one
      INFOLERP_ASSERT(st.ok());
      ++report_.batches;
      report_.selections += selected_.size();
      follow_splits();
      render(exec);
      report_.stage2 = figures();
    }
    return refine_progress::refined;
  }

  [[nodiscard]] glm::vec3 pixel_colour(std::size_t p) const {
    const std::uint32_t leaf = pixel_leaf_[p];
    if (leaf == invalid_id) return options_.background;
    const std::uint32_t d = display_of_[leaf];
    if (d == invalid_id) return options_.background;
    const glm::uvec3 v = mesh_.triangle(d).vertices;
    const glm::vec3 w = d == leaf ? pixel_weights_[p] : weights_in(d, leaf, pixel_weights_[p]);
    const glm::vec3 a = colour_[v.x], b = colour_[v.y], c = colour_[v.z];
    // Inside the corners' range, as exact interpolation is: the stored weights' rounding (a few
    // ulps per re-location) must not carry a pixel past what was delivered.
    return glm::clamp(w.x * a + w.y * b + w.z * c, glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c)));
  }
  // The barycentric weights in ancestor a of the point with weights w in leaf l (planar).
  [[nodiscard]] glm::vec3 weights_in(std::uint32_t a, std::uint32_t l, glm::vec3 w) const {
    const glm::uvec3 lv = mesh_.triangle(l).vertices, av = mesh_.triangle(a).vertices;
    const glm::dvec3 p = double(w.x) * glm::dvec3(mesh_.position(lv.x)) + double(w.y) * glm::dvec3(mesh_.position(lv.y)) +
                         double(w.z) * glm::dvec3(mesh_.position(lv.z));
    const glm::dvec3 b = barycentric(av, p);
    return glm::vec3(b);
  }
  [[nodiscard]] glm::dvec3 barycentric(glm::uvec3 t, glm::dvec3 p) const {
    const glm::dvec3 a(mesh_.position(t.x)), b(mesh_.position(t.y)), c(mesh_.position(t.z));
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double nn = glm::dot(n, n);
    const double u = glm::dot(glm::cross(p - a, c - a), n) / nn, v = glm::dot(glm::cross(b - a, p - a), n) / nn;
    return {1.0 - u - v, u, v};
  }

  [[nodiscard]] stage_figures figures() const {
    stage_figures s;
    s.triangles = visible_.size();
    s.triangles_total = sent_total_;
    s.triangles_produced = mesh_.triangle_count();
    s.shading_samples = samples_;
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    return s;
  }

  void grow() {
    const std::size_t nt = mesh_.triangle_count(), nv = mesh_.vertex_count();
    leaf_pixels_.resize(nt, 0);
    leaf_head_.resize(nt, invalid_id);
    green_first_.resize(nt, invalid_id);
    visible_.grow(nt);
    shown_.grow(nt);
    in_sent_.resize(nt, 0);
    listed_.resize(nt, 0);
    in_view_.resize(nt, 0);
    display_of_.resize(nt, invalid_id);
    dirty_mark_.resize(nt, 0);
    shown_count_.resize(nt, 0);
    decided_.resize(nt, 0);
    shown_mark_.resize(nt, 0);
    decision_.resize(nt);
    waiter_head_.resize(nv, invalid_id);
    waiter_clock_.resize(nv, 0);
    vstate_.resize(nv, unshaded);
    colour_.resize(nv, glm::vec3(0.0f));
    luminance_.resize(nv, 0.0f);
    last_seen_.resize(nv, 0);
    delivered_epoch_.resize(nv, 0);
  }

  // Puts pixel p on its leaf's list; a leaf's first pixel makes it visible (fresh_).
  void add_pixel(std::uint32_t p, std::uint32_t leaf) {
    pixel_next_[p] = leaf_head_[leaf];
    leaf_head_[leaf] = p;
    if (leaf_pixels_[leaf]++ == 0) fresh_.push_back(leaf);
  }

  // A new view: every pixel is located from its hit's original triangle and listed under its
  // leaf; the previous view's lists are dropped through its visible leaves, so the hierarchy
  // outside both views costs nothing. O(pixels · level + previous visible).
  template <class E>
  void view_leaves(const std::vector<hit>& hits, E&& exec) {
    for (std::uint32_t t : visible_.unordered()) leaf_pixels_[t] = 0, leaf_head_[t] = invalid_id;
    const std::size_t n = hits.size();
    pixel_leaf_.resize(n);
    pixel_weights_.resize(n);
    exec.parallel_for(n, options_.grain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t p = begin; p < end; ++p) {
        const hit& h = hits[p];
        point_location loc;  // a miss: no leaf
        const glm::vec2 b = h.barycentric;
        if (h.valid()) loc = mesh_.locate_from(h.triangle, glm::vec3(1.0f - b.x - b.y, b.x, b.y));  // a leaf returns at once
        pixel_leaf_[p] = loc.leaf;
        pixel_weights_[p] = loc.weights;
      }
    });
    grow();
    pixel_next_.resize(n);
    fresh_.clear();
    for (std::size_t p = 0; p < n; ++p)
      if (pixel_leaf_[p] != invalid_id) add_pixel(static_cast<std::uint32_t>(p), pixel_leaf_[p]);
    std::sort(fresh_.begin(), fresh_.end());
    visible_.assign(fresh_);
    nld_os_.clear();
    if (options_.criteria.criterion == refinement_criterion::nld_os)
      for (std::uint32_t t : fresh_) nld_os_.add(t);
    ++clock_;
    in_view_vertices_ = 0;
    all_dirty_ = true;
    waiters_.clear();
    stamp_in_view(fresh_);
    enforce_cache_bound();
    update_display();
    prune_hierarchy();
  }

  // The hierarchy bound (see the prologue): the largest subtrees outside the view (split
  // triangles out of view whose parent is in view, or roots), least recently in view first
  // (ties by id), each collapsed with what its split edges tie it to when nothing it holds is
  // in view, shown, awaiting a delta, cached or requested. O(triangles · log) per call that
  // prunes, once per bound/8 growth: a call that cannot reach bound − bound/8 (what is left is
  // in view or cached) waits until the hierarchy grew by bound/8 more.
  void prune_hierarchy() {
    const std::size_t bound = options_.max_hierarchy_triangles;
    if (mesh_.live_triangle_count() <= bound || mesh_.live_triangle_count() < prune_retry_) return;
    const std::size_t target = bound - bound / 8;
    evict_.clear();
    for (std::uint32_t t = 0; t < mesh_.triangle_count(); ++t) {
      const subdivision_triangle& n = mesh_.triangle(t);
      if (n.child_count == 0 || n.retired || in_view_[t] == clock_) continue;
      if (n.parent == invalid_id || in_view_[n.parent] == clock_) evict_.push_back(t);
    }
    std::sort(evict_.begin(), evict_.end(),
              [&](std::uint32_t a, std::uint32_t b) { return in_view_[a] != in_view_[b] ? in_view_[a] < in_view_[b] : a < b; });
    const auto allow_triangle = [&](std::uint32_t t) {
      return in_view_[t] != clock_ && !in_sent_[t] && !listed_[t] && !shown_.contains(t);
    };
    const auto allow_vertex = [&](std::uint32_t v) { return vstate_[v] == unshaded && last_seen_[v] != clock_; };
    for (std::uint32_t t : evict_) {
      if (mesh_.live_triangle_count() <= target) break;
      if (mesh_.triangle(t).child_count == 0) continue;  // collapsed with an earlier one
      freed_triangles_.clear();
      freed_vertices_.clear();
      if (!mesh_.coarsen(t, allow_triangle, allow_vertex, freed_triangles_, freed_vertices_)) continue;
      for (std::uint32_t x : mesh_.coarsened()) green_first_[x] = invalid_id;
      for (std::uint32_t x : freed_triangles_) {
        leaf_pixels_[x] = 0, leaf_head_[x] = invalid_id, green_first_[x] = invalid_id, in_sent_[x] = 0, listed_[x] = 0;
        in_view_[x] = 0, display_of_[x] = invalid_id, dirty_mark_[x] = 0, shown_count_[x] = 0, decided_[x] = 0;
        shown_mark_[x] = 0, decision_[x] = display_step{};
      }
      for (std::uint32_t v : freed_vertices_) {
        waiter_head_[v] = invalid_id, waiter_clock_[v] = 0, vstate_[v] = unshaded, colour_[v] = glm::vec3(0.0f);
        luminance_[v] = 0.0f, last_seen_[v] = 0, delivered_epoch_[v] = 0;
      }
    }
    prune_retry_ = mesh_.live_triangle_count() > target ? mesh_.live_triangle_count() + bound / 8 : 0;
  }

  // The first children of every 1:2 split (their parent's 1:4 resplit retires both).
  void index_green_splits() {
    green_first_.assign(mesh_.triangle_count(), invalid_id);
    for (std::uint32_t t = 0; t < mesh_.triangle_count(); ++t)
      if (mesh_.triangle(t).child_count == 2) green_first_[t] = mesh_.triangle(t).first_child;
  }

  // The visible leaves a batch's splits took out of the leaf set, found from the triangles it
  // created (subdivision_mesh::created): a split leaf is the parent of new children, a retired
  // 1:2 child is a child of a parent resplit 1:4. Ascending. O(new triangles · log).
  void find_split_leaves() {
    split_.clear();
    for (std::uint32_t c : mesh_.created()) {
      const std::uint32_t p = mesh_.triangle(c).parent;
      const subdivision_triangle& n = mesh_.triangle(p);
      if (n.first_child != c) continue;  // one visit per split (a 1:2 split resplit in this batch has another first child)
      if (leaf_pixels_[p] > 0) split_.push_back(p);
      if (n.child_count == 4 && green_first_[p] != invalid_id) {
        for (std::uint32_t g = green_first_[p]; g < green_first_[p] + 2; ++g)
          if (leaf_pixels_[g] > 0) split_.push_back(g);
        green_first_[p] = invalid_id;
      }
      if (n.child_count == 2) green_first_[p] = c;
    }
    std::sort(split_.begin(), split_.end());
  }

  // After a batch's splits: only the pixels of the visible leaves that were split follow them
  // down (pixel lists), the visible set loses those leaves and gains the children that cover
  // pixels, and only the new leaves are walked up for the in-view marks and requests (the
  // in-view set of a view only grows). O(new triangles · log + pixels of the split leaves · level)
  // (the visible set is an id_set: O(1) per leaf that leaves or enters).
  void follow_splits() {
    grow();
    find_split_leaves();
    fresh_.clear();
    begin_display_update();
    for (std::uint32_t t : split_) {
      set_display(t, invalid_id);  // no longer a visible leaf
      seeds_.push_back(mesh_.triangle(t).parent != invalid_id ? mesh_.triangle(t).parent : t);
      std::uint32_t p = leaf_head_[t];
      leaf_head_[t] = invalid_id;
      leaf_pixels_[t] = 0;
      while (p != invalid_id) {
        const std::uint32_t next = pixel_next_[p];
        const point_location loc = mesh_.locate_from(t, pixel_weights_[p]);
        pixel_leaf_[p] = loc.leaf;
        pixel_weights_[p] = loc.weights;
        add_pixel(p, loc.leaf);
        p = next;
      }
    }
    if (fresh_.empty()) return finish_display_update();
    std::sort(fresh_.begin(), fresh_.end());
    for (std::uint32_t t : fresh_) mark_dirty(t);
    if (options_.criteria.criterion == refinement_criterion::nld_os)
      for (std::uint32_t t : fresh_) nld_os_.add(t);
    for (std::uint32_t t : split_) visible_.erase(t);
    for (std::uint32_t t : fresh_) visible_.insert(t);
    stamp_in_view(fresh_);
    enforce_cache_bound();
    finish_display_update();
  }

  // In view: the given leaves and their ancestors up to the first already marked; their corners
  // are stamped and requested.
  void stamp_in_view(std::span<const std::uint32_t> leaves) {
    for (std::uint32_t leaf : leaves)
      for (std::uint32_t t = leaf; t != invalid_id && in_view_[t] != clock_; t = mesh_.triangle(t).parent) {
        in_view_[t] = clock_;
        const glm::uvec3 v = mesh_.triangle(t).vertices;
        for (int c = 0; c < 3; ++c) {
          if (last_seen_[v[c]] != clock_) ++in_view_vertices_;
          last_seen_[v[c]] = clock_;
          if (vstate_[v[c]] == unshaded) vstate_[v[c]] = requested, to_issue_.push_back(v[c]), ++outstanding_, ++view_requests_;
          if (vstate_[v[c]] != shaded) add_waiter(v[c], t);
        }
      }
  }

  // Triangles of the view waiting for a vertex (one list per vertex, valid for clock_'s view).
  void add_waiter(std::uint32_t v, std::uint32_t t) {
    if (waiter_clock_[v] != clock_) waiter_clock_[v] = clock_, waiter_head_[v] = invalid_id;
    waiters_.push_back({t, waiter_head_[v]});
    waiter_head_[v] = static_cast<std::uint32_t>(waiters_.size() - 1);
  }
  // A delivered vertex: the shown cut may change under the parents of the triangles waiting for it
  // (their readiness, and so their parents' expansion).
  void seed_waiters(std::uint32_t v) {
    if (waiter_clock_[v] != clock_) return;
    for (std::uint32_t i = waiter_head_[v]; i != invalid_id; i = waiters_[i].next) {
      const std::uint32_t t = waiters_[i].triangle, parent = mesh_.triangle(t).parent;
      seeds_.push_back(parent != invalid_id ? parent : t);
    }
    waiter_head_[v] = invalid_id;
  }

  // A leaf whose pixels' colours may have changed since the last luminance image.
  void mark_dirty(std::uint32_t leaf) {
    if (all_dirty_ || dirty_mark_[leaf] == dirty_clock_) return;
    dirty_mark_[leaf] = dirty_clock_;
    dirty_.push_back(leaf);
  }

  // The current view alone fills the cache: nothing is left to evict.
  [[nodiscard]] bool cache_full() const noexcept { return in_view_vertices_ >= options_.max_cached_samples; }

  [[nodiscard]] bool ready(std::uint32_t t) const {
    const glm::uvec3 v = mesh_.triangle(t).vertices;
    return vstate_[v.x] == shaded && vstate_[v.y] == shaded && vstate_[v.z] == shaded;
  }
  // A shown split triangle gives way to its children once every child in view is ready.
  [[nodiscard]] bool expands(std::uint32_t t) const {
    const subdivision_triangle& n = mesh_.triangle(t);
    for (std::uint32_t c = n.first_child; c < n.first_child + n.child_count; ++c)
      if (in_view_[c] == clock_ && !ready(c)) return false;
    return true;
  }
  // The display walk's outcome at a triangle: the triangle shown so far, and whether the walk
  // goes on below it.
  struct display_step {
    std::uint32_t shown = invalid_id;
    bool open = true;
  };
  // Triangle t's outcome from its parent's (`above`): the walk stops at a triangle not ready;
  // a ready one is shown and the walk goes on below it when it expands.
  [[nodiscard]] display_step decide(std::uint32_t t, display_step above) const {
    if (!above.open) return above;
    if (!ready(t)) return {above.shown, false};
    return {t, !mesh_.triangle(t).is_leaf() && expands(t)};
  }
  [[nodiscard]] bool newly_delivered(std::uint32_t t) const {
    const glm::uvec3 v = mesh_.triangle(t).vertices;
    return delivered_epoch_[v.x] == delta_epoch_ || delivered_epoch_[v.y] == delta_epoch_ ||
           delivered_epoch_[v.z] == delta_epoch_;
  }

  // A new stamp for decided_ and shown_mark_ (arrays sized by grow()); on wrap-around both restart.
  void next_display_clock() {
    if (++display_clock_ != 0) return;
    std::fill(decided_.begin(), decided_.end(), 0u);
    std::fill(shown_mark_.begin(), shown_mark_.end(), 0u);
    display_clock_ = 1;
  }

  // The shown set: for each visible leaf, walk down from its root while triangles are ready and
  // expand (the cut described in the prologue). A triangle's outcome depends on its ancestors
  // alone, so each in-view triangle is decided once per call: O(in-view triangles), not
  // O(visible · level).
  void update_display() {
    next_display_clock();
    merged_.clear();  // the new shown set: leaves shown themselves (ascending as visible_ is), then ancestors
    shown_above_.clear();
    for (std::uint32_t leaf : visible_.sorted()) {
      path_.clear();
      std::uint32_t t = leaf;
      for (; t != invalid_id && decided_[t] != display_clock_; t = mesh_.triangle(t).parent) path_.push_back(t);
      display_step above = t == invalid_id ? display_step{invalid_id, true} : decision_[t];
      for (auto it = path_.rbegin(); it != path_.rend(); ++it) {
        above = decide(*it, above);
        decided_[*it] = display_clock_;
        decision_[*it] = above;
      }
      if (display_of_[leaf] != above.shown) display_of_[leaf] = above.shown, mark_dirty(leaf);
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
    for (std::uint32_t leaf : visible_.unordered())
      if (display_of_[leaf] != invalid_id) ++shown_count_[display_of_[leaf]];
  }

  // A triangle whose membership in the shown set may have changed since the last delta.
  void note_change(std::uint32_t t) {
    if (listed_[t]) return;
    listed_[t] = 1;
    changed_.push_back(t);
  }

  // The shown cut brought up to date under seed triangles only (split leaves' parents, parents of
  // triangles that got a corner delivered): each in-view triangle's decision depends on its
  // parent's, its own readiness and its in-view children's, so the seeds' in-view subtrees,
  // parents first, are all that can change. The shown set follows per-triangle counts of the
  // visible leaves showing it. O(seeded subtrees + shown); the same cut as update_display().
  void begin_display_update() {
    next_display_clock();
    seeds_.clear();
    touched_.clear();
  }
  void set_display(std::uint32_t leaf, std::uint32_t shown) {
    const std::uint32_t old = display_of_[leaf];
    if (old == shown) return;
    if (old != invalid_id) touch(old), --shown_count_[old];
    if (shown != invalid_id) touch(shown), ++shown_count_[shown];
    display_of_[leaf] = shown;
    mark_dirty(leaf);
  }
  void touch(std::uint32_t t) {
    if (shown_mark_[t] == display_clock_) return;
    shown_mark_[t] = display_clock_;
    touched_.push_back({t, shown_count_[t] > 0});
  }
  void finish_display_update() {
    std::sort(seeds_.begin(), seeds_.end(), [&](std::uint32_t a, std::uint32_t b) {
      const auto la = mesh_.triangle(a).level, lb = mesh_.triangle(b).level;
      return la != lb ? la < lb : a < b;
    });
    for (std::uint32_t s : seeds_) {
      if (in_view_[s] != clock_ || decided_[s] == display_clock_) continue;
      stack_.push_back(s);
      while (!stack_.empty()) {
        const std::uint32_t t = stack_.back();
        stack_.pop_back();
        decided_[t] = display_clock_;
        const subdivision_triangle& n = mesh_.triangle(t);
        const display_step above = decide(t, n.parent == invalid_id ? display_step{invalid_id, true} : decision_[n.parent]);
        decision_[t] = above;
        if (n.is_leaf()) set_display(t, above.shown);
        for (std::uint32_t c = n.first_child; c < n.first_child + n.child_count; ++c)
          if (in_view_[c] == clock_) stack_.push_back(c);
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

  // Least recently visible first (ties by id), never a vertex of the current view. Past the bound
  // the cache is brought down to its low-water mark, bound − bound/8, so the O(vertices) scan
  // runs once per bound/8 deliveries, not on every one.
  void enforce_cache_bound() {
    const std::size_t bound = options_.max_cached_samples;
    if (shaded_count_ <= bound) return;
    evict_.clear();
    for (std::uint32_t v = 0; v < vstate_.size(); ++v)
      if (vstate_[v] == shaded && last_seen_[v] != clock_) evict_.push_back(v);
    const std::size_t excess = std::min(shaded_count_ - (bound - bound / 8), evict_.size());
    if (excess == 0) return;
    std::nth_element(evict_.begin(), evict_.begin() + std::ptrdiff_t(excess - 1), evict_.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return last_seen_[a] != last_seen_[b] ? last_seen_[a] < last_seen_[b] : a < b; });
    for (std::size_t i = 0; i < excess; ++i) {
      const std::uint32_t v = evict_[i];
      vstate_[v] = unshaded;
      colour_[v] = glm::vec3(0.0f);
      luminance_[v] = 0.0f;
    }
    shaded_count_ -= excess;
  }

  [[nodiscard]] shading_point point_of(std::uint32_t v) const {
    shading_point sp;
    sp.vertex = v;
    sp.position = mesh_.position(v);
    sp.triangle = mesh_.vertex_source(v);
    const glm::uvec3 o = mesh_.triangle(sp.triangle).vertices;  // original triangles keep their ids
    const glm::dvec3 a(mesh_.position(o.x)), b(mesh_.position(o.y)), c(mesh_.position(o.z));
    sp.normal = glm::vec3(glm::normalize(glm::cross(b - a, c - a)));
    const glm::dvec3 w = barycentric(o, glm::dvec3(sp.position));
    sp.barycentric = glm::vec2(static_cast<float>(w.y), static_cast<float>(w.z));
    return sp;
  }

  // The interpolated luminance per pixel and L_max, its maximum over the image (§4). After a new
  // view every pixel is computed; afterwards only the pixels of leaves marked dirty (split, or
  // shown through another triangle), and L_max comes from a max-tree over the pixels (root at
  // 1, pixel p's luminance at n + p: the leaves are the luminance image NLD_IS reads).
  // O(pixels) per view; per batch O(dirty pixels + tree nodes whose maximum changed).
  template <class E>
  void luminance_image(E&& exec) {
    const std::size_t n = pixel_leaf_.size();
    if (all_dirty_) {
      lum_tree_.resize(2 * n);
      exec.parallel_for(n, options_.grain, [&](std::size_t begin, std::size_t end) {
        for (std::size_t p = begin; p < end; ++p) lum_tree_[n + p] = luminance(pixel_colour(p));
      });
      for (std::size_t i = n; i-- > 1;) lum_tree_[i] = std::max(lum_tree_[2 * i], lum_tree_[2 * i + 1]);
      all_dirty_ = false;
    } else {
      tree_level_.clear();  // parents of the pixels whose value changed
      for (std::uint32_t leaf : dirty_)
        for (std::uint32_t p = leaf_head_[leaf]; p != invalid_id; p = pixel_next_[p]) {
          const float l = luminance(pixel_colour(p));
          if (lum_tree_[n + p] == l) continue;
          lum_tree_[n + p] = l;
          const auto parent = static_cast<std::uint32_t>((n + p) / 2);
          if (tree_level_.empty() || tree_level_.back() != parent) tree_level_.push_back(parent);
        }
      update_lum_tree();
    }
    dirty_.clear();
    if (++dirty_clock_ == 0) std::fill(dirty_mark_.begin(), dirty_mark_.end(), 0u), dirty_clock_ = 1;
    l_max_ = n == 0 ? 0.0f : std::max(0.0f, lum_tree_[1]);
  }

  // The max-tree's nodes above changed pixels, one round at a time: each queued node is
  // recomputed from its children and queues its parent only when its own value changed, so the
  // rounds end once no maximum changes, and a node whose child changed later (pixels sit at two
  // depths when the pixel count is not a power of two) is queued again and recomputed after it.
  // O(changed nodes + repeats), no sorting.
  void update_lum_tree() {
    while (!tree_level_.empty()) {
      tree_next_.clear();
      for (std::uint32_t i : tree_level_) {
        if (i == 0) continue;  // a one-pixel image: its pixel is the root
        const float v = std::max(lum_tree_[2 * std::size_t(i)], lum_tree_[2 * std::size_t(i) + 1]);
        if (lum_tree_[i] == v) continue;
        lum_tree_[i] = v;
        if (i > 1 && (tree_next_.empty() || tree_next_.back() != i / 2)) tree_next_.push_back(i / 2);
      }
      tree_level_.swap(tree_next_);
    }
  }

  subdivision_mesh initial_mesh_, mesh_;
  driver_options options_;
  criterion_state state_;
  std::uint32_t width_ = 0, height_ = 0;
  pinhole_frame projection_;     // the view's camera, when it is a pinhole one (NLD_IS's projected areas)
  bool has_projection_ = false;
  std::vector<std::uint32_t> pixel_leaf_;
  std::vector<glm::vec3> pixel_weights_;
  std::vector<std::uint32_t> leaf_pixels_;
  id_set visible_;                          // the visible leaves
  std::vector<std::uint32_t> in_view_;     // per triangle: clock_ when it or a descendant is visible
  std::vector<std::uint32_t> display_of_;  // per visible leaf: the shown triangle over it
  // The display walk's per-triangle outcome, stamped with display_clock_, and its mark of
  // triangles already in shown_.
  std::vector<display_step> decision_;
  std::vector<std::uint32_t> decided_, shown_mark_;
  std::uint32_t display_clock_ = 0;
  std::vector<std::uint32_t> leaf_head_;   // per triangle: first pixel of its list (visible leaves), else invalid_id
  std::vector<std::uint32_t> pixel_next_;  // per pixel: the next pixel of its leaf's list
  std::vector<std::uint32_t> fresh_;       // leaves that gained their first pixel
  std::vector<std::uint32_t> split_;        // a batch's split visible leaves
  std::vector<std::uint32_t> green_first_;  // per triangle split 1:2: its first child, else invalid_id
  nld_os_queue nld_os_;                     // NLD_OS's candidates in the current view
  std::vector<float> lum_tree_;            // max-tree whose leaves are the pixel luminances (luminance_image)
  std::vector<std::uint32_t> tree_level_, tree_next_;  // update_lum_tree's nodes of one round and the next
  std::vector<std::uint32_t> dirty_, dirty_mark_;  // leaves to recompute, and their dirty_clock_ stamps
  std::uint32_t dirty_clock_ = 1;
  bool all_dirty_ = true;                  // every pixel is recomputed (a new view)
  std::vector<std::uint32_t> shown_above_, merged_, scratch_;
  std::vector<std::uint32_t> shown_count_;  // per triangle: visible leaves showing it
  struct waiter {
    std::uint32_t triangle, next;
  };
  std::vector<waiter> waiters_;                            // the current view's waiting lists
  std::vector<std::uint32_t> waiter_head_, waiter_clock_;  // per vertex: first waiter, its view's clock_
  struct touched_triangle {
    std::uint32_t triangle;
    bool was;  // shown before this update
  };
  std::vector<touched_triangle> touched_;
  std::vector<std::uint32_t> seeds_, stack_;
  std::size_t sent_total_ = 0;             // triangles that entered the shown set since the view was set
  std::vector<std::uint8_t> vstate_;       // per vertex: unshaded, requested, shaded
  std::vector<glm::vec3> colour_;
  std::vector<float> luminance_;
  std::vector<std::uint32_t> last_seen_;        // per vertex: clock_ when last in view
  std::vector<std::uint32_t> delivered_epoch_;  // per vertex: delta_epoch_ of its delivery
  std::vector<std::uint32_t> to_issue_;
  std::size_t issued_ = 0;
  std::size_t outstanding_ = 0;
  std::size_t shaded_count_ = 0;
  std::size_t in_view_vertices_ = 0;  // vertices stamped with the current clock_
  std::size_t view_requests_ = 0;     // requests issued since the view was set
  id_set shown_;                             // the shown set
  std::vector<std::uint8_t> in_sent_, listed_;  // per triangle: shown at the last delta; in changed_
  std::vector<std::uint32_t> changed_;         // triangles whose membership changed since the last delta
  std::vector<std::uint32_t> path_, evict_;
  std::vector<std::uint32_t> freed_triangles_, freed_vertices_;  // prune_hierarchy()'s, per coarsen
  std::size_t prune_retry_ = 0;  // prune_hierarchy() waits until this many triangles are in use
  std::vector<std::uint32_t> selected_;
  float l_max_ = 0.0f;
  std::size_t samples_ = 0;
  std::uint32_t clock_ = 0, delta_epoch_ = 0;
  bool finished_ = false, stage1_recorded_ = false;
  refinement_report report_;
  std::chrono::steady_clock::time_point started_{};
};

}  // namespace infolerp
