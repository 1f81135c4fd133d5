#pragma once
// Gaussian-weighted ball averages of a value over a vertex set, for several radii at once: the
// G(C, σ) of mesh saliency (saliency/mesh_saliency.hpp, Lee et al. 2005; salient-clustering
// paper eq. 1), exact to rounding.
//
// Vertices are sorted into the columns of an xy grid (columns 2σ_max/3 wide, vertex_grids.hpp),
// by z inside a column, so the candidates of a vertex are, per nearby column, one contiguous z-run
// (binary search). Each pair is evaluated once: a vertex meets the vertices after it in that
// order (the rest of its own column's run, then the later columns), for all distinct σ (σ_i and
// 2σ_i: 8 values for the default scales) in one pass, 8 candidates at a time with vector code
// (blocks aligned to multiples of 8 in the sorted order); σ run from the largest down and stop
// at the first ball that holds none of the 8. Only σ whose double 2σ is not in the set need an
// exp (3 of the 8 by default): w_σ = w_2σ⁴. A pair's terms go to the vertex's own sums (in
// registers, 8 lane sums added pairwise at the end) and to the candidates' sums (in memory, a
// block's sums for every σ side by side).
// Determinism: tiles of 3 × 3 columns write only their own and neighbouring tiles' vertices, so
// 6 phases (tile x mod 2, tile y mod 3) run one after another, the tiles of a phase in parallel
// (largest first) with disjoint writes; each vertex receives its terms in an order fixed by the
// data, and the result has identical bits for any executor and thread count. Memory O(V·σs);
// pairs are never stored.
// Vector code: GCC/Clang vector extensions, 2 doubles (SSE2, NEON) in the portable build, plus
// AVX2+FMA (4) and AVX-512F (8) versions chosen at run time on x86-64 (define
// INFOLERP_NO_RUNTIME_DISPATCH to always use the portable one, INFOLERP_NO_AVX512 for AVX2 at
// most); they differ only by FMA contraction (1e-16 relative per operation). Other compilers get
// a plain 4-double struct. exp(−x) on [0, 2] (the only range the ball cutoff produces) is a
// polynomial fit, relative error ~1e-16.
// Measured times per kernel and what was tried instead: benchmarks/NOTES.md (BM_Saliency_Exact).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>
#include "infolerp/core/detail/cpu.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/saliency/detail/vertex_grids.hpp"

