#pragma once
// Texture-stretch channel (clustering paper §3.1.3): a direct channel T→T with p(t) = 1/M and
//   p(t_j|t_i) = (1 − |S(t_i) − S(t_j)|) / Σ_t (1 − |S(t_i) − S(t)|),
// S(t) the stretch of Degener, Meseth & Klein 2003 ("An adaptable surface parameterization
// method", the paper's [38]) normalised to [0,1] within the (sub)mesh being clustered.
//
// S(t): σ1 >= σ2 are the singular values of the Jacobian J of the affine map from the triangle
// (in an orthonormal frame of its plane) to its UV triangle, the UVs first scaled by one factor
// so that the mesh's total UV area equals its total surface area (S is then scale-free):
//   S = (σ1/σ2 + σ2/σ1) · (σ1σ2 + 1/(σ1σ2))^θ        θ >= 0, default 1; S >= 4 for θ = 1.
// Special case: a triangle whose UV image or 3D triangle has zero area has no finite S; it gets
// the largest normalised stretch of its set, 1. A set whose finite stretches are all equal
// normalises them to 0.
//
// Exact (bins = 0): classes are the distinct normalised values, sorted; O(U) per row. Binned
// (bins = K): the columns are the occupied ones of K equal cells over [0,1]; per-cell rows
// (exact_rows = false) let a cell's mean value stand for its elements, O(C) per row, C <= K;
// exact rows (exact_rows = true) keep every distinct value's own row over the cells, with each
// cell's mass Σ(1 − |s_a − s|) exact by prefix sums (also the cell holding s_a), O(C) per row.
// Binned error: per-cell rows replace the triangle's own value by its cell's mean (error <=
// 1/K), over-estimate the own cell's mass by at most count/K, and take the entries inside a cell
// as equal (which can only lower JS); exact rows keep only the last. Per-cell rows can move
// clusters a lot where S is near 1 (the row entries 1 − |ΔS| of the least stretched triangles
// are tiny, so a 1/K shift of the own value changes them by large factors); exact rows agree
// with exact at a fraction of its time (benchmarks/NOTES.md, BM_StretchChannel).
// Meshes without texcoords: prepare() succeeds and skip_reason() says the channel is skipped.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numeric>
#include <span>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/cluster/channel.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/topology.hpp"

