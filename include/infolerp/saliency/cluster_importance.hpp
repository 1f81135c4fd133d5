#pragma once
// View-dependent cluster importance and budget distribution (salient-clustering paper §IV.A,
// eqs. 5–9). Per cluster (precomputed once): centroid, area, mean normal, peak normal deviation,
// normal spread (for screen_error_selection.hpp), bounding radius, total/mean/peak saliency. Per view:
//   λ_angle = ∠(v_cam, μ(n_c)) − peak(n_c)          (eq. 5; v_cam from the camera to the centroid,
//                                                    radians, clamped at 0: "very low" visibility)
//   λ_dist  = |x̄_c − p_cam| − r_c                    (eq. 6)
//   A_est   = λ_angle · 1/λ_dist · A_cluster         (eq. 7)
//   I_est   = S_c · peak(S_c) · μ(S_c) / S_mesh       (eq. 8)
// A λ_dist <= 0 (the camera touches or is inside the bounding sphere) is the paper's "zero"
// case: clusters are evaluated in index order and such a cluster uses the last positive λ_dist
// met before it (the first positive one of the view when none came before; 1 if none is).
// Budget (eq. 9): clusters sorted by A_est·I_est ascending (ties: lower index first) each get
// R_local = ceil(λ_perc · R_global) contractions in turn, clamped to what the cluster can still
// take and to what remains of R_global, wrapping around the list until R_global is reached or
// every cluster is full. The engine feeds the per-cluster counts to its own LOD.
// Saliency per face is the mean of its corners' vertex saliencies; a cluster's total is the sum
// over its faces, so the totals add up to S_mesh.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numeric>
#include <span>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/saliency/salient_clustering.hpp"

