#pragma once
// Per-view contraction selection by projected error (the default of view_dependent_lod; the
// paper's eqs. 5–9 are the other option, cluster_importance.hpp). Every cluster applies the
// owned contractions whose error, seen from the camera, stays under one threshold τ shared by
// all clusters; τ is chosen so that, after neighbour matching closes the stop points over the
// recorded dependencies (view_selection.hpp: no cracks), the clusters apply at most the frame's
// budget.
//
// Seen error of contraction i owned by cluster c: √error_i · k_c, with error_i the hierarchy's
// cost (a squared distance per unit area, saliency-weighted; contraction_hierarchy.hpp) and
//   k_c = view weight_c · focal / max(|x̄_c − eye| − r_c, near_fraction · r_c)
// the pixels per unit length at the cluster's nearest point (focal = height / (2 tan(fov/2)));
// a camera inside a cluster's bounding sphere sees it at near_fraction · r_c, so the nearest
// clusters are finest and every valid camera gets a LOD. View weight (never 0):
//   hidden_weight      the sphere lies outside the frustum (behind the camera included), or the
//                      cluster's normals (mean normal, spread: the angle whose cosine is their
//                      mean resultant length) all face away from every point of the sphere;
//   silhouette_weight  the normals face both towards and away from the camera;
//   1                  otherwise (the cluster faces the camera).
// A cluster applies a prefix of its owned contractions (in global order): the longest whose
// running maximum of √error · k_c is <= τ, so that budgets grow monotonically with τ. For a
// target, τ is the largest value whose budgets sum to at most the target (bisection over the
// bits of a double: 64 steps of O(C log n)), topped up to the target from the next larger τ.
// Matching only adds contractions and grows with the target, so the target handed to this
// step is bisected (at most 11 rounds: to 1/1024 of the budget) to a target whose matched sum
// fits the budget. Where matching cannot fit the view's choice into half the budget (a cluster's
// first contractions depend on many of the others'), the frame takes the global prefix of the
// budget's length instead: it applies exactly the budget and needs no matching.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/view_selection.hpp"
#include "infolerp/saliency/cluster_importance.hpp"

