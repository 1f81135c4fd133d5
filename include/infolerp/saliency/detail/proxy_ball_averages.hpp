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
#include <cstring>
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

// x where x > 0, else +0, by a mask rather than a branch (the compilers kept a branch for
// `x > 0 ? x : 0`, mispredicted about half the time in the blend below).
inline double positive_part(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  bits &= std::uint64_t{0} - static_cast<std::uint64_t>(x > 0.0);
  std::memcpy(&x, &bits, sizeof x);
  return x;
}

// Sorted runs of v ([k·run, (k+1)·run) each ascending) merged in pairs through exec, each round's
// merges in parallel. The elements must be distinct (or equal only when identical), so the
// result is the one sorted order whatever the executor and run length. O(n log(n / run)) work,
// allocation O(n).
template <class E, class T>
void merge_sorted_runs(E& exec, std::vector<T>& v, std::size_t run) {
  const std::size_t n = v.size();
  if (n <= run) return;
  std::vector<T> merged(n);
  for (std::size_t width = run; width < n; width *= 2) {
    for_each_chunk(exec, n, 2 * width, [&](std::size_t, std::size_t b, std::size_t e) {
      const auto at = [](auto& x, std::size_t k) { return x.begin() + static_cast<std::ptrdiff_t>(k); };
      const std::size_t mid = std::min(e, b + width);
      std::merge(at(v, b), at(v, mid), at(v, mid), at(v, e), at(merged, b));
    });
    v.swap(merged);
  }
}

