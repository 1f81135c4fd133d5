#pragma once
// Per-view contraction selection by projected error (the default of view_dependent_lod; the
// paper's eqs. 5–9 are the other option, cluster_importance.hpp). Every cluster applies the
// owned contractions whose error, seen from the camera, stays under one threshold τ shared by
// all clusters; τ is chosen so that, after neighbour matching closes the stop points over the
// recorded dependencies (view_selection.hpp: no cracks), the frame draws at most its budget of
// triangles.
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
// running maximum of √error · k_c is <= τ, so that budgets grow monotonically with τ. The frame
// draws what each cluster keeps times its seen share s_c (1 when nothing is culled), so for a
// count of triangles to draw, τ is the largest value whose seen removal Σ_c s_c · (triangles
// c's budget removes) stays within Σ_c s_c·T_c minus that count (bisection over the bits of a
// double: 64 steps of O(C log n)), topped up from the next larger τ. A cluster with s_c = 0
// costs nothing drawn and takes the facing weight, so that it is not simplified past its
// neighbours only to drag them through matching. Matching only adds contractions, so the goal
// handed to this step is bisected (at most 12 rounds: to 1/1024) to the smallest whose matched
// removal reaches the frame's; the cut just short of it is then raised to at least the shortest
// global prefix that reaches it (a prefix is closed over its dependencies, and so is the
// maximum of two closed cuts: no matching needed), so that the count is met to one contraction.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"
#include "infolerp/core/unit_vector.hpp"
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
// (bad_parameter, each named); a zero-size viewport (bad_size). Any finite length of forward and
// up is fine (they are scaled before they are normalised). O(1).
inline status check_camera(const lod_camera& cam) {
  if (!all_finite(cam.position)) return make_error(errc::bad_parameter, no_element, "camera position is not finite");
  if (!all_finite(cam.forward) || !all_finite(cam.up))
    return make_error(errc::bad_parameter, no_element, "camera forward or up vector is not finite");
  const glm::dvec3 f = unit_or_zero(cam.forward), u = unit_or_zero(cam.up);
  if (f == glm::dvec3(0.0)) return make_error(errc::bad_parameter, no_element, "camera forward vector is zero");
  if (u == glm::dvec3(0.0)) return make_error(errc::bad_parameter, no_element, "camera up vector is zero");
  if (!(glm::length(glm::cross(f, u)) > 1e-12))
    return make_error(errc::bad_parameter, no_element, "camera up vector is parallel to forward");
  if (!(cam.vertical_fov > 0.0 && cam.vertical_fov < std::numbers::pi))
    return make_error(errc::bad_parameter, no_element, "camera vertical_fov ", cam.vertical_fov, " must be in (0, pi)");
  if (cam.width == 0 || cam.height == 0)
    return make_error(errc::bad_size, no_element, "camera viewport ", cam.width, "x", cam.height, " is empty");
  return {};
}

// The camera's unit forward, right and up vectors. Preconditions: check_camera(cam) passed. O(1).
struct camera_basis {
  glm::dvec3 forward, right, up;
};
inline camera_basis make_camera_basis(const lod_camera& cam) {
  const glm::dvec3 f = unit_or_zero(cam.forward);
  const glm::dvec3 right = unit_or_zero(glm::cross(f, unit_or_zero(cam.up)));
  return {f, right, glm::cross(right, f)};
}

// A region of the mesh as the view weight sees it.
struct view_patch {
  glm::dvec3 centre{0.0};
  double radius = 0.0;
  glm::dvec3 normal{0.0};  // unit mean normal; 0 when unknown (the normals cancel)
  double cone = 0.0;       // largest angle between a normal of the region and `normal`, radians
};

