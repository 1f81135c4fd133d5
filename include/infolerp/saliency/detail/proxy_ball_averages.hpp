#pragma once
// Approximate Gaussian-weighted ball averages G(C, σ) of mesh saliency (saliency/mesh_saliency.hpp)
// through one proxy point set per σ. For each σ the points are grouped into cubic cells of edge
// h = σ / cells_per_sigma; each occupied cell becomes one weighted point (the centroid of its
// points, the sum of their values, their count as weight), so that a ball sum over the proxy
// approximates the sum over the points it stands for (the proxy of a larger σ groups the
// previous proxy's points rather than the mesh's). The weighted averages over the proxy are
// exact to rounding (exact_gaussian_averages), and each point receives the blend of the averages
// at the proxies within h of it, weights (1 − d²/h²)², or its own cell's when none is that near.
// Accuracy follows cells_per_sigma: with cells smaller than the point spacing every cell holds
// one point and the result is the exact one. Cost: O(P log P) once to group the points; per σ,
// the proxy's pairs within 2σ (about (4·cells_per_sigma)² per proxy point on a surface, whatever
// the mesh's resolution) and 27 cells per point to blend. Allocation O(P) per σ. Sums run in
// an order fixed by the data: identical bits for any executor and thread count.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>
#include "infolerp/core/executor.hpp"
#include "infolerp/saliency/detail/gaussian_ball_averages.hpp"
#include "infolerp/saliency/detail/vertex_grids.hpp"