// Groups the points (weighted or not) into cells of edge h: per cell the weighted centroid, the
// sum of the values and of the weights (the caller guarantees the extent over h stays below
// proxy_max_cells). Parallel through exec; every step is a function of the sorted keys, so the
// result is the same for any executor. O(P log P), allocation O(P).
template <class E>
proxy_cells make_proxy_cells(E& exec, const vertex_points& pts, double h) {
  constexpr std::size_t chunk = 8192;
  proxy_cells c;
  c.h = h;
  const std::size_t P = pts.x.size();
  double lo[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                  std::numeric_limits<double>::infinity()};
  for (std::size_t k = 0; k < P; ++k)
    lo[0] = std::min(lo[0], pts.x[k]), lo[1] = std::min(lo[1], pts.y[k]), lo[2] = std::min(lo[2], pts.z[k]);
  auto cell = [&](double v, int axis) { return static_cast<std::uint64_t>(std::floor((v - lo[axis]) / h)) + 1; };
  // Keys and their sorted runs in one parallel phase, then the runs merged.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(P);
  const std::size_t run = std::max<std::size_t>(chunk, (P + 7) / 8);
  for_each_chunk(exec, P, run, [&](std::size_t, std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k)
      keyed[k] = {cell(pts.x[k], 0) << 42 | cell(pts.y[k], 1) << 21 | cell(pts.z[k], 2), static_cast<std::uint32_t>(k)};
    std::sort(keyed.begin() + static_cast<std::ptrdiff_t>(b), keyed.begin() + static_cast<std::ptrdiff_t>(e));
  });
  merge_sorted_runs(exec, keyed, run);
  // Cell starts: per chunk of sorted points the positions where a new key begins, then their
  // offsets in chunk order.
  const std::size_t chunks = chunk_count(P, chunk);
  std::vector<std::vector<std::uint32_t>> starts_of(chunks);
  for_each_chunk(exec, P, chunk, [&](std::size_t ch, std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k)
      if (k == 0 || keyed[k].first != keyed[k - 1].first) starts_of[ch].push_back(static_cast<std::uint32_t>(k));
  });
  std::vector<std::uint32_t> start;
  for (const auto& s : starts_of) start.insert(start.end(), s.begin(), s.end());
  start.push_back(static_cast<std::uint32_t>(P));
  const std::size_t cells = start.size() - 1;
  c.order.resize(P);
  c.cell_of.resize(P);
  vertex_points& q = c.points;
  q.x.resize(cells), q.y.resize(cells), q.z.resize(cells), q.value.resize(cells), q.weight.resize(cells), q.id.resize(cells);
  std::vector<std::uint64_t> keys(cells);
  for_each_chunk(exec, cells, chunk, [&](std::size_t, std::size_t cb, std::size_t ce) {
    for (std::size_t i = cb; i < ce; ++i) {
      double sx = 0.0, sy = 0.0, sz = 0.0, sv = 0.0, sw = 0.0;
      for (std::size_t e = start[i]; e < start[i + 1]; ++e) {
        const std::uint32_t k = keyed[e].second;
        const double w = pts.weight.empty() ? 1.0 : pts.weight[k];
        sx += w * pts.x[k], sy += w * pts.y[k], sz += w * pts.z[k], sv += pts.value[k], sw += w;
        c.cell_of[k] = static_cast<std::uint32_t>(i);
        c.order[e] = k;
      }
      q.x[i] = sx / sw, q.y[i] = sy / sw, q.z[i] = sz / sw, q.value[i] = sv, q.weight[i] = sw;
      q.id[i] = static_cast<std::uint32_t>(i);
      keys[i] = keyed[start[i]].first;
    }
  });
  // Neighbour cells: for each of the 9 (x, y) offsets the three z neighbours are consecutive
  // keys, and the queried keys grow with the proxy's key, so one pointer per offset walks the keys
  // (O(9·proxies) instead of a search per neighbour); each chunk of cells starts its pointers by
  // a search, and the chunks' lists are joined in order. A sentinel key ends the walks, and the up
  // to three cells of an offset are taken by counting, not branching (the branches were
  // mispredicted about once per offset).
  constexpr std::uint64_t one_x = std::uint64_t{1} << 42, one_y = std::uint64_t{1} << 21;
  std::uint64_t offset[9];
  for (int o = 0; o < 9; ++o) offset[o] = static_cast<std::uint64_t>(o / 3) * one_x + static_cast<std::uint64_t>(o % 3) * one_y;
  const std::uint64_t centre = one_x + one_y + 1;  // key + offset[o] − centre: the cell below in z
  keys.push_back(std::numeric_limits<std::uint64_t>::max());
  const std::size_t cell_chunks = chunk_count(cells, chunk);
  std::vector<std::vector<std::uint32_t>> near_of(cell_chunks);
  c.near_start.assign(cells + 1, 0);  // counts first, at i + 1
  for_each_chunk(exec, cells, chunk, [&](std::size_t ch, std::size_t cb, std::size_t ce) {
    std::size_t at[9];
    const auto end = keys.begin() + static_cast<std::ptrdiff_t>(cells);
    for (int o = 0; o < 9; ++o)
      at[o] = static_cast<std::size_t>(std::lower_bound(keys.begin(), end, keys[cb] + offset[o] - centre) - keys.begin());
    std::vector<std::uint32_t>& out = near_of[ch];
    out.resize(27 * (ce - cb));
    std::size_t n = 0;
    for (std::size_t i = cb; i < ce; ++i) {
      const std::size_t before = n;
      for (int o = 0; o < 9; ++o) {
        const std::uint64_t first = keys[i] + offset[o] - centre;
        std::size_t p = at[o];
        while (keys[p] < first) ++p;
        at[o] = p;
        for (int z = 0; z < 3; ++z) {
          out[n] = static_cast<std::uint32_t>(p);
          const std::size_t in = keys[p] <= first + 2 ? 1 : 0;
          n += in, p += in;
        }
      }
      c.near_start[i + 1] = static_cast<std::uint32_t>(n - before);
    }
    out.resize(n);
  });
  for (std::size_t i = 0; i < cells; ++i) c.near_start[i + 1] += c.near_start[i];
  c.near.resize(c.near_start[cells]);
  for_each_chunk(exec, cells, chunk, [&](std::size_t ch, std::size_t cb, std::size_t) {
    std::copy(near_of[ch].begin(), near_of[ch].end(), c.near.begin() + c.near_start[cb]);
  });
  return c;
}

