#pragma once
// Saliency-weighted quadric simplification into a contraction hierarchy (salient-clustering
// paper §III.C, with the bookkeeping §IV.A's neighbour matching needs).
//
// Quadrics (Garland–Heckbert): each triangle's plane quadric, scaled by its area and the
// weighting map (weighting_map.hpp) at each corner, goes to that corner; mesh-boundary edges add
// a perpendicular plane (boundary_weight × squared length). Contractions are half-edge collapses
// u → v (v keeps its position, so every level indexes the original vertices) costing
// Q_u(p_v) / A_u, A_u the unweighted area Q_u gathered, so that saliency, not gathered area,
// decides the order. Order: global by (cost, u, v), one heap entry per vertex (its cheapest
// allowed contraction, updated in place); refused: non-manifold or duplicate results (link
// condition), a normal turning past acos(min_normal_cos), a boundary vertex leaving its boundary.
// Weights count relative to the largest (so their scale does not matter); floor: a weight below
// weight_floor × the mean weight counts as that (all weights 1 when the mean is 0), so that a region of zero saliency (a floor, a wall) keeps its feature and boundary
// planes instead of collapsing at no cost.
// Cluster-local phase (cluster_local_first, for the paper's eq. 9 selection): contractions whose
// vertices and 1-rings lie in one cluster run first, so clusters simplify independently and
// neighbour matching does not drag every cluster to the coarsest; then the whole mesh, down to
// backstop × V vertices (paper: 1%). Off by default: run to exhaustion, the phase leaves
// full-resolution bands along cluster borders, and view_dependent_lod's default selection
// does better on one global order (benchmarks/NOTES.md).
//
// Hierarchy, per contraction i: removed[i], target[i], parent[i] (the last contraction that
// changed the fan of u, v or a neighbour; no_parent if none), its owning cluster (that of the
// removed vertex's lowest-index triangle) and, per other cluster it depends on, the latest such
// contraction (cross_dependency). A cluster's capacity is the contractions it owns.
//
// Preconditions: an edge-manifold mesh, finite positions (both checked).
// Complexity: O(T log T) heap work plus O(valence²) per contraction, mostly scattered memory
// accesses since the global order jumps across the mesh. Allocation: about 150 bytes per
// triangle during the build; the result keeps 21 bytes per contraction, 12 per cross-cluster
// dependency, 16 per triangle, 16 per vertex (positions included).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/detail/csr.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/curvature.hpp"

namespace infolerp {

inline constexpr std::uint32_t no_parent = invalid_id;

struct simplification_options {
  double backstop = 0.01;         // stop when this fraction of the vertices is left, in [0, 1]
  double boundary_weight = 10.0;  // weight of the planes that hold mesh-boundary edges, >= 0
  double min_normal_cos = 0.0;    // a triangle's normal may turn by at most acos of this, in [0, 1)
  bool cluster_local_first = false;  // first only contractions whose 2-ring lies in one cluster (see above)
  double weight_floor = 0.1;      // weights below this fraction of their mean count as it, in [0, 1] (see above)
};

struct cross_dependency {
  std::uint32_t order;    // a contraction owned by the listing cluster
  std::uint32_t cluster;  // another cluster
  std::uint32_t needs;    // the latest contraction of `cluster` that `order` depends on
};

struct contraction_hierarchy {
  // Per contraction, in global order.
  std::vector<std::uint32_t> removed, target, parent, owner;
  std::vector<std::uint8_t> faces_removed;  // triangles the contraction removes (1 on a boundary edge, 2 inside)
  std::vector<float> error;                 // its cost Q_u(p_v) / A_u (see the top of the file)
  // Per vertex: the order of the contraction removing it, or invalid_id.
  std::vector<std::uint32_t> removal_order;
  // Per cluster (CSR): owned contractions ascending.
  std::vector<std::uint32_t> cluster_offsets, cluster_contractions;
  // Per cluster (CSR): dependencies on other clusters' contractions, ascending by order.
  std::vector<std::uint32_t> cross_offsets;
  std::vector<cross_dependency> cross;
  // The mesh's triangles grouped by cluster (index buffer order, original vertex ids) and the
  // triangle offsets of each cluster. Inside a cluster: by the owner of the contraction that
  // removes the triangle, then latest removal first (never removed: first, with owner 0), so
  // that at any stop point a cluster keeps a prefix of each owner's run (vertex_contraction.hpp).
  std::vector<std::uint32_t> indices, triangle_offsets;
  // Per triangle of that buffer: the contraction that removes it (invalid_id: none).
  std::vector<std::uint32_t> killer;
  // Per vertex: its position (contractions keep positions), for view_dependent_lod's culling.
  std::vector<glm::vec3> positions;
  std::uint32_t vertex_count = 0, cluster_count = 0;
  std::uint32_t local_contractions = 0;  // the first ones, that touch only their own cluster's vertices

