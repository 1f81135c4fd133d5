#pragma once
// The simplification weighting map (salient-clustering paper §III.C): the cluster-localised
// saliency of eq. 4, smoothed and amplified as Lee, Varshney and Jacobs (2005, §5) prepare
// saliency for weighting quadrics:
//
//   1. smoothing: G(S, σ_s)(v) = Σ_{|x−v| ≤ 2σ_s} S(x) w / Σ w, w = exp(−|x−v|²/2σ_s²), over the
//      referenced vertices (the same Gaussian ball average as mesh_saliency.hpp), σ_s =
//      smoothing_scale · ε, ε = epsilon × bounding-box diagonal (defaults 3 and 0.3%: Lee's 3ε);
//      the ball sums are exact, or (smoothing_method, as compute_saliency's: by default from
//      exact_below referenced vertices on) taken over saliency's proxy
//      (saliency/detail/proxy_ball_averages.hpp), whose cost per vertex does not grow with the
//      resolution while the exact pairs within 2σ_s grow with its square;
//   2. localisation: eq. 4 applied per triangle corner to the smoothed values (min, max and mean
//      over the vertices of the corner's cluster). Eq. 4 is affine per cluster and the Gaussian
//      is linear, so this equals smoothing the localised map, except that the cluster's min, max
//      and mean are those of the smoothed values: the map stays within [μ, μ + 1] per cluster;
//   3. amplification: A(x) = λ·x for x ≥ α, x otherwise, with α the amplify_percentile-th
//      percentile of the corner values (nearest rank) and λ = amplification. Lee et al. use the
//      30th percentile and λ = 100; the default here is λ = 1 (no amplification): with the
//      area-normalised collapse cost of contraction_hierarchy.hpp, the map of steps 1–2 alone
//      already left a smaller saliency-weighted distance than meshoptimizer on bunny00,
//      armadillo and refined_elephant (35% to 1% of the triangles), and larger λ traded it for
//      a larger Hausdorff distance (infolerp_pareto lod --amplification λ measures it;
//      benchmarks/NOTES.md has the figures).
// The result holds one weight per triangle corner (3 per triangle, corner j of triangle t at
// 3t + j): a vertex on a cluster border weights each of its triangles' quadrics with that
// triangle's cluster's value.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"