namespace infolerp {

// Degener stretch of one triangle; +inf when the 3D or the (scaled) UV triangle has no area.
// Preconditions: finite inputs, theta >= 0. O(1), no allocation.
inline double degener_stretch(const triangle_corners& c, glm::dvec2 uv0, glm::dvec2 uv1, glm::dvec2 uv2,
                              double uv_scale, double theta) {
  const glm::dvec3 e1 = c.p1 - c.p0, e2 = c.p2 - c.p0;
  const double l1 = glm::length(e1);
  const glm::dvec3 n = glm::cross(e1, e2);
  const double twice_area = glm::length(n);
  if (!(l1 > 0.0) || !(twice_area > 0.0)) return std::numeric_limits<double>::infinity();
  const glm::dvec3 x = e1 / l1, y = glm::cross(n / twice_area, x);
  // Q = [q1 q2] (3D triangle in its frame), D = [d1 d2] (UV edges); J = D Q⁻¹.
  const double q1x = l1, q2x = glm::dot(e2, x), q2y = glm::dot(e2, y);  // q1y = 0
  const glm::dvec2 d1 = (uv1 - uv0) * uv_scale, d2 = (uv2 - uv0) * uv_scale;
  const double det_q = q1x * q2y;
  // Q⁻¹ = [q2y, -q2x; 0, q1x] / det_q.
  const double a = d1.x * q2y / det_q, b = (d2.x * q1x - d1.x * q2x) / det_q;
  const double cc = d1.y * q2y / det_q, d = (d2.y * q1x - d1.y * q2x) / det_q;
  // Closed-form singular values of [a b; cc d].
  const double e = 0.5 * (a + d), f = 0.5 * (a - d), g = 0.5 * (cc + b), h = 0.5 * (cc - b);
  // |(u, w)|: sqrt(u² + w²) where the squares can neither overflow nor underflow (libm's
  // hypot is a visible share of the three-channel clustering), hypot elsewhere.
  auto norm = [](double u, double w) {
    const double big = std::max(std::abs(u), std::abs(w));
    return big < 0x1p500 && big > 0x1p-500 ? std::sqrt(u * u + w * w) : std::hypot(u, w);
  };
  const double qn = norm(e, h), rn = norm(f, g);
  const double s1 = qn + rn, s2 = std::abs(qn - rn);
  if (!(s2 > 0.0) || !std::isfinite(s1)) return std::numeric_limits<double>::infinity();
  const double area = s1 * s2;
  const double value = (s1 / s2 + s2 / s1) * (theta == 1.0 ? area + 1.0 / area : std::pow(area + 1.0 / area, theta));  // pow(x, 1) == x
  return std::isfinite(value) ? value : std::numeric_limits<double>::infinity();
}

// Per-triangle Degener stretch of a textured mesh (+inf where undefined, see above).
// Errors: mesh without texcoords (unsupported), non-finite texcoords (names the triangle),
// theta negative or NaN. Complexity O(T), allocation T doubles.
template <class M>
result<std::vector<double>> texture_stretch(const M& m, double theta = 1.0) {
  static_assert(check_mesh<M>());
  if (!(theta >= 0.0) || !std::isfinite(theta))
    return make_error(errc::bad_parameter, no_element, "stretch channel: theta ", theta, " must be finite and >= 0");
  const std::size_t nt = mesh_triangle_count(m);
  if (!mesh_has_texcoords(m)) return make_error(errc::unsupported, no_element, "stretch channel: mesh has no texcoords");
  std::vector<double> out(nt, std::numeric_limits<double>::infinity());
  if constexpr (textured_mesh<M>) {
    std::vector<glm::dvec2> uv(3 * nt);
    double area3 = 0.0, area_uv = 0.0;
    for (std::size_t t = 0; t < nt; ++t) {
      for (unsigned k = 0; k < 3; ++k) {
        uv[3 * t + k] = glm::dvec2(mesh_traits<M>::texcoord(m, t, k));
        if (!std::isfinite(uv[3 * t + k].x) || !std::isfinite(uv[3 * t + k].y))
          return make_error(errc::non_finite, t, "stretch channel: triangle ", t, " corner ", k, ": non-finite texcoord");
      }
      area3 += triangle_area(corners(m, t));
      const glm::dvec2 d1 = uv[3 * t + 1] - uv[3 * t], d2 = uv[3 * t + 2] - uv[3 * t];
      area_uv += 0.5 * std::abs(d1.x * d2.y - d1.y * d2.x);
    }
    if (!(area_uv > 0.0) || !(area3 > 0.0)) return out;  // every triangle is the special case
    const double scale = std::sqrt(area3 / area_uv);
    for (std::size_t t = 0; t < nt; ++t)
      out[t] = degener_stretch(corners(m, t), uv[3 * t], uv[3 * t + 1], uv[3 * t + 2], scale, theta);
  }
  return out;
}

// Classes of normalised stretch values, sorted ascending by value.
struct stretch_kernel {
  std::vector<double> counts;        // elements per row class
  std::vector<double> reps;          // normalised stretch of the row class, ascending (cell mean for per-cell rows)
  std::vector<double> totals;        // Σ_c mass(a, c), by prefix sums
  std::vector<std::uint32_t> first;  // column c holds the row classes [first[c], first[c + 1])
  std::vector<double> cnt_prefix, sum_prefix;  // Σ count and Σ count·rep over row classes [0, a)

