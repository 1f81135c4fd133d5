#pragma once
// The per-frame entry point of view-dependent multiresolution rendering (salient-clustering
// paper §IV): camera + a budget of triangles drawn → index buffer + per-cluster ranges.
//
// Selection (lod_options::selection):
//   screen_error (default): per-cluster budgets from one projected-error threshold, the view
//     weight seeing the frustum, back-facing clusters and silhouettes, chosen so that the
//     budget holds after neighbour matching (screen_error_selection.hpp); meant for the default
//     hierarchy (one global order);
//   paper: eqs. 5–9 as written: A_est, I_est per cluster (cluster_importance.hpp) and eq. 9's
//     equal portions by A_est·I_est, each cluster clamped to its cluster-local capacity
//     (contraction_hierarchy.hpp explains the cluster-local phase, which this option needs); a
//     budget beyond the local phase is a global prefix (every local contraction plus the first
//     R_global − Σ local of the rest, the same for all clusters; a prefix of the global order
//     needs no matching); then neighbour matching (view_selection.hpp).
// Both then contract into the caller's index buffer (vertex_contraction.hpp), by default without
// the triangles the camera cannot see (hidden_triangles.hpp: outside the frustum, or facing away
// on a closed part of the mesh; never where back faces may be seen). The budget counts what is
// drawn: screen_error spends it on the seen part, each cluster's seen share estimated from a
// sample of its triangles (stats: estimated against indices / 3). keep_hidden draws the same cut whole, for a
// shadow-map pass or a ray tracer's BVH (frame() from a light's camera is the light's own LOD).
// paper needs a hierarchy with the cluster-local phase (create() refuses one without it).
// Each step is usable on its own; this class keeps their buffers between frames, so frame()
// allocates nothing after construction (unless it returns an error). Any valid camera gets a
// LOD, inside the mesh (its back faces are then drawn) or a cluster's bounding sphere included (screen_error: a cluster around
// the camera is seen at a tenth of its radius; paper: eq. 6's fallback, 1 when no cluster has a
// positive λ_dist).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/hidden_triangles.hpp"
#include "infolerp/lod/screen_error_selection.hpp"
#include "infolerp/lod/vertex_contraction.hpp"
#include "infolerp/lod/view_selection.hpp"
#include "infolerp/saliency/cluster_importance.hpp"

namespace infolerp {

struct lod_frame_stats {
  std::size_t indices = 0;              // indices written (3 per triangle drawn)
  std::uint64_t estimated = 0;          // the triangles the selection expected to draw (from the
                                        // seen share of each cluster's samples)
  std::uint64_t budgeted = 0;           // Σ per-cluster budgets before matching (paper: = R_global)
  std::uint64_t applied = 0;            // contractions applied after matching (>= budgeted)
  std::uint32_t matching_sweeps = 0;    // paper: neighbour-matching sweeps; screen_error: selection rounds
};

enum class lod_selection { screen_error, paper };

struct lod_options {
  lod_selection selection = lod_selection::screen_error;
  view_weight_options view;   // screen_error only
  double lambda_perc = 0.02;  // paper only: eq. 9's portion, in (0, 1]
  std::size_t grain = 4096;   // triangles per parallel task of the contraction pass
  // false (default): draw no triangle the camera cannot see (hidden_triangles.hpp), and spend
  // the budget on the triangles drawn. true: the same cut with its hidden triangles drawn too
  // (for a shadow-map pass or a ray tracer's BVH); screen_error then counts every kept triangle.
  bool keep_hidden = false;
  // Clusters whose back faces may be seen (never back-face culled); read by create() only.
  std::span<const std::uint32_t> two_sided{};
};

class view_dependent_lod {
 public:
  // Keeps references to h and table (they must outlive this object). Errors: table with a
  // different cluster count (bad_size) or a hierarchy without positions (bad_size), options
  // outside their ranges (bad_parameter), a two_sided cluster out of range (index_out_of_range),
  // paper on a hierarchy without cluster-local contractions (bad_parameter).
  // Allocation O(V + clusters + T + contractions); O(T log T) time.
  static result<view_dependent_lod> create(const contraction_hierarchy& h, const cluster_table& table,
                                           const lod_options& opt = {}) {
    if (table.clusters.size() != h.cluster_count)
      return make_error(errc::bad_size, table.clusters.size(), "cluster table has ", table.clusters.size(),
                        " clusters, hierarchy ", h.cluster_count);
    if (!(opt.lambda_perc > 0.0 && opt.lambda_perc <= 1.0))
      return make_error(errc::bad_parameter, no_element, "lambda_perc ", opt.lambda_perc, " must be in (0, 1]");
    const view_weight_options& v = opt.view;
    if (!(v.hidden_weight > 0.0 && v.hidden_weight <= 1.0) || !(v.silhouette_weight >= 1.0) ||
        !std::isfinite(v.silhouette_weight) || !(v.near_fraction > 0.0) || !std::isfinite(v.near_fraction))
      return make_error(errc::bad_parameter, no_element, "view weights: hidden ", v.hidden_weight, " must be in (0, 1], silhouette ",
                        v.silhouette_weight, " >= 1 and finite, near_fraction ", v.near_fraction, " > 0 and finite");
    if (h.positions.size() != h.vertex_count)
      return make_error(errc::bad_size, h.positions.size(), "hierarchy holds ", h.positions.size(), " positions for ",
                        h.vertex_count, " vertices");
    for (std::size_t k = 0; k < opt.two_sided.size(); ++k)
      if (opt.two_sided[k] >= h.cluster_count)
        return make_error(errc::index_out_of_range, k, "two_sided cluster ", opt.two_sided[k], " >= cluster count ",
                          h.cluster_count);
    if (opt.selection == lod_selection::paper && h.local_contractions == 0 && h.contraction_count() > 0)
      return make_error(errc::bad_parameter, no_element,
                        "lod_selection::paper needs a hierarchy built with cluster_local_first (this one has no "
                        "cluster-local contractions: every budget would be one global prefix)");
    return view_dependent_lod(h, table, opt);
  }