namespace infolerp {

struct cluster_attributes {
  glm::dvec3 centroid{0.0};        // area-weighted centroid of the cluster's faces
  double area = 0.0;               // total face area
  glm::dvec3 mean_normal{0.0};     // unit area-weighted mean normal (0 when the normals cancel)
  double peak_normal_deviation = 0.0;  // largest angle (radians) between a face normal and mean_normal
  double normal_spread = 0.0;      // acos of the area-weighted mean resultant length of the face normals (0: flat)
  double radius = 0.0;             // bounding sphere about centroid (farthest corner)
  double total_saliency = 0.0;     // Σ face saliency
  double mean_saliency = 0.0;      // total / faces
  double peak_saliency = 0.0;      // largest face saliency
  std::uint32_t faces = 0;
};

struct cluster_table {
  std::vector<cluster_attributes> clusters;
  double mesh_saliency = 0.0;      // S_mesh: Σ face saliency over the whole mesh
};

// Per-cluster attributes. Errors: mesh errors as mean_curvature; saliency.size() != V or
// cluster.size() != T (bad_size); a cluster id >= cluster_count (names the triangle); a
// negative or non-finite saliency (names the vertex). Complexity O(V + T), allocation O(clusters).
// Serial; pure (concurrent calls are safe).
template <class M>
result<cluster_table> compute_cluster_attributes(const M& m, std::span<const double> saliency,
                                                 std::span<const std::uint32_t> cluster, std::uint32_t cluster_count) {
  static_assert(check_mesh<M>());
  if (status s = detail::check_cluster_inputs(m, saliency, cluster, cluster_count); !s.ok()) return s;
  const std::size_t nt = mesh_triangle_count(m);
  cluster_table out;
  auto& cs = out.clusters;
  cs.assign(cluster_count, {});
  std::vector<glm::dvec3> nsum(cluster_count, glm::dvec3(0.0)), csum(cluster_count, glm::dvec3(0.0));
  auto face_saliency = [&](std::size_t t) {
    const glm::uvec3 tri = mesh_triangle(m, t);
    return (saliency[tri.x] + saliency[tri.y] + saliency[tri.z]) / 3.0;
  };
  for (std::size_t t = 0; t < nt; ++t) {
    cluster_attributes& c = cs[cluster[t]];
    const triangle_corners tc = corners(m, t);
    const double a = triangle_area(tc);
    const double s = face_saliency(t);
    c.area += a;
    csum[cluster[t]] += a * triangle_centroid(tc);
    nsum[cluster[t]] += area_vector(tc);
    c.total_saliency += s;
    c.peak_saliency = std::max(c.peak_saliency, s);
    ++c.faces;
    out.mesh_saliency += s;
  }
  for (std::uint32_t k = 0; k < cluster_count; ++k) {
    cluster_attributes& c = cs[k];
    if (c.area > 0.0) c.centroid = csum[k] / c.area;
    const double len = glm::length(nsum[k]);
    if (len > 0.0) c.mean_normal = nsum[k] / len;
    c.normal_spread = c.area > 0.0 ? std::acos(std::clamp(0.5 * len / c.area, 0.0, 1.0)) : 0.0;
    if (c.faces) c.mean_saliency = c.total_saliency / c.faces;
  }
  for (std::size_t t = 0; t < nt; ++t) {
    cluster_attributes& c = cs[cluster[t]];
    const triangle_corners tc = corners(m, t);
    if (c.area <= 0.0) c.centroid = triangle_centroid(tc);  // all faces degenerate: any point of them
    const glm::dvec3 n = glm::dvec3(triangle_normal(tc));
    if (glm::length(n) > 0.0)
      c.peak_normal_deviation = std::max(c.peak_normal_deviation, std::acos(std::clamp(glm::dot(n, c.mean_normal), -1.0, 1.0)));
    for (const glm::dvec3& p : {tc.p0, tc.p1, tc.p2}) c.radius = std::max(c.radius, glm::length(p - c.centroid));
  }
  return out;
}

struct view_importance {
  std::vector<double> area_estimate;        // A_est per cluster (eq. 7)
  std::vector<double> importance_estimate;  // I_est per cluster (eq. 8)
};

// Eq. 8's I_est = S_c · S_peak · S_mean / S_mesh, computed as (S_c / S_mesh) · (S_peak · S_mean)
// with each factor capped at the largest double, so that huge but finite saliency (whose product
// or sums overflow) gives a finite importance; 0 when S_mesh is 0. O(1).
inline double importance_of(const cluster_attributes& c, double mesh_saliency) {
  if (!(mesh_saliency > 0.0)) return 0.0;
  constexpr double top = std::numeric_limits<double>::max();
  double share = c.total_saliency / mesh_saliency;  // in [0, 1]; inf / inf: the cluster holds the overflow
  if (std::isnan(share)) share = 1.0;
  return std::min(top, std::min(share, 1.0) * std::min(top, c.peak_saliency * std::min(top, c.mean_saliency)));
}

// A_est and I_est of every cluster for a camera at camera_position, into caller-owned spans of
// one entry per cluster. Errors: a non-finite camera position (bad_parameter), spans of the
// wrong size (bad_size). Complexity O(clusters); no allocation unless an error is returned.
inline status estimate_view_importance(const cluster_table& table, const glm::dvec3& camera_position,
                                       std::span<double> area_estimate, std::span<double> importance_estimate) {
  if (!all_finite(camera_position))
    return make_error(errc::bad_parameter, no_element, "camera position is not finite");
  const auto& cs = table.clusters;
  if (area_estimate.size() != cs.size() || importance_estimate.size() != cs.size())
    return make_error(errc::bad_size, no_element, "importance spans hold ", area_estimate.size(), " and ",
                      importance_estimate.size(), " entries for ", cs.size(), " clusters");
  double fallback = 1.0;  // λ_dist for a "zero" case with no earlier positive value
  for (const auto& c : cs)
    if (const double d = glm::length(c.centroid - camera_position) - c.radius; d > 0.0) {
      fallback = d;
      break;
    }
  double last = fallback;
  for (std::size_t k = 0; k < cs.size(); ++k) {
    const cluster_attributes& c = cs[k];
    const glm::dvec3 v = c.centroid - camera_position;
    const double vlen = glm::length(v);
    double angle = 0.0;  // ∠(v_cam, μ(n_c)); 0 when either vector vanishes
    if (vlen > 0.0 && glm::length(c.mean_normal) > 0.0)
      angle = std::acos(std::clamp(glm::dot(v / vlen, c.mean_normal), -1.0, 1.0));
    const double lambda_angle = std::max(0.0, angle - c.peak_normal_deviation);
    double lambda_dist = vlen - c.radius;
    if (lambda_dist > 0.0) last = lambda_dist;
    else lambda_dist = last;
    area_estimate[k] = lambda_angle / lambda_dist * c.area;
    importance_estimate[k] = importance_of(c, table.mesh_saliency);
  }
  return {};
}

// The same, returning new vectors. Allocation: the result. Pure, thread-safe.
inline result<view_importance> estimate_view_importance(const cluster_table& table, const glm::dvec3& camera_position) {
  view_importance out;
  out.area_estimate.resize(table.clusters.size());
  out.importance_estimate.resize(table.clusters.size());
  if (status s = estimate_view_importance(table, camera_position, out.area_estimate, out.importance_estimate); !s.ok())
    return s;
  return out;
}

// Eq. (9): contractions per cluster from a global target. priority[k] = A_est·I_est;
// capacity[k] = the most contractions cluster k allows. The result goes to out, with `order`
// as scratch (both one entry per cluster). Errors: sizes differ (bad_size), lambda_perc
// outside (0, 1] or a non-finite priority (bad_parameter). The sum of the result is
// min(global_target, Σ capacity). Complexity O(C log C + C · passes), passes <= 1/lambda_perc + C.
// No allocation unless an error is returned (the sort is in place).
inline status distribute_contractions(std::span<const double> priority, std::span<const std::uint64_t> capacity,
                                      std::uint64_t global_target, double lambda_perc, std::span<std::size_t> order,
                                      std::span<std::uint64_t> out) {
  if (priority.size() != capacity.size())
    return make_error(errc::bad_size, capacity.size(), "priority has ", priority.size(), " entries, capacity ",
                      capacity.size());
  if (order.size() != priority.size() || out.size() != priority.size())
    return make_error(errc::bad_size, out.size(), "order and out hold ", order.size(), " and ", out.size(),
                      " entries for ", priority.size(), " clusters");
  if (!(lambda_perc > 0.0 && lambda_perc <= 1.0))
    return make_error(errc::bad_parameter, no_element, "lambda_perc ", lambda_perc, " must be in (0, 1]");
  for (std::size_t k = 0; k < priority.size(); ++k)
    if (!std::isfinite(priority[k]))
      return make_error(errc::bad_parameter, k, "cluster ", k, ": priority is not finite");
  std::iota(order.begin(), order.end(), std::size_t{0});
  // std::sort does not allocate; equal priorities keep index order (the comparison includes it).
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return priority[a] < priority[b] || (priority[a] == priority[b] && a < b); });
  // A portion at or above 2^64 (global_target near UINT64_MAX) cannot be cast: it is the whole target.
  const double portion = std::ceil(lambda_perc * static_cast<double>(global_target));
  const std::uint64_t step =
      portion >= 0x1p64 ? global_target : std::max<std::uint64_t>(1, static_cast<std::uint64_t>(portion));
  std::fill(out.begin(), out.end(), std::uint64_t{0});
  std::uint64_t remaining = global_target;
  bool progress = true;
  while (remaining > 0 && progress) {
    progress = false;
    for (std::size_t k : order) {
      if (remaining == 0) break;
      const std::uint64_t give = std::min({step, remaining, capacity[k] - out[k]});
      if (give == 0) continue;
      out[k] += give;
      remaining -= give;
      progress = true;
    }
  }
  return {};
}

// The same, returning a new vector. Allocation: the result and a sorted order (O(C)). Pure,
// thread-safe.
inline result<std::vector<std::uint64_t>> distribute_contractions(std::span<const double> priority,
                                                                  std::span<const std::uint64_t> capacity,
                                                                  std::uint64_t global_target, double lambda_perc = 0.02) {
  std::vector<std::size_t> order(priority.size());
  std::vector<std::uint64_t> out(priority.size(), 0);
  if (status s = distribute_contractions(priority, capacity, global_target, lambda_perc, order, out); !s.ok()) return s;
  return out;
}

}  // namespace infolerp