  std::size_t class_count() const { return counts.size(); }
  double count(std::uint32_t a) const { return counts[a]; }
  std::size_t column_count() const { return first.size() - 1; }
  double column_size(std::uint32_t c) const { return cnt_prefix[first[c + 1]] - cnt_prefix[first[c]]; }
  // Σ over the column's elements of 1 − |s_a − s| (never negative: every s is in [0, 1]).
  // A one-class column (exact and per-cell rows, every column) takes the direct product: fewer
  // loads on the row-building path, and the bits those modes always had; the prefix sums give
  // the same value to rounding.
  double mass(std::uint32_t a, std::uint32_t c) const {
    const std::uint32_t lo = first[c], hi = first[c + 1];
    if (hi == lo + 1) return counts[lo] * std::max(0.0, 1.0 - std::abs(reps[a] - reps[lo]));
    const double x = reps[a];
    const auto below = [&](std::uint32_t b, std::uint32_t e) {  // Σ count·(x − rep) over [b, e), reps <= x
      return x * (cnt_prefix[e] - cnt_prefix[b]) - (sum_prefix[e] - sum_prefix[b]);
    };
    double dist;
    if (a < lo) dist = -below(lo, hi);
    else if (a >= hi) dist = below(lo, hi);
    else dist = below(lo, a) - below(a + 1, hi);
    return std::max(0.0, column_size(c) - dist);
  }
  double total(std::uint32_t a) const { return totals[a]; }
};

using stretch_state = direct_channel_state<stretch_kernel>;

// Normalises raw stretch values (+inf = special case) to [0,1] and builds the channel.
// bins = 0: exact (row classes and columns are the distinct values). bins = K: the columns are
// the occupied ones of K equal cells over [0, 1]; exact_rows = false: the rows are per cell too
// (the cell's mean value stands for its elements); exact_rows = true: every distinct value keeps
// its own row over the cells, with masses exact by prefix sums (U rows of C entries).
// Complexity O(M log M) with exact classes, O(M + K) per-cell rows (O(M log M) when K > 4·M +
// 4096) (+ the O(U·C) output distribution). Allocation O(M + U + C + min(K, 4·M + 4096)).
inline stretch_state make_stretch_state(std::span<const double> raw, std::uint32_t bins, bool exact_rows = false) {
  const std::size_t m = raw.size();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double s : raw)
    if (std::isfinite(s)) {
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
  std::vector<double> s(m);
  for (std::size_t i = 0; i < m; ++i)
    s[i] = !std::isfinite(raw[i]) ? 1.0 : hi > lo ? std::clamp((raw[i] - lo) / (hi - lo), 0.0, 1.0) : 0.0;

  const auto cell_of = [&](double v) { return std::min(bins - 1, static_cast<std::uint32_t>(v * bins)); };
  std::vector<std::uint32_t> class_of(m);
  stretch_kernel k;
  if (bins == 0 || exact_rows) {
    std::vector<std::uint32_t> order(m);
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return s[a] != s[b] ? s[a] < s[b] : a < b; });
    for (std::size_t i = 0; i < m; ++i) {
      if (i == 0 || s[order[i]] != s[order[i - 1]]) {
        k.counts.push_back(0.0);
        k.reps.push_back(s[order[i]]);
      }
      class_of[order[i]] = static_cast<std::uint32_t>(k.counts.size() - 1);
      k.counts.back() += 1.0;
    }
  } else {
    std::vector<std::uint32_t> cell(m);
    for (std::size_t i = 0; i < m; ++i) cell[i] = cell_of(s[i]);
    const std::uint32_t u = detail::number_occupied_cells(cell, bins, class_of);
    k.counts.assign(u, 0.0);
    k.reps.assign(u, 0.0);
    for (std::size_t i = 0; i < m; ++i) {
      k.counts[class_of[i]] += 1.0;
      k.reps[class_of[i]] += s[i];
    }
    for (std::uint32_t c = 0; c < u; ++c) k.reps[c] /= k.counts[c];
  }
  // Columns: one per row class, or (exact rows, binned) the runs of ascending values in one cell.
  const std::size_t u = k.counts.size();
  for (std::uint32_t a = 0; a < u; ++a)
    if (!(bins > 0 && exact_rows) || a == 0 || cell_of(k.reps[a]) != cell_of(k.reps[a - 1])) k.first.push_back(a);
  k.first.push_back(static_cast<std::uint32_t>(u));
  // totals: M − Σ_c count_c |rep_a − rep_c| with reps ascending (masses never clamp: reps in [0,1]).
  k.cnt_prefix.assign(u + 1, 0.0);
  k.sum_prefix.assign(u + 1, 0.0);
  for (std::size_t c = 0; c < u; ++c) {
    k.cnt_prefix[c + 1] = k.cnt_prefix[c] + k.counts[c];
    k.sum_prefix[c + 1] = k.sum_prefix[c] + k.counts[c] * k.reps[c];
  }
  k.totals.resize(u);
  for (std::size_t a = 0; a < u; ++a) {
    const double x = k.reps[a];
    const double below = x * k.cnt_prefix[a] - k.sum_prefix[a];
    const double above = (k.sum_prefix[u] - k.sum_prefix[a + 1]) - x * (k.cnt_prefix[u] - k.cnt_prefix[a + 1]);
    k.totals[a] = std::max(0.0, static_cast<double>(m) - below - above);
  }
  return stretch_state(std::move(class_of), std::move(k));
}