namespace infolerp {

struct weighting_map_options {
  double epsilon = 0.003;           // ε as a fraction of the bounding-box diagonal
  double smoothing_scale = 3.0;     // σ_s = smoothing_scale · ε; 0 skips the smoothing
  double amplify_percentile = 30.0;  // α: corner values at or above this percentile are amplified, in [0, 100]
  double amplification = 1.0;       // λ >= 1; 1 skips the amplification (Lee et al.: 100)
  std::size_t grain = 1;            // tiles of the Gaussian kernel per parallel task
  saliency_method smoothing_method = saliency_method::automatic;  // exact, proxy, or automatic (see exact_below)
  std::size_t exact_below = 200000;     // automatic: exact smoothing below this many referenced vertices
  double proxy_cells_per_sigma = 4.0;   // proxy: cells per σ_s along an axis (accuracy against time)
};

namespace detail {
// smooth_vertex_values over the referenced points already gathered (grid: values at the
// referenced vertices); the other vertices keep their value.
template <class E>
std::vector<double> smooth_points(E& exec, const vertex_points& grid, std::span<const double> values, double sigma,
                                  std::size_t grain, double proxy_cells_per_sigma) {
  const std::vector<double> avg = proxy_cells_per_sigma > 0.0
                                      ? proxy_gaussian_averages(exec, grid, {sigma}, proxy_cells_per_sigma, grain)
                                      : exact_gaussian_averages(exec, grid, {sigma}, grain);
  std::vector<double> out(values.begin(), values.end());
  for (std::size_t k = 0; k < grid.id.size(); ++k) out[grid.id[k]] = avg[k];
  return out;
}
}  // namespace detail

// Amplification step alone (step 3), in place over the corner values: values >= the
// percentile-th percentile (nearest rank over the sorted values) are multiplied by lambda.
// Preconditions: finite values, percentile in [0, 100]. O(n log n), allocation O(n).
inline void amplify_weights(std::span<double> values, double percentile, double lambda) {
  if (values.empty() || lambda == 1.0) return;
  std::vector<double> sorted(values.begin(), values.end());
  std::sort(sorted.begin(), sorted.end());
  const auto rank = static_cast<std::size_t>(std::ceil(percentile / 100.0 * static_cast<double>(sorted.size())));
  const double alpha = sorted[std::min(sorted.size() - 1, rank == 0 ? 0 : rank - 1)];
  for (double& x : values)
    if (x >= alpha) x *= lambda;
}

// Smoothing step alone (step 1): the Gaussian ball average of per-vertex values with
// σ = sigma (mesh units); unreferenced vertices keep their value. proxy_cells_per_sigma 0: exact
// ball sums, O(pairs within 2σ); > 0: over the proxy with that many cells per σ, O(V log V).
// Precondition: a valid mesh. Errors (bad_parameter): values.size() != V; sigma not positive
// and finite; proxy_cells_per_sigma negative or not finite, or so large that the proxy grid
// would pass detail::proxy_max_cells cells along the bounding-box diagonal (its keys hold 21
// bits per axis). Allocation O(V). Identical bits for any executor.
template <class M, class E = serial_executor>
result<std::vector<double>> smooth_vertex_values(const M& m, std::span<const double> values, double sigma, E&& exec = E{},
                                                 std::size_t grain = 1, double proxy_cells_per_sigma = 0.0) {
  if (values.size() != mesh_vertex_count(m))
    return make_error(errc::bad_parameter, no_element, "smooth_vertex_values: ", values.size(), " values for ",
                      mesh_vertex_count(m), " vertices");
  if (!(sigma > 0.0) || !std::isfinite(sigma))
    return make_error(errc::bad_parameter, no_element, "smooth_vertex_values: sigma ", sigma, " must be positive and finite");
  if (!(proxy_cells_per_sigma >= 0.0) || !std::isfinite(proxy_cells_per_sigma))
    return make_error(errc::bad_parameter, no_element, "smooth_vertex_values: proxy_cells_per_sigma ", proxy_cells_per_sigma,
                      " must be >= 0 and finite");
  if (proxy_cells_per_sigma > 0.0)
    if (auto method = detail::choose_saliency_method(saliency_method::proxy, 0, 0, proxy_cells_per_sigma, sigma,
                                                     mesh_bounds(m).diagonal(), "smooth_vertex_values");
        !method.ok())
      return method.error();
  return detail::smooth_points(exec, detail::referenced_points(m, detail::referenced_vertices(m), values), values, sigma,
                               grain, proxy_cells_per_sigma);
}

// The weighting map: 3 weights per triangle (corner order), every one finite and > 0 when some
// saliency is > 0. Errors: the inputs of cluster_localized_saliency (sizes, negative or
// non-finite saliency naming the vertex, cluster ids); options outside their ranges
// (bad_parameter), or a smoothing σ whose square under- or overflows (bad_parameter); a mesh with
// a zero bounding-box diagonal (degenerate_triangle); a weight that
// overflows double for finite inputs, e.g. saliency near 1e300 or saliency × amplification
// above 1.8e308 (bad_parameter, names the corner).
// Errors also: smoothing_method not one of the three, proxy_cells_per_sigma not positive and
// finite or (proxy) so fine that its grid would pass detail::proxy_max_cells cells along the
// diagonal (bad_parameter).
// Complexity exact O(pairs within 2σ_s + T log T), proxy O(V log V + T log T); allocation O(V + T). Parallel through exec;
// identical bits for any executor.
template <class M, class E = serial_executor>
result<std::vector<double>> weighting_map(const M& m, std::span<const double> saliency,
                                          std::span<const std::uint32_t> cluster, std::uint32_t cluster_count,
                                          const weighting_map_options& opt = {}, E&& exec = E{}) {
  static_assert(check_mesh<M>());
  static_assert(check_executor<std::remove_cvref_t<E>>());
  if (status s = detail::check_cluster_inputs(m, saliency, cluster, cluster_count); !s.ok()) return s;
  if (!(opt.epsilon > 0.0) || !std::isfinite(opt.epsilon))
    return make_error(errc::bad_parameter, no_element, "weighting map epsilon ", opt.epsilon, " must be positive and finite");
  if (!(opt.smoothing_scale >= 0.0) || !std::isfinite(opt.smoothing_scale))
    return make_error(errc::bad_parameter, no_element, "smoothing_scale ", opt.smoothing_scale, " must be >= 0 and finite");
  if (!(opt.amplify_percentile >= 0.0 && opt.amplify_percentile <= 100.0))
    return make_error(errc::bad_parameter, no_element, "amplify_percentile ", opt.amplify_percentile, " must be in [0, 100]");
  if (!(opt.amplification >= 1.0) || !std::isfinite(opt.amplification))
    return make_error(errc::bad_parameter, no_element, "amplification ", opt.amplification, " must be >= 1 and finite");
  if (status s = detail::check_saliency_method(opt.smoothing_method, opt.proxy_cells_per_sigma, "weighting map",
                                               "smoothing_method");
      !s.ok())
    return s;
  std::vector<double> smoothed(saliency.begin(), saliency.end());
  if (opt.smoothing_scale > 0.0) {
    const double diag = mesh_bounds(m).diagonal();
    const double sigma = opt.smoothing_scale * opt.epsilon * diag;
    if (!(sigma * sigma >= std::numeric_limits<double>::min()) || !std::isfinite(16.0 * sigma * sigma))
      return make_error(diag > 0.0 ? errc::bad_parameter : errc::degenerate_triangle, no_element, "smoothing sigma ",
                        sigma, " (smoothing_scale x epsilon x bounding-box diagonal) is outside double precision");
    const detail::vertex_points grid = detail::referenced_points(m, detail::referenced_vertices(m), saliency);
    const auto method = detail::choose_saliency_method(opt.smoothing_method, grid.id.size(), opt.exact_below,
                                                      opt.proxy_cells_per_sigma, sigma, diag, "weighting map");
    if (!method.ok()) return method.error();
    const bool proxy = *method == saliency_method::proxy;
    smoothed = detail::smooth_points(exec, grid, saliency, sigma, opt.grain, proxy ? opt.proxy_cells_per_sigma : 0.0);
  }
  auto local = cluster_localized_saliency(m, std::span<const double>(smoothed), cluster, cluster_count);
  if (!local.ok()) return local.error();
  amplify_weights(*local, opt.amplify_percentile, opt.amplification);
  for (std::size_t k = 0; k < local->size(); ++k)  // finite inputs can still overflow double
    if (!std::isfinite((*local)[k]))
      return make_error(errc::bad_parameter, k, "weighting map: the weight of corner ", k % 3, " of triangle ", k / 3,
                        " overflows double (saliency up to ", *std::max_element(saliency.begin(), saliency.end()),
                        ", amplification ", opt.amplification, "); scale the saliency down");
  return std::move(*local);
}

}  // namespace infolerp
