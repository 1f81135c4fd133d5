#pragma once
// Progressive refinement along a walkthrough: Oliveira, Santos, Proença, "Refinement Criteria
// for High Fidelity Interactive Walkthroughs", §2 (the Shading Management Agent: visibility, an
// object-space shading cache, asynchronous shading, the incremental add/delete protocol), §4.1
// (refinement interrupted after every R selections) and §5 (Table 1: Δ, Δ_total, samples, time).
// progressive_refiner is the one entry point; its parts, each in its own header:
//   refine/detail/view_pixels.hpp     a view: primary rays, pixels located and re-located;
//   refine/detail/luminance_image.hpp the pixel luminances and L_max the criteria read;
//   refine/detail/shown_cut.hpp       the shown cut of the hierarchy and its deltas;
//   refine/detail/shading_cache.hpp   per-vertex colours, requests and eviction;
// selection (criteria.hpp, nld_os_queue.hpp), the batch loop and hierarchy pruning are here.
// Views: set_view() traces one primary ray per pixel; later (planar) splits re-locate pixels
// without tracing. Hierarchy and cache survive view changes; only leaves shown now are refined,
// requested or displayed. start() is a full restart.
// Cache: 20 bytes per vertex plus 40 per hierarchy triangle. With max_cached_samples, vertices
// outside the view are evicted least recently visible first; the current view's are never
// evicted, and refinement stops (cache_full) once they alone reach the bound.
// Hierarchy: with max_hierarchy_triangles, a new view prunes (subdivision_mesh::coarsen) subtrees
// none of whose triangles is in view, shown or awaiting a delta and none of whose vertices is
// cached or requested, least recently in view first, down to bound − bound/8; ids are reused.
// Shading: each vertex of a shown leaf and of its ancestors is requested once; take_requests()
// hands out shading_points, deliver() takes colours for any subset in any order, from any thread
// or machine (calls on one refiner must not overlap). shade_requests() is the synchronous adaptor.
// A batch runs only when nothing is outstanding, so results are bit-identical for any executor
// and delivery order.
// L_max (§4): the largest luminance of the current image, recomputed before every selection;
// Rec. 709 luminance of the linear colour stands in for Drago et al.'s tone mapper.
// Display: the shown set is always a non-overlapping cut of the hierarchy; take_delta() gives the
// changes in the paper's order: added from the cache, deleted, newly shaded.
// Figures: stage 1 shades every visible leaf's vertices; stage 2 runs batches until the criterion
// selects nothing, the budget is reached (checked per batch) or max_batches ran. Δ: triangles
// shown now; Δ_total: triangles sent to the visualizer since the view was set.
// Work: a batch touches the pixels of the leaves it split, never the whole image, visible set or
// hierarchy. A new view is O(pixels).
//
// The tracer models infolerp::tracer with the mesh's triangle ids; the synchronous callback
// glm::vec3 shade(const shading_point&) is called once per request, concurrently.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/refine/criteria.hpp"
#include "infolerp/refine/detail/luminance_image.hpp"
#include "infolerp/refine/detail/shading_cache.hpp"
#include "infolerp/refine/detail/shown_cut.hpp"
#include "infolerp/refine/detail/view_pixels.hpp"
#include "infolerp/refine/nld.hpp"
#include "infolerp/refine/nld_os_queue.hpp"
#include "infolerp/refine/pinhole_camera.hpp"
#include "infolerp/refine/refiner_types.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"

namespace infolerp {

// Not thread-safe: one call at a time per object (each call runs in parallel through the
// executor). Accessors below are O(1) and allocate nothing, but visible_leaves() and
// shown_triangles() sort in place on their first call after a change.
class progressive_refiner {
 public:
  // Largest image a view may have (width · height): 2^25 pixels (8192 x 4096, above 8K UHD);
  // the agent keeps about 60 bytes per pixel, so a view stays under 2 GB.
  static constexpr std::size_t max_view_pixels = detail::max_view_pixels;

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
    r.view_.reset(r.mesh_);
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
    return cache_.take_requests(mesh_, out, max_count);
  }
  // Requests not yet delivered (handed out or not).
  [[nodiscard]] std::size_t outstanding_requests() const noexcept { return cache_.outstanding(); }

