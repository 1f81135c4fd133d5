#pragma once
// What a camera cannot see of a LOD (view_dependent_lod's culling, salient-clustering paper §IV
// draws per view; culling is ours): a triangle wholly outside one side of the view frustum or
// behind the eye, and a triangle facing away from the eye on a closed part of the mesh.
// Closed part: an edge-connected component each of whose edges joins two triangles of opposite
// winding, with a positive signed volume (normals outward). Seen from outside such a part, the
// first surface a ray meets faces the eye, and half-edge collapses (contraction_hierarchy.hpp:
// manifold, orientation kept) keep the part closed, so its back faces are hidden at every level
// (unless a contracted surface passes through itself). Back faces elsewhere (boundary edges,
// inconsistent winding, an inside-out part, a cluster the caller marks two-sided) may be seen and
// are never culled, nor are any when the eye is inside a closed part of the cut (the signed
// crossings of a ray from the eye with its triangles do not sum to 0); the frustum test applies
// to every triangle.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numeric>
#include <span>
#include <vector>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/lod/screen_error_selection.hpp"

namespace infolerp {

// Per-triangle flags of the culling spans (one_sided): a closed_face is back-face culled and
// counts in the eye-inside test; a two_sided_face (a closed part's triangle in a cluster the
// caller marks two-sided) is never culled but still counts, so that its part stays closed for
// the test; 0 (open, inconsistent or inside-out) does neither.
inline constexpr std::uint8_t closed_face = 1, two_sided_face = 2;

// 1 per triangle of indices (3 per triangle) on a closed part (see above), else 0; a triangle
// with a repeated index is 0 and holds none of its edges. Preconditions: indices < positions.size().
// O(T log T), allocation O(T).
inline std::vector<std::uint8_t> closed_part_triangles(std::span<const std::uint32_t> indices,
                                                       std::span<const glm::vec3> positions) {
  const std::size_t nt = indices.size() / 3;
  struct half_edge {
    std::uint64_t key;  // min << 32 | max
    std::uint32_t triangle;
    bool forward;  // min → max in the triangle's winding
  };
  std::vector<half_edge> edges;
  edges.reserve(3 * nt);
  auto degenerate = [&](std::size_t t) {
    const std::uint32_t* f = indices.data() + 3 * t;
    return f[0] == f[1] || f[1] == f[2] || f[0] == f[2];
  };
  for (std::size_t t = 0; t < nt; ++t) {
    if (degenerate(t)) continue;
    for (std::size_t j = 0; j < 3; ++j) {
      const std::uint32_t a = indices[3 * t + j], b = indices[3 * t + (j + 1) % 3];
      edges.push_back({std::uint64_t{std::min(a, b)} << 32 | std::max(a, b), static_cast<std::uint32_t>(t), a < b});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const half_edge& x, const half_edge& y) { return x.key < y.key; });
  std::vector<std::uint32_t> parent(nt);
  std::iota(parent.begin(), parent.end(), 0u);
  auto root = [&](std::uint32_t t) {
    while (parent[t] != t) t = parent[t] = parent[parent[t]];
    return t;
  };
  std::vector<std::uint8_t> open(nt, 0);
  for (std::size_t i = 0, e = 0; i < edges.size(); i = e) {
    while (e < edges.size() && edges[e].key == edges[i].key) ++e;
    const bool shared = e - i == 2 && edges[i].forward != edges[i + 1].forward;
    for (std::size_t k = i; k < e; ++k) {
      const std::uint32_t r = root(edges[k].triangle), s = root(edges[i].triangle);
      if (!shared) open[r] = 1;
      if (r != s) parent[r] = s, open[s] = open[s] | open[r];
    }
  }
  std::vector<double> volume(nt, 0.0);
  for (std::size_t t = 0; t < nt; ++t) {
    if (degenerate(t)) continue;
    const glm::dvec3 a(positions[indices[3 * t]]), b(positions[indices[3 * t + 1]]), c(positions[indices[3 * t + 2]]);
    volume[root(static_cast<std::uint32_t>(t))] += glm::dot(a, glm::cross(b, c));
  }
  std::vector<std::uint8_t> closed(nt, 0);
  for (std::size_t t = 0; t < nt; ++t) {
    const std::uint32_t r = root(static_cast<std::uint32_t>(t));
    closed[t] = !degenerate(t) && !open[r] && volume[r] > 0.0 ? 1 : 0;
  }
  return closed;
}

// The bounding box of the vertices of one-sided triangles (empty: lo > hi). O(T).
inline void closed_part_bounds(std::span<const std::uint32_t> indices, std::span<const glm::vec3> positions,
                               std::span<const std::uint8_t> one_sided, glm::dvec3& lo, glm::dvec3& hi) {
  lo = glm::dvec3(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t t = 0; t < one_sided.size(); ++t)
    if (one_sided[t])
      for (std::size_t j = 0; j < 3; ++j) {
        const glm::dvec3 p(positions[indices[3 * t + j]]);
        lo = glm::min(lo, p), hi = glm::max(hi, p);
      }
}

// The camera's eye and the inward normals of its frustum's side planes and of the plane through
// the eye facing forward (no near or far plane).
struct view_frustum {
  glm::dvec3 eye{0.0};
  glm::dvec3 inward[5]{};
  glm::vec3 eye_f{0.0f}, inward_f[5]{};  // the same in single precision (hidden_triangle)
  // A box holding every closed part: an eye outside it is outside them all (no winding pass).
  glm::dvec3 closed_lo{-std::numeric_limits<double>::infinity()}, closed_hi{std::numeric_limits<double>::infinity()};
  [[nodiscard]] bool may_be_inside_closed() const {
    return eye.x >= closed_lo.x && eye.y >= closed_lo.y && eye.z >= closed_lo.z && eye.x <= closed_hi.x &&
           eye.y <= closed_hi.y && eye.z <= closed_hi.z;
  }
};

// Preconditions: check_camera(cam) passed. O(1).
inline view_frustum make_view_frustum(const lod_camera& cam) {
  const auto [f, right, up] = make_camera_basis(cam);
  const double tv = std::tan(0.5 * cam.vertical_fov);
  const double th = tv * static_cast<double>(cam.width) / static_cast<double>(cam.height);
  view_frustum v;
  constexpr double big = std::numeric_limits<float>::max();  // a farther eye converts to the largest float
  v.eye = cam.position, v.eye_f = glm::vec3(glm::clamp(cam.position, glm::dvec3(-big), glm::dvec3(big)));
  const glm::dvec3 inward[5] = {f, th * f - right, th * f + right, tv * f - up, tv * f + up};
  for (int k = 0; k < 5; ++k) v.inward[k] = inward[k], v.inward_f[k] = glm::vec3(inward[k]);
  return v;
}

// Whether triangle (a, b, c) faces away from the eye: its normal along eye → a. Single
// precision (the positions' own): edges from the corners, not from the eye, so that a distant
// eye costs no precision in the normal. O(1).
inline bool facing_away(const view_frustum& v, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  return glm::dot(glm::cross(b - a, c - a), a - v.eye_f) > 0.0f;
}

// Whether no pixel of the camera sees triangle (a, b, c): wholly outside one plane of the
// frustum, or facing away from the eye when `one_sided` (on a closed part). O(1).
inline bool hidden_triangle(const view_frustum& v, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                            bool one_sided) {
  const glm::vec3 pa = a - v.eye_f, pb = b - v.eye_f, pc = c - v.eye_f;
  if (one_sided && facing_away(v, a, b, c)) return true;
  for (const glm::vec3& n : v.inward_f)
    if (glm::dot(n, pa) < 0.0f && glm::dot(n, pb) < 0.0f && glm::dot(n, pc) < 0.0f) return true;
  return false;
}

// Triangles hidden_block tests at once.
inline constexpr std::size_t hidden_block_size = 64;

// The corners of up to hidden_block_size triangles, one array per coordinate and corner (a
// structure of arrays, so that hidden_block's loop runs on several triangles per instruction).
struct triangle_block {
  float x[3][hidden_block_size], y[3][hidden_block_size], z[3][hidden_block_size];
  std::int32_t one_sided[hidden_block_size];  // nonzero: back faces hidden
};

// hidden[i] = hidden_triangle(v, corners of i, one_sided[i] != 0), the same single-precision
// operations bit for bit, for i < n <= hidden_block_size. O(n), branch-free.
inline void hidden_block(const view_frustum& v, const triangle_block& b, std::size_t n, std::int32_t* hidden) {
  const float ex = v.eye_f.x, ey = v.eye_f.y, ez = v.eye_f.z;
  for (std::size_t i = 0; i < n; ++i) {  // glm's order: cross(b − a, c − a), dot as (x + y) + z
    const float ax = b.x[0][i] - ex, ay = b.y[0][i] - ey, az = b.z[0][i] - ez;
    const float e1x = b.x[1][i] - b.x[0][i], e1y = b.y[1][i] - b.y[0][i], e1z = b.z[1][i] - b.z[0][i];
    const float e2x = b.x[2][i] - b.x[0][i], e2y = b.y[2][i] - b.y[0][i], e2z = b.z[2][i] - b.z[0][i];
    const float nx = e1y * e2z - e2y * e1z, ny = e1z * e2x - e2z * e1x, nz = e1x * e2y - e2x * e1y;
    hidden[i] = (b.one_sided[i] != 0) & (nx * ax + ny * ay + nz * az > 0.0f);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const float ax = b.x[0][i] - ex, ay = b.y[0][i] - ey, az = b.z[0][i] - ez;
    const float bx = b.x[1][i] - ex, by = b.y[1][i] - ey, bz = b.z[1][i] - ez;
    const float cx = b.x[2][i] - ex, cy = b.y[2][i] - ey, cz = b.z[2][i] - ez;
    std::int32_t out = 0;
    for (const glm::vec3& p : v.inward_f)
      out |= (p.x * ax + p.y * ay + p.z * az < 0.0f) & (p.x * bx + p.y * by + p.z * bz < 0.0f) &
             (p.x * cx + p.y * cy + p.z * cz < 0.0f);
    hidden[i] |= out;
  }
}

// Whether every point of the box [lo, hi] lies inside every plane of v as hidden_triangle
// computes it in single precision (a margin of 1e-5 of the terms covers its rounding), so that
// no triangle within the box lies outside one: then facing_away alone decides. O(1).
inline bool box_inside_frustum(const view_frustum& v, const glm::dvec3& lo, const glm::dvec3& hi) {
  if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) return true;  // empty
  const glm::dvec3 e(v.eye_f), far = glm::max(glm::abs(lo - e), glm::abs(hi - e));
  for (const glm::vec3& pf : v.inward_f) {
    const glm::dvec3 p(pf), corner(p.x >= 0.0 ? lo.x : hi.x, p.y >= 0.0 ? lo.y : hi.y, p.z >= 0.0 ? lo.z : hi.z);
    if (!(glm::dot(p, corner - e) >= 1e-5 * glm::dot(glm::abs(p), far))) return false;
  }
  return true;
}