  [[nodiscard]] std::size_t contraction_count() const { return removed.size(); }
  [[nodiscard]] std::size_t triangle_count() const { return indices.size() / 3; }
  [[nodiscard]] std::uint64_t capacity(std::uint32_t c) const { return cluster_offsets[c + 1] - cluster_offsets[c]; }
  // Contractions of cluster c in the cluster-local phase (those with order < local_contractions).
  [[nodiscard]] std::uint64_t local_capacity(std::uint32_t c) const {
    const auto b = cluster_contractions.begin() + cluster_offsets[c], e = cluster_contractions.begin() + cluster_offsets[c + 1];
    return static_cast<std::uint64_t>(std::lower_bound(b, e, local_contractions) - b);
  }
  [[nodiscard]] std::size_t memory_bytes() const {
    return 4 * (removed.size() + target.size() + parent.size() + owner.size() + error.size() + removal_order.size() +
                cluster_offsets.size() + cluster_contractions.size() + cross_offsets.size() + 3 * cross.size() +
                indices.size() + triangle_offsets.size() + killer.size()) +
           faces_removed.size() + sizeof(glm::vec3) * positions.size();
  }
};

namespace detail {

struct quadric {  // symmetric 4×4: a (xx xy xz yy yz zz), b (x y z), c; area: triangle area gathered
  double a[6] = {}, b[3] = {}, c = 0.0, area = 0.0;
  void add_plane(const glm::dvec3& n, double d, double w) {
    a[0] += w * n.x * n.x, a[1] += w * n.x * n.y, a[2] += w * n.x * n.z;
    a[3] += w * n.y * n.y, a[4] += w * n.y * n.z, a[5] += w * n.z * n.z;
    b[0] += w * n.x * d, b[1] += w * n.y * d, b[2] += w * n.z * d, c += w * d * d;
  }
  quadric& operator+=(const quadric& q) {
    for (int k = 0; k < 6; ++k) a[k] += q.a[k];
    for (int k = 0; k < 3; ++k) b[k] += q.b[k];
    c += q.c;
    area += q.area;
    return *this;
  }
  [[nodiscard]] double eval(const glm::dvec3& p) const {
    const double e = p.x * (a[0] * p.x + 2.0 * (a[1] * p.y + a[2] * p.z + b[0])) +
                     p.y * (a[3] * p.y + 2.0 * (a[4] * p.z + b[1])) + p.z * (a[5] * p.z + 2.0 * b[2]) + c;
    return std::max(0.0, e);
  }
};

// The cost of moving a vertex with quadric q to p: q(p) per unit of gathered area.
inline double collapse_cost(const quadric& q, const glm::dvec3& p) {
  return q.area > 0.0 ? q.eval(p) / q.area : q.eval(p);
}

// Vertex u's cheapest contraction u → v.
struct collapse_entry {
  double cost;
  std::uint32_t u, v;
  bool operator<(const collapse_entry& o) const {
    if (cost != o.cost) return cost < o.cost;
    if (u != o.u) return u < o.u;
    return v < o.v;
  }
};

// 4-ary min-heap of collapse entries, at most one per vertex, with each vertex's slot known so
// that its entry is replaced in place: O(log V) per update, no stale entries, no allocation
// after reset. Four children side by side: half the levels, and cache misses, of a binary heap.
class vertex_heap {
 public:
  static constexpr std::uint32_t none = invalid_id;
  void reset(std::size_t vertices) {
    slot_.assign(vertices, none);
    heap_.clear();
    heap_.reserve(vertices);
  }
  [[nodiscard]] bool empty() const { return heap_.empty(); }
  [[nodiscard]] const collapse_entry& top() const { return heap_.front(); }
  [[nodiscard]] const collapse_entry* find(std::uint32_t u) const { return slot_[u] == none ? nullptr : &heap_[slot_[u]]; }
  // Inserts u's entry or replaces it.
  void set(const collapse_entry& e) {
    std::uint32_t i = slot_[e.u];
    if (i == none) {
      i = static_cast<std::uint32_t>(heap_.size());
      heap_.push_back(e);
    } else {
      heap_[i] = e;
    }
    place(i);
  }
  void erase(std::uint32_t u) {
    const std::uint32_t i = slot_[u];
    if (i == none) return;
    slot_[u] = none;
    const collapse_entry last = heap_.back();
    heap_.pop_back();
    if (i == heap_.size()) return;
    heap_[i] = last;
    place(i);
  }

