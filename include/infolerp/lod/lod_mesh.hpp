#pragma once
// The one way into view-dependent multiresolution rendering (salient-clustering paper §III–IV):
// mesh (+ saliency, or none) → a ready LOD that draws at most a budget of triangles per frame.
//
// make_lod_mesh runs the paper's chain with its defaults: mesh saliency (Lee et al., computed
// here when the caller passes none), salient clustering into 10 clusters (§III.A), the
// weighting map (§III.C), the saliency-weighted contraction hierarchy (one global order, the
// default of contraction_hierarchy.hpp), the clusters' attributes (cluster_importance.hpp) and
// view_dependent_lod (its default selection and culling). Each step stays public for an engine
// that stores the hierarchy in its asset pipeline; this is the chain in the order they need.
// lod_mesh owns the hierarchy and the table the view_dependent_lod reads, so it moves freely.
//
// Per frame:
//   std::vector<std::uint32_t> indices(lod.index_bound());
//   std::vector<infolerp::index_range> ranges(lod.range_count());
//   auto st = lod.frame(camera, 20000, indices, ranges);  // at most 20,000 triangles drawn
//   draw(indices.data(), st->indices);                     // ranges: one per cluster
// Allocation: the build's (about 200 bytes per triangle at its peak); frame() allocates nothing.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/view_dependent_lod.hpp"
#include "infolerp/lod/weighting_map.hpp"
#include "infolerp/saliency/cluster_importance.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"

namespace infolerp {

struct lod_mesh_options {
  saliency_options saliency{};               // used when the caller passes no saliency
  salient_clustering_options clustering{};   // clusters = 10, the paper's
  weighting_map_options weighting{};
  simplification_options simplification{};
  lod_options lod{};                         // selection, view weights, culling, two_sided
};

class lod_mesh {
 public:
  // Sizes of frame()'s buffers.
  [[nodiscard]] std::size_t index_bound() const { return contracted_index_bound(*hierarchy_); }
  [[nodiscard]] std::size_t range_count() const { return hierarchy_->cluster_count; }
  // The full mesh's triangle count (the largest useful budget).
  [[nodiscard]] std::size_t triangle_count() const { return hierarchy_->triangle_count(); }
  // One frame: view_dependent_lod::frame (at most `triangles` drawn; errors named there).
  template <class E = serial_executor>
  result<lod_frame_stats> frame(const lod_camera& camera, std::uint64_t triangles, std::span<std::uint32_t> out,
                                std::span<index_range> ranges, E&& exec = E{}) {
    return lod_.frame(camera, triangles, out, ranges, std::forward<E>(exec));
  }
  [[nodiscard]] const contraction_hierarchy& hierarchy() const { return *hierarchy_; }
  [[nodiscard]] const cluster_table& clusters() const { return *table_; }
  [[nodiscard]] view_dependent_lod& lod() { return lod_; }

  lod_mesh(std::unique_ptr<contraction_hierarchy> h, std::unique_ptr<cluster_table> t, view_dependent_lod lod)
      : hierarchy_(std::move(h)), table_(std::move(t)), lod_(std::move(lod)) {}

 private:
  std::unique_ptr<contraction_hierarchy> hierarchy_;  // on the heap: lod_ points at it
  std::unique_ptr<cluster_table> table_;
  view_dependent_lod lod_;
};

// Builds a ready LOD of mesh m. saliency: one value per vertex (compute_saliency's), or empty to
// compute it here with opt.saliency. Errors: those of each step, unchanged (the mesh's, a
// saliency of the wrong size or with a non-finite or negative value, options out of range).
// Complexity: the steps' (saliency and clustering dominate; the hierarchy is O(T log T)).
template <class M, class E = serial_executor>
result<lod_mesh> make_lod_mesh(const M& m, std::span<const double> saliency = {}, const lod_mesh_options& opt = {},
                               E&& exec = E{}) {
  static_assert(check_mesh<M>());
  static_assert(check_executor<std::remove_cvref_t<E>>());
  std::vector<double> computed;
  if (saliency.empty()) {
    auto s = compute_saliency(m, opt.saliency, exec);
    if (!s.ok()) return s.error();
    computed = std::move(s->saliency);
    saliency = computed;
  }
  auto clusters = salient_clustering(m, saliency, opt.clustering, exec);
  if (!clusters.ok()) return clusters.error();
  auto weights = weighting_map(m, saliency, clusters->cluster, clusters->count, opt.weighting, exec);
  if (!weights.ok()) return weights.error();
  auto h = make_contraction_hierarchy(m, *weights, clusters->cluster, clusters->count, opt.simplification);
  if (!h.ok()) return h.error();
  auto table = compute_cluster_attributes(m, saliency, clusters->cluster, clusters->count);
  if (!table.ok()) return table.error();
  auto hp = std::make_unique<contraction_hierarchy>(std::move(*h));
  auto tp = std::make_unique<cluster_table>(std::move(*table));
  auto lod = view_dependent_lod::create(*hp, *tp, opt.lod);
  if (!lod.ok()) return lod.error();
  return lod_mesh(std::move(hp), std::move(tp), std::move(*lod));
}

}  // namespace infolerp
