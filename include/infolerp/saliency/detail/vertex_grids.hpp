#pragma once
// Vertex containers for the saliency ball sums (saliency/detail/gaussian_ball_averages.hpp):
// the referenced vertices of a mesh, and a sparse grid of xy columns sorted by z in which the
// vertices near a point are a few contiguous runs. Only occupied columns are stored, so memory
// and time follow the vertices, not the bounding box (one far vertex leaves the columns as fine
// as without it).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/core/mesh_traits.hpp"

namespace infolerp::detail {

// The referenced vertices (those a triangle uses), in index order: position, value, index; or
// weighted points (a proxy's cells: value = the sum of the values it stands for, weight = their
// count). An empty weight means weight 1 everywhere.
struct vertex_points {
  std::vector<double> x, y, z, value, weight;
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
  std::vector<double> rows;               // sorted points: x, y, z, value (, weight) rows (see row)
  bool weighted = false;                  // a weight row follows the value row
  std::size_t points = 0, stride = 0, offset = 0;
  std::vector<std::uint32_t> src;         // index of each sorted point in the source vertex_points
  std::vector<std::uint64_t> col_key;     // occupied columns, ascending: cx << 32 | cy
  std::vector<std::uint32_t> col_start;   // occupied columns + 1 offsets into the sorted points
  double x0 = 0.0, y0 = 0.0, h = 1.0;     // grid origin and column width
  // Row r (0 x, 1 y, 2 z, 3 value, 4 weight when weighted), 64-byte aligned (unless the grid was copied).
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
  c.weighted = !g.weight.empty();
  c.rows.assign((c.weighted ? 5 : 4) * c.stride + block_lanes, 0.0);
  c.offset = aligned_offset(c.rows);
  double* r = c.rows.data() + c.offset;
  for (std::size_t k = 0; k < P; ++k) {
    const std::uint32_t s = order[k];
    r[k] = g.x[s], r[c.stride + k] = g.y[s], r[2 * c.stride + k] = g.z[s], r[3 * c.stride + k] = g.value[s];
    if (c.weighted) r[4 * c.stride + k] = g.weight[s];
  }
  c.src = std::move(order);
  return c;
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
                          std::vector<column_ref>& nearby) {
  nearby.clear();
  for (std::uint32_t ax = cx; ax <= cx + span; ++ax)
    for (std::uint32_t ay = ax == cx ? cy : (cy > span ? cy - span : 0); ay <= cy + span; ++ay)
      if (const std::size_t q = g.find(ax, ay); q < g.col_key.size()) nearby.push_back({q, ax, ay});
}

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

}  // namespace infolerp::detail