namespace infolerp::detail {

// Cells per axis the proxy grid may use (21 bits of a 64-bit key each, with room for ±1).
inline constexpr double proxy_max_cells = 2097150.0;

// The proxy of one σ: one weighted point per occupied cell, in cell-key order.
struct proxy_cells {
  vertex_points points;                         // centroid, Σ value, count
  std::vector<std::uint32_t> cell_of;           // per grouped point: its proxy
  std::vector<std::uint32_t> order;             // the grouped points in cell order
  std::vector<std::uint32_t> near_start, near;  // per proxy: the proxies of the 27 cells around its cell
  double h = 1.0;
};

// Groups the points (weighted or not) into cells of edge h: per cell the weighted centroid, the
// sum of the values and of the weights (the caller guarantees the extent over h stays below
// proxy_max_cells). O(P log P), allocation O(P).
inline proxy_cells make_proxy_cells(const vertex_points& pts, double h) {
  proxy_cells c;
  c.h = h;
  const std::size_t P = pts.x.size();
  double lo[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                  std::numeric_limits<double>::infinity()};
  for (std::size_t k = 0; k < P; ++k)
    lo[0] = std::min(lo[0], pts.x[k]), lo[1] = std::min(lo[1], pts.y[k]), lo[2] = std::min(lo[2], pts.z[k]);
  auto cell = [&](double v, int axis) { return static_cast<std::uint64_t>(std::floor((v - lo[axis]) / h)) + 1; };
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(P);
  for (std::size_t k = 0; k < P; ++k)
    keyed[k] = {cell(pts.x[k], 0) << 42 | cell(pts.y[k], 1) << 21 | cell(pts.z[k], 2), static_cast<std::uint32_t>(k)};
  std::sort(keyed.begin(), keyed.end());
  c.order.resize(P);
  for (std::size_t k = 0; k < P; ++k) c.order[k] = keyed[k].second;
  std::vector<std::uint64_t> keys;
  c.cell_of.resize(P);
  vertex_points& q = c.points;
  for (std::size_t b = 0; b < P;) {
    double sx = 0.0, sy = 0.0, sz = 0.0, sv = 0.0, sw = 0.0;
    std::size_t e = b;
    for (; e < P && keyed[e].first == keyed[b].first; ++e) {
      const std::uint32_t k = keyed[e].second;
      const double w = pts.weight.empty() ? 1.0 : pts.weight[k];
      sx += w * pts.x[k], sy += w * pts.y[k], sz += w * pts.z[k], sv += pts.value[k], sw += w;
      c.cell_of[k] = static_cast<std::uint32_t>(keys.size());
    }
    q.x.push_back(sx / sw), q.y.push_back(sy / sw), q.z.push_back(sz / sw);
    q.value.push_back(sv), q.weight.push_back(sw);
    q.id.push_back(static_cast<std::uint32_t>(keys.size()));
    keys.push_back(keyed[b].first);
    b = e;
  }
  // Neighbour cells: for each of the 9 (x, y) offsets the three z neighbours are consecutive
  // keys, and the queried keys grow with the proxy's key, so one pointer per offset walks the keys
  // once (O(9·proxies) instead of a search per neighbour).
  constexpr std::uint64_t one_x = std::uint64_t{1} << 42, one_y = std::uint64_t{1} << 21;
  std::uint64_t offset[9];
  std::size_t at[9] = {};
  for (int o = 0; o < 9; ++o) offset[o] = static_cast<std::uint64_t>(o / 3) * one_x + static_cast<std::uint64_t>(o % 3) * one_y;
  const std::uint64_t centre = one_x + one_y + 1;  // key + offset[o] − centre: the cell below in z
  c.near_start.push_back(0);
  for (const std::uint64_t key : keys) {
    for (int o = 0; o < 9; ++o) {
      const std::uint64_t first = key + offset[o] - centre;
      std::size_t& p = at[o];
      while (p < keys.size() && keys[p] < first) ++p;
      for (std::size_t i = p; i < keys.size() && keys[i] <= first + 2; ++i)
        c.near.push_back(static_cast<std::uint32_t>(i));
    }
    c.near_start.push_back(static_cast<std::uint32_t>(c.near.size()));
  }
  return c;
}

// Approximate averages for L ascending radii sigma[u] (see the top of the file), in the layout of
// exact_gaussian_averages: avg[u * P + k] for point k of pts. cells_per_sigma > 0, with
// (extent of pts) · cells_per_sigma / sigma[0] below proxy_max_cells.
template <class E>
std::vector<double> proxy_gaussian_averages(E& exec, const vertex_points& pts, const std::vector<double>& sigma,
                                            double cells_per_sigma, std::size_t grain) {
  const std::size_t P = pts.x.size(), L = sigma.size();
  // Each proxy groups the previous one (the finest groups the points): the sort of the points is
  // paid once. cell_of[u][i]: the cell at σ_u of the i-th point in the finest proxy's cell order
  // (the cell of its cell at σ_{u−1}).
  std::vector<proxy_cells> proxies(L);
  std::vector<std::vector<std::uint32_t>> cell_of(L, std::vector<std::uint32_t>(P));
  for (std::size_t u = 0; u < L; ++u) {
    proxies[u] = make_proxy_cells(u == 0 ? pts : proxies[u - 1].points, sigma[u] / cells_per_sigma);
    for (std::size_t i = 0; i < P; ++i)
      cell_of[u][i] = proxies[u].cell_of[u == 0 ? proxies[0].order[i] : cell_of[u - 1][i]];
  }
  // Blend: points in cell order (so that neighbouring points read neighbouring proxies), each
  // proxy's position and average side by side.
  // The σ run in parallel, each serially: a proxy's kernel is small, and 8 parallel phases per σ
  // cost more than they gain when other processes share the cores (OpenMP barriers).
  std::vector<std::vector<std::array<double, 4>>> at_proxy(L);
  exec.parallel_for(L, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t u = b; u < e; ++u) {
      const vertex_points& q = proxies[u].points;
      // Columns one ball wide: a proxy has about (4·cells_per_sigma)² neighbours in a ball, too
      // few for the exact kernel's narrower columns to pay for their overhead (3x slower at 2
      // cells per σ).
      serial_executor serial;
      const std::vector<double> a = exact_gaussian_averages(serial, q, {sigma[u]}, grain, 1.0);
      at_proxy[u].resize(a.size());
      for (std::size_t i = 0; i < a.size(); ++i) at_proxy[u][i] = {q.x[i], q.y[i], q.z[i], a[i]};
    }
  });
  const std::vector<std::uint32_t>& order = proxies[0].order;
  std::vector<double> sx(P), sy(P), sz(P);
  for (std::size_t i = 0; i < P; ++i) sx[i] = pts.x[order[i]], sy[i] = pts.y[order[i]], sz[i] = pts.z[order[i]];
  std::vector<double> avg(L * P);
  constexpr std::size_t chunk = 4096;
  exec.parallel_for((P + chunk - 1) / chunk, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t u = 0; u < L; ++u) {
      const proxy_cells& c = proxies[u];
      const std::array<double, 4>* ap = at_proxy[u].data();
      const double inv_h2 = 1.0 / (c.h * c.h);
      for (std::size_t i = b * chunk; i < std::min(P, e * chunk); ++i) {
        const std::uint32_t own = cell_of[u][i];
        double num = 0.0, den = 0.0;
        for (std::uint32_t n = c.near_start[own]; n < c.near_start[own + 1]; ++n) {
          const std::array<double, 4>& q = ap[c.near[n]];
          const double dx = q[0] - sx[i], dy = q[1] - sy[i], dz = q[2] - sz[i];
          const double t = 1.0 - (dx * dx + dy * dy + dz * dz) * inv_h2;
          if (t > 0.0) num += t * t * q[3], den += t * t;
        }
        avg[u * P + order[i]] = den > 0.0 ? num / den : ap[own][3];
      }
    }
  });
  return avg;
}

}  // namespace infolerp::detail