// The stretch channel prepared for one mesh: raw per-triangle stretch, or skipped.
struct prepared_stretch_channel {
  double threshold = 0.1;
  std::uint32_t bins = 1024;
  bool exact_rows = false;
  std::vector<double> stretch;  // raw Degener stretch per triangle (+inf: special case)
  bool skipped = false;

  // nullptr when active; otherwise why Algorithm 1 skips this channel.
  const char* skip_reason() const { return skipped ? "stretch channel skipped: mesh has no texture coordinates" : nullptr; }

  // Algorithm 1's ch.init(cl). Errors: empty set, id out of range, channel skipped.
  result<stretch_state> init(std::span<const std::uint32_t> triangles) const {
    if (skipped) return make_error(errc::unsupported, no_element, skip_reason());
    if (triangles.empty()) return make_error(errc::empty_input, no_element, "stretch channel: empty triangle set");
    std::vector<double> raw(triangles.size());
    for (std::size_t i = 0; i < triangles.size(); ++i) {
      if (triangles[i] >= stretch.size())
        return make_error(errc::index_out_of_range, triangles[i], "stretch channel: triangle ", triangles[i],
                          " out of range (", stretch.size(), " triangles)");
      raw[i] = stretch[triangles[i]];
    }
    return make_stretch_state(raw, bins, exact_rows);
  }
};

struct stretch_channel {
  double threshold = 0.1;     // JS threshold Th in [0,1]
  std::uint32_t bins = 1024;  // K cells over the normalised stretch; 0 = exact rows. Any K is valid:
                              // memory follows the occupied cells (<= triangles), not K
  bool exact_rows = false;    // with bins > 0: each distinct value keeps its own row over the cells
  double theta = 1.0;         // Degener's area-distortion exponent θ >= 0

  // Computes the raw stretch per triangle, or marks the channel skipped (no texcoords).
  // Errors: as texture_stretch (non-finite texcoords, bad theta). O(T), allocation T doubles.
  template <class M, class T, class E>
  result<prepared_stretch_channel> prepare(const M& m, const mesh_topology& /*topo*/, const T& /*tracer*/,
                                           E& /*exec*/) const {
    static_assert(check_mesh<M>());
    prepared_stretch_channel p{threshold, bins, exact_rows, {}, false};
    if (!mesh_has_texcoords(m)) {
      p.skipped = true;
      return p;
    }
    auto s = texture_stretch(m, theta);
    if (!s) return s.error();
    p.stretch = std::move(*s);
    return p;
  }
};

}  // namespace infolerp
