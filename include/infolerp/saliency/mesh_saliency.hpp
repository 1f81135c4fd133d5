#pragma once
// Mesh saliency (Lee, Varshney, Jacobs, "Mesh Saliency", SIGGRAPH 2005), as used by the
// salient-clustering paper (§III.A, eq. 1):
//
//   G(C, σ)(v) = Σ_{|x−v| ≤ 2σ} C(x) exp(−|x−v|²/(2σ²)) / Σ_{|x−v| ≤ 2σ} exp(−|x−v|²/(2σ²))
//   S_i(v)     = |G(C, σ_i)(v) − G(C, 2σ_i)(v)|                                         (eq. 1)
//   S(v)       = Σ_i N(S_i)(v)
//
// C is the signed mean curvature of mesh/curvature.hpp; the sums run over the mesh's vertices
// (those used by a triangle) in the Euclidean ball of radius 2σ, the vertex itself included.
// σ_i = scales[i]·ε, ε = epsilon × bounding-box diagonal (defaults 2..6 and 0.3%, the paper's).
//
// N is Lee et al.'s non-linear normalisation, pinned down here as:
//   1. scale S_i to [0, 1] by dividing by max(max_v S_i, flat_level_threshold · mean_v |C|)
//      (a level with no structure above the threshold is not stretched: a sphere's rounding
//      noise stays near zero instead of becoming a full-range map);
//   2. M = the scaled maximum; m̄ = mean of the scaled values at local maxima other than the
//      global one (the first vertex attaining M), m̄ = 0 when there is none. A local maximum is a
//      vertex whose value exceeds the value at each 1-ring neighbour (vertices sharing an edge)
//      by more than 1e-12 · max_v S_i, so plateaus (e.g. zero saliency on a flat region) are not
//      maxima, and neither are mathematical ties that rounding splits (a symmetric mesh has many:
//      with a strict comparison, two computations that agree to 1e-14 gave saliencies 1% apart);
//   3. N(S_i) = scaled S_i · (M − m̄)².
//
// The ball sums G are computed one of two ways (saliency_method), both with identical bits for any
// executor and thread count:
//   exact: exact to rounding, every vertex pair within 2σ_max evaluated once with vector code
//     (saliency/detail/gaussian_ball_averages.hpp). Its cost grows with the pairs: on one surface,
//     4x the vertices give 16x the pairs, since σ is a fraction of the bounding box.
//   proxy: the same sums over one proxy per σ, the vertices grouped into cells of edge
//     σ / proxy_cells_per_sigma (saliency/detail/proxy_ball_averages.hpp). Its cost per vertex
//     does not grow with the resolution; its error falls as proxy_cells_per_sigma grows. It is
//     judged by what saliency decides (which vertices are the 10% most salient, the LOD built on
//     it), not by its L2 distance to exact: the hard 2σ edge of the kernel gives exact saliency
//     vertex-scale structure no smooth approximation reproduces (benchmarks/NOTES.md,
//     infolerp_pareto saliency).
//   automatic (the default): exact below exact_below referenced vertices, proxy from there on.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/topology.hpp"
#include "infolerp/saliency/detail/gaussian_ball_averages.hpp"
#include "infolerp/saliency/detail/proxy_ball_averages.hpp"