// The signed crossing of a fixed ray from the eye (a direction of irrational slopes) with
// triangle (a, b, c): +1 leaving through its front (counter-clockwise normal along the ray), −1
// entering, 0 missing it. Summed over a closed part, 0 when the eye is outside it, also when the
// ray passes exactly through a shared edge or vertex: the corners are projected on the plane
// across the ray (the same corner, the same 2D point in every triangle), each edge's side of the
// ray is the sign of a 2D cross product that two triangles sharing the edge compute as exact
// negatives, and a ray exactly on an edge's line belongs to one side by the edge's direction (a
// fill rule), so every crossing counts once. O(1).
inline int eye_ray_crossing(const view_frustum& v, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::dvec3 d(0.7296190, 0.3022190, 0.5341045);  // ∝ (1, √2 − 1, √3 − 1), rounded
  const glm::dvec3 e1 = glm::normalize(glm::dvec3(d.y, -d.x, 0.0));  // unit, ⊥ d
  const glm::dvec3 e2 = glm::cross(d, e1);             // e1 × e2 ∥ d
  const glm::dvec3 pa = glm::dvec3(a) - v.eye, pb = glm::dvec3(b) - v.eye, pc = glm::dvec3(c) - v.eye;
  if (glm::dot(pa, d) < 0.0 && glm::dot(pb, d) < 0.0 && glm::dot(pc, d) < 0.0) return 0;  // behind the eye
  const double ax = glm::dot(pa, e1), ay = glm::dot(pa, e2), bx = glm::dot(pb, e1), by = glm::dot(pb, e2);
  const double cx = glm::dot(pc, e1), cy = glm::dot(pc, e2);
  // Whether the ray (the 2D origin) lies left of edge p → q, ties by the edge's direction.
  const auto left = [](double px, double py, double qx, double qy) {
    const double e = px * qy - py * qx;
    return e > 0.0 || (e == 0.0 && (qy - py > 0.0 || (qy == py && qx - px < 0.0)));
  };
  const bool l0 = left(ax, ay, bx, by), l1 = left(bx, by, cx, cy), l2 = left(cx, cy, ax, ay);
  if (l0 != l1 || l1 != l2) return 0;
  const glm::dvec3 n = glm::cross(pb - pa, pc - pa);
  const double nd = glm::dot(n, d);
  if (nd == 0.0 || !(glm::dot(n, pa) / nd > 0.0)) return 0;  // edge-on, or the plane behind the eye
  return l0 ? 1 : -1;
}

