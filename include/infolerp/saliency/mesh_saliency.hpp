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
//      vertex whose value is strictly greater than at each 1-ring neighbour (vertices sharing an
//      edge), so plateaus (e.g. zero saliency on a flat region) are not maxima;
//   3. N(S_i) = scaled S_i · (M − m̄)².
//
// Exact mode: vertices are sorted into a uniform grid with cells at least 2σ_max wide; each
// pair of vertices within 2σ_max is visited once (same cell, or one of 13 forward neighbour
// cells) and adds its Gaussian weights to both ends for every distinct σ whose ball holds it
// (σ_i and 2σ_i: 8 distinct values for the default scales), all in one pass. Memory O(V·σs):
// per vertex and distinct σ a numerator and denominator; pairs are never stored.
// Determinism: cells are coloured (x mod 2, y mod 3, z mod 3); cells of one colour write to
// disjoint vertex sets, and each colour runs as one parallel_for. Every accumulator therefore
// receives its terms in a fixed order: identical bits for any executor and thread count.
// The Gaussian uses a polynomial exp valid on [−2, 0] (the only range the ball cutoff produces),
// relative error below 1e-15.
//
// Approximate mode (method = approximate): the ball sums are taken over cell representatives
// instead of vertices. For each distinct σ the vertices are binned into cells of size
// σ / approx_cells_per_sigma (sparse: sorted 63-bit cell keys); a representative sits at its
// vertices' centroid and carries their count, curvature sum and RMS spread. Each vertex sums
// exp(−d²/2σ²)·(count, sum C) over representatives near its ball; a representative straddling
// the 2σ edge counts with a linear ramp over ±1.5 × its spread (a single vertex keeps the hard
// cutoff), which removes most of the in/out error of whole cells.
// Measured relative L2 error of the final saliency against exact (default 3 cells per σ):
// 0.5% on a 10k-vertex bumpy sphere (tests), but 6.2% on refined_elephant subdivided once
// (9.6% at 1 cell/σ, 7.9% at 2), where Lee's local-maxima normalisation amplifies small level
// errors. Note the normalisation is discontinuous: a 1e-15 change of a level can flip a local
// maximum (exact ties on symmetric meshes), so even exact-to-rounding levels differ by ~0.3%.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/topology.hpp"

namespace infolerp {

enum class saliency_method : std::uint8_t {
  exact,        // every vertex pair within 2σ (matches the O(V²) definition to rounding)
  approximate,  // cell representatives per σ (see the top of this file)
};

struct saliency_options {
  double epsilon = 0.003;                          // ε as a fraction of the bounding-box diagonal
  std::vector<double> scales{2.0, 3.0, 4.0, 5.0, 6.0};  // σ_i = scales[i]·ε; each level uses σ_i and 2σ_i
  double flat_level_threshold = 1e-3;              // levels below this × mean|C| are not stretched to [0,1]
  saliency_method method = saliency_method::exact;  // exact or approximate
  double approx_cells_per_sigma = 3.0;             // approximate mode: representative cells per σ (>= 0.5)
  std::size_t grain = 1;                           // cells per parallel task (exact) ×256 vertices (approximate)
};

struct mesh_saliency {
  std::vector<double> saliency;   // per vertex: Σ_i N(S_i); 0 for vertices no triangle uses
  std::vector<double> curvature;  // per vertex signed mean curvature (the C that was filtered)
  std::vector<std::vector<double>> levels;  // per scale i, per vertex: S_i before normalisation
  double epsilon = 0.0;           // ε in mesh units
};

namespace detail {

// exp(x) for x in [−2, 0]: Taylor polynomial of exp(x/8) (|x/8| ≤ 1/4, degree 11, truncation
// < 2e-16) raised to the 8th power. Branch-free, relative error ~1e-15.
inline double exp_neg2(double x) {
  const double y = x * 0.125;
  double p = 1.0 / 39916800.0;
  p = p * y + 1.0 / 3628800.0;
  p = p * y + 1.0 / 362880.0;
  p = p * y + 1.0 / 40320.0;
  p = p * y + 1.0 / 5040.0;
  p = p * y + 1.0 / 720.0;
  p = p * y + 1.0 / 120.0;
  p = p * y + 1.0 / 24.0;
  p = p * y + 1.0 / 6.0;
  p = p * y + 0.5;
  p = p * y + 1.0;
  p = p * y + 1.0;
  p *= p;
  p *= p;
  return p * p;
}

// Points (x, y, z, value, weight) sorted by the cell of a uniform grid, cells at least
// `min_cell` wide (wider when needed to keep the cell count O(points)).
struct point_grid {
  std::vector<double> x, y, z, value, weight;
  std::vector<std::uint32_t> id;          // caller's id of each sorted point
  std::vector<std::uint32_t> cell_start;  // cells + 1 offsets into the sorted points
  glm::dvec3 lo{0.0};
  double cell = 1.0;
  std::array<std::uint32_t, 3> n{1, 1, 1};

