#pragma once
// Orientation channel (clustering paper §3.1.2): a direct channel T→T with p(t) = 1/M and
//   p(t_i|t_j) = (1 − n(t_i)·n(t_j)) / Σ_t (1 − n(t)·n(t_j)),
// evaluated per class of normals (channel.hpp), never as an M×M matrix.
//
// Three evaluations (rows per row class, entries per column; channel.hpp):
//   exact        (bins = 0): row classes and columns are the distinct normals (bitwise); the
//                rows are the M-entry rows aggregated without loss. O(U) per row, U <= M.
//   binned       (bins = K, exact_rows = false): row classes and columns are the occupied cells
//                of an r×r octahedral normal map (r = floor(√K)). O(C) per row, C <= K + 1.
//   exact rows   (bins = K, exact_rows = true): row classes are the distinct normals, columns
//                the occupied cells: the exact channel to the cells. O(C) per row, U rows.
// Binned error: the kernel is linear in n', so each cell's mass Σ(1 − n·n') = count − n·Σn' is
// exact for any row normal n. Per-cell rows add two approximations: (1) every triangle of a cell
// uses the cell's mean normal as its own (angular error up to about half a cell diagonal,
// ≈ 2.5/√K rad before the octahedral map's up-to-2× area distortion), and (2) the entries inside
// a cell are taken as equal, which can only lower JS (data-processing inequality). Exact rows
// keep only (2). Per-cell rows are the fast choice inside Algorithm 1; exact rows agree with
// exact more closely at U rows' cost (benchmarks/NOTES.md, BM_OrientationChannel).
// Degenerate cases: a planar set is one class (all alike: one cluster, no work); a zero-area
// triangle's normal is (0,0,0) (mesh/geometry.hpp), its own class with a uniform row.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <span>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/cluster/channel.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/topology.hpp"

namespace infolerp {

// Mass of the orientation kernel: per row class its normal and size, per column its size and
// summed normal (for exact rows and per-cell rows the columns are the row classes).
struct orientation_kernel {
  std::vector<double> counts;          // elements per row class
  std::vector<glm::dvec3> reps;        // the row class's normal (exact) or normalised cell mean
  std::vector<double> column_counts;   // elements per column
  std::vector<glm::dvec3> column_sums; // Σ n over the column
  glm::dvec3 total_sum{0.0};
  double elements = 0.0;