// Approximate averages for L ascending radii sigma[u] (see the top of the file), in the layout of
// exact_gaussian_averages: avg[k * L + u] for point k of pts. cells_per_sigma > 0, with
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
  // Groupings of 2^19 points or more run through exec; the smaller ones serially: their ~10
  // parallel phases cost more in barriers than they gain when other processes share the cores
  // (benchmarks/NOTES.md, saliency proxy).
  serial_executor serial;
  for (std::size_t u = 0; u < L; ++u) {
    const vertex_points& grouped = u == 0 ? pts : proxies[u - 1].points;
    if (grouped.x.size() >= (std::size_t{1} << 19))
      proxies[u] = make_proxy_cells(exec, grouped, sigma[u] / cells_per_sigma);
    else
      proxies[u] = make_proxy_cells(serial, grouped, sigma[u] / cells_per_sigma);
    for (std::size_t i = 0; i < P; ++i) cell_of[u][i] = proxies[u].cell_of[u == 0 ? proxies[0].order[i] : cell_of[u - 1][i]];
  }
  // Blend: points in cell order (so that neighbouring points read neighbouring proxies), each
  // proxy's position and average side by side.
  // The σ run in parallel, each serially: a proxy's kernel is small, and 8 parallel phases per σ
  // cost more than they gain when other processes share the cores (OpenMP barriers). A single σ
  // (the weighting map's smoothing) runs its kernel through exec.
  std::vector<std::vector<std::array<double, 4>>> at_proxy(L);
  auto kernel = [&](auto& ex, std::size_t u) {
    const vertex_points& q = proxies[u].points;
    // Columns one ball wide: a proxy has about (4·cells_per_sigma)² neighbours in a ball, too
    // few for the exact kernel's narrower columns to pay for their overhead.
    const std::vector<double> a = exact_gaussian_averages(ex, q, {sigma[u]}, grain, 1.0);
    at_proxy[u].resize(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) at_proxy[u][i] = {q.x[i], q.y[i], q.z[i], a[i]};
  };
  if (L == 1) {
    kernel(exec, 0);
  } else {
    exec.parallel_for(L, 1, [&](std::size_t b, std::size_t e) {
      serial_executor one;
      for (std::size_t u = b; u < e; ++u) kernel(one, u);
    });
  }
  const std::vector<std::uint32_t>& order = proxies[0].order;
  // Per chunk of points: the L averages of each point side by side in a small buffer, then
  // copied to the point's L adjacent entries (one scattered line per point instead of L).
  // Outside h a proxy's weight is 0 (positive_part: the same sums without a branch).
  std::vector<double> avg(P * L);
  constexpr std::size_t chunk = 4096;
  for_each_chunk(exec, P, chunk, [&](std::size_t, std::size_t b, std::size_t e) {
    std::vector<double> blended((e - b) * L), sx(e - b), sy(e - b), sz(e - b);
    for (std::size_t i = b; i < e; ++i) sx[i - b] = pts.x[order[i]], sy[i - b] = pts.y[order[i]], sz[i - b] = pts.z[order[i]];
    for (std::size_t u = 0; u < L; ++u) {
      const proxy_cells& c = proxies[u];
      const std::array<double, 4>* ap = at_proxy[u].data();
      const double inv_h2 = 1.0 / (c.h * c.h);
      for (std::size_t i = b; i < e; ++i) {
        const std::uint32_t own = cell_of[u][i];
        double num = 0.0, den = 0.0;
        for (std::uint32_t n = c.near_start[own]; n < c.near_start[own + 1]; ++n) {
          const std::array<double, 4>& q = ap[c.near[n]];
          const double dx = q[0] - sx[i - b], dy = q[1] - sy[i - b], dz = q[2] - sz[i - b];
          const double t = positive_part(1.0 - (dx * dx + dy * dy + dz * dz) * inv_h2);
          num += t * t * q[3], den += t * t;
        }
        blended[(i - b) * L + u] = den > 0.0 ? num / den : ap[own][3];
      }
    }
    for (std::size_t i = b; i < e; ++i)
      std::copy_n(blended.begin() + static_cast<std::ptrdiff_t>((i - b) * L), L,
                  avg.begin() + static_cast<std::ptrdiff_t>(std::size_t{order[i]} * L));
  });
  return avg;
}

}  // namespace infolerp::detail