  std::uint32_t cell_index(std::uint32_t cx, std::uint32_t cy, std::uint32_t cz) const {
    return (cx * n[1] + cy) * n[2] + cz;
  }
  std::uint32_t coord(double p, int axis) const {
    const double f = std::floor((p - lo[axis]) / cell);
    return f <= 0.0 ? 0u : static_cast<std::uint32_t>(std::min<double>(f, n[static_cast<std::size_t>(axis)] - 1));
  }
};

// Builds a point_grid over pts (positions), values, weights. Counting sort: O(P + cells).
inline point_grid make_point_grid(const std::vector<glm::dvec3>& pts, const std::vector<double>& values,
                                  const std::vector<double>& weights, const std::vector<std::uint32_t>& ids,
                                  double min_cell) {
  point_grid g;
  bounding_box box;
  for (const auto& p : pts) box.extend(p);
  g.lo = box.empty() ? glm::dvec3(0.0) : box.lo;
  const glm::dvec3 ext = box.empty() ? glm::dvec3(0.0) : box.hi - box.lo;
  const double max_cells = 4.0 * static_cast<double>(pts.size()) + 64.0;
  double h = min_cell > 0.0 ? min_cell : 1.0;
  for (;;) {
    double total = 1.0;
    for (int a = 0; a < 3; ++a) total *= std::max(1.0, std::floor(ext[a] / h));
    if (total <= max_cells) break;
    h *= 1.25;
  }
  g.cell = h;
  for (int a = 0; a < 3; ++a) g.n[static_cast<std::size_t>(a)] = static_cast<std::uint32_t>(std::max(1.0, std::floor(ext[a] / h)));
  // Cells are floor(ext/h) wide in count, so the last one may be up to 2h wide: still >= h.
  const std::size_t cells = std::size_t{g.n[0]} * g.n[1] * g.n[2];
  std::vector<std::uint32_t> cell_of(pts.size());
  g.cell_start.assign(cells + 1, 0);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    cell_of[i] = g.cell_index(g.coord(pts[i].x, 0), g.coord(pts[i].y, 1), g.coord(pts[i].z, 2));
    ++g.cell_start[cell_of[i] + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) g.cell_start[c + 1] += g.cell_start[c];
  std::vector<std::uint32_t> cursor(g.cell_start.begin(), g.cell_start.end() - 1);
  g.x.resize(pts.size()), g.y.resize(pts.size()), g.z.resize(pts.size());
  g.value.resize(pts.size()), g.weight.resize(pts.size()), g.id.resize(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const std::uint32_t k = cursor[cell_of[i]]++;
    g.x[k] = pts[i].x, g.y[k] = pts[i].y, g.z[k] = pts[i].z;
    g.value[k] = values[i], g.weight[k] = weights[i], g.id[k] = ids[i];
  }
  return g;
}

// Exact Gaussian-weighted averages for L ascending radii sigma[u] (ball 2σ) over the grid's
// points (weights are 1). Returns avg[u * P + k] for sorted point k. Needs grid cells >= 2σ_max.
template <class E>
std::vector<double> exact_gaussian_averages(E& exec, const point_grid& g, const std::vector<double>& sigma,
                                            std::size_t grain) {
  const std::size_t P = g.x.size(), L = sigma.size();
  std::vector<double> r2(L), a(L);
  for (std::size_t u = 0; u < L; ++u) r2[u] = 4.0 * sigma[u] * sigma[u], a[u] = 1.0 / (2.0 * sigma[u] * sigma[u]);
  const double r2max = r2[L - 1];
  // acc[k*2L + 2u] = numerator, +1 = denominator; the vertex itself contributes weight 1.
  std::vector<double> acc(P * 2 * L);
  for (std::size_t k = 0; k < P; ++k)
    for (std::size_t u = 0; u < L; ++u) acc[k * 2 * L + 2 * u] = g.value[k], acc[k * 2 * L + 2 * u + 1] = 1.0;

  // Lexicographically positive neighbour offsets: each unordered cell pair once.
  static constexpr int forward[13][3] = {{1, -1, -1}, {1, -1, 0}, {1, -1, 1}, {1, 0, -1}, {1, 0, 0},
                                         {1, 0, 1},   {1, 1, -1}, {1, 1, 0},  {1, 1, 1},  {0, 1, -1},
                                         {0, 1, 0},   {0, 1, 1},  {0, 0, 1}};
  auto process_cell = [&](std::uint32_t cx, std::uint32_t cy, std::uint32_t cz) {
    const std::uint32_t c = g.cell_index(cx, cy, cz);
    const std::uint32_t b0 = g.cell_start[c], b1 = g.cell_start[c + 1];
    std::array<std::pair<std::uint32_t, std::uint32_t>, 14> ranges{};
    std::size_t nr = 0;
    for (const auto& o : forward) {
      const long long nx = static_cast<long long>(cx) + o[0], ny = static_cast<long long>(cy) + o[1], nz = static_cast<long long>(cz) + o[2];
      if (nx >= g.n[0] || ny < 0 || ny >= g.n[1] || nz < 0 || nz >= g.n[2]) continue;
      const std::uint32_t d = g.cell_index(static_cast<std::uint32_t>(nx), static_cast<std::uint32_t>(ny),
                                           static_cast<std::uint32_t>(nz));
      if (g.cell_start[d] != g.cell_start[d + 1]) ranges[nr++] = {g.cell_start[d], g.cell_start[d + 1]};
    }
    std::array<double, 64> local{};
    for (std::uint32_t i = b0; i < b1; ++i) {
      std::fill(local.begin(), local.begin() + static_cast<std::ptrdiff_t>(2 * L), 0.0);
      const double xi = g.x[i], yi = g.y[i], zi = g.z[i], ci = g.value[i];
      auto visit = [&](std::uint32_t j0, std::uint32_t j1) {
        for (std::uint32_t j = j0; j < j1; ++j) {
          const double dx = g.x[j] - xi, dy = g.y[j] - yi, dz = g.z[j] - zi;
          const double d2 = dx * dx + dy * dy + dz * dz;
          if (d2 > r2max) continue;
          const double cj = g.value[j];
          double* aj = &acc[std::size_t{j} * 2 * L];
          for (std::size_t u = L; u-- > 0;) {
            if (d2 > r2[u]) break;
            const double w = exp_neg2(-d2 * a[u]);
            local[2 * u] += w * cj;
            local[2 * u + 1] += w;
            aj[2 * u] += w * ci;
            aj[2 * u + 1] += w;
          }
        }
      };
      visit(i + 1, b1);
      for (std::size_t r = 0; r < nr; ++r) visit(ranges[r].first, ranges[r].second);
      double* ai = &acc[std::size_t{i} * 2 * L];
      for (std::size_t u = 0; u < 2 * L; ++u) ai[u] += local[u];
    }
  };
  // 18 colours; cells of one colour write to disjoint vertex sets (see the top of the file).
  std::vector<std::uint32_t> cells;
  for (std::uint32_t colour = 0; colour < 18; ++colour) {
    cells.clear();
    for (std::uint32_t cx = colour / 9; cx < g.n[0]; cx += 2)
      for (std::uint32_t cy = (colour / 3) % 3; cy < g.n[1]; cy += 3)
        for (std::uint32_t cz = colour % 3; cz < g.n[2]; cz += 3) {
          const std::uint32_t c = g.cell_index(cx, cy, cz);
          if (g.cell_start[c] != g.cell_start[c + 1]) cells.push_back(c);
        }
    exec.parallel_for(cells.size(), std::max<std::size_t>(grain, 1), [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        const std::uint32_t c = cells[k];
        process_cell(c / (g.n[1] * g.n[2]), (c / g.n[2]) % g.n[1], c % g.n[2]);
      }
    });
  }
  std::vector<double> avg(L * P);
  for (std::size_t k = 0; k < P; ++k)
    for (std::size_t u = 0; u < L; ++u) avg[u * P + k] = acc[k * 2 * L + 2 * u] / acc[k * 2 * L + 2 * u + 1];
  return avg;
}

// Approximate averages: per σ, representatives of cells σ/cells_per_sigma wide, gathered per
// vertex over the representatives within 2σ. Parallel over vertices; deterministic.
template <class E>
std::vector<double> approximate_gaussian_averages(E& exec, const point_grid& g, const std::vector<double>& sigma,
                                                  double cells_per_sigma, std::size_t grain) {
  const std::size_t P = g.x.size(), L = sigma.size();
  std::vector<double> avg(L * P);
  std::vector<glm::dvec3> rep_pos;
  std::vector<double> rep_sum, rep_count, rep_spread;
  std::vector<std::uint32_t> rep_ids;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  for (std::size_t u = 0; u < L; ++u) {
    // Representatives: bin the points into cells of size h (sparse: sort by 63-bit cell key).
    const double h = sigma[u] / cells_per_sigma;
    keyed.resize(P);
    for (std::size_t k = 0; k < P; ++k) {
      auto q = [&](double p, int axis) {
        return static_cast<std::uint64_t>(std::min(std::floor((p - g.lo[axis]) / h), 2097151.0));
      };
      keyed[k] = {(q(g.x[k], 0) << 42) | (q(g.y[k], 1) << 21) | q(g.z[k], 2), static_cast<std::uint32_t>(k)};
    }
    std::sort(keyed.begin(), keyed.end());
    rep_pos.clear(), rep_sum.clear(), rep_count.clear(), rep_ids.clear(), rep_spread.clear();
    for (std::size_t b = 0; b < P;) {
      std::size_t e = b;
      glm::dvec3 s(0.0);
      double cs = 0.0;
      for (; e < P && keyed[e].first == keyed[b].first; ++e) {
        const std::uint32_t k = keyed[e].second;
        s += glm::dvec3(g.x[k], g.y[k], g.z[k]), cs += g.value[k];
      }
      const double cnt = static_cast<double>(e - b);
      const glm::dvec3 centre = s / cnt;
      double spread = 0.0;  // RMS distance of the cell's points to their centroid
      for (std::size_t f = b; f < e; ++f) {
        const std::uint32_t k = keyed[f].second;
        const glm::dvec3 d = glm::dvec3(g.x[k], g.y[k], g.z[k]) - centre;
        spread += glm::dot(d, d);
      }
      rep_pos.push_back(centre), rep_sum.push_back(cs), rep_count.push_back(cnt);
      rep_spread.push_back(std::sqrt(spread / cnt));
      rep_ids.push_back(static_cast<std::uint32_t>(rep_ids.size()));
      b = e;
    }
    const point_grid reps = make_point_grid(rep_pos, rep_sum, rep_count, rep_ids, 2.0 * sigma[u] + 1.5 * h);
    const double r2 = 4.0 * sigma[u] * sigma[u], a = 1.0 / (2.0 * sigma[u] * sigma[u]);
    const double inner = std::max(0.0, 2.0 * sigma[u] - 1.5 * h), outer = 2.0 * sigma[u] + 1.5 * h;
    const std::vector<double>& reps_spread = rep_spread;
    const double inner2 = inner * inner, outer2 = outer * outer;
    exec.parallel_for(P, 256 * std::max<std::size_t>(grain, 1), [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        const double xi = g.x[k], yi = g.y[k], zi = g.z[k];
        const std::uint32_t cx = reps.coord(xi, 0), cy = reps.coord(yi, 1), cz = reps.coord(zi, 2);
        double num = 0.0, den = 0.0;
        for (std::uint32_t ax = cx > 0 ? cx - 1 : 0; ax <= std::min(cx + 1, reps.n[0] - 1); ++ax)
          for (std::uint32_t ay = cy > 0 ? cy - 1 : 0; ay <= std::min(cy + 1, reps.n[1] - 1); ++ay)
            for (std::uint32_t az = cz > 0 ? cz - 1 : 0; az <= std::min(cz + 1, reps.n[2] - 1); ++az) {
              const std::uint32_t c = reps.cell_index(ax, ay, az);
              for (std::uint32_t j = reps.cell_start[c]; j < reps.cell_start[c + 1]; ++j) {
                const double dx = reps.x[j] - xi, dy = reps.y[j] - yi, dz = reps.z[j] - zi;
                const double d2 = dx * dx + dy * dy + dz * dz;
                if (d2 > outer2) continue;
                // Soft cutoff: a cell straddling the ball's edge counts with roughly the
                // fraction of its points inside (a linear ramp of half-width 1.5 × its RMS
                // spread around 2σ; a single point keeps the hard cutoff).
                double w = exp_neg2(-std::min(d2, r2) * a);
                if (d2 > inner2) {
                  const double ramp = 1.5 * reps_spread[reps.id[j]];
                  const double dist = std::sqrt(d2);
                  if (ramp > 0.0)
                    w *= std::clamp(0.5 + (2.0 * sigma[u] - dist) / (2.0 * ramp), 0.0, 1.0);
                  else if (d2 > r2)
                    continue;
                }
                num += w * reps.value[j];
                den += w * reps.weight[j];
              }
            }
        avg[u * P + k] = den > 0.0 ? num / den : g.value[k];
      }
    });
  }
  return avg;
}

}  // namespace detail