 private:
  void put(std::uint32_t i, const collapse_entry& e) { heap_[i] = e, slot_[e.u] = i; }
  void place(std::uint32_t i) {  // sift heap_[i] up or down
    const collapse_entry e = heap_[i];
    while (i > 0 && e < heap_[(i - 1) / 4]) put(i, heap_[(i - 1) / 4]), i = (i - 1) / 4;
    for (;;) {
      const std::size_t first = 4 * std::size_t{i} + 1, end = std::min(first + 4, heap_.size());
      if (first >= end) break;
      std::size_t c = first;
      for (std::size_t k = first + 1; k < end; ++k)
        if (heap_[k] < heap_[c]) c = k;
      if (!(heap_[c] < e)) break;
      put(i, heap_[c]), i = static_cast<std::uint32_t>(c);
    }
    put(i, e);
  }
  std::vector<collapse_entry> heap_;
  std::vector<std::uint32_t> slot_;
};

// Triangle t seen from its corner j (vertex x): corner = 3t + j; a and b are the vertices of
// corners j + 1 and j + 2, so that x's neighbours are read without looking up the triangle.
struct fan_entry {
  std::uint32_t corner, a, b;
};

// The mutable mesh of the build: each vertex's live triangles as a slice of one flat array
// (vertex → triangle adjacency in CSR form; a dead triangle leaves its corners' slices at once,
// and a slice that outgrows its room moves to the end of the array), and quadrics.
class collapse_mesh {
 public:
  static constexpr std::uint32_t nil = invalid_id;
  // What a contraction reads of each vertex in its 2-ring, in one record (32 bytes: two per
  // cache line) rather than in one array per field, since the global cost order visits the mesh
  // at random. fallback: the vertex's heap entry is not its cheapest contraction (refused).
  struct alignas(32) vertex_state {
    glm::vec3 pos;  // as given (exact in double)
    std::uint32_t stamp = 0, first = 0, count = 0, last_touch = invalid_id;  // slice: fan[first ..+ count)
    std::uint8_t alive = 0, boundary = 0, fallback = 0;
  };
  std::vector<vertex_state> vx;
  std::vector<fan_entry> fan;        // the slices
  std::vector<std::uint32_t> room;   // vertex x's slice has room[x] entries
  std::vector<std::uint32_t> killed_by;
  std::vector<quadric> q;
  std::uint32_t stamp_now = 0;
  std::vector<std::uint32_t> ring_u, ring_v;