namespace infolerp {

// How the ball sums are computed (see the top of the file).
enum class saliency_method { automatic, exact, proxy };

namespace detail {
// The option checks that compute_saliency and weighting_map share; who and option name the
// caller and its method option in messages ("saliency", "method"). O(1).
inline status check_saliency_method(saliency_method method, double cells_per_sigma, const char* who, const char* option) {
  if (method != saliency_method::automatic && method != saliency_method::exact && method != saliency_method::proxy)
    return make_error(errc::bad_parameter, no_element, who, " ", option, " ", static_cast<int>(method),
                      " is not automatic, exact or proxy");
  if (!(cells_per_sigma > 0.0) || !std::isfinite(cells_per_sigma))
    return make_error(errc::bad_parameter, no_element, who, " proxy_cells_per_sigma ", cells_per_sigma,
                      " must be positive and finite");
  return {};
}

// The method taken for `referenced` points (automatic: exact below exact_below), after
// check_saliency_method; a proxy whose finest cells (finest_sigma / cells_per_sigma) would pass
// proxy_max_cells along the bounding-box diagonal is a bad_parameter. O(1).
inline result<saliency_method> choose_saliency_method(saliency_method method, std::size_t referenced,
                                                      std::size_t exact_below, double cells_per_sigma,
                                                      double finest_sigma, double diagonal, const char* who) {
  if (method == saliency_method::automatic)
    method = referenced < exact_below ? saliency_method::exact : saliency_method::proxy;
  if (method == saliency_method::proxy && !(diagonal * cells_per_sigma / finest_sigma < proxy_max_cells))
    return make_error(errc::bad_parameter, no_element, who, " proxy_cells_per_sigma ", cells_per_sigma,
                      " makes proxy cells of ", finest_sigma / cells_per_sigma, ", more than ", proxy_max_cells,
                      " along the bounding-box diagonal ", diagonal);
  return method;
}
}  // namespace detail

struct saliency_options {
  double epsilon = 0.003;                          // ε as a fraction of the bounding-box diagonal
  std::vector<double> scales{2.0, 3.0, 4.0, 5.0, 6.0};  // σ_i = scales[i]·ε; each level uses σ_i and 2σ_i
  double flat_level_threshold = 1e-3;              // levels below this × mean|C| are not stretched to [0,1]
  std::size_t grain = 1;                           // tiles of 3 × 3 columns per parallel task
  saliency_method method = saliency_method::automatic;
  std::size_t exact_below = 200000;                // automatic: exact below this many referenced vertices
  double proxy_cells_per_sigma = 4.0;              // proxy: cells per σ along an axis (accuracy against time)
};

struct mesh_saliency {
  std::vector<double> saliency;   // per vertex: Σ_i N(S_i); 0 for vertices no triangle uses
  std::vector<double> curvature;  // per vertex signed mean curvature (the C that was filtered)
  std::vector<std::vector<double>> levels;  // per scale i, per vertex: S_i before normalisation
  double epsilon = 0.0;           // ε in mesh units
  saliency_method method = saliency_method::exact;  // the one used (never automatic)
};

namespace detail {
// One level of Lee's normalisation (see the top of the file): s receives S_i = |G(σ_lo) − G(σ_hi)|
// per vertex (0 where unused) from avg[k · L + u] (L = avg.size() / P); returns the factor N(S_i) = s · factor, or 0 when the level adds
// nothing (flat: its range below `floor`, or so small that 1/range overflows). is_max: scratch of
// V entries. O(V + T), serial.
template <class M>
double normalise_level(const M& m, const vertex_points& grid, const std::vector<char>& used, const std::vector<double>& avg,
                       std::size_t lo, std::size_t hi, double floor, std::vector<double>& s, std::vector<char>& is_max) {
  const std::size_t nv = used.size(), P = grid.x.size(), L = avg.size() / P;
  s.assign(nv, 0.0);
  double mx = 0.0;
  for (std::size_t k = 0; k < P; ++k) {
    s[grid.id[k]] = std::abs(avg[k * L + lo] - avg[k * L + hi]);
    mx = std::max(mx, s[grid.id[k]]);
  }
  const double range = std::max(mx, floor);
  // A flat mesh, or a range so small that 1/range overflows: this level adds nothing.
  if (!(range >= std::numeric_limits<double>::min())) return 0.0;
  const double scale = 1.0 / range, big_m = mx * scale;
  std::size_t global = nv;
  for (std::size_t v = 0; v < nv; ++v) {
    is_max[v] = used[v];
    if (used[v] && global == nv && s[v] == mx) global = v;
  }
  const double tie = 1e-12 * mx;  // differences below this are rounding, not structure
  // The triangles' edges (an edge shared by two triangles is met twice, which changes nothing;
  // the (a, a) side of a degenerate triangle is no edge).
  for (std::size_t t = 0; t < mesh_triangle_count(m); ++t) {
    const glm::uvec3 tri = mesh_triangle(m, t);
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t a = tri[c], b = tri[(c + 1) % 3];
      if (a == b) continue;
      is_max[a] &= static_cast<char>(s[a] > s[b] + tie);  // selects, not branches (unpredictable)
      is_max[b] &= static_cast<char>(s[b] > s[a] + tie);
    }
  }
  double sum_max = 0.0;
  std::size_t count_max = 0;
  for (std::size_t v = 0; v < nv; ++v)
    if (is_max[v] && v != global) sum_max += s[v] * scale, ++count_max;
  const double mbar = count_max ? sum_max / static_cast<double>(count_max) : 0.0;
  return scale * (big_m - mbar) * (big_m - mbar);
}
}  // namespace detail