// k_g (see the top of the file) of the patches listed in `active` into k (others untouched).
// Preconditions: check_camera(cam) passed, options in range, k.size() == patches.size(), active
// entries < patches.size(). O(active), no allocation.
inline void pixels_per_unit(std::span<const view_patch> patches, std::span<const std::uint32_t> active,
                            const lod_camera& cam, const view_weight_options& opt, std::span<double> k) {
  const auto [f, right, up] = make_camera_basis(cam);
  const double tv = std::tan(0.5 * cam.vertical_fov);
  const double th = tv * static_cast<double>(cam.width) / static_cast<double>(cam.height);
  const double focal = static_cast<double>(cam.height) / (2.0 * tv);
  // Side planes through the eye: a point (x, y, z) in camera space is inside when |x| <= z·th.
  const double ch = 1.0 / std::sqrt(1.0 + th * th), cv = 1.0 / std::sqrt(1.0 + tv * tv);
  constexpr double half_pi = 1.5707963267948966;
  for (const std::uint32_t g : active) {
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
    // Clamped to positive finite values: a camera farther than a double's length (d = inf) sees
    // the coarsest level, not a 0 that budget_at would divide by.
    k[g] = std::clamp(weight * focal / std::max({d - r, opt.near_fraction * r, 1e-300}), std::numeric_limits<double>::min(),
                      std::numeric_limits<double>::max());
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

// Per-cluster prefix sums of the triangles its owned contractions remove (faces_removed, aligned
// with h.cluster_contractions). O(contractions), allocation: the result.
inline std::vector<std::uint32_t> cluster_removed_faces(const contraction_hierarchy& h) {
  std::vector<std::uint32_t> out(h.cluster_contractions.size());
  for (std::uint32_t c = 0; c < h.cluster_count; ++c) {
    std::uint32_t n = 0;
    for (std::uint32_t j = h.cluster_offsets[c]; j < h.cluster_offsets[c + 1]; ++j)
      out[j] = n += h.faces_removed[h.cluster_contractions[j]];
  }
  return out;
}

// Triangles the first b owned contractions of cluster c remove. O(1).
inline std::uint64_t removed_at(const contraction_hierarchy& h, std::span<const std::uint32_t> faces, std::uint32_t c,
                                std::uint64_t b) {
  return b == 0 ? 0 : faces[h.cluster_offsets[c] + b - 1];
}

// Owned contractions of cluster c whose running maximum times k is <= tau. O(log n).
inline std::uint64_t budget_at(const contraction_hierarchy& h, std::span<const float> maxima, std::uint32_t c, double k,
                               double tau) {
  const auto b = maxima.begin() + h.cluster_offsets[c], e = maxima.begin() + h.cluster_offsets[c + 1];
  const double limit = tau / k;
  return static_cast<std::uint64_t>(std::upper_bound(b, e, limit, [](double l, float x) { return l < static_cast<double>(x); }) - b);
}

// Per-cluster budgets for the largest τ whose seen removal Σ_c share_c · removed_at(c, b_c)
// stays within `goal` (see the top of the file), topped up from the budgets at the next larger
// τ as far as the goal allows (none when even τ = 0 removes more). Returns the seen removal.
// Only the clusters in `active` (those holding triangles, neighbour_table::active) are visited;
// the others' budgets are left as they are. Preconditions: maxima = cluster_error_maxima(h),
// faces = cluster_removed_faces(h); k, share and budget one per cluster, every active k finite
// and > 0, shares in [0, 1]. O(64 · active · log n), no allocation.
inline double budgets_for_removal(const contraction_hierarchy& h, std::span<const std::uint32_t> active,
                                  std::span<const float> maxima,
                                  std::span<const std::uint32_t> faces, std::span<const double> k,
                                  std::span<const double> share, double goal, std::span<std::uint64_t> budget) {
  auto seen = [&](std::uint32_t c, std::uint64_t b) { return share[c] * static_cast<double>(removed_at(h, faces, c, b)); };
  // During the bisection budget[c] holds c's budgets at lo (low 32 bits) and hi (high 32 bits;
  // capacities fit, orders being 32-bit): budgets grow with τ, so budget_at at a τ between them
  // lies between them and is searched for there.
  auto between = [&](std::uint32_t c, double tau) {
    const auto b = maxima.begin() + h.cluster_offsets[c];
    const double limit = tau / k[c];  // as budget_at
    return static_cast<std::uint64_t>(std::upper_bound(b + static_cast<long>(budget[c] & 0xffffffffu),
                                                       b + static_cast<long>(budget[c] >> 32), limit,
                                                       [](double l, float x) { return l < static_cast<double>(x); }) - b);
  };
  auto sum_at = [&](double tau) {
    double s = 0.0;
    for (const std::uint32_t c : active) s += seen(c, budget_at(h, maxima, c, k[c], tau));
    return s;
  };
  // Non-negative doubles order like their bit patterns: bisect over the bits, keeping
  // sum(lo) <= goal < sum(hi) (none when sum(0) > goal already).
  constexpr double inf = std::numeric_limits<double>::infinity();
  const std::uint64_t top = std::bit_cast<std::uint64_t>(inf);
  std::uint64_t lo = 0, hi = top;
  bool below_zero = false;
  if (sum_at(inf) <= goal) lo = top;
  else if (sum_at(0.0) > goal) below_zero = true, hi = 0;
  for (const std::uint32_t c : active) budget[c] = budget_at(h, maxima, c, k[c], 0.0) | h.capacity(c) << 32;
  while (!below_zero && lo != top && hi - lo > 1) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    double s = 0.0;
    for (const std::uint32_t c : active) s += seen(c, between(c, std::bit_cast<double>(mid)));
    const bool below = s <= goal;
    for (const std::uint32_t c : active) {  // the budget at mid bounds its side
      const std::uint64_t m = between(c, std::bit_cast<double>(mid));
      budget[c] = below ? (budget[c] >> 32 << 32) | m : (budget[c] & 0xffffffffu) | m << 32;
    }
    (below ? lo : hi) = mid;
  }
  double sum = 0.0;
  for (const std::uint32_t c : active)
    sum += seen(c, budget[c] = below_zero ? 0 : budget_at(h, maxima, c, k[c], std::bit_cast<double>(lo)));
  if (lo == top) return sum;
  for (const std::uint32_t c : active) {
    const std::uint64_t more = budget_at(h, maxima, c, k[c], std::bit_cast<double>(hi));
    if (more <= budget[c]) continue;
    if (share[c] <= 0.0) {  // costs nothing drawn
      budget[c] = more;
      continue;
    }
    // The most further contractions of c whose removal still fits the goal.
    const double room = static_cast<double>(removed_at(h, faces, c, budget[c])) + (goal - sum) / share[c];
    const auto b = faces.begin() + h.cluster_offsets[c];
    const auto at = std::upper_bound(b + static_cast<long>(budget[c]), b + static_cast<long>(more), room,
                                     [](double r, std::uint32_t f) { return r < static_cast<double>(f); });
    const auto nb = static_cast<std::uint64_t>(at - b);
    sum += seen(c, nb) - seen(c, budget[c]);
    budget[c] = nb;
  }
  return sum;
}

struct selection_stats {
  std::uint64_t budgeted = 0, applied = 0;
  double drawn = 0.0;       // the estimated triangles drawn: Σ share_c · (T_c − removed_c)
  std::uint32_t rounds = 0;  // budget-and-matching rounds
};

// The frame's stop points (see the top of the file), matched, drawing an estimated at most
// `triangles` (to about 1/1024 of the triangles to remove): cluster c of T_c triangles draws
// share_c of those it keeps: the view's cut whose matched removal falls just short, raised to
// the shortest global prefix that reaches the count (the coarsest cut if none does). k and budget are
// scratch (one per cluster). Preconditions: check_camera(cam) passed, options in range, maxima
// = cluster_error_maxima(h), faces = cluster_removed_faces(h), spans one per cluster, shares in
// [0, 1], neighbours = make_neighbour_table(h). Only neighbours.active clusters are visited;
// stop points of the others are 0. O(12 · (64 · A log n + matching)) for A active clusters,
// no allocation.
inline selection_stats select_for_view(const contraction_hierarchy& h, const neighbour_table& neighbours,
                                       std::span<const view_patch> patches,
                                       std::span<const float> maxima, std::span<const std::uint32_t> faces,
                                       const lod_camera& cam, const view_weight_options& opt,
                                       std::span<const double> share, std::uint64_t triangles,
                                       std::span<double> k, std::span<std::uint64_t> budget,
                                       std::span<std::uint32_t> stop) {
  const std::span<const std::uint32_t> active = neighbours.active;
  pixels_per_unit(patches, active, cam, opt, k);
  // A cluster the camera cannot see costs no triangle drawn; simplifying it past its neighbours
  // would only drag them coarser through matching, so it is weighted as if it faced the camera.
  for (const std::uint32_t c : active)
    if (share[c] == 0.0 && k[c] < std::numeric_limits<double>::max()) k[c] /= opt.hidden_weight;
  double seen_total = 0.0;
  for (const std::uint32_t c : active)
    seen_total += share[c] * static_cast<double>(h.triangle_offsets[c + 1] - h.triangle_offsets[c]);
  const double goal = seen_total - static_cast<double>(triangles);  // the seen removal needed
  selection_stats st;
  st.drawn = seen_total;
  for (const std::uint32_t c : active) stop[c] = 0, budget[c] = 0;
  if (goal <= 0.0) return st;
  auto run = [&](double g) {
    (void)budgets_for_removal(h, active, maxima, faces, k, share, g, budget);
    st.budgeted = 0;
    for (const std::uint32_t c : active) st.budgeted += budget[c];
    for (const std::uint32_t c : active)  // budgets never exceed capacities
      stop[c] = budget[c] == 0 ? 0 : h.cluster_contractions[h.cluster_offsets[c] + budget[c] - 1] + 1;
    match_neighbours(neighbours, stop);
    double removed = 0.0;
    st.applied = 0;
    for (const std::uint32_t c : active) {
      const std::uint64_t a = applied_count(h, c, stop[c]);
      st.applied += a;
      removed += share[c] * static_cast<double>(removed_at(h, faces, c, a));
    }
    st.drawn = seen_total - removed;
    ++st.rounds;
    return removed >= goal;
  };
  // Matching only adds contractions, so the goal handed to the budgets is bisected (to 1/1024)
  // between the largest whose matched removal falls short of the frame's (lo) and the smallest
  // that reaches it (hi).
  double lo = 0.0, hi = goal;
  bool lo_run = false, at_lo = false;  // lo has been run; the last run was lo's
  if (!run(goal)) {
    lo_run = true, lo = goal, hi = seen_total;
    if ((at_lo = !run(hi))) lo = hi;  // matching never reaches the goal: the top-up below does
  }
  while (hi - lo > std::max(1.0, goal / 1024.0)) {
    const double mid = 0.5 * (lo + hi);
    at_lo = !run(mid);
    (at_lo ? lo : hi) = mid;
    lo_run = lo_run || at_lo;
  }
  // Top-up: lo's cut (none when lo was never run) raised to at least a global prefix P, the
  // shortest that reaches the goal. The maximum of two dependency-closed stop vectors is closed,
  // and so is a prefix, so no matching is needed; a prefix step is one contraction, so the
  // frame's estimate lands within a contraction of its count. budget holds lo's stop points.
  if (lo_run && !at_lo) run(lo);
  for (const std::uint32_t c : active) budget[c] = lo_run ? stop[c] : 0;
  auto removal_at = [&](std::uint32_t p) {
    double removed = 0.0;
    for (const std::uint32_t c : active)
      removed += share[c] * static_cast<double>(removed_at(h, faces, c, applied_count(h, c, std::max(static_cast<std::uint32_t>(budget[c]), p))));
    return removed;
  };
  std::uint32_t lo_p = 0, hi_p = static_cast<std::uint32_t>(h.contraction_count());
  while (lo_p < hi_p) {
    const std::uint32_t mid = lo_p + (hi_p - lo_p) / 2;
    if (removal_at(mid) >= goal) hi_p = mid;
    else lo_p = mid + 1;
  }
  st.drawn = seen_total - removal_at(lo_p);
  st.applied = 0;
  for (const std::uint32_t c : active) {
    stop[c] = std::max(static_cast<std::uint32_t>(budget[c]), lo_p);
    st.applied += budget[c] = applied_count(h, c, stop[c]);
  }
  return st;
}

}  // namespace infolerp