  [[nodiscard]] glm::dvec3 at(std::uint32_t x) const { return glm::dvec3(vx[x].pos); }
  [[nodiscard]] std::span<const fan_entry> triangles(std::uint32_t x) const { return {fan.data() + vx[x].first, vx[x].count}; }
  // Distinct neighbours of x into out, each marked with a fresh stamp.
  void ring(std::uint32_t x, std::vector<std::uint32_t>& out) {
    out.clear();
    const std::uint32_t s = ++stamp_now;
    for (const fan_entry& e : triangles(x)) {
      if (vx[e.a].stamp != s) vx[e.a].stamp = s, out.push_back(e.a);
      if (vx[e.b].stamp != s) vx[e.b].stamp = s, out.push_back(e.b);
    }
  }
  // The §III.C validity tests for u → v (see the top of the file). Afterwards ring(u) is in
  // ring_u (already there when ring_u_known); when they pass, ring(v) is in ring_v, marked with
  // stamp_now.
  bool can_collapse(std::uint32_t u, std::uint32_t v, double min_cos, bool ring_u_known = false) {
    std::uint32_t opp[2] = {nil, nil}, k = 0;  // the triangles on the edge and their third corners
    if (!ring_u_known) ring(u, ring_u);
    for (const fan_entry& e : triangles(u))
      if (e.a == v || e.b == v) {
        if (k < 2) opp[k] = e.a == v ? e.b : e.a;
        ++k;
      }
    if (k == 0 || k > 2) return false;
    if (vx[u].boundary && !(vx[v].boundary && k == 1)) return false;
    ring(v, ring_v);
    const std::uint32_t sv = stamp_now;  // ring(v) carries this stamp
    // Link condition: a common neighbour must be opposite the edge.
    for (std::uint32_t x : ring_u)
      if (x != v && vx[x].stamp == sv && x != opp[0] && x != opp[1]) return false;
    for (const fan_entry& e : triangles(u)) {
      if (e.a == v || e.b == v) continue;
      const std::uint32_t j = e.corner % 3;
      glm::dvec3 p[3];
      p[j] = at(u), p[(j + 1) % 3] = at(e.a), p[(j + 2) % 3] = at(e.b);
      const glm::dvec3 n0 = glm::cross(p[1] - p[0], p[2] - p[0]);
      p[j] = at(v);
      const glm::dvec3 n1 = glm::cross(p[1] - p[0], p[2] - p[0]);
      if (!(glm::dot(n0, n1) > min_cos * glm::length(n0) * glm::length(n1))) return false;
      // A duplicate triangle (v, a, b) would appear when v already has one on a and b.
      if (k == 2 && (e.a == opp[0] || e.a == opp[1]) && (e.b == opp[0] || e.b == opp[1]))
        for (const fan_entry& g : triangles(v))
          if ((g.a == e.a || g.b == e.a) && (g.a == e.b || g.b == e.b)) return false;
    }
    return true;
  }
  // Performs u → v as contraction `order`; returns the triangles removed (killed_by names it).
  std::uint8_t collapse(std::uint32_t u, std::uint32_t v, std::uint32_t order) {
    std::uint8_t removed = 0;
    std::uint32_t kept = 0;
    const std::uint32_t fu = vx[u].first;
    for (std::uint32_t i = 0; i < vx[u].count; ++i) {
      const fan_entry e = fan[fu + i];
      const std::uint32_t t = e.corner / 3;
      if (e.a == v || e.b == v) {
        killed_by[t] = order;
        ++removed;
        drop(e.a, t), drop(e.b, t);
        continue;
      }
      rename(e.a, t, u, v), rename(e.b, t, u, v);
      fan[fu + kept++] = e;
    }
    // u's surviving triangles join v's slice.
    const std::uint32_t need = vx[v].count + kept;
    if (need > room[v]) {
      const auto end = static_cast<std::uint32_t>(fan.size());
      fan.resize(fan.size() + need + need / 2);
      std::copy_n(fan.begin() + vx[v].first, vx[v].count, fan.begin() + end);
      vx[v].first = end, room[v] = need + need / 2;
    }
    std::copy_n(fan.begin() + fu, kept, fan.begin() + vx[v].first + vx[v].count);
    vx[v].count = need, vx[u].count = 0;
    vx[u].alive = 0;
    q[v] += q[u];
    return removed;
  }