namespace infolerp {

// A perspective camera and its viewport.
struct lod_camera {
  glm::dvec3 position{0.0};
  glm::dvec3 forward{0.0, 0.0, -1.0};  // viewing direction (any length > 0)
  glm::dvec3 up{0.0, 1.0, 0.0};        // not parallel to forward
  double vertical_fov = 0.8;           // radians, in (0, π)
  std::uint32_t width = 1, height = 1;  // viewport in pixels, > 0
};

struct view_weight_options {
  double hidden_weight = 0.05;     // clusters outside the frustum or facing away, in (0, 1]
  double silhouette_weight = 2.0;  // clusters whose normal cone straddles the view, >= 1
  double near_fraction = 0.1;      // nearest distance, as a fraction of the cluster radius, > 0
};

// Errors: a non-finite field, a zero forward vector, up parallel to forward, fov outside (0, π)
// (bad_parameter, each named); a zero-size viewport (bad_size). O(1).
inline status check_camera(const lod_camera& cam) {
  if (!all_finite(cam.position)) return make_error(errc::bad_parameter, no_element, "camera position is not finite");
  if (!all_finite(cam.forward) || !all_finite(cam.up))
    return make_error(errc::bad_parameter, no_element, "camera forward or up vector is not finite");
  if (!(glm::length(cam.forward) > 0.0)) return make_error(errc::bad_parameter, no_element, "camera forward vector is zero");
  if (!(glm::length(glm::cross(cam.forward, cam.up)) > 1e-12 * glm::length(cam.forward) * glm::length(cam.up)))
    return make_error(errc::bad_parameter, no_element, "camera up vector is zero or parallel to forward");
  if (!(cam.vertical_fov > 0.0 && cam.vertical_fov < 3.14159))
    return make_error(errc::bad_parameter, no_element, "camera vertical_fov ", cam.vertical_fov, " must be in (0, pi)");
  if (cam.width == 0 || cam.height == 0)
    return make_error(errc::bad_size, no_element, "camera viewport ", cam.width, "x", cam.height, " is empty");
  return {};
}

// A region of the mesh as the view weight sees it.
struct view_patch {
  glm::dvec3 centre{0.0};
  double radius = 0.0;
  glm::dvec3 normal{0.0};  // unit mean normal; 0 when unknown (the normals cancel)
  double cone = 0.0;       // largest angle between a normal of the region and `normal`, radians
};

// k_g (see the top of the file) of every patch into k. Preconditions: check_camera(cam)
// passed, options in range, k.size() == patches.size(). O(patches), no allocation.
inline void pixels_per_unit(std::span<const view_patch> patches, const lod_camera& cam, const view_weight_options& opt,
                            std::span<double> k) {
  const glm::dvec3 f = glm::normalize(cam.forward);
  const glm::dvec3 right = glm::normalize(glm::cross(f, cam.up)), up = glm::cross(right, f);
  const double tv = std::tan(0.5 * cam.vertical_fov);
  const double th = tv * static_cast<double>(cam.width) / static_cast<double>(cam.height);
  const double focal = static_cast<double>(cam.height) / (2.0 * tv);
  // Side planes through the eye: a point (x, y, z) in camera space is inside when |x| <= z·th.
  const double ch = 1.0 / std::sqrt(1.0 + th * th), cv = 1.0 / std::sqrt(1.0 + tv * tv);
  constexpr double half_pi = 1.5707963267948966;
  for (std::size_t g = 0; g < patches.size(); ++g) {
    const view_patch& a = patches[g];
    const glm::dvec3 v = a.centre - cam.position;
    const double x = glm::dot(v, right), y = glm::dot(v, up), z = glm::dot(v, f), r = a.radius, d = glm::length(v);
    const bool outside = z < -r || (std::abs(x) - z * th) * ch > r || (std::abs(y) - z * tv) * cv > r;
    double weight = opt.silhouette_weight;  // unknown normals, or the camera inside the sphere
    if (outside) {
      weight = opt.hidden_weight;
    } else if (glm::length(a.normal) > 0.0 && d > r) {
      // The cone widened by the angle the sphere subtends; the patch faces one way when the
      // view direction lies outside both the cone and its opposite.
      const double spread = a.cone + std::asin(r / d);
      const double away = std::acos(std::clamp(glm::dot(v / d, a.normal), -1.0, 1.0));  // 0: facing away
      if (away + spread < half_pi) weight = opt.hidden_weight;
      else if (away - spread > half_pi) weight = 1.0;
    }
    k[g] = weight * focal / std::max({d - r, opt.near_fraction * r, 1e-300});
  }
}

// The view patch of every cluster of a table. O(C), allocation: the result.
inline std::vector<view_patch> cluster_patches(const cluster_table& table) {
  std::vector<view_patch> out;
  out.reserve(table.clusters.size());
  for (const cluster_attributes& c : table.clusters) out.push_back({c.centroid, c.radius, c.mean_normal, c.normal_spread});
  return out;
}

// Per-cluster running maxima of √error over each cluster's owned contractions (aligned with
// h.cluster_contractions). O(contractions), allocation: the result.
inline std::vector<float> cluster_error_maxima(const contraction_hierarchy& h) {
  std::vector<float> out(h.cluster_contractions.size());
  for (std::uint32_t c = 0; c < h.cluster_count; ++c) {
    float m = 0.0f;
    for (std::uint32_t j = h.cluster_offsets[c]; j < h.cluster_offsets[c + 1]; ++j)
      out[j] = m = std::max(m, std::sqrt(std::max(0.0f, h.error[h.cluster_contractions[j]])));
  }
  return out;
}

// Owned contractions of cluster c whose running maximum times k is <= tau. O(log n).
inline std::uint64_t budget_at(const contraction_hierarchy& h, std::span<const float> maxima, std::uint32_t c, double k,
                               double tau) {
  const auto b = maxima.begin() + h.cluster_offsets[c], e = maxima.begin() + h.cluster_offsets[c + 1];
  const double limit = tau / k;
  return static_cast<std::uint64_t>(std::upper_bound(b, e, limit, [](double l, float x) { return l < static_cast<double>(x); }) - b);
}

// Per-cluster budgets summing to min(target, contractions) (see the top of the file). Returns
// the sum. Preconditions: maxima = cluster_error_maxima(h); k and budget one per cluster, every
// k finite and > 0. O(64 · C log n), no allocation.
inline std::uint64_t budgets_for_target(const contraction_hierarchy& h, std::span<const float> maxima,
                                        std::span<const double> k, std::uint64_t target, std::span<std::uint64_t> budget) {
  auto sum_at = [&](double tau) {
    std::uint64_t s = 0;
    for (std::uint32_t c = 0; c < h.cluster_count; ++c) s += budget_at(h, maxima, c, k[c], tau);
    return s;
  };
  // Non-negative doubles order like their bit patterns: bisect over the bits, keeping
  // sum(hi) > target and sum(lo) <= target (none when sum(0) > target already).
  constexpr double inf = std::numeric_limits<double>::infinity();
  const std::uint64_t top = std::bit_cast<std::uint64_t>(inf);
  std::uint64_t lo = 0, hi = top;
  bool below_zero = false;
  if (sum_at(inf) <= target) lo = top;
  else if (sum_at(0.0) > target) below_zero = true, hi = 0;
  while (!below_zero && lo != top && hi - lo > 1) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    (sum_at(std::bit_cast<double>(mid)) <= target ? lo : hi) = mid;
  }
  std::uint64_t sum = 0;
  for (std::uint32_t c = 0; c < h.cluster_count; ++c)
    sum += budget[c] = below_zero ? 0 : budget_at(h, maxima, c, k[c], std::bit_cast<double>(lo));
  if (lo == top) return sum;
  for (std::uint32_t c = 0; c < h.cluster_count && sum < target; ++c) {
    const std::uint64_t more = std::min(target - sum, budget_at(h, maxima, c, k[c], std::bit_cast<double>(hi)) - budget[c]);
    budget[c] += more, sum += more;
  }
  return sum;
}

