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
// Vertices are sorted into the columns of an xy grid (columns 2σ_max/3 wide), by z
// inside a column, so the candidates of a vertex are, per nearby column, one contiguous z-run
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
#include <utility>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/core/detail/cpu.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/topology.hpp"

namespace infolerp {

struct saliency_options {
  double epsilon = 0.003;                          // ε as a fraction of the bounding-box diagonal
  std::vector<double> scales{2.0, 3.0, 4.0, 5.0, 6.0};  // σ_i = scales[i]·ε; each level uses σ_i and 2σ_i
  double flat_level_threshold = 1e-3;              // levels below this × mean|C| are not stretched to [0,1]
  std::size_t grain = 1;                           // tiles of 3 × 3 columns per parallel task
};

struct mesh_saliency {
  std::vector<double> saliency;   // per vertex: Σ_i N(S_i); 0 for vertices no triangle uses
  std::vector<double> curvature;  // per vertex signed mean curvature (the C that was filtered)
  std::vector<std::vector<double>> levels;  // per scale i, per vertex: S_i before normalisation
  double epsilon = 0.0;           // ε in mesh units
};

namespace detail {


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

// The referenced vertices (those a triangle uses), in index order: position, value, index.
struct vertex_points {
  std::vector<double> x, y, z, value;
  std::vector<std::uint32_t> id;
};

// used[v] = 1 when a triangle references vertex v. O(V + T), allocation O(V).
template <class M>
std::vector<char> referenced_vertices(const M& m) {
  std::vector<char> used(mesh_vertex_count(m), 0);
  for (std::size_t t = 0; t < mesh_triangle_count(m); ++t) {
    const glm::uvec3 tri = mesh_triangle(m, t);
    used[tri.x] = used[tri.y] = used[tri.z] = 1;
  }
  return used;
}

// The vertices with used[v], value values[v]. O(V), allocation O(V).
template <class M>
vertex_points referenced_points(const M& m, const std::vector<char>& used, std::span<const double> values) {
  vertex_points g;
  for (std::size_t v = 0; v < used.size(); ++v)
    if (used[v]) {
      const glm::dvec3 p(mesh_position(m, v));
      g.x.push_back(p.x), g.y.push_back(p.y), g.z.push_back(p.z);
      g.value.push_back(values[v]);
      g.id.push_back(static_cast<std::uint32_t>(v));
    }
  return g;
}

inline constexpr std::size_t block_lanes = 8;  // candidates per block of the pair kernel

// Rows of n doubles rounded up to a multiple of 8 (whole blocks), each 64-byte aligned when the
// first is: aligned_offset(v) is where the first 64-byte boundary of v's storage lies.
inline std::size_t block_stride(std::size_t n) { return (n + block_lanes - 1) / block_lanes * block_lanes; }
inline std::size_t aligned_offset(const std::vector<double>& v) {
  const auto misalign = reinterpret_cast<std::uintptr_t>(v.data()) % (block_lanes * sizeof(double));
  return misalign == 0 ? 0 : (block_lanes * sizeof(double) - misalign) / sizeof(double);
}

// Points sorted into the columns of an xy grid, by z (then id) inside each column, so the points
// of one column within a z interval are one contiguous run (found by binary search). Sparse:
// only occupied columns are stored, ordered by (cx, cy), so memory and time follow the points,
// not the bounding box (one far vertex leaves the other columns as fine as without it).
struct column_grid {
  std::vector<double> rows;               // sorted points: x, y, z, value rows (see row)
  std::size_t points = 0, stride = 0, offset = 0;
  std::vector<std::uint32_t> src;         // index of each sorted point in the source vertex_points
  std::vector<std::uint64_t> col_key;     // occupied columns, ascending: cx << 32 | cy
  std::vector<std::uint32_t> col_start;   // occupied columns + 1 offsets into the sorted points
  double x0 = 0.0, y0 = 0.0, h = 1.0;     // grid origin and column width
  // Row r (0 x, 1 y, 2 z, 3 value), 64-byte aligned (unless the grid was copied).
  const double* row(std::size_t r) const { return rows.data() + offset + r * stride; }
  static std::uint64_t key(std::uint32_t cx, std::uint32_t cy) { return std::uint64_t{cx} << 32 | cy; }
  // Index of column (cx, cy) among the occupied ones, or col_key.size() when it is empty.
  std::size_t find(std::uint32_t cx, std::uint32_t cy) const {
    const auto it = std::lower_bound(col_key.begin(), col_key.end(), key(cx, cy));
    return it != col_key.end() && *it == key(cx, cy) ? static_cast<std::size_t>(it - col_key.begin()) : col_key.size();
  }
};

// Builds a column_grid with columns `width` wide (wider only when a coordinate would pass 2^31
// columns). O(P log P), allocation O(P); the columns are sorted in parallel through exec.
template <class E>
column_grid make_column_grid(E& exec, const vertex_points& g, double width) {
  column_grid c;
  const std::size_t P = g.x.size();
  double xlo = std::numeric_limits<double>::infinity(), xhi = -xlo, ylo = xlo, yhi = -xlo;
  for (std::size_t k = 0; k < P; ++k)
    xlo = std::min(xlo, g.x[k]), xhi = std::max(xhi, g.x[k]), ylo = std::min(ylo, g.y[k]), yhi = std::max(yhi, g.y[k]);
  double h = width > 0.0 ? width : 1.0;
  while (std::max(xhi - xlo, yhi - ylo) / h >= 2147483647.0) h *= 2.0;
  c.x0 = xlo, c.y0 = ylo, c.h = h;
  const auto nx = static_cast<std::uint32_t>(std::floor((xhi - xlo) / h)) + 1;
  const auto ny = static_cast<std::uint32_t>(std::floor((yhi - ylo) / h)) + 1;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(P);
  for (std::size_t k = 0; k < P; ++k) {
    const auto cx = std::min(static_cast<std::uint32_t>((g.x[k] - xlo) / h), nx - 1);
    const auto cy = std::min(static_cast<std::uint32_t>((g.y[k] - ylo) / h), ny - 1);
    keyed[k] = {column_grid::key(cx, cy), static_cast<std::uint32_t>(k)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> order(P);
  for (std::size_t k = 0; k < P; ++k) {
    order[k] = keyed[k].second;
    if (k == 0 || keyed[k].first != keyed[k - 1].first) {
      c.col_key.push_back(keyed[k].first);
      c.col_start.push_back(static_cast<std::uint32_t>(k));
    }
  }
  c.col_start.push_back(static_cast<std::uint32_t>(P));
  exec.parallel_for(c.col_key.size(), 64, [&](std::size_t b, std::size_t e) {
    for (std::size_t q = b; q < e; ++q)
      std::sort(order.begin() + c.col_start[q], order.begin() + c.col_start[q + 1], [&](std::uint32_t x, std::uint32_t y) {
        return g.z[x] != g.z[y] ? g.z[x] < g.z[y] : g.id[x] < g.id[y];
      });
  });
  c.points = P, c.stride = block_stride(P);
  c.rows.assign(4 * c.stride + block_lanes, 0.0);
  c.offset = aligned_offset(c.rows);
  double* r = c.rows.data() + c.offset;
  for (std::size_t k = 0; k < P; ++k) {
    const std::uint32_t s = order[k];
    r[k] = g.x[s], r[c.stride + k] = g.y[s], r[2 * c.stride + k] = g.z[s], r[3 * c.stride + k] = g.value[s];
  }
  c.src = std::move(order);
  return c;
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

// A tile: the occupied columns of a column_grid within span × span column positions, in
// (cx, cy) order.
struct column_tile {
  const std::uint32_t* cols;  // column indices (into col_key)
  std::uint32_t count;        // columns in the tile
  std::uint32_t points;       // points in the tile
};

// An occupied column near another: its index and grid position.
struct column_ref {
  std::size_t q;
  std::uint32_t ax, ay;
};

// The occupied columns that a point of column (cx, cy) meets: its own, the later ones in its
// x, and those up to span later in x and span either side in y, in (x, y) order.
inline void columns_after(const column_grid& g, std::uint32_t cx, std::uint32_t cy, std::uint32_t span,
                          std::vector<column_ref>& near) {
  near.clear();
  for (std::uint32_t ax = cx; ax <= cx + span; ++ax)
    for (std::uint32_t ay = ax == cx ? cy : (cy > span ? cy - span : 0); ay <= cy + span; ++ay)
      if (const std::size_t q = g.find(ax, ay); q < g.col_key.size()) near.push_back({q, ax, ay});
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
template <class V, std::size_t LC>
INFOLERP_FORCE_INLINE void gather_tile(const column_grid& g, const sigma_table& t, std::uint32_t span,
                                          column_tile tile, double* sums) {
  constexpr std::size_t width = sizeof(V) / sizeof(double), G = block_lanes / width;  // G vectors per block
  const std::size_t L = t.r2.size();
  const double r2max = t.r2[L - 1];
  const double *px_all = g.row(0), *py_all = g.row(1), *pz_all = g.row(2), *pc_all = g.row(3);
  std::vector<column_ref> near;
  for (std::uint32_t tc = 0; tc < tile.count; ++tc) {
    const std::uint32_t own = tile.cols[tc];
    columns_after(g, static_cast<std::uint32_t>(g.col_key[own] >> 32), static_cast<std::uint32_t>(g.col_key[own]), span,
                  near);
      for (std::size_t i = g.col_start[own]; i < g.col_start[own + 1]; ++i) {
        const double xi = px_all[i], yi = py_all[i], zi = pz_all[i], ci = pc_all[i];
        V acc_n[LC][G] = {}, acc_d[LC][G] = {}, w[LC][G];  // index s: σ number L − 1 − s
        for (const column_ref& nb : near) {
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
              V d2[G], c[G];
              for (std::size_t k = 0; k < G; ++k) {
                const std::size_t o = j + k * width;
                V vx, vy, vz;
                load_lanes(vx, px_all + o), load_lanes(vy, py_all + o), load_lanes(vz, pz_all + o), load_lanes(c[k], pc_all + o);
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
                  acc_d[s][k] = acc_d[s][k] + m;
                  md[k] = m, mn[k] = m * ci;
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
          ni[0] += n[0] + ci;  // i itself: weight 1
          ni[block_lanes] += d[0] + 1.0;
        }
      }
  }
}

// One tile with vectors V, 8 or 32 σ slots.
template <class V>
INFOLERP_FORCE_INLINE void gather_tile_any(const column_grid& g, const sigma_table& t, std::uint32_t span,
                                              column_tile tile, double* sums) {
  if (t.r2.size() <= 8) return gather_tile<V, 8>(g, t, span, tile, sums);
  gather_tile<V, 32>(g, t, span, tile, sums);
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

// The tiles of span × span column positions that hold points, each with its phase
// (tile x mod 2) · 3 + (tile y mod 3); cols receives the tiles' column lists. O(C log C) for C
// occupied columns.
inline std::vector<std::pair<std::uint32_t, column_tile>> make_column_tiles(const column_grid& g, std::uint32_t span,
                                                                            std::vector<std::uint32_t>& cols) {
  std::vector<std::pair<std::uint64_t, std::uint32_t>> by_tile(g.col_key.size());
  for (std::size_t q = 0; q < by_tile.size(); ++q) {
    const auto cx = static_cast<std::uint32_t>(g.col_key[q] >> 32), cy = static_cast<std::uint32_t>(g.col_key[q]);
    by_tile[q] = {column_grid::key(cx / span, cy / span), static_cast<std::uint32_t>(q)};
  }
  std::sort(by_tile.begin(), by_tile.end());  // by tile, then column index: (cx, cy) order
  cols.resize(by_tile.size());
  for (std::size_t k = 0; k < by_tile.size(); ++k) cols[k] = by_tile[k].second;
  std::vector<std::pair<std::uint32_t, column_tile>> tiles;
  for (std::size_t b = 0; b < by_tile.size();) {
    std::size_t e = b;
    std::uint32_t points = 0;
    for (; e < by_tile.size() && by_tile[e].first == by_tile[b].first; ++e)
      points += g.col_start[cols[e] + 1] - g.col_start[cols[e]];
    const auto tx = static_cast<std::uint32_t>(by_tile[b].first >> 32), ty = static_cast<std::uint32_t>(by_tile[b].first);
    tiles.push_back({tx % 2 * 3 + ty % 3, column_tile{cols.data() + b, static_cast<std::uint32_t>(e - b), points}});
    b = e;
  }
  return tiles;
}

// Exact Gaussian-weighted averages for L ascending radii sigma[u] (ball 2σ) over the grid's
// points. Returns avg[u * P + k] for point k of g. Every pair is evaluated once (gather_tile),
// tiles of span × span columns in 6 phases by (tile x mod 2, tile y mod 3): the tiles of one
// phase write disjoint points, so they run in parallel, and every point receives its terms in
// an order fixed by the data: identical bits for any executor, thread count and grain (tiles
// per task).
template <class E>
std::vector<double> exact_gaussian_averages(E& exec, const vertex_points& pg, const std::vector<double>& sigma,
                                            std::size_t grain) {
  const std::size_t P = pg.x.size(), L = sigma.size();
  const sigma_table t = make_sigma_table(sigma);
  const double rmax = 2.0 * sigma[L - 1];
  const column_grid g = make_column_grid(exec, pg, rmax / 3.0);
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
  std::vector<double> avg(L * P);
  exec.parallel_for(L, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t u = b; u < e; ++u)
      for (std::size_t k = 0; k < P; ++k) {
        const double* nk = point_sums(sums, L, k, u);
        avg[u * P + g.src[k]] = nk[0] / nk[block_lanes];
      }
  });
  return avg;
}

}  // namespace detail

// Per-vertex mesh saliency of any infolerp::mesh (see the top of this file).
// Errors: empty mesh, index out of range, non-finite position; epsilon <= 0 or not finite, no
// scales or more than 16 (counted as given, repeats included), a scale <= 0 or not finite,
// flat_level_threshold negative or not finite, a σ
// (scale × epsilon × diagonal) below ~1.5e-154 or above ~3.3e153, where σ² underflows or 16σ²
// overflows (bad_parameter); a
// mesh whose bounding box has zero diagonal (degenerate_triangle).
// Complexity: O(V log V + T + candidate pairs · distinct σs) (candidates: ~1.3× the unordered
// pairs within 2σ_max, each evaluated once). Allocation O(V·σs) (3 doubles per vertex and
// distinct σ, 64 at most; never per pair). Parallel through exec (6 phases of tiles); the
// result is identical for every executor and thread count.
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
  const std::vector<double> avg = detail::exact_gaussian_averages(exec, grid, sigma, opt.grain);

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
    const double tie = 1e-12 * mx;  // differences below this are rounding, not structure
    for (const glm::uvec2& e : topo->edges) {
      if (s[e.x] <= s[e.y] + tie) is_max[e.x] = 0;
      if (s[e.y] <= s[e.x] + tie) is_max[e.y] = 0;
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