 private:
  fan_entry* find(std::uint32_t x, std::uint32_t t) {  // triangle t in x's slice
    fan_entry* e = fan.data() + vx[x].first;
    while (e->corner / 3 != t) ++e;
    return e;
  }
  void drop(std::uint32_t x, std::uint32_t t) { *find(x, t) = fan[vx[x].first + --vx[x].count]; }  // order within a slice is free
  void rename(std::uint32_t x, std::uint32_t t, std::uint32_t from, std::uint32_t to) {
    fan_entry* e = find(x, t);
    (e->a == from ? e->a : e->b) = to;
  }
};

}  // namespace detail

// Builds the hierarchy. weights: 3 per triangle (corner order; weighting_map.hpp), finite and
// >= 0. cluster: one id < cluster_count per triangle. Errors: mesh errors (empty, index out of
// range, non-finite position), a non-manifold edge (names the edge's first vertex), weights or
// cluster of the wrong size (bad_size), a non-finite weight (non_finite) or a negative one
// (bad_parameter), naming the corner, a cluster id out of range (names the triangle), options
// outside their ranges.
// Serial (the global order is inherently sequential); pure.
template <class M>
result<contraction_hierarchy> make_contraction_hierarchy(const M& m, std::span<const double> weights,
                                                          std::span<const std::uint32_t> cluster,
                                                          std::uint32_t cluster_count,
                                                          const simplification_options& opt = {}) {
  static_assert(check_mesh<M>());
  if (status s = detail::check_indices_and_positions(m); !s.ok()) return s;
  const std::size_t nv = mesh_vertex_count(m), nt = mesh_triangle_count(m);
  if (weights.size() != 3 * nt)
    return make_error(errc::bad_size, weights.size(), "weights has ", weights.size(), " values for ", 3 * nt,
                      " triangle corners");
  if (cluster.size() != nt)
    return make_error(errc::bad_size, cluster.size(), "cluster has ", cluster.size(), " ids for ", nt, " triangles");
  for (std::size_t k = 0; k < weights.size(); ++k)
    if (!(weights[k] >= 0.0) || !std::isfinite(weights[k]))
      return make_error(non_negative_errc(weights[k]), k, "weight of corner ", k % 3, " of triangle ", k / 3, " is ", weights[k],
                        "; must be finite and >= 0");
  for (std::size_t t = 0; t < nt; ++t)
    if (cluster[t] >= cluster_count)
      return make_error(errc::index_out_of_range, t, "triangle ", t, ": cluster ", cluster[t], " >= cluster count ",
                        cluster_count);
  if (!(opt.backstop >= 0.0 && opt.backstop <= 1.0))
    return make_error(errc::bad_parameter, no_element, "backstop ", opt.backstop, " must be in [0, 1]");
  if (!(opt.min_normal_cos >= 0.0 && opt.min_normal_cos < 1.0))
    return make_error(errc::bad_parameter, no_element, "min_normal_cos ", opt.min_normal_cos, " must be in [0, 1)");
  if (!(opt.weight_floor >= 0.0 && opt.weight_floor <= 1.0))
    return make_error(errc::bad_parameter, no_element, "weight_floor ", opt.weight_floor, " must be in [0, 1]");
  if (!(opt.boundary_weight >= 0.0) || !std::isfinite(opt.boundary_weight))
    return make_error(errc::bad_parameter, no_element, "boundary_weight ", opt.boundary_weight, " must be >= 0 and finite");
  if (nt >= (std::size_t{1} << 32) / 3 || nv >= invalid_id)
    return make_error(errc::unsupported, nt, "mesh has ", nv, " vertices and ", nt, " triangles; at most 4294967294 and 1431655764 are supported");

  // Relative to the largest weight (exact: equal weights of any finite scale are all 1, so the
  // order and the costs do not depend on the weights' scale), floored at weight_floor × the mean
  // (see the top of the file).
  const double top = weights.empty() ? 0.0 : *std::max_element(weights.begin(), weights.end());
  double mean_weight = 0.0;  // of the weights over the largest, in [0, 1]
  for (std::size_t k = 0; k < weights.size(); ++k) mean_weight += weights[k] / top / static_cast<double>(weights.size());
  const auto weight = [&](std::size_t k) {
    return mean_weight > 0.0 ? std::max(weights[k] / top, opt.weight_floor * mean_weight) : 1.0;
  };
  detail::collapse_mesh cm;
  cm.vx.resize(nv);
  for (std::size_t v = 0; v < nv; ++v) cm.vx[v].pos = mesh_position(m, v);
  cm.killed_by.assign(nt, invalid_id);
  cm.q.assign(nv, {});
  std::vector<std::uint32_t> owner(nv, invalid_id);
  bool repeated = false;
  for (std::size_t t = nt; t-- > 0;) {
    const glm::uvec3 f = mesh_triangle(m, t);
    if (f.x == f.y || f.y == f.z || f.x == f.z) {
      repeated = true;  // a repeated index draws nothing; it counts for the edges below only
      continue;
    }
    for (int j = 0; j < 3; ++j) {
      cm.vx[f[j]].alive = 1;
      owner[f[j]] = cluster[t];  // last write wins: the lowest-index triangle
    }
    const glm::dvec3 p0 = cm.at(f.x), p1 = cm.at(f.y), p2 = cm.at(f.z);
    const glm::dvec3 n2 = glm::cross(p1 - p0, p2 - p0);
    const double len = glm::length(n2);
    if (!(len > 0.0)) continue;
    const glm::dvec3 n = n2 / len;
    const double d = -glm::dot(n, p0), area = 0.5 * len;
    for (int j = 0; j < 3; ++j) {
      cm.q[f[j]].add_plane(n, d, area * weight(3 * t + static_cast<std::size_t>(j)));
      cm.q[f[j]].area += area;
    }
  }
  // Vertex → triangle adjacency, ascending triangle ids, every triangle under each distinct corner.
  auto distinct = [](const glm::uvec3& f, int j) { return j == 0 || (f[j] != f.x && (j == 1 || f.z != f.y)); };
  cm.fan.reserve(6 * nt);  // room for slices moved to the end, without reallocation copies
  detail::group_by_key(
      nv, 3 * nt,
      [&](std::size_t c) {
        const glm::uvec3 f = mesh_triangle(m, c / 3);
        const int j = static_cast<int>(c % 3);
        return distinct(f, j) ? f[j] : detail::no_bucket;
      },
      [&](std::size_t c) {
        const glm::uvec3 f = mesh_triangle(m, c / 3);
        const int j = static_cast<int>(c % 3);
        return detail::fan_entry{static_cast<std::uint32_t>(c), f[(j + 1) % 3], f[(j + 2) % 3]};
      },
      cm.room, cm.fan);  // room holds the slice starts until the slices are final
  for (std::size_t v = 0; v < nv; ++v) cm.vx[v].first = cm.room[v], cm.vx[v].count = cm.room[v + 1] - cm.room[v];
  // Edges (a, b), a < b, from a's triangles in ascending (a, b): more than two distinct triangles
  // is an error; one makes a boundary edge, held by a plane through it perpendicular to its
  // (lowest-index) triangle.
  {
    std::vector<std::uint32_t> hits(nv), edge_tri(nv), others, open;
    for (std::uint32_t a = 0; a < nv; ++a) {
      const std::uint32_t s = ++cm.stamp_now;
      others.clear();
      auto hit = [&](std::uint32_t b, std::uint32_t t) {
        if (b <= a) return;
        if (cm.vx[b].stamp != s) cm.vx[b].stamp = s, hits[b] = 0, edge_tri[b] = t, others.push_back(b);
        ++hits[b];
      };
      for (const detail::fan_entry& e : cm.triangles(a)) {
        hit(e.a, e.corner / 3);
        if (e.b != e.a) hit(e.b, e.corner / 3);  // a triangle counts once per edge
      }
      std::sort(others.begin(), others.end());
      open.clear();
      for (std::uint32_t b : others) {
        if (hits[b] > 2)
          return make_error(errc::non_manifold_edge, a, "edge (", a, ", ", b, ") has ", hits[b], " triangles");
        if (hits[b] == 1) open.push_back(b);
      }
      for (std::uint32_t b : open) {
        cm.vx[a].boundary = cm.vx[b].boundary = 1;
        const std::uint32_t t = edge_tri[b];
        const glm::uvec3 f = mesh_triangle(m, t);
        const glm::dvec3 fn = glm::cross(cm.at(f.y) - cm.at(f.x), cm.at(f.z) - cm.at(f.x));
        const glm::dvec3 ev = cm.at(b) - cm.at(a);
        const glm::dvec3 pn = glm::cross(ev, fn);
        const double len = glm::length(pn);
        if (!(len > 0.0)) continue;
        const glm::dvec3 n = pn / len;
        const double d = -glm::dot(n, cm.at(a));
        const double w = opt.boundary_weight * glm::dot(ev, ev) * (weight(3 * t) + weight(3 * t + 1) + weight(3 * t + 2)) / 3.0;
        cm.q[a].add_plane(n, d, w);
        cm.q[b].add_plane(n, d, w);
      }
    }
  }
  // Triangles with a repeated index leave the slices; each slice's room is its initial length.
  if (repeated)
    for (std::uint32_t v = 0; v < nv; ++v) {
      std::uint32_t kept = 0;
      for (std::uint32_t i = 0; i < cm.vx[v].count; ++i) {
        const detail::fan_entry e = cm.fan[cm.vx[v].first + i];
        if (e.a != e.b && e.a != v && e.b != v) cm.fan[cm.vx[v].first + kept++] = e;
      }
      cm.vx[v].count = kept;
    }
  for (std::uint32_t v = 0; v < nv; ++v) cm.room[v] = cm.room[v + 1] - cm.vx[v].first;
  cm.room.pop_back();

  std::size_t live = 0;
  for (std::size_t v = 0; v < nv; ++v) live += cm.vx[v].alive ? 1 : 0;
  const auto floor_count = static_cast<std::size_t>(std::ceil(opt.backstop * static_cast<double>(live)));

  contraction_hierarchy h;
  h.vertex_count = static_cast<std::uint32_t>(nv);
  h.positions.resize(nv);
  for (std::size_t v = 0; v < nv; ++v) h.positions[v] = glm::vec3(mesh_position(m, v));
  h.cluster_count = cluster_count;
  h.removal_order.assign(nv, invalid_id);
  std::vector<std::pair<std::uint32_t, cross_dependency>> crossing;  // (owner, entry), ascending order
  std::vector<std::pair<std::uint32_t, std::uint32_t>> dep_scratch;  // (cluster, order) of dependencies

  // One heap entry per vertex: its cheapest contraction (the global minimum over pairs is the
  // minimum over vertices). A contraction u → v changes the costs of v (Q_v grew) and the
  // candidates of v's neighbours (u is gone, v may be new), whose entries are updated.
  detail::vertex_heap heap;
  heap.reset(nv);
  std::vector<std::uint32_t> candidates, joining;
  std::vector<std::pair<double, std::uint32_t>> ranked;
  auto cost = [&](std::uint32_t u, std::uint32_t v) { return detail::collapse_cost(cm.q[u], cm.at(v)); };
  // u's entry from its neighbours (ring(u)).
  auto rank = [&](std::uint32_t u, const std::vector<std::uint32_t>& ring) {
    detail::collapse_entry best{std::numeric_limits<double>::infinity(), u, invalid_id};
    for (std::uint32_t v : ring)
      if (const detail::collapse_entry e{cost(u, v), u, v}; e < best) best = e;
    cm.vx[u].fallback = 0;
    if (best.v != invalid_id) heap.set(best);
    else heap.erase(u);
  };
  auto set_best = [&](std::uint32_t u) {
    cm.ring(u, candidates);
    rank(u, candidates);
  };
  auto fill = [&] {
    heap.reset(nv);
    for (std::uint32_t x = 0; x < nv; ++x)
      if (cm.vx[x].alive) set_best(x);
  };
  fill();
  bool progress_since_fill = false, local_phase = opt.cluster_local_first;
  auto local_to_cluster = [&](std::uint32_t c) {
    for (std::uint32_t x : cm.ring_u) if (owner[x] != c) return false;
    for (std::uint32_t x : cm.ring_v) if (owner[x] != c) return false;
    return true;
  };
  auto valid = [&](std::uint32_t u, std::uint32_t v, bool ring_u_known = false) {
    return cm.can_collapse(u, v, opt.min_normal_cos, ring_u_known) && (!local_phase || local_to_cluster(owner[u]));
  };
  // u's cheapest contraction failed the tests (which left ring(u) in ring_u, unchanged by the
  // tests below): queue its cheapest valid one, or drop u until its neighbourhood changes (or the
  // next round).
  auto requeue = [&](std::uint32_t u, std::uint32_t failed) {
    ranked.clear();
    for (std::uint32_t v : cm.ring_u)
      if (v != failed) ranked.push_back({cost(u, v), v});
    std::sort(ranked.begin(), ranked.end());
    for (const auto& [c, v] : ranked)
      if (valid(u, v, true)) return heap.set({c, u, v}), void(cm.vx[u].fallback = 1);
    heap.erase(u);
  };
  while (live > floor_count) {
    if (heap.empty()) {
      if (!progress_since_fill && !local_phase) break;
      if (!progress_since_fill) {
        local_phase = false;
        h.local_contractions = static_cast<std::uint32_t>(h.removed.size());
      }
      progress_since_fill = false;
      fill();
      continue;
    }
    const detail::collapse_entry e = heap.top();
    if (!valid(e.u, e.v)) {
      requeue(e.u, e.v);
      continue;
    }
    heap.erase(e.u);
    joining.clear();  // the neighbours of u that v gains
    for (std::uint32_t x : cm.ring_u)
      if (x != e.v && cm.vx[x].stamp != cm.stamp_now) joining.push_back(x);
    // Dependencies: the last contraction that changed the fan of u, v or a neighbour of either.
    const auto order = static_cast<std::uint32_t>(h.removed.size());
    std::uint32_t parent = no_parent;
    dep_scratch.clear();
    auto note = [&](std::uint32_t x) {
      const std::uint32_t j = cm.vx[x].last_touch;
      if (j == no_parent) return;
      parent = parent == no_parent ? j : std::max(parent, j);
      if (h.owner[j] != owner[e.u]) dep_scratch.push_back({h.owner[j], j});
    };
    note(e.u), note(e.v);
    for (std::uint32_t x : cm.ring_u) note(x);
    for (std::uint32_t x : cm.ring_v) note(x);
    std::sort(dep_scratch.begin(), dep_scratch.end());
    for (std::size_t k = 0; k < dep_scratch.size(); ++k)  // the latest per cluster
      if (k + 1 == dep_scratch.size() || dep_scratch[k + 1].first != dep_scratch[k].first)
        crossing.push_back({owner[e.u], {order, dep_scratch[k].first, dep_scratch[k].second}});
    const std::uint8_t gone = cm.collapse(e.u, e.v, order);
    h.removed.push_back(e.u), h.target.push_back(e.v), h.parent.push_back(parent), h.owner.push_back(owner[e.u]);
    h.faces_removed.push_back(gone);
    h.error.push_back(static_cast<float>(e.cost));
    h.removal_order[e.u] = order;
    cm.vx[e.v].last_touch = order;
    for (std::uint32_t x : cm.ring_u) cm.vx[x].last_touch = order;
    --live;
    progress_since_fill = true;
    cm.ring(e.v, cm.ring_v);
    rank(e.v, cm.ring_v);
    // A neighbour x of v: x → u vanished and x → v may be new (its cost depends on Q_x and p_v
    // only); an entry not aiming at u stays exact unless x joined v and x → v beats it. A vertex
    // without an entry or with a fallback one is ranked anew: its refused contractions may pass.
    for (std::uint32_t x : cm.ring_v) {
      const detail::collapse_entry* old = heap.find(x);
      if (!old || cm.vx[x].fallback || old->v == e.u) {
        set_best(x);
      } else if (std::find(joining.begin(), joining.end(), x) != joining.end()) {
        if (const detail::collapse_entry to_v{cost(x, e.v), x, e.v}; to_v < *old) heap.set(to_v);
      }
    }
  }

  if (local_phase) h.local_contractions = static_cast<std::uint32_t>(h.removed.size());
  // Per-cluster contraction lists and cross-cluster dependencies (stable, in contraction order).
  detail::group_by_key(
      cluster_count, h.owner.size(), [&](std::size_t i) { return h.owner[i]; },
      [](std::size_t i) { return static_cast<std::uint32_t>(i); }, h.cluster_offsets, h.cluster_contractions);
  detail::group_by_key(
      cluster_count, crossing.size(), [&](std::size_t i) { return crossing[i].first; },
      [&](std::size_t i) { return crossing[i].second; }, h.cross_offsets, h.cross);
  // Index buffer grouped by cluster, then by the removing contraction's owner, latest removal
  // first (see the struct); ties keep the input order.
  h.triangle_offsets.assign(cluster_count + 1, 0);
  for (std::size_t t = 0; t < nt; ++t) ++h.triangle_offsets[cluster[t] + 1];
  for (std::uint32_t c = 0; c < cluster_count; ++c) h.triangle_offsets[c + 1] += h.triangle_offsets[c];
  {
    // Each triangle's sort key in one record, (cluster, owner) then (~killer, t): the sort reads
    // nothing else (~ puts the latest removal, and invalid_id, first).
    std::vector<std::pair<std::uint64_t, std::uint64_t>> key(nt);
    for (std::uint32_t t = 0; t < nt; ++t) {
      const std::uint32_t k = cm.killed_by[t], kill_owner = k == invalid_id ? 0 : h.owner[k];
      key[t] = {std::uint64_t{cluster[t]} << 32 | kill_owner, std::uint64_t{~k} << 32 | t};
    }
    std::sort(key.begin(), key.end());
    h.indices.resize(3 * nt);
    h.killer.resize(nt);
    for (std::size_t k = 0; k < nt; ++k) {
      const auto t = static_cast<std::uint32_t>(key[k].second);
      const glm::uvec3 f = mesh_triangle(m, t);
      h.indices[3 * k] = f.x, h.indices[3 * k + 1] = f.y, h.indices[3 * k + 2] = f.z;
      h.killer[k] = cm.killed_by[t];
    }
  }
  return h;
}

}  // namespace infolerp