  // Accepts the colours of requested vertices, in any order and any grouping. Errors: sizes
  // differ; a vertex out of range, never requested, already delivered, or named twice; a
  // non-finite colour (names the entry). On error nothing is stored.
  // Complexity O(n + the in-view subtrees under the parents of the triangles waiting for these
  // vertices) (the shown set is brought up to date), plus O(V) when
  // the cache bound evicts (once per bound/8 deliveries); allocation: the eviction's candidates.
  status deliver(std::span<const std::uint32_t> vertices, std::span<const glm::vec3> colours) {
    if (auto st = cache_.deliver(vertices, colours, delta_epoch_); !st) return st;
    cache_.enforce_bound(options_.max_cached_samples, clock_);
    cut_.begin_update();
    for (std::uint32_t v : vertices) cut_.seed_waiters(mesh_, v, clock_);
    cut_.finish_update(cut_inputs(), lum_);
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
  // triangle changed + max-tree nodes that changed) for NLD_IS, O(leaves whose shown triangle
  // changed · log + leaves evaluated for L_max · their pixels) for the others; the view's first
  // batch also builds NLD_IS's luminance image, O(pixels), or the others' bounds, O(visible).
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
    cut_.take_delta(out, mesh_, cache_, delta_epoch_);
    ++delta_epoch_;
  }

  // Bounds the cache (see the prologue). Errors: a bound of 0; then nothing changes.
  status set_cache_bound(std::size_t max_cached_samples) {
    if (max_cached_samples == 0) return make_error(errc::bad_parameter, no_element, "cache bound must be >= 1");
    options_.max_cached_samples = max_cached_samples;
    cache_.enforce_bound(options_.max_cached_samples, clock_);
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
    for (std::size_t p = 0; p < view_.pixel_leaf().size() && p < image.size(); ++p) image[p] = pixel_colour(p);
  }