// A few triangles of each cluster, to estimate the share a camera sees (visible_shares).
struct visibility_samples {
  std::vector<std::uint32_t> offsets;  // per cluster, samples + 1
  std::vector<glm::vec3> corners;      // 3 per sample
  std::vector<std::uint8_t> one_sided; // per sample
  std::vector<glm::vec3> coarsest;     // 3 per one-sided triangle of the coarsest cut (all contractions)
};

// Up to per_cluster triangles of each cluster of h (evenly spaced in its triangle range), and the
// closed triangles of the coarsest cut; one_sided: closed_part_triangles of h.indices, with
// two_sided_face on two-sided clusters (samples there count as two-sided).
// O(C · per_cluster + T + contractions), allocation: the result and O(V).
inline visibility_samples make_visibility_samples(const contraction_hierarchy& h, std::span<const std::uint8_t> one_sided,
                                                  std::uint32_t per_cluster = 128) {
  visibility_samples s;
  s.offsets.push_back(0);
  for (std::uint32_t c = 0; c < h.cluster_count; ++c) {
    const std::uint32_t b = h.triangle_offsets[c], n = h.triangle_offsets[c + 1] - b, k = std::min(n, per_cluster);
    for (std::uint32_t i = 0; i < k; ++i) {
      const std::size_t t = b + static_cast<std::size_t>((2 * std::uint64_t{i} + 1) * n / (2 * std::uint64_t{k}));
      for (std::size_t j = 0; j < 3; ++j) s.corners.push_back(h.positions[h.indices[3 * t + j]]);
      s.one_sided.push_back(one_sided[t] == closed_face);
    }
    s.offsets.push_back(static_cast<std::uint32_t>(s.one_sided.size()));
  }
  std::vector<std::uint32_t> remap(h.vertex_count);  // the coarsest cut: every contraction applied
  for (std::uint32_t v = 0; v < h.vertex_count; ++v) remap[v] = v;
  for (std::size_t i = h.contraction_count(); i-- > 0;) remap[h.removed[i]] = remap[h.target[i]];
  for (std::size_t t = 0; t < h.triangle_count(); ++t) {
    const std::uint32_t a = remap[h.indices[3 * t]], b = remap[h.indices[3 * t + 1]], c = remap[h.indices[3 * t + 2]];
    if (one_sided[t] && a != b && b != c && a != c)
      s.coarsest.insert(s.coarsest.end(), {h.positions[a], h.positions[b], h.positions[c]});
  }
  return s;
}