  // Per-cluster stop points and budgets (before matching) of the last frame.
  [[nodiscard]] std::span<const std::uint32_t> stop_points() const { return stop_; }
  [[nodiscard]] std::span<const std::uint64_t> budgets() const { return budget_; }

  // One frame drawing at most `triangles` (what engines budget: triangles drawn after culling;
  // with keep_hidden, triangles kept, counted exactly) as estimated from each cluster's sampled
  // share in view (stats.estimated, to one contraction): the count drawn follows the estimate
  // within the samples' error, which grows as the cut coarsens (a coarse triangle straddles
  // what its samples saw). A budget below the coarsest cut's draws the coarsest cut, one at or
  // above the mesh's triangle count the full mesh.
  // paper: R_global is the shortest global prefix that keeps triangles / f, f the estimated
  // share in view of the whole mesh (eq. 9 distributes R_global). Errors: an invalid camera
  // (check_camera: bad_parameter, or bad_size for an empty viewport); out smaller than
  // contracted_index_bound or ranges not one per cluster (bad_size).
  // screen_error: O(12 · (64 · A log n + matching) + samples + coarsest triangles + contractions
  // + kept triangles / threads) for A clusters that hold triangles; paper: O(C log C + matching
  // + contractions + kept triangles / threads); twice that when the eye turns out inside a
  // closed part of the cut. No allocation.
  template <class E = serial_executor>
  result<lod_frame_stats> frame(const lod_camera& camera, std::uint64_t triangles, std::span<std::uint32_t> out,
                                std::span<index_range> ranges, E&& exec = E{}) {
    static_assert(check_executor<std::remove_cvref_t<E>>());
    if (status s = check_camera(camera); !s.ok()) return s;
    lod_frame_stats st;
    view_frustum view = make_view_frustum(camera);
    view.closed_lo = closed_lo_, view.closed_hi = closed_hi_;
    const std::span<const std::uint32_t> active = neighbours_.active;
    bool back_faces_hidden = eye_outside_coarsest(samples_, view);
    if (opt_.keep_hidden) std::fill(share_.begin(), share_.end(), 1.0);
    else visible_shares(samples_, view, back_faces_hidden, active, share_);
    // The shares assume back faces hidden where the eye is outside the coarsest cut's closed
    // parts; if this cut shows the eye inside one (back faces then drawn), they are counted again
    // and the frame selected once more.
    for (int attempt = 0;; ++attempt) {
      if (status s = select(camera, triangles, st); !s.ok()) return s;
      auto n = opt_.keep_hidden ? contract_indices(*h_, stop_, work_, out, ranges, exec)
                                : contract_visible_indices(*h_, stop_, work_, view, one_sided_, out, ranges, exec);
      if (!n.ok()) return n.error();
      st.indices = *n;
      if (attempt == 1 || opt_.keep_hidden || work_.back_faces_hidden == back_faces_hidden) break;
      visible_shares(samples_, view, back_faces_hidden = work_.back_faces_hidden, active, share_);
    }
    return st;
  }