struct selection_stats {
  std::uint64_t budgeted = 0, applied = 0;
  std::uint32_t rounds = 0;  // budget-and-matching rounds
};

// The frame's stop points (see the top of the file), matched, applying at most `target`
// contractions; k and budget are scratch (one per cluster). Preconditions: check_camera(cam)
// passed, options in range, maxima = cluster_error_maxima(h), spans one per cluster.
// O(11 · (64 · C log n + matching)), no allocation.
inline selection_stats select_for_view(const contraction_hierarchy& h, std::span<const view_patch> patches,
                                       std::span<const float> maxima, const lod_camera& cam,
                                       const view_weight_options& opt, std::uint64_t target, std::span<double> k,
                                       std::span<std::uint64_t> budget, std::span<std::uint32_t> stop) {
  pixels_per_unit(patches, cam, opt, k);
  selection_stats st;
  auto run = [&](std::uint64_t t) {
    st.budgeted = budgets_for_target(h, maxima, k, t, budget);
    (void)stop_points_from_budgets(h, budget, stop);  // budgets never exceed capacities
    match_neighbours(h, stop);
    st.applied = applied_total(h, stop);
    ++st.rounds;
    return st.applied <= target;
  };
  if (run(target)) return st;
  std::uint64_t lo = 0, hi = target;  // run(0) fits: nothing applied
  bool at_lo = false;
  while (hi - lo > std::max<std::uint64_t>(1, target / 1024)) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    at_lo = run(mid);
    (at_lo ? lo : hi) = mid;
  }
  if (!at_lo) run(lo);
  if (st.applied < target / 2) {  // the global prefix (see the top of the file)
    std::fill(stop.begin(), stop.end(), static_cast<std::uint32_t>(target));
    for (std::uint32_t c = 0; c < h.cluster_count; ++c) budget[c] = applied_count(h, c, stop[c]);
    st.budgeted = st.applied = target;
  }
  return st;
}

}  // namespace infolerp