  std::size_t class_count() const { return counts.size(); }
  double count(std::uint32_t a) const { return counts[a]; }
  std::size_t column_count() const { return column_counts.size(); }
  double column_size(std::uint32_t c) const { return column_counts[c]; }
  double mass(std::uint32_t a, std::uint32_t c) const {
    return std::max(0.0, column_counts[c] - glm::dot(reps[a], column_sums[c]));
  }
  double total(std::uint32_t a) const { return std::max(0.0, elements - glm::dot(reps[a], total_sum)); }
};

using orientation_state = direct_channel_state<orientation_kernel>;

// Octahedral cell of a unit normal on an r×r grid; (0,0,0) maps to cell r·r.
inline std::uint32_t octahedral_cell(glm::vec3 n, std::uint32_t r) {
  const double l1 = std::abs(double(n.x)) + std::abs(double(n.y)) + std::abs(double(n.z));
  if (!(l1 > 0.0)) return r * r;
  double x = n.x / l1, y = n.y / l1;
  if (n.z < 0.0f) {
    const double sx = x >= 0.0 ? 1.0 : -1.0, sy = y >= 0.0 ? 1.0 : -1.0;
    const double nx = (1.0 - std::abs(y)) * sx, ny = (1.0 - std::abs(x)) * sy;
    x = nx;
    y = ny;
  }
  const double rr = static_cast<double>(r);
  const auto ix = static_cast<std::uint32_t>(std::clamp((x + 1.0) * 0.5 * rr, 0.0, rr - 1.0));
  const auto iy = static_cast<std::uint32_t>(std::clamp((y + 1.0) * 0.5 * rr, 0.0, rr - 1.0));
  return iy * r + ix;
}

// Builds the orientation channel over the given normals (one per element).
// bins = 0: exact (row classes and columns are the distinct normals). bins = K: the columns are
// the occupied cells of the octahedral map; exact_rows = false: the rows are per cell too (the
// cell's mean normal stands for its elements); exact_rows = true: every distinct normal keeps
// its own row over the cells (U rows of C entries).
// Preconditions: normals unit or (0,0,0). Complexity O(M log M) with exact classes, O(M + K)
// per-cell rows (O(M log M) when K > 4·M + 4096) (+ the O(U·C) output distribution).
// Allocation O(M + U + C + min(K, 4·M + 4096)): any K, up to 2^32 − 1, sizes nothing beyond the
// cells in use (channel.hpp, number_occupied_cells).
inline orientation_state make_orientation_state(std::span<const glm::vec3> normals, std::uint32_t bins,
                                                bool exact_rows = false) {
  const std::size_t m = normals.size();
  std::vector<std::uint32_t> class_of(m);
  orientation_kernel k;
  k.elements = static_cast<double>(m);
  if (bins == 0 || exact_rows) {
    std::vector<std::uint32_t> order(m);
    std::iota(order.begin(), order.end(), 0u);
    auto less = [&](std::uint32_t a, std::uint32_t b) {
      const glm::vec3 p = normals[a], q = normals[b];
      return p.x != q.x ? p.x < q.x : p.y != q.y ? p.y < q.y : p.z != q.z ? p.z < q.z : a < b;
    };
    std::sort(order.begin(), order.end(), less);
    for (std::size_t i = 0; i < m; ++i) {
      if (i == 0 || normals[order[i]] != normals[order[i - 1]]) {
        k.counts.push_back(0.0);
        k.column_sums.emplace_back(0.0);
        k.reps.emplace_back(normals[order[i]]);
      }
      class_of[order[i]] = static_cast<std::uint32_t>(k.counts.size() - 1);
      k.counts.back() += 1.0;
      k.column_sums.back() += glm::dvec3(normals[order[i]]);
    }
    k.column_counts = k.counts;
  }
  if (bins > 0) {
    const auto r = std::max<std::uint32_t>(1, static_cast<std::uint32_t>(std::sqrt(double(bins))));
    std::vector<std::uint32_t> cell(m), column;
    for (std::size_t i = 0; i < m; ++i) cell[i] = octahedral_cell(normals[i], r);
    const std::uint32_t u = detail::number_occupied_cells(cell, std::size_t{r} * r + 1, column);
    k.column_counts.assign(u, 0.0);
    k.column_sums.assign(u, glm::dvec3(0.0));
    for (std::size_t i = 0; i < m; ++i) {
      const std::uint32_t c = column[i];
      k.column_counts[c] += 1.0;
      k.column_sums[c] += glm::dvec3(normals[i]);
    }
    if (!exact_rows) {
      class_of = std::move(column);
      k.counts = k.column_counts;
      k.reps.resize(u);
      for (std::uint32_t c = 0; c < u; ++c) {
        const double len = glm::length(k.column_sums[c]);
        k.reps[c] = len > 0.0 ? k.column_sums[c] / len : glm::dvec3(0.0);
      }
    }
  }
  for (const auto& s : k.column_sums) k.total_sum += s;
  return orientation_state(std::move(class_of), std::move(k));
}

// The orientation channel prepared for one mesh: face normals, ready to init on triangle sets.
struct prepared_orientation_channel {
  double threshold = 0.02;
  std::uint32_t bins = 1024;
  bool exact_rows = false;
  std::vector<glm::vec3> normals;  // per triangle of the mesh

  // Algorithm 1's ch.init(cl). Errors: empty set, triangle id out of range.
  // Complexity as make_orientation_state. Thread-safe (const).
  result<orientation_state> init(std::span<const std::uint32_t> triangles) const {
    if (triangles.empty()) return make_error(errc::empty_input, no_element, "orientation channel: empty triangle set");
    std::vector<glm::vec3> n(triangles.size());
    for (std::size_t i = 0; i < triangles.size(); ++i) {
      if (triangles[i] >= normals.size())
        return make_error(errc::index_out_of_range, triangles[i], "orientation channel: triangle ", triangles[i],
                          " out of range (", normals.size(), " triangles)");
      n[i] = normals[triangles[i]];
    }
    return make_orientation_state(n, bins, exact_rows);
  }
};

// User-facing options (Algorithm 1 takes it directly, e.g. orientation_channel{.threshold = 0.02}).
struct orientation_channel {
  double threshold = 0.02;  // JS threshold Th in [0,1]: 0 = one cluster per triangle, 1 = one cluster
  std::uint32_t bins = 1024;  // K octahedral cells (rounded down to a square); 0 = exact rows. Any
                              // K is valid: memory follows the occupied cells (<= triangles), not K
  bool exact_rows = false;    // with bins > 0: each distinct normal keeps its own row over the cells

  // Computes the face normals. Complexity O(T), allocation T normals. Never fails for a valid mesh.
  template <class M, class T, class E>
  result<prepared_orientation_channel> prepare(const M& m, const mesh_topology& /*topo*/, const T& /*tracer*/,
                                               E& /*exec*/) const {
    static_assert(check_mesh<M>());
    return prepared_orientation_channel{threshold, bins, exact_rows, face_normals(m)};
  }
};

}  // namespace infolerp