 private:
  // The stop points for `triangles` drawn as estimated, into stop_ (and st's selection figures).
  status select(const lod_camera& camera, std::uint64_t triangles, lod_frame_stats& st) {
    const std::span<const std::uint32_t> active = neighbours_.active;
    if (opt_.selection == lod_selection::screen_error) {
      const selection_stats sel = select_for_view(*h_, neighbours_, patches_, maxima_, faces_, camera, opt_.view, share_,
                                                  triangles, area_, budget_, stop_);
      st.budgeted = sel.budgeted, st.applied = sel.applied, st.matching_sweeps = sel.rounds;
      st.estimated = static_cast<std::uint64_t>(std::max(0.0, std::round(sel.drawn)));
      return {};
    }
    double seen = 0.0;
    for (const std::uint32_t c : active)
      seen += share_[c] * static_cast<double>(h_->triangle_offsets[c + 1] - h_->triangle_offsets[c]);
    const double f = h_->triangle_count() > 0 ? seen / static_cast<double>(h_->triangle_count()) : 1.0;
    // The shortest prefix whose kept triangles, times f, are within the budget (kept_ falls).
    const auto within = std::partition_point(kept_.begin(), kept_.end(), [&](std::uint64_t kept) {
      return f * static_cast<double>(kept) > static_cast<double>(triangles);
    });
    const auto global_contractions = static_cast<std::uint64_t>(
        std::min(within - kept_.begin(), static_cast<std::ptrdiff_t>(h_->contraction_count())));
    if (status s = paper_stop_points(camera.position, global_contractions); !s.ok()) return s;
    st.budgeted = 0;
    for (std::uint64_t b : budget_) st.budgeted += b;
    st.matching_sweeps = match_neighbours(neighbours_, stop_);
    st.applied = applied_total(*h_, stop_);
    st.estimated = static_cast<std::uint64_t>(std::round(f * static_cast<double>(kept_[global_contractions])));
    return {};
  }


 private:
  view_dependent_lod(const contraction_hierarchy& h, const cluster_table& table, const lod_options& opt)
      : h_(&h), table_(&table), opt_(opt), work_(make_contraction_workspace(h, opt.grain)),
        neighbours_(make_neighbour_table(h)) {
    const std::size_t c = h.cluster_count;
    area_.resize(c), importance_.resize(c), priority_.resize(c), order_.resize(c), budget_.resize(c), stop_.resize(c);
    capacity_.resize(c), share_.resize(c);
    for (std::uint32_t k = 0; k < h.cluster_count; ++k) capacity_[k] = h.local_capacity(k);
    kept_.resize(h.contraction_count() + 1);
    kept_[0] = h.triangle_count();
    for (std::size_t i = 0; i < h.contraction_count(); ++i) kept_[i + 1] = kept_[i] - h.faces_removed[i];
    if (opt.selection == lod_selection::screen_error)
      patches_ = cluster_patches(table), maxima_ = cluster_error_maxima(h), faces_ = cluster_removed_faces(h);
    if (!opt.keep_hidden) {
      one_sided_ = closed_part_triangles(h.indices, h.positions);
      for (std::uint32_t g : opt.two_sided)
        for (std::uint32_t t = h.triangle_offsets[g]; t < h.triangle_offsets[g + 1]; ++t)
          if (one_sided_[t]) one_sided_[t] = two_sided_face;
      samples_ = make_visibility_samples(h, one_sided_);
      closed_part_bounds(h.indices, h.positions, one_sided_, closed_lo_, closed_hi_);
    }
    opt_.two_sided = {};
  }
  // Eqs. 5–9 (see the top of the file) into budget_ and stop_.
  status paper_stop_points(const glm::dvec3& camera, std::uint64_t global_contractions) {
    if (status s = estimate_view_importance(*table_, camera, area_, importance_); !s.ok()) return s;
    if (global_contractions <= h_->local_contractions) {
      for (std::size_t k = 0; k < priority_.size(); ++k)  // capped: a huge area times a huge importance overflows
        priority_[k] = std::min(area_[k] * importance_[k], std::numeric_limits<double>::max());
      if (status s = distribute_contractions(priority_, capacity_, global_contractions, opt_.lambda_perc, order_, budget_);
          !s.ok())
        return s;
      return stop_points_from_budgets(*h_, budget_, stop_);
    }
    std::fill(stop_.begin(), stop_.end(), static_cast<std::uint32_t>(global_contractions));
    for (std::uint32_t c = 0; c < h_->cluster_count; ++c) budget_[c] = applied_count(*h_, c, stop_[c]);
    return {};
  }
  const contraction_hierarchy* h_;
  const cluster_table* table_;
  lod_options opt_;
  contraction_workspace work_;
  neighbour_table neighbours_;
  std::vector<double> area_, importance_, priority_, share_;  // screen_error: area_ holds k_c
  std::vector<std::uint64_t> kept_;                          // triangles the global prefix of i contractions keeps
  std::vector<std::uint32_t> faces_;                         // cluster_removed_faces
  std::vector<std::uint8_t> one_sided_;                      // per triangle of h.indices: closed_face, two_sided_face or 0
  visibility_samples samples_;
  glm::dvec3 closed_lo_{0.0}, closed_hi_{0.0};                // closed_part_bounds
  std::vector<view_patch> patches_;
  std::vector<float> maxima_;
  std::vector<std::size_t> order_;
  std::vector<std::uint64_t> budget_, capacity_;
  std::vector<std::uint32_t> stop_;
};

}  // namespace infolerp
