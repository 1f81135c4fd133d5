#pragma once
// The per-frame entry point of view-dependent multiresolution rendering (salient-clustering
// paper §IV): camera + global contraction budget → index buffer + per-cluster ranges.
//
//   1. A_est, I_est per cluster (eqs. 5–8, cluster_importance.hpp);
//   2. eq. 9: the global budget R_global spread over clusters by A_est·I_est, each cluster
//      clamped to its cluster-local capacity (distribute_contractions; contraction_hierarchy.hpp
//      explains the cluster-local phase). A budget beyond the local phase is a global prefix:
//      every local contraction plus the first R_global − Σ local of the rest, the same for all
//      clusters (a prefix of the global order needs no matching);
//   3. stop points and neighbour matching (view_selection.hpp);
//   4. vertex contraction into the caller's index buffer (vertex_contraction.hpp).
// Each step is usable on its own; this class keeps their buffers between frames, so frame()
// allocates nothing after construction (unless it returns an error). A camera inside every
// cluster's bounding sphere (inside the mesh, for a mesh of one cluster) is refused: no cluster
// has a positive λ_dist (eq. 6) for the paper's "last non-zero value" fallback. Deciding
// whether a camera is inside a mesh of many clusters would cost O(T) per frame; it is not tried
// (clusters with peak normal deviations near π, common on real meshes, make A_est 0 from any
// side, so A_est cannot tell either).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/vertex_contraction.hpp"
#include "infolerp/lod/view_selection.hpp"
#include "infolerp/saliency/cluster_importance.hpp"

namespace infolerp {

struct lod_frame_stats {
  std::size_t indices = 0;              // indices written
  std::uint64_t budgeted = 0;           // Σ per-cluster budgets (= R_global)
  std::uint64_t applied = 0;            // contractions applied after neighbour matching (>= budgeted)
  std::uint32_t matching_sweeps = 0;
};

class view_dependent_lod {
 public:
  // Keeps references to h and table (they must outlive this object). Errors: table with a
  // different cluster count (bad_size), lambda_perc outside (0, 1] (bad_parameter).
  // Allocation O(V + clusters + T / grain).
  static result<view_dependent_lod> create(const contraction_hierarchy& h, const cluster_table& table,
                                           double lambda_perc = 0.02, std::size_t grain = 4096) {
    if (table.clusters.size() != h.cluster_count)
      return make_error(errc::bad_size, table.clusters.size(), "cluster table has ", table.clusters.size(),
                        " clusters, hierarchy ", h.cluster_count);
    if (!(lambda_perc > 0.0 && lambda_perc <= 1.0))
      return make_error(errc::bad_parameter, no_element, "lambda_perc ", lambda_perc, " must be in (0, 1]");
    return view_dependent_lod(h, table, lambda_perc, grain);
  }

  // Total contractions the hierarchy offers (the largest useful R_global).
  [[nodiscard]] std::uint64_t capacity() const { return h_->contraction_count(); }
  // Per-cluster stop points and budgets of the last frame.
  [[nodiscard]] std::span<const std::uint32_t> stop_points() const { return stop_; }
  [[nodiscard]] std::span<const std::uint64_t> budgets() const { return budget_; }

  // One frame. Errors: a non-finite camera, a camera inside every cluster's bounding sphere,
  // global_contractions > capacity() (bad_parameter); out smaller than contracted_index_bound
  // or ranges not one per cluster (bad_size). O(C log C + contractions + kept triangles / threads).
  template <class E = serial_executor>
  result<lod_frame_stats> frame(const glm::dvec3& camera, std::uint64_t global_contractions,
                                std::span<std::uint32_t> out, std::span<index_range> ranges, E&& exec = E{}) {
    static_assert(check_executor<std::remove_cvref_t<E>>());
    if (global_contractions > capacity())
      return make_error(errc::bad_parameter, no_element, "global budget ", global_contractions,
                        " exceeds the hierarchy's ", capacity(), " contractions");
    if (status s = estimate_view_importance(*table_, camera, area_, importance_); !s.ok()) return s;
    bool outside = table_->clusters.empty();
    for (const cluster_attributes& c : table_->clusters) outside = outside || glm::length(c.centroid - camera) > c.radius;
    if (!outside)
      return make_error(errc::bad_parameter, no_element, "camera is inside every cluster's bounding sphere");
    lod_frame_stats st;
    if (global_contractions <= h_->local_contractions) {
      for (std::size_t k = 0; k < priority_.size(); ++k) priority_[k] = area_[k] * importance_[k];
      if (status s = distribute_contractions(priority_, capacity_, global_contractions, lambda_perc_, order_, budget_);
          !s.ok())
        return s;
      if (status s = stop_points_from_budgets(*h_, budget_, stop_); !s.ok()) return s;
    } else {
      std::fill(stop_.begin(), stop_.end(), static_cast<std::uint32_t>(global_contractions));
      for (std::uint32_t c = 0; c < h_->cluster_count; ++c) budget_[c] = applied_count(*h_, c, stop_[c]);
    }
    for (std::uint64_t b : budget_) st.budgeted += b;
    st.matching_sweeps = match_neighbours(*h_, stop_);
    for (std::uint32_t c = 0; c < h_->cluster_count; ++c) st.applied += applied_count(*h_, c, stop_[c]);
    auto n = contract_indices(*h_, stop_, work_, out, ranges, exec);
    if (!n.ok()) return n.error();
    st.indices = *n;
    return st;
  }

 private:
  view_dependent_lod(const contraction_hierarchy& h, const cluster_table& table, double lambda_perc, std::size_t grain)
      : h_(&h), table_(&table), lambda_perc_(lambda_perc), work_(make_contraction_workspace(h, grain)) {
    const std::size_t c = h.cluster_count;
    area_.resize(c), importance_.resize(c), priority_.resize(c), order_.resize(c), budget_.resize(c), stop_.resize(c);
    capacity_.resize(c);
    for (std::uint32_t k = 0; k < h.cluster_count; ++k) capacity_[k] = h.local_capacity(k);
  }
  const contraction_hierarchy* h_;
  const cluster_table* table_;
  double lambda_perc_;
  contraction_workspace work_;
  std::vector<double> area_, importance_, priority_;
  std::vector<std::size_t> order_;
  std::vector<std::uint64_t> budget_, capacity_;
  std::vector<std::uint32_t> stop_;
};

}  // namespace infolerp