namespace infolerp::detail {

// x ← exp(−x) for x in [0, 2] (the only range the 2σ ball cutoff produces), for double or a
// vector of doubles: q(x)⁴ with q the degree-10 Chebyshev fit of exp(−x/4) on [0, 2]. Relative
// error ~1e-16 (fit) plus a few roundings; q(0) = 1 exactly. Branch-free; x > 2 gives finite or
// infinite values that callers mask out. In place: vector arguments by value would trip GCC's
// -Wpsabi note in the user's translation unit.
template <class T>
INFOLERP_FORCE_INLINE void exp_neg_inplace(T& x) {
  // Estrin's scheme: 4 dependent multiply-adds instead of Horner's 10 (the kernel is latency-bound).
  const T x2 = x * x, x4 = x2 * x2, x8 = x4 * x4;
  const T p01 = x * -0.24999999999999944 + 1.0, p23 = x * -0.0026041666665787633 + 0.03124999999998875;
  const T p45 = x * -8.138020007655508e-06 + 0.00016276041631414334;
  const T p67 = x * -1.2109012825312624e-08 + 3.3908299377631024e-07;
  const T p89 = x * -1.024918557153169e-11 + 3.77751130723742e-10;
  const T p03 = x2 * p23 + p01, p47 = x2 * p67 + p45, p810 = x2 * 2.049410196605228e-13 + p89;
  const T q = x8 * p810 + (x4 * p47 + p03);
  const T q2 = q * q;
  x = q2 * q2;
}

// Weights of one σ from the next: w_σ = exp(−d²/2σ²) = (w_2σ)⁴, so only the σ whose double is
// not in the set need an exp. pow_of[u] = index of 2σ_u, or -1.
struct sigma_table {
  std::vector<double> r2, a;   // ball radius² (2σ)² and 1/(2σ²), ascending σ
  std::vector<int> pow_of;
};

inline sigma_table make_sigma_table(const std::vector<double>& sigma) {
  sigma_table t;
  const std::size_t L = sigma.size();
  t.r2.resize(L), t.a.resize(L), t.pow_of.assign(L, -1);
  for (std::size_t u = 0; u < L; ++u) {
    t.r2[u] = 4.0 * sigma[u] * sigma[u], t.a[u] = 1.0 / (2.0 * sigma[u] * sigma[u]);
    for (std::size_t v = u + 1; v < L; ++v)
      if (sigma[v] == 2.0 * sigma[u]) t.pow_of[u] = static_cast<int>(v);
  }
  return t;
}

// The pair kernel works on blocks of 8 candidates ("lanes"), held in G vectors of V (G·width
// = 8). With GCC/Clang V is a vector extension type: 2 doubles (SSE2/NEON) by default, 4 in the
// AVX2+FMA and 8 in the AVX-512F versions chosen at run time on x86-64; other compilers get a
// plain 4-double struct. Every lane receives the same operations in the same order in each
// version, so the versions differ only by FMA contraction (relative 1e-16 per operation).
inline constexpr std::size_t fallback_width = 4;

struct lanes_fallback {  // 4 doubles, for compilers without vector extensions
  double v[fallback_width];
};
struct mask_fallback {
  bool v[fallback_width];
};
inline lanes_fallback operator+(lanes_fallback a, lanes_fallback b) {
  for (std::size_t l = 0; l < fallback_width; ++l) a.v[l] += b.v[l];
  return a;
}
inline lanes_fallback operator*(lanes_fallback a, lanes_fallback b) {
  for (std::size_t l = 0; l < fallback_width; ++l) a.v[l] *= b.v[l];
  return a;
}
inline lanes_fallback operator+(lanes_fallback a, double b) {
  for (std::size_t l = 0; l < fallback_width; ++l) a.v[l] += b;
  return a;
}
inline lanes_fallback operator-(lanes_fallback a, double b) {
  for (std::size_t l = 0; l < fallback_width; ++l) a.v[l] -= b;
  return a;
}
inline lanes_fallback operator*(lanes_fallback a, double b) {
  for (std::size_t l = 0; l < fallback_width; ++l) a.v[l] *= b;
  return a;
}
inline mask_fallback operator<=(lanes_fallback a, double b) {
  mask_fallback m;
  for (std::size_t l = 0; l < fallback_width; ++l) m.v[l] = a.v[l] <= b;
  return m;
}

#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"  // vectors only pass between inlined helpers
using v2d = double __attribute__((vector_size(16)));
using v4d = double __attribute__((vector_size(32)));
// out = v where m, else +0 (bitwise, so an Inf outside the ball is harmless). Arguments by
// reference: vector arguments by value would trip GCC's -Wpsabi note in the user's code.
template <class V, class M>
INFOLERP_FORCE_INLINE void keep(V& out, const M& m, const V& v) {
  out = reinterpret_cast<V>(m & reinterpret_cast<M>(v));
}
// a = min(a, b) per lane (for finite values or +Inf).
template <class V>
INFOLERP_FORCE_INLINE void lane_min(V& a, const V& b) {
  const auto m = b < a;
  using M = decltype(m);
  a = reinterpret_cast<V>((m & reinterpret_cast<M>(b)) | (~m & reinterpret_cast<M>(a)));
}
// The smallest lane of v, by halving (log2(width) shuffles and minima, not width − 1 scalar ones).
template <class V>
INFOLERP_FORCE_INLINE double lanes_min(const V& lanes) {
  constexpr std::size_t width = sizeof(V) / sizeof(double);
  V v = lanes;
  if constexpr (width == 8) {
    lane_min(v, __builtin_shufflevector(v, v, 4, 5, 6, 7, 0, 1, 2, 3));
    lane_min(v, __builtin_shufflevector(v, v, 2, 3, 0, 1, 6, 7, 4, 5));
    lane_min(v, __builtin_shufflevector(v, v, 1, 0, 3, 2, 5, 4, 7, 6));
  } else if constexpr (width == 4) {
    lane_min(v, __builtin_shufflevector(v, v, 2, 3, 0, 1));
    lane_min(v, __builtin_shufflevector(v, v, 1, 0, 3, 2));
  } else {
    lane_min(v, __builtin_shufflevector(v, v, 1, 0));
  }
  return v[0];
}
#endif
inline void keep(lanes_fallback& out, const mask_fallback& m, const lanes_fallback& v) {
  for (std::size_t l = 0; l < fallback_width; ++l) out.v[l] = m.v[l] ? v.v[l] : 0.0;
}
inline void lane_min(lanes_fallback& a, const lanes_fallback& b) {
  for (std::size_t l = 0; l < fallback_width; ++l) a.v[l] = std::min(a.v[l], b.v[l]);
}
inline double lanes_min(const lanes_fallback& v) {
  double m = v.v[0];
  for (std::size_t l = 1; l < fallback_width; ++l) m = std::min(m, v.v[l]);
  return m;
}

template <class V>
INFOLERP_FORCE_INLINE void load_lanes(V& v, const double* p) {
  std::memcpy(&v, p, sizeof v);
}

template <class V>
INFOLERP_FORCE_INLINE void store_lanes(double* p, const V& v) {
  std::memcpy(p, &v, sizeof v);
}

inline constexpr double lane_numbers[block_lanes] = {0, 1, 2, 3, 4, 5, 6, 7};

// The sums of the points, by blocks of 8 sorted points: per block, per σ, 8 numerators then 8
// denominators (one 64-byte line each), so that a block's sums for every σ are adjacent (few
// pages per pass: the kernel is memory-bound there). Point j's numerator for σ u:
inline double* point_sums(double* sums, std::size_t L, std::size_t j, std::size_t u) {
  return sums + j / block_lanes * (2 * block_lanes * L) + u * 2 * block_lanes + j % block_lanes;
}

#if defined(__clang__)
#define INFOLERP_SALIENCY_UNROLL _Pragma("unroll 8")
#elif defined(__GNUC__)
#define INFOLERP_SALIENCY_UNROLL _Pragma("GCC unroll 8")
#else
#define INFOLERP_SALIENCY_UNROLL
#endif

// Every pair once: each point i of the tile (in sorted order) meets the points j after it in
// the sorted order (its own column above i, then the later columns within 2σ_max), 8
// candidates j at a time, σ from the largest down, stopping at the first ball that holds none
// of the 8. A pair's weights are added to i's sums (registers, one partial sum per lane, added
// in a fixed order when i is done) and to j's sums (point_sums, in memory). Writes
// reach the tile's columns and the columns up to `span` later in x and span either side in y;
// the caller runs tiles whose write sets are disjoint concurrently, in a fixed order otherwise.
// LC >= the number of σ: the σ loop is unrolled (8 at a time) so that, with LC = 8, i's sums
// stay in registers (AVX-512: 16 of its 32).
// Weighted: points carry a weight row (column_grid::weighted); a pair adds weight · kernel to the
// denominators and the value row (already the weighted value) · kernel to the numerators.
template <class V, std::size_t LC, bool Weighted>
INFOLERP_FORCE_INLINE void gather_tile(const column_grid& g, const sigma_table& t, std::uint32_t span,
                                          column_tile tile, double* sums) {
  constexpr std::size_t width = sizeof(V) / sizeof(double), G = block_lanes / width;  // G vectors per block
  const std::size_t L = t.r2.size();
  const double r2max = t.r2[L - 1];
  const double *px_all = g.row(0), *py_all = g.row(1), *pz_all = g.row(2), *pc_all = g.row(3);
  const double* pw_all = Weighted ? g.row(4) : nullptr;
  std::vector<column_ref> nearby;
  for (std::uint32_t tc = 0; tc < tile.count; ++tc) {
    const std::uint32_t own = tile.cols[tc];
    columns_after(g, static_cast<std::uint32_t>(g.col_key[own] >> 32), static_cast<std::uint32_t>(g.col_key[own]), span,
                  nearby);
      for (std::size_t i = g.col_start[own]; i < g.col_start[own + 1]; ++i) {
        const double xi = px_all[i], yi = py_all[i], zi = pz_all[i], ci = pc_all[i];
        const double wi = Weighted ? pw_all[i] : 1.0;
        V acc_n[LC][G] = {}, acc_d[LC][G] = {}, w[LC][G];  // index s: σ number L − 1 − s
        for (const column_ref& nb : nearby) {
            const std::size_t q = nb.q;
            const std::uint32_t ax = nb.ax, ay = nb.ay;
            const double lx = g.x0 + ax * g.h, ly = g.y0 + ay * g.h;
            const double gx = std::max({0.0, lx - xi, xi - (lx + g.h)}), gy = std::max({0.0, ly - yi, yi - (ly + g.h)});
            const double dxy2 = gx * gx + gy * gy;
            if (dxy2 > r2max) continue;
            const double half = std::sqrt(r2max - dxy2);
            const double* zb = pz_all + g.col_start[q];
            const double* ze = pz_all + g.col_start[q + 1];
            const std::size_t j1 = static_cast<std::size_t>(std::upper_bound(zb, ze, zi + half) - pz_all);
            const std::size_t j0 = q == own ? i + 1  // own column: the points above i
                                   : static_cast<std::size_t>(std::lower_bound(zb, ze, zi - half) - pz_all);
            // Blocks start at multiples of 8, so that j's sums are whole aligned vectors.
            for (std::size_t j = j0 / block_lanes * block_lanes; j < j1; j += block_lanes) {
              const bool partial = j < j0 || j + block_lanes > j1;
              V d2[G], c[G], wt[G];
              for (std::size_t k = 0; k < G; ++k) {
                const std::size_t o = j + k * width;
                V vx, vy, vz;
                load_lanes(vx, px_all + o), load_lanes(vy, py_all + o), load_lanes(vz, pz_all + o), load_lanes(c[k], pc_all + o);
                if constexpr (Weighted) load_lanes(wt[k], pw_all + o);
                const V dx = vx - xi, dy = vy - yi, dz = vz - zi;
                d2[k] = dx * dx + dy * dy + dz * dz;
                if (partial) {  // lanes outside [j0, j1) (other points, or the rows' padding) get d² = +Inf
                  V lane;
                  load_lanes(lane, lane_numbers + k * width);
                  const V after_j0 = lane + (static_cast<double>(j) - static_cast<double>(j0) + 0.5);
                  const V before_j1 = lane * -1.0 + (static_cast<double>(j1) - static_cast<double>(j) - 0.5);
                  V pad;
                  keep(pad, after_j0 * before_j1 <= 0.0, lane * 0.0 + std::numeric_limits<double>::infinity());
                  d2[k] = d2[k] + pad;
                }
              }
              V nearest = d2[0];
              for (std::size_t k = 1; k < G; ++k) lane_min(nearest, d2[k]);
              const double dmin = lanes_min(nearest);
              INFOLERP_SALIENCY_UNROLL
              for (std::size_t s = 0; s < LC; ++s) {
                if (s == L || !(dmin <= t.r2[L - 1 - s])) break;  // smaller σ have smaller balls
                const std::size_t u = L - 1 - s;
                const int p = t.pow_of[u];
                V mn[G], md[G];
                for (std::size_t k = 0; k < G; ++k) {
                  if (p >= 0) {
                    const V& wp = w[L - 1 - static_cast<std::size_t>(p)][k];
                    const V s2 = wp * wp;
                    w[s][k] = s2 * s2;
                  } else {
                    w[s][k] = d2[k] * t.a[u];
                    exp_neg_inplace(w[s][k]);
                  }
                  V m;
                  keep(m, d2[k] <= t.r2[u], w[s][k]);
                  acc_n[s][k] = acc_n[s][k] + m * c[k];
                  if constexpr (Weighted) {
                    acc_d[s][k] = acc_d[s][k] + m * wt[k];
                    md[k] = m * wi;
                  } else {
                    acc_d[s][k] = acc_d[s][k] + m;
                    md[k] = m;
                  }
                  mn[k] = m * ci;
                }
                double* nj = point_sums(sums, L, j, u);
                double* dj = nj + block_lanes;
                if (!partial) {
                  for (std::size_t k = 0; k < G; ++k) {
                    V a, b;
                    load_lanes(a, nj + k * width), load_lanes(b, dj + k * width);
                    a = a + mn[k], b = b + md[k];
                    store_lanes(nj + k * width, a), store_lanes(dj + k * width, b);
                  }
                } else {  // only the real lanes: the rest belong to other points
                  double n[block_lanes], d[block_lanes];
                  std::memcpy(n, mn, sizeof n);
                  std::memcpy(d, md, sizeof d);
                  for (std::size_t l = j0 > j ? j0 - j : 0; j + l < j1 && l < block_lanes; ++l) nj[l] += n[l], dj[l] += d[l];
                }
              }
            }
          }
        for (std::size_t s = 0; s < L; ++s) {
          double n[block_lanes], d[block_lanes];
          std::memcpy(n, acc_n[s], sizeof n);
          std::memcpy(d, acc_d[s], sizeof d);
          for (std::size_t h = block_lanes / 2; h > 0; h /= 2)  // pairwise, in a fixed order
            for (std::size_t l = 0; l < h; ++l) n[l] += n[l + h], d[l] += d[l + h];
          double* ni = point_sums(sums, L, i, L - 1 - s);
          ni[0] += n[0] + ci;  // i itself: kernel 1
          ni[block_lanes] += d[0] + wi;
        }
      }
  }
}

// One tile with vectors V, 8 or 32 σ slots, weighted or not.
template <class V>
INFOLERP_FORCE_INLINE void gather_tile_any(const column_grid& g, const sigma_table& t, std::uint32_t span,
                                              column_tile tile, double* sums) {
  if (g.weighted) {
    if (t.r2.size() <= 8) return gather_tile<V, 8, true>(g, t, span, tile, sums);
    return gather_tile<V, 32, true>(g, t, span, tile, sums);
  }
  if (t.r2.size() <= 8) return gather_tile<V, 8, false>(g, t, span, tile, sums);
  gather_tile<V, 32, false>(g, t, span, tile, sums);
}

inline void gather_tile_portable(const column_grid& g, const sigma_table& t, std::uint32_t span, column_tile tile,
                                 double* sums) {
#if defined(__GNUC__) || defined(__clang__)
  gather_tile_any<v2d>(g, t, span, tile, sums);
#else
  gather_tile_any<lanes_fallback>(g, t, span, tile, sums);
#endif
}

// Define INFOLERP_NO_RUNTIME_DISPATCH to always use the portable kernel, INFOLERP_NO_AVX512 to
// use AVX2 at most.
#ifdef INFOLERP_X86_DISPATCH
using v8d = double __attribute__((vector_size(64)));
__attribute__((target("avx2,fma"))) inline void gather_tile_avx2(const column_grid& g, const sigma_table& t,
                                                                 std::uint32_t span, column_tile tile, double* sums) {
  gather_tile_any<v4d>(g, t, span, tile, sums);
}
__attribute__((target("avx512f,avx2,fma"))) inline void gather_tile_avx512(const column_grid& g, const sigma_table& t,
                                                                           std::uint32_t span, column_tile tile,
                                                                           double* sums) {
  gather_tile_any<v8d>(g, t, span, tile, sums);
}
#endif
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic pop
#endif

// Exact Gaussian-weighted averages for L ascending radii sigma[u] (ball 2σ) over the grid's
// points (weighted ones too, vertex_points::weight), in columns 2σ_max / columns_per_ball wide.
// Returns avg[k * L + u] for point k of g. Every pair is evaluated once (gather_tile),
// tiles of span × span columns in 6 phases by (tile x mod 2, tile y mod 3): the tiles of one
// phase write disjoint points, so they run in parallel, and every point receives its terms in
// an order fixed by the data: identical bits for any executor, thread count and grain (tiles
// per task).
template <class E>
std::vector<double> exact_gaussian_averages(E& exec, const vertex_points& pg, const std::vector<double>& sigma,
                                            std::size_t grain, double columns_per_ball = 3.0) {
  const std::size_t P = pg.x.size(), L = sigma.size();
  const sigma_table t = make_sigma_table(sigma);
  const double rmax = 2.0 * sigma[L - 1];
  const column_grid g = make_column_grid(exec, pg, rmax / columns_per_ball);
  const auto span = static_cast<std::uint32_t>(std::ceil(rmax / g.h));
  const std::size_t stride = g.stride;
  std::vector<double> storage(2 * L * stride + block_lanes, 0.0);  // see point_sums
  double* sums = storage.data() + aligned_offset(storage);
#ifdef INFOLERP_X86_DISPATCH
  const int level = x86_vector_level();
#endif
  // Tiles of span × span columns: a tile writes its own columns and those up to span later in x,
  // span either side in y, so tiles 2 apart in x or 3 apart in y never write the same point.
  // Phase (tile x mod 2, tile y mod 3).
  std::vector<std::uint32_t> tile_cols;
  const std::vector<std::pair<std::uint32_t, column_tile>> all_tiles = make_column_tiles(g, span, tile_cols);
  std::vector<column_tile> tiles;
  for (std::uint32_t phase = 0; phase < 6; ++phase) {
    tiles.clear();
    for (const auto& [tile_phase, tile] : all_tiles)
      if (tile_phase == phase) tiles.push_back(tile);
    // Largest first balances the workers; the order within a phase does not change any result.
    std::stable_sort(tiles.begin(), tiles.end(), [](const column_tile& a, const column_tile& b) { return a.points > b.points; });
    exec.parallel_for(tiles.size(), std::max<std::size_t>(grain, 1), [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
#ifdef INFOLERP_X86_DISPATCH
        if (level == 2) {
          gather_tile_avx512(g, t, span, tiles[k], sums);
          continue;
        }
        if (level == 1) {
          gather_tile_avx2(g, t, span, tiles[k], sums);
          continue;
        }
#endif
        gather_tile_portable(g, t, span, tiles[k], sums);
      }
    });
  }
  // A point's L averages side by side: one scattered line per point.
  std::vector<double> avg(L * P);
  for_each_chunk(exec, P, 4096, [&](std::size_t, std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k)
      for (std::size_t u = 0; u < L; ++u) {
        const double* nk = point_sums(sums, L, k, u);
        avg[std::size_t{g.src[k]} * L + u] = nk[0] / nk[block_lanes];
      }
  });
  return avg;
}

}  // namespace infolerp::detail