// Per-vertex mesh saliency of any infolerp::mesh (see the top of this file).
// Errors: empty mesh, index out of range, non-finite position; epsilon <= 0 or not finite, no
// scales, a scale <= 0 or not finite, approx_cells_per_sigma < 0.5, a σ whose square is not a
// normal double (scale × epsilon × diagonal below ~1e-154 or above ~1e154) (bad_parameter); a mesh
// whose bounding box has zero diagonal (degenerate_triangle).
// Complexity, exact: O(V + T + pairs within 2σ_max · distinct σs); approximate: O(V·σs·k) with
// k ~ (4·approx_cells_per_sigma)² representatives per ball. Allocation O(V·σs) (16 doubles per
// vertex and distinct σ at most; never per pair). Parallel through exec; the result is
// identical for every executor and thread count.
template <class M, class E = serial_executor>
result<mesh_saliency> compute_saliency(const M& m, const saliency_options& opt = {}, E&& exec = E{}) {
  static_assert(check_mesh<M>());
  static_assert(check_executor<std::remove_cvref_t<E>>());
  if (!(opt.epsilon > 0.0) || !std::isfinite(opt.epsilon))
    return make_error(errc::bad_parameter, no_element, "saliency epsilon ", opt.epsilon, " must be positive and finite");
  if (opt.scales.empty()) return make_error(errc::bad_parameter, no_element, "saliency needs at least one scale");
  for (std::size_t i = 0; i < opt.scales.size(); ++i)
    if (!(opt.scales[i] > 0.0) || !std::isfinite(opt.scales[i]))
      return make_error(errc::bad_parameter, i, "saliency scale ", i, " is ", opt.scales[i], "; must be positive and finite");
  if (opt.method == saliency_method::approximate && !(opt.approx_cells_per_sigma >= 0.5))
    return make_error(errc::bad_parameter, no_element, "approx_cells_per_sigma ", opt.approx_cells_per_sigma,
                      " must be at least 0.5");
  auto curv = mean_curvature(m);
  if (!curv.ok()) return curv.error();
  const bounding_box box = mesh_bounds(m);
  if (!(box.diagonal() > 0.0))
    return make_error(errc::degenerate_triangle, no_element, "mesh bounding box has zero diagonal");

  mesh_saliency out;
  out.curvature = std::move(*curv);
  out.epsilon = opt.epsilon * box.diagonal();
  const std::size_t nv = mesh_vertex_count(m), nt = mesh_triangle_count(m);

  // Distinct σ multipliers (σ_i and 2σ_i), ascending; level i uses entries lo[i] and hi[i].
  std::vector<double> mult;
  for (double s : opt.scales) mult.push_back(s), mult.push_back(2.0 * s);
  std::sort(mult.begin(), mult.end());
  mult.erase(std::unique(mult.begin(), mult.end()), mult.end());
  if (mult.size() > 32) return make_error(errc::bad_parameter, no_element, "at most 16 saliency scales are supported");
  std::vector<double> sigma(mult.size());
  for (std::size_t u = 0; u < mult.size(); ++u) {
    sigma[u] = mult[u] * out.epsilon;
    // The Gaussian divides by 2σ²: a σ² that underflows (or overflows) would turn the weights
    // of coincident vertices into NaN (0 · Inf).
    const double s2 = sigma[u] * sigma[u];
    if (!(s2 >= std::numeric_limits<double>::min()) || !std::isfinite(s2))
      return make_error(errc::bad_parameter, no_element, "saliency sigma ", sigma[u],
                        " (scale x epsilon x bounding-box diagonal) is outside double precision");
  }
  auto index_of = [&](double s) {
    return static_cast<std::size_t>(std::lower_bound(mult.begin(), mult.end(), s) - mult.begin());
  };

  // Referenced vertices only: an unused vertex has no curvature and must not dilute averages.
  std::vector<char> used(nv, 0);
  for (std::size_t t = 0; t < nt; ++t) {
    const glm::uvec3 tri = mesh_triangle(m, t);
    used[tri.x] = used[tri.y] = used[tri.z] = 1;
  }
  std::vector<glm::dvec3> pts;
  std::vector<double> vals, ones;
  std::vector<std::uint32_t> ids;
  for (std::size_t v = 0; v < nv; ++v)
    if (used[v]) {
      pts.push_back(glm::dvec3(mesh_position(m, v)));
      vals.push_back(out.curvature[v]);
      ids.push_back(static_cast<std::uint32_t>(v));
    }
  ones.assign(pts.size(), 1.0);
  const std::size_t P = pts.size();
  const detail::point_grid grid = detail::make_point_grid(pts, vals, ones, ids, 2.0 * sigma.back());
  const std::vector<double> avg =
      opt.method == saliency_method::exact
          ? detail::exact_gaussian_averages(exec, grid, sigma, opt.grain)
          : detail::approximate_gaussian_averages(exec, grid, sigma, opt.approx_cells_per_sigma, opt.grain);

  // Levels and Lee's normalisation.
  double mean_abs_c = 0.0;
  for (std::size_t k = 0; k < P; ++k) mean_abs_c += std::abs(grid.value[k]);
  mean_abs_c /= static_cast<double>(P);
  auto topo = build_topology(m);
  if (!topo.ok()) return topo.error();
  out.saliency.assign(nv, 0.0);
  out.levels.assign(opt.scales.size(), std::vector<double>(nv, 0.0));
  std::vector<char> is_max(nv);
  for (std::size_t i = 0; i < opt.scales.size(); ++i) {
    std::vector<double>& s = out.levels[i];
    const std::size_t lo = index_of(opt.scales[i]), hi = index_of(2.0 * opt.scales[i]);
    double mx = 0.0;
    for (std::size_t k = 0; k < P; ++k) {
      s[grid.id[k]] = std::abs(avg[lo * P + k] - avg[hi * P + k]);
      mx = std::max(mx, s[grid.id[k]]);
    }
    const double range = std::max(mx, opt.flat_level_threshold * mean_abs_c);
    if (!(range > 0.0)) continue;  // a flat mesh: this level adds nothing
    const double scale = 1.0 / range, big_m = mx * scale;
    std::size_t global = nv;
    for (std::size_t v = 0; v < nv; ++v) {
      is_max[v] = used[v];
      if (used[v] && global == nv && s[v] == mx) global = v;
    }
    for (const glm::uvec2& e : topo->edges) {
      if (s[e.x] <= s[e.y]) is_max[e.x] = 0;
      if (s[e.y] <= s[e.x]) is_max[e.y] = 0;
    }
    double sum_max = 0.0;
    std::size_t count_max = 0;
    for (std::size_t v = 0; v < nv; ++v)
      if (is_max[v] && v != global) sum_max += s[v] * scale, ++count_max;
    const double mbar = count_max ? sum_max / static_cast<double>(count_max) : 0.0;
    const double factor = scale * (big_m - mbar) * (big_m - mbar);
    for (std::size_t v = 0; v < nv; ++v) out.saliency[v] += s[v] * factor;
  }
  return out;
}

}  // namespace infolerp