  [[nodiscard]] const refinement_report& report() const noexcept { return report_; }
  [[nodiscard]] const subdivision_mesh& mesh() const noexcept { return mesh_; }
  [[nodiscard]] std::span<const std::uint32_t> pixel_leaves() const noexcept { return view_.pixel_leaf(); }
  // The visible leaves (ascending; sorted on the first call after a batch changed them).
  [[nodiscard]] std::span<const std::uint32_t> visible_leaves() const { return view_.visible().sorted(); }
  [[nodiscard]] std::span<const std::uint32_t> leaf_pixels() const noexcept { return view_.leaf_pixels(); }
  // The triangles the criterion selected in the last batch.
  [[nodiscard]] std::span<const std::uint32_t> last_selection() const noexcept { return selected_; }
  // The shown set (ascending; sorted on the first call after it changed): equals
  // visible_leaves() once every request is delivered.
  [[nodiscard]] std::span<const std::uint32_t> shown_triangles() const { return cut_.shown().sorted(); }
  // Shaded colour of a vertex (meaningful when vertex_shaded(v)).
  [[nodiscard]] glm::vec3 vertex_colour(std::size_t v) const { return cache_.colour(v); }
  [[nodiscard]] bool vertex_shaded(std::size_t v) const { return cache_.shaded_vertex(v); }
  // Shaded values held now, and samples delivered since start() (evicted ones shaded again count twice).
  [[nodiscard]] std::size_t cached_samples() const noexcept { return cache_.shaded_count(); }
  [[nodiscard]] std::size_t samples_delivered() const noexcept { return cache_.samples(); }
  // Bytes the refiner holds: the hierarchy (and the copy start() returns to), the cache and the
  // per-triangle, per-vertex and per-view buffers, by capacity. O(1).
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    const auto b = [](const auto&... v) { return ((v.capacity() * sizeof(typename std::remove_cvref_t<decltype(v)>::value_type)) + ...); };
    return initial_mesh_.memory_bytes() + mesh_.memory_bytes() + nld_os_.memory_bytes() + view_.memory_bytes() +
           cut_.memory_bytes() + cache_.memory_bytes() + lum_.memory_bytes() +
           b(in_view_, candidates_, selected_, freed_triangles_, freed_vertices_);
  }
  // The frame the criteria see (pixel luminances filled only for NLD_IS).
  [[nodiscard]] refinement_frame frame() const {
    refinement_frame f;
    f.width = width_;
    f.height = height_;
    f.mesh = &mesh_;
    f.pixel_leaf = view_.pixel_leaf();
    f.pixel_luminance = lum_.pixels(view_.pixel_leaf().size());  // the max-tree's leaves
    f.leaf_pixels = view_.leaf_pixels();
    f.visible = view_.visible().unordered();
    f.vertex_luminance = cache_.luminances();
    f.vertex_colour = cache_.colours();
    f.l_max = lum_.l_max();
    f.view_samples = cache_.view_requests();
    f.projection = has_projection_ ? &projection_ : nullptr;
    return f;
  }

 private:
  template <class Shade>
  static constexpr bool check_shade() {
    static_assert(std::is_invocable_r_v<glm::vec3, Shade&, const shading_point&>,
                  "infolerp: shading callback needs `glm::vec3 shade(const infolerp::shading_point&)`");
    return true;
  }

  // What the shown cut reads (valid until the per-triangle arrays grow).
  [[nodiscard]] detail::cut_inputs cut_inputs() const { return {mesh_, cache_, in_view_, clock_}; }

  // Traces and checks the view; only then (optionally) restarts and takes the view.
  template <class T, class Camera, class E>
  status view(const T& tracer, const Camera& camera, E&& exec, bool restart) {
    const auto began = std::chrono::steady_clock::now();
    std::vector<hit> hits;
    if (auto st = detail::trace_view(tracer, camera, exec, options_.grain, mesh_.original_triangle_count(), hits); !st)
      return st;
    if (restart) reset();
    apply_view(camera, hits, exec, began);
    return {};
  }

  void reset() {
    mesh_ = initial_mesh_;
    view_.reset(mesh_);
    selected_.clear();
    state_ = criterion_state{};
    state_.rng = splitmix64{options_.criteria.seed};
    lum_.reset();
    in_view_.clear();
    cut_.reset();
    cache_.reset();
    clock_ = 0;
    delta_epoch_ = 0;
    prune_retry_ = 0;
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
    state_.points_drawn = 0;
    state_.exhausted = false;
    report_ = {};
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

  // Selection (§4.1): the luminance image and L_max brought up to date, then up to R triangles
  // selected by the criterion (criteria.hpp; NLD_OS's heap in nld_os_queue.hpp) and split.
  template <class E, class Render>
  refine_progress refine_impl(E& exec, refine_budget budget, Render&& render) {
    const auto began = std::chrono::steady_clock::now();
    const std::size_t samples_before = cache_.samples() + cache_.outstanding();
    // Stops early return the reason unless a batch ran in this call (the next call reports it).
    for (std::size_t b = 0; b < budget.batches; ++b) {
      if (b > 0 && (cache_.samples() + cache_.outstanding() - samples_before >= budget.samples ||
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count() >= budget.seconds))
        break;
      if (cache_.outstanding() > 0) return b == 0 ? refine_progress::waiting : refine_progress::refined;
      record_stage1();
      if (finished_) return b == 0 ? refine_progress::finished : refine_progress::refined;
      if (cache_full()) return b == 0 ? refine_progress::cache_full : refine_progress::refined;
      update_luminance(exec);
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

  // L_max (and for NLD_IS, the only criterion that reads them, the pixel luminances) brought up
  // to date. Without the image, a visible leaf's pixels are bounded by its shown triangle's
  // brightest corner: luminance grows with each channel and pixel_colour() clamps to the corners.
  template <class E>
  void update_luminance(E& exec) {
    if (options_.criteria.criterion == refinement_criterion::nld_is)
      return lum_.update(view_.pixel_leaf().size(), exec, options_.grain, [&](std::size_t p) { return luminance(pixel_colour(p)); },
                         [&](std::uint32_t leaf, auto&& f) { view_.for_each_pixel(leaf, f); });
    const float background = luminance(options_.background), none = -std::numeric_limits<float>::infinity();
    const std::span<const glm::vec3> colour = cache_.colours();
    const auto bound = [&](std::uint32_t leaf) {
      if (view_.leaf_pixels()[leaf] == 0 || !view_.visible().contains(leaf)) return none;
      const std::uint32_t d = cut_.display_of(leaf);
      if (d == invalid_id) return background;
      const glm::uvec3 v = mesh_.triangle(d).vertices;
      const float b = luminance(glm::max(colour[v.x], glm::max(colour[v.y], colour[v.z])));
      return b + std::abs(b) * 0x1p-20f + 0x1p-126f;  // a margin for the rounding of the interpolation
    };
    const auto exact = [&](std::uint32_t leaf) {
      if (cut_.display_of(leaf) == invalid_id) return background;
      float m = none;
      view_.for_each_pixel(leaf, [&](std::uint32_t p) { m = std::max(m, luminance(pixel_colour(p))); });
      return m;
    };
    lum_.update_bounds(view_.visible().unordered(), view_missed_ ? background : 0.0f, bound, exact);
  }

  [[nodiscard]] glm::vec3 pixel_colour(std::size_t p) const {
    const std::uint32_t leaf = view_.pixel_leaf()[p];
    if (leaf == invalid_id) return options_.background;
    const std::uint32_t d = cut_.display_of(leaf);
    if (d == invalid_id) return options_.background;
    const glm::uvec3 v = mesh_.triangle(d).vertices;
    const glm::vec3 w = d == leaf ? view_.weights(p) : weights_in(d, leaf, view_.weights(p));
    const std::span<const glm::vec3> colour = cache_.colours();
    const glm::vec3 a = colour[v.x], b = colour[v.y], c = colour[v.z];
    // Inside the corners' range, as exact interpolation is: the stored weights' rounding (a few
    // ulps per re-location) must not carry a pixel past what was delivered.
    return glm::clamp(w.x * a + w.y * b + w.z * c, glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c)));
  }
  // The barycentric weights in ancestor a of the point with weights w in leaf l (planar).
  [[nodiscard]] glm::vec3 weights_in(std::uint32_t a, std::uint32_t l, glm::vec3 w) const {
    const glm::uvec3 lv = mesh_.triangle(l).vertices, av = mesh_.triangle(a).vertices;
    const glm::dvec3 p = double(w.x) * glm::dvec3(mesh_.position(lv.x)) + double(w.y) * glm::dvec3(mesh_.position(lv.y)) +
                         double(w.z) * glm::dvec3(mesh_.position(lv.z));
    return glm::vec3(detail::barycentric_in(mesh_, av, p));
  }

  [[nodiscard]] stage_figures figures() const {
    stage_figures s;
    s.triangles = view_.visible().size();
    s.triangles_total = cut_.sent_total();
    s.triangles_produced = mesh_.triangle_count();
    s.shading_samples = cache_.samples();
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    return s;
  }

  void grow() {
    const std::size_t nt = mesh_.triangle_count(), nv = mesh_.vertex_count();
    view_.grow(nt);
    cut_.grow(nt, nv);
    lum_.grow(nt);
    in_view_.resize(nt, 0);
    cache_.grow(nv);
  }

  // A new view: every pixel located and listed (view_pixels.hpp), the visible leaves stamped in
  // view and their unshaded corners requested, the shown cut rebuilt, then the bounds applied.
  // O(pixels · level + previous visible + in-view triangles).
  template <class E>
  void view_leaves(const std::vector<hit>& hits, E&& exec) {
    grow();
    view_.locate(mesh_, hits, exec, options_.grain);
    view_missed_ = std::find(view_.pixel_leaf().begin(), view_.pixel_leaf().end(), invalid_id) != view_.pixel_leaf().end();
    nld_os_.clear();
    if (options_.criteria.criterion == refinement_criterion::nld_os)
      for (std::uint32_t t : view_.fresh()) nld_os_.add(t);
    ++clock_;
    cache_.begin_view();
    cut_.begin_view();
    lum_.invalidate();
    stamp_in_view(view_.fresh());
    cache_.enforce_bound(options_.max_cached_samples, clock_);
    cut_.rebuild(cut_inputs(), view_.visible(), lum_);
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
    candidates_.clear();
    for (std::uint32_t t = 0; t < mesh_.triangle_count(); ++t) {
      const subdivision_triangle& n = mesh_.triangle(t);
      if (n.child_count == 0 || n.retired || in_view_[t] == clock_) continue;
      if (n.parent == invalid_id || in_view_[n.parent] == clock_) candidates_.push_back(t);
    }
    std::sort(candidates_.begin(), candidates_.end(),
              [&](std::uint32_t a, std::uint32_t b) { return in_view_[a] != in_view_[b] ? in_view_[a] < in_view_[b] : a < b; });
    const auto allow_triangle = [&](std::uint32_t t) { return in_view_[t] != clock_ && !cut_.holds(t); };
    const auto allow_vertex = [&](std::uint32_t v) { return cache_.holds_nothing(v, clock_); };
    for (std::uint32_t t : candidates_) {
      if (mesh_.live_triangle_count() <= target) break;
      if (mesh_.triangle(t).child_count == 0) continue;  // collapsed with an earlier one
      freed_triangles_.clear();
      freed_vertices_.clear();
      if (!mesh_.coarsen(t, allow_triangle, allow_vertex, freed_triangles_, freed_vertices_)) continue;
      for (std::uint32_t x : mesh_.coarsened()) view_.forget_split(x);
      for (std::uint32_t x : freed_triangles_) view_.forget(x), cut_.forget_triangle(x), lum_.forget(x), in_view_[x] = 0;
      for (std::uint32_t v : freed_vertices_) cut_.forget_vertex(v), cache_.forget(v);
    }
    prune_retry_ = mesh_.live_triangle_count() > target ? mesh_.live_triangle_count() + bound / 8 : 0;
  }

  // After a batch's splits: only the pixels of the visible leaves that were split follow them
  // down, the visible set loses those leaves and gains the children that cover pixels, and only
  // the new leaves are walked up for the in-view marks and requests (the in-view set of a view
  // only grows). O(new triangles · log + pixels of the split leaves · level).
  void follow_splits() {
    grow();
    view_.find_split_leaves(mesh_);
    cut_.begin_update();
    for (std::uint32_t t : view_.split()) {
      cut_.set_display(t, invalid_id, lum_);  // no longer a visible leaf
      lum_.mark_dirty(t);                     // (also when nothing was shown over it)
      cut_.seed(mesh_, t);
      view_.relocate(mesh_, t);
    }
    if (view_.fresh().empty()) return cut_.finish_update(cut_inputs(), lum_);
    view_.update_visible();
    for (std::uint32_t t : view_.fresh()) lum_.mark_dirty(t);
    if (options_.criteria.criterion == refinement_criterion::nld_os)
      for (std::uint32_t t : view_.fresh()) nld_os_.add(t);
    stamp_in_view(view_.fresh());
    cache_.enforce_bound(options_.max_cached_samples, clock_);
    cut_.finish_update(cut_inputs(), lum_);
  }

  // In view: the given leaves and their ancestors up to the first already marked; their corners
  // are seen by the cache (requested when unshaded), and the triangle waits for those not shaded.
  void stamp_in_view(std::span<const std::uint32_t> leaves) {
    for (std::uint32_t leaf : leaves)
      for (std::uint32_t t = leaf; t != invalid_id && in_view_[t] != clock_; t = mesh_.triangle(t).parent) {
        in_view_[t] = clock_;
        const glm::uvec3 v = mesh_.triangle(t).vertices;
        for (int c = 0; c < 3; ++c)
          if (cache_.see(v[c], clock_)) cut_.add_waiter(v[c], t, clock_);
      }
  }

  // The current view alone fills the cache: nothing is left to evict.
  [[nodiscard]] bool cache_full() const noexcept { return cache_.in_view_vertices() >= options_.max_cached_samples; }

  subdivision_mesh initial_mesh_, mesh_;
  driver_options options_;
  criterion_state state_;
  std::uint32_t width_ = 0, height_ = 0;
  pinhole_frame projection_;     // the view's camera, when it is a pinhole one (NLD_IS's projected areas)
  bool has_projection_ = false;
  bool view_missed_ = false;     // a pixel of the view missed the scene (shows the background)
  detail::view_pixels view_;              // pixels located in the hierarchy, the visible leaves
  detail::shading_cache cache_;           // per-vertex colours and requests
  detail::shown_cut cut_;                 // the shown set and its deltas
  detail::luminance_image lum_;           // the pixel luminances and L_max
  nld_os_queue nld_os_;                   // NLD_OS's candidates in the current view
  std::vector<std::uint32_t> in_view_;    // per triangle: clock_ when it or a descendant is visible
  std::vector<std::uint32_t> candidates_;                        // prune_hierarchy()'s subtrees
  std::vector<std::uint32_t> freed_triangles_, freed_vertices_;  // prune_hierarchy()'s, per coarsen
  std::size_t prune_retry_ = 0;  // prune_hierarchy() waits until this many triangles are in use
  std::vector<std::uint32_t> selected_;
  std::uint32_t clock_ = 0, delta_epoch_ = 0;
  bool finished_ = false, stage1_recorded_ = false;
  refinement_report report_;
  std::chrono::steady_clock::time_point started_{};
};

}  // namespace infolerp