// Whether the eye is outside every closed part of the coarsest cut (then visible_shares counts
// back faces hidden). O(coarsest triangles), no allocation.
inline bool eye_outside_coarsest(const visibility_samples& s, const view_frustum& v) {
  if (!v.may_be_inside_closed()) return true;
  long winding = 0;
  for (std::size_t i = 0; i < s.coarsest.size(); i += 3) winding += eye_ray_crossing(v, s.coarsest[i], s.coarsest[i + 1], s.coarsest[i + 2]);
  return winding == 0;
}

// Per cluster listed in `active` (the others untouched), the share of its samples the camera may
// see (1 for a cluster without samples); back_faces_hidden false: back faces count as seen.
// O(active + their samples), no allocation.
inline void visible_shares(const visibility_samples& s, const view_frustum& v, bool back_faces_hidden,
                           std::span<const std::uint32_t> active, std::span<double> share) {
  for (const std::uint32_t c : active) {
    const std::uint32_t b = s.offsets[c], e = s.offsets[c + 1];
    std::uint32_t seen = 0;
    for (std::uint32_t i = b; i < e; ++i)
      seen += hidden_triangle(v, s.corners[3 * i], s.corners[3 * i + 1], s.corners[3 * i + 2],
                              back_faces_hidden && s.one_sided[i]) ? 0u : 1u;
    share[c] = e > b ? static_cast<double>(seen) / static_cast<double>(e - b) : 1.0;
  }
}

}  // namespace infolerp