// Per-vertex mesh saliency of any infolerp::mesh (see the top of this file).
// Errors: empty mesh, index out of range, non-finite position; method not one of the three,
// epsilon <= 0 or not finite, no scales or more than 16 (counted as given, repeats included), a
// scale <= 0 or not finite, flat_level_threshold negative or not finite, proxy_cells_per_sigma
// not positive and finite or (proxy) so large that the finest proxy grid would need 2^21 cells
// along the bounding-box diagonal, a σ (scale × epsilon × diagonal) below ~1.5e-154 or above
// ~3.3e153, where σ² underflows or 16σ² overflows (bad_parameter); a mesh whose bounding box has
// zero diagonal (degenerate_triangle).
// Complexity: exact O(V log V + T + candidate pairs · distinct σs) (candidates: ~1.3× the
// unordered pairs within 2σ_max, each evaluated once); proxy O(V log V + T + σs · (V + proxy
// pairs)), the proxy pairs about (4·proxy_cells_per_sigma)² per proxy point.
// Allocation O(V·σs) (exact: 3 doubles per vertex and distinct σ, 64 at most; proxy: about 6
// more per vertex and σ; never per pair). Parallel through exec; the result is identical for
// every executor and thread count.
template <class M, class E = serial_executor>
result<mesh_saliency> compute_saliency(const M& m, const saliency_options& opt = {}, E&& exec = E{}) {
  static_assert(check_mesh<M>());
  static_assert(check_executor<std::remove_cvref_t<E>>());
  if (!(opt.epsilon > 0.0) || !std::isfinite(opt.epsilon))
    return make_error(errc::bad_parameter, no_element, "saliency epsilon ", opt.epsilon, " must be positive and finite");
  if (opt.scales.empty()) return make_error(errc::bad_parameter, no_element, "saliency needs at least one scale");
  if (opt.scales.size() > 16)
    return make_error(errc::bad_parameter, no_element, "saliency got ", opt.scales.size(),
                      " scales; at most 16 are supported");
  if (!(opt.flat_level_threshold >= 0.0) || !std::isfinite(opt.flat_level_threshold))
    return make_error(errc::bad_parameter, no_element, "saliency flat_level_threshold ", opt.flat_level_threshold,
                      " must be finite and >= 0");
  for (std::size_t i = 0; i < opt.scales.size(); ++i)
    if (!(opt.scales[i] > 0.0) || !std::isfinite(opt.scales[i]))
      return make_error(errc::bad_parameter, i, "saliency scale ", i, " is ", opt.scales[i], "; must be positive and finite");
  if (status s = detail::check_saliency_method(opt.method, opt.proxy_cells_per_sigma, "saliency", "method"); !s.ok())
    return s;
  auto curv = mean_curvature(m);
  if (!curv.ok()) return curv.error();
  const bounding_box box = mesh_bounds(m);
  if (!(box.diagonal() > 0.0))
    return make_error(errc::degenerate_triangle, no_element, "mesh bounding box has zero diagonal");

  mesh_saliency out;
  out.curvature = std::move(*curv);
  out.epsilon = opt.epsilon * box.diagonal();
  const std::size_t nv = mesh_vertex_count(m);

  // Distinct σ multipliers (σ_i and 2σ_i), ascending; level i uses entries lo[i] and hi[i].
  std::vector<double> mult;
  for (double s : opt.scales) mult.push_back(s), mult.push_back(2.0 * s);
  std::sort(mult.begin(), mult.end());
  mult.erase(std::unique(mult.begin(), mult.end()), mult.end());
  std::vector<double> sigma(mult.size());
  for (std::size_t u = 0; u < mult.size(); ++u) {
    sigma[u] = mult[u] * out.epsilon;
    // The Gaussian divides by 2σ²: a σ² that underflows would turn the weights of coincident
    // vertices into NaN (0 · Inf); the ball's squared radius 4σ² must not overflow either (at
    // σ ~5e153 the exact kernel's cutoff became Inf and the averages NaN; fuzzer). 16σ² leaves
    // a factor 4 of headroom.
    const double s2 = sigma[u] * sigma[u];
    if (!(s2 >= std::numeric_limits<double>::min()) || !std::isfinite(16.0 * s2))
      return make_error(errc::bad_parameter, no_element, "saliency sigma ", sigma[u],
                        " (scale x epsilon x bounding-box diagonal) is outside double precision");
  }
  auto index_of = [&](double s) {
    return static_cast<std::size_t>(std::lower_bound(mult.begin(), mult.end(), s) - mult.begin());
  };

  // Referenced vertices only: an unused vertex has no curvature and must not dilute averages.
  const std::vector<char> used = detail::referenced_vertices(m);
  const detail::vertex_points grid = detail::referenced_points(m, used, out.curvature);
  const std::size_t P = grid.x.size();
  const auto method = detail::choose_saliency_method(opt.method, P, opt.exact_below, opt.proxy_cells_per_sigma, sigma[0],
                                                    box.diagonal(), "saliency");
  if (!method.ok()) return method.error();
  out.method = *method;
  const std::vector<double> avg =
      out.method == saliency_method::exact
          ? detail::exact_gaussian_averages(exec, grid, sigma, opt.grain)
          : detail::proxy_gaussian_averages(exec, grid, sigma, opt.proxy_cells_per_sigma, opt.grain);

  // Levels and Lee's normalisation: the levels in parallel (each serially), then their sum per
  // vertex in level order.
  double mean_abs_c = 0.0;
  for (std::size_t k = 0; k < P; ++k) mean_abs_c += std::abs(grid.value[k]);
  mean_abs_c /= static_cast<double>(P);
  const std::size_t levels = opt.scales.size();
  out.levels.resize(levels);
  std::vector<double> factor(levels, 0.0);  // 0 for a level that adds nothing (skipped)
  const double floor = opt.flat_level_threshold * mean_abs_c;
  exec.parallel_for(levels, 1, [&](std::size_t b, std::size_t e) {
    std::vector<char> is_max(nv);
    for (std::size_t i = b; i < e; ++i)
      factor[i] = detail::normalise_level(m, grid, used, avg, index_of(opt.scales[i]), index_of(2.0 * opt.scales[i]), floor,
                                          out.levels[i], is_max);
  });
  out.saliency.assign(nv, 0.0);
  for (std::size_t i = 0; i < levels; ++i)
    if (factor[i] != 0.0)
      for (std::size_t v = 0; v < nv; ++v) out.saliency[v] += out.levels[i][v] * factor[i];
  return out;
}

}  // namespace infolerp
