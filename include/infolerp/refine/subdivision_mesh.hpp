#pragma once
// Hierarchical subdivision mesh: Oliveira, Santos, Proença, "Refinement Criteria for High
// Fidelity Interactive Walkthroughs", §4.2 (1:4 subdivision at edge midpoints, after Loop 1987,
// propagated to neighbours, 1:2 splits where the neighbour is flat), and the large-triangle
// tessellation of "Feature-based clustered geometry for interpolated ray-casting", §4.1.
//
// Every original triangle owns a hierarchy; triangles are never deleted, so an id stays valid
// for the life of the mesh. The leaves form the current, always conforming, triangulation.
//
// THE RULE (red–green refinement; the paper leaves the closure open, this is what we do):
//  1. A selected leaf splits 1:4 ("red") at its three edge midpoints. A midpoint is created
//     once per edge and shared by both sides, so a vertex is shaded once.
//  2. A leaf that gets a midpoint on one of its edges (a "hanging" vertex) must split:
//       - one hanging edge, the leaf is within `propagation_depth` steps of the selected
//         triangle and its height-to-width ratio over that edge (height of the opposite corner
//         over the edge length) is >= `bisect_ratio`: it splits 1:4 and propagates further;
//       - one hanging edge otherwise: it splits 1:2 ("green", bisecting that edge) and stops;
//       - two or three hanging edges: it splits 1:4 (a 1:2 split cannot close them).
//  3. A 1:2 child is never split itself (that degrades shape). When one is selected, or gets a
//     hanging vertex, its two-child split is undone ("retired": the two children stay in the
//     hierarchy's storage with `retired` set, no longer children of anyone) and the parent
//     splits 1:4 instead, reusing the existing midpoint; the closure continues from there.
//  4. Closure runs to completion inside every split call: between calls no T-vertex exists, and
//     every leaf edge is matched by exactly one leaf edge on the other side (or lies on a
//     boundary edge of the input mesh).
// Shape: red children are similar to their parent and green children are never split, so the
// smallest angle is at least half the input's smallest angle.
//
// Children order: a red split of (v0,v1,v2) with midpoints m0=(v0v1), m1=(v1v2), m2=(v2v0)
// gives (v0,m0,m2), (m0,v1,m1), (m2,m1,v2), (m0,m1,m2); a green split on edge k with
// (a,b,c) = (v_k, v_k+1, v_k+2) and midpoint m of ab gives (a,m,c), (m,b,c). Winding is kept.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/validate.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "infolerp/refine/detail/edge_table.hpp"

namespace infolerp {

struct subdivision_options {
  float bisect_ratio = 0.5f;            // propagated neighbours flatter than this (height/width) split 1:2
  std::uint32_t propagation_depth = 1;  // 1:4 splits propagate this many neighbour steps (paper: unbounded)
};

// One triangle of the hierarchy (32 bytes).
struct subdivision_triangle {
  glm::uvec3 vertices{0u};                  // winding of the original triangle
  std::uint32_t parent = invalid_id;        // invalid_id for an original triangle
  std::uint32_t first_child = invalid_id;   // children are first_child .. first_child + child_count - 1
  std::uint32_t original = invalid_id;      // the input triangle this one lies in
  std::uint8_t level = 0;                   // 0 for original triangles, parent's + 1 (saturating at 255)
  std::uint8_t child_count = 0;             // 0 (leaf or retired), 2 (1:2 split) or 4 (1:4 split)
  std::uint8_t split_edge = 0;              // for a 1:2 split: the bisected edge k (corner k to k+1)
  std::uint8_t retired = 0;                 // 1 or 2: first or second 1:2 child, replaced by the parent's 1:4 split
                                            // (split_edge then keeps the parent's bisected edge); 3: a free slot
  [[nodiscard]] bool is_leaf() const noexcept { return child_count == 0 && retired == 0; }
};

// Where a point lies: the leaf and the point's barycentric weights for the leaf's vertices.
struct point_location {
  std::uint32_t leaf = invalid_id;
  glm::vec3 weights{0.0f};
};

// §4.1 of the clustering paper: "tessellate these polygons until they had a ratio of polygon
// area to on-screen-projected area below a user-provided threshold". A triangle's own
// area/projected-area ratio does not change under 1:4 splitting, so we read the ratio as the
// triangle's on-screen area over the screen's area: split while it exceeds `max_fraction`.
// On-screen area: the triangle clipped in homogeneous clip space against the six planes of the
// view volume (-w <= x, y, z <= w, OpenGL depth; Sutherland–Hodgman), the clipped polygon's
// corners divided by w, its area taken in NDC. So a triangle behind the eye or outside the
// frustum has area 0 and is never split, and one crossing the eye plane counts only its part
// in front of the near plane. O(1) (at most 9 polygon corners), no allocation.
struct screen_fraction_test {
  glm::mat4 view_projection{1.0f};  // world to clip space
  float max_fraction = 0.01f;       // largest share of the screen a triangle may cover

  // The share of the screen [-1,1]² the triangle covers, in [0, 1] for a triangle that does not
  // overlap itself in projection; 0 when nothing of it lies in the view volume.
  [[nodiscard]] float screen_fraction(glm::vec3 a, glm::vec3 b, glm::vec3 c) const {
    glm::vec4 poly[9], next[9];
    poly[0] = view_projection * glm::vec4(a, 1.0f);
    poly[1] = view_projection * glm::vec4(b, 1.0f);
    poly[2] = view_projection * glm::vec4(c, 1.0f);
    int n = 3;
    for (int plane = 0; plane < 6 && n > 0; ++plane) {
      const int axis = plane / 2;
      const float sign = (plane % 2) ? -1.0f : 1.0f;
      auto distance = [&](const glm::vec4& p) { return p.w + sign * p[axis]; };  // >= 0 inside
      int m = 0;
      for (int i = 0; i < n; ++i) {
        const glm::vec4& p = poly[i];
        const glm::vec4& q = poly[(i + 1) % n];
        const float dp = distance(p), dq = distance(q);
        if (dp >= 0.0f) next[m++] = p;
        if ((dp >= 0.0f) != (dq >= 0.0f)) next[m++] = p + (dp / (dp - dq)) * (q - p);
      }
      n = m;
      std::copy(next, next + m, poly);
    }
    if (n < 3) return 0.0f;
    double twice_area = 0.0;
    glm::dvec2 first{0.0}, prev{0.0};
    for (int i = 0; i < n; ++i) {
      if (!(poly[i].w > 0.0f)) return 0.0f;  // only the eye point itself: nothing on screen
      const glm::dvec2 p = glm::dvec2(poly[i].x, poly[i].y) / double(poly[i].w);
      if (i == 0) first = p;
      else twice_area += prev.x * p.y - prev.y * p.x;
      prev = p;
    }
    twice_area += prev.x * first.y - prev.y * first.x;
    return static_cast<float>(std::abs(twice_area) / 8.0);  // the screen spans [-1,1]², area 4
  }
  bool operator()(glm::vec3 a, glm::vec3 b, glm::vec3 c) const { return screen_fraction(a, b, c) > max_fraction; }
};

// Not thread-safe for modification (split, tessellate); const members may be called
// concurrently. Accessors: preconditions v < vertex_count(), t < triangle_count() (unchecked);
// O(1), no allocation.
class subdivision_mesh {
 public:
  // Builds the hierarchy roots (triangle t of the input is hierarchy triangle t, vertex v is
  // vertex v). Errors: no triangles; non-finite position; index out of range; degenerate
  // triangle (repeated index or zero area); an edge shared by more than two triangles, or two
  // triangles on the same three vertices; bisect_ratio negative or NaN. Complexity O(V + T)
  // expected; allocation O(V + T).
  template <class M>
  static result<subdivision_mesh> create(const M& m, subdivision_options options = {}) {
    static_assert(check_mesh<M>());
    if (!(options.bisect_ratio >= 0.0f))
      return make_error(errc::bad_parameter, no_element, "bisect_ratio ", options.bisect_ratio, " must be >= 0");
    // Empty mesh, index range, NaN/Inf, repeated index, zero area, non-manifold edge.
    if (auto valid = validate_mesh(m); !valid) return valid;
    const std::size_t nv = mesh_vertex_count(m), nt = mesh_triangle_count(m);
    if (nv >= invalid_id / 2 || nt >= invalid_id / 8)
      return make_error(errc::unsupported, no_element, "mesh too large for 32-bit subdivision ids");
    subdivision_mesh s;
    s.options_ = options;
    s.positions_.resize(nv);
    s.vertex_source_.assign(nv, invalid_id);
    for (std::size_t v = 0; v < nv; ++v) s.positions_[v] = mesh_position(m, v);
    s.tris_.resize(nt);
    s.retired_first_.assign(nt, invalid_id);
    s.edges_.reserve(3 * nt / 2 + 3);
    for (std::size_t t = 0; t < nt; ++t) {
      const glm::uvec3 tri = mesh_triangle(m, t);
      const auto id = static_cast<std::uint32_t>(t);
      s.tris_[t].vertices = tri;
      s.tris_[t].original = id;
      for (int c = 0; c < 3; ++c) {
        if (s.vertex_source_[tri[c]] == invalid_id) s.vertex_source_[tri[c]] = id;
        auto& e = s.edges_.get(tri[c], tri[(c + 1) % 3]);
        [[maybe_unused]] const bool manifold = detail::edge_table::add_face(e, id);
        INFOLERP_ASSERT(manifold && "validate_mesh rejects non-manifold edges");
      }
    }
    // Two triangles on the same three vertices (either winding) would share all three midpoints,
    // and their children the inner edges: a split could not keep two faces per edge.
    for (std::uint32_t t = 0; t < nt; ++t) {
      const glm::uvec3 v = s.tris_[t].vertices;
      const auto other = [&](std::uint32_t a, std::uint32_t b) {
        const auto& e = s.edges_.get(a, b);
        return e.face[0] == t ? e.face[1] : e.face[0];
      };
      if (const std::uint32_t o = other(v[0], v[1]); o != invalid_id && o == other(v[1], v[2]) && o == other(v[2], v[0]))
        return make_error(errc::non_manifold_edge, t, "triangles ", std::min(t, o), " and ", std::max(t, o),
                          " have the same three vertices");
    }
    s.original_count_ = nt;
    s.original_vertex_count_ = nv;
    s.leaf_count_ = nt;
    return s;
  }

  [[nodiscard]] const subdivision_options& options() const noexcept { return options_; }
  [[nodiscard]] std::size_t vertex_count() const noexcept { return positions_.size(); }
  [[nodiscard]] glm::vec3 position(std::size_t v) const { return positions_[v]; }
  [[nodiscard]] std::span<const glm::vec3> positions() const noexcept { return positions_; }
  // An original triangle the vertex lies in (the one it was created in); invalid_id for an
  // input vertex no triangle uses.
  [[nodiscard]] std::uint32_t vertex_source(std::size_t v) const { return vertex_source_[v]; }
  // Every triangle ever produced, retired ones included.
  [[nodiscard]] std::size_t triangle_count() const noexcept { return tris_.size(); }
  [[nodiscard]] std::size_t original_triangle_count() const noexcept { return original_count_; }
  [[nodiscard]] std::size_t leaf_count() const noexcept { return leaf_count_; }
  [[nodiscard]] const subdivision_triangle& triangle(std::size_t t) const { return tris_[t]; }
  [[nodiscard]] std::span<const subdivision_triangle> triangles() const noexcept { return tris_; }
  [[nodiscard]] bool is_leaf(std::size_t t) const { return tris_[t].is_leaf(); }
  // Bytes held by the hierarchy: triangles, vertices, the edge table and the closure's queue
  // (capacities, so what the allocator holds). O(1).
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    return tris_.capacity() * sizeof(subdivision_triangle) + positions_.capacity() * sizeof(glm::vec3) +
           vertex_source_.capacity() * sizeof(std::uint32_t) + edges_.memory_bytes() + queue_.capacity() * sizeof(pending);
  }
  // Whether a 1:4 split of t gives children whose corners are distinct in float: every edge's
  // midpoint, as a split computes it, differs from both ends and from the other midpoints. False
  // once t is so small against its coordinates that halving an edge no longer moves (about 23
  // levels below a triangle of the size of its coordinates); refinement stops there. O(1).
  [[nodiscard]] bool splittable(std::uint32_t t) const {
    const glm::uvec3 v = tris_[t].vertices;
    const glm::vec3 a = positions_[v.x], b = positions_[v.y], c = positions_[v.z];
    const glm::vec3 m0 = midpoint(a, b), m1 = midpoint(b, c), m2 = midpoint(c, a);
    return m0 != a && m0 != b && m1 != b && m1 != c && m2 != c && m2 != a && m0 != m1 && m1 != m2 && m2 != m0;
  }
  // The midpoint vertex of edge (a, b), or invalid_id.
  [[nodiscard]] std::uint32_t edge_midpoint(std::uint32_t a, std::uint32_t b) const noexcept {
    return edges_.midpoint(a, b);
  }

  // Selects triangle t for subdivision and closes the mesh (THE RULE above). A triangle that
  // is no longer a leaf (already split, or retired) is left alone: not an error.
  // Errors: t >= triangle_count(). Complexity: O(new triangles) expected (the closure is
  // local); allocation: amortised growth of the triangle, vertex and edge arrays.
  status split(std::uint32_t t) { return split(t, options_.propagation_depth); }
  // As above with an explicit propagation depth (0: only the closure, no 1:4 propagation).
  status split(std::uint32_t t, std::uint32_t propagation_depth) {
    if (t >= tris_.size())
      return make_error(errc::index_out_of_range, t, "triangle ", t, " out of range (", tris_.size(), " triangles)");
    created_.clear();
    select(t, propagation_depth);
    return {};
  }
  // Splits each selected triangle in order (see split). Errors: the first id out of range;
  // then nothing is split (all ids are checked before the mesh changes).
  status split(std::span<const std::uint32_t> selected) {
    for (std::size_t i = 0; i < selected.size(); ++i)
      if (selected[i] >= tris_.size())
        return make_error(errc::index_out_of_range, selected[i], "selection ", i, ": triangle ", selected[i],
                          " out of range (", tris_.size(), " triangles)");
    created_.clear();
    for (std::uint32_t t : selected) select(t, options_.propagation_depth);
    return {};
  }
  // The triangles the last split() call made (reused slots included: after coarsen(), a new
  // triangle's id may be smaller than older ones'). Valid until the next split or coarsen.
  [[nodiscard]] std::span<const std::uint32_t> created() const noexcept { return created_; }
  // Triangles in use: triangle_count() less the slots coarsen() freed and no split reused yet.
  [[nodiscard]] std::size_t live_triangle_count() const noexcept {
    return tris_.size() - 4 * free4_.size() - 2 * free2_.size();
  }

  // The triangles the last successful coarsen() made leaves again.
  [[nodiscard]] std::span<const std::uint32_t> coarsened() const noexcept { return component_; }
  // The inverse of split, for memory: collapses the subtree under t, and under every triangle
  // tied to it across an edge that a collapsed subtree splits (transitively), so the mesh stays
  // conforming: each becomes a leaf again. Only when allow_triangle(x) holds for each triangle
  // of those subtrees and allow_vertex(v) for each vertex they created; otherwise nothing
  // changes. Freed triangle slots (1:2 children a 1:4 split retired included) and vertex ids are
  // appended to freed_triangles and freed_vertices and reused by later splits. Returns whether
  // it collapsed. Complexity O(collapsed · log) expected; allocation: the work and free lists.
  template <class AllowTriangle, class AllowVertex>
  bool coarsen(std::uint32_t t, AllowTriangle&& allow_triangle, AllowVertex&& allow_vertex,
               std::vector<std::uint32_t>& freed_triangles, std::vector<std::uint32_t>& freed_vertices) {
    if (t >= tris_.size() || !collect_component(t, allow_triangle, allow_vertex)) return false;
    created_.clear();
    for (std::uint32_t d : subtree_) {  // every edge inside a collapsed subtree goes (its member's own edges stay)
      std::uint32_t x = d;  // the member d lies in: a subtree's edges lie inside it or on its edges
      while (tris_[x].parent != invalid_id && mark_[tris_[x].parent] == mark_clock_) x = tris_[x].parent;
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = tris_[d].vertices[k], b = tris_[d].vertices[(k + 1) % 3];
        if (!(has_vertex(x, a) && has_vertex(x, b))) edges_.erase(a, b);
      }
    }
    for (std::uint32_t x : component_) {  // the members' own edges: no midpoint, the member as a face
      for (int k = 0; k < 3; ++k) {
        auto& e = edges_.get(tris_[x].vertices[k], tris_[x].vertices[(k + 1) % 3]);
        for (std::uint32_t f : {e.face[0], e.face[1]})
          if (f != invalid_id && mark_[f] == mark_clock_ && f != x) detail::edge_table::remove_face(e, f);
        e.midpoint = invalid_id;
      }
    }
    for (std::uint32_t x : component_)
      for (int k = 0; k < 3; ++k) {
        [[maybe_unused]] const bool ok = detail::edge_table::add_face(edges_.get(tris_[x].vertices[k], tris_[x].vertices[(k + 1) % 3]), x);
        INFOLERP_ASSERT(ok);
      }
    blocks_.clear();  // the child blocks, all read before any is freed (freeing clears a slot)
    for (const auto* list : {&subtree_, &component_})
      for (std::uint32_t d : *list) {
        const subdivision_triangle& n = tris_[d];
        if (retired_first_[d] != invalid_id) blocks_.push_back({retired_first_[d], 2}), retired_first_[d] = invalid_id;
        if (n.child_count == 0 || n.retired) continue;
        leaf_count_ -= n.child_count - 1u;
        blocks_.push_back({n.first_child, n.child_count});
      }
    for (const block& b : blocks_) free_block(b.first, b.size, freed_triangles);
    for (std::uint32_t x : component_) {
      tris_[x].first_child = invalid_id;
      tris_[x].child_count = 0;
      tris_[x].split_edge = 0;
    }
    for (std::uint32_t v : vertices_) free_vertices_.push_back(v), freed_vertices.push_back(v);
    return true;
  }

  // The leaf containing the point with Embree barycentrics (u, v) in original triangle
  // `original` (point = (1-u-v)·p0 + u·p1 + v·p2), and its weights for the leaf's vertices.
  // Points outside the triangle are clamped to the nearest child at each level.
  // Preconditions: original < original_triangle_count(). O(level of the leaf), no allocation.
  [[nodiscard]] point_location locate(std::uint32_t original, glm::vec2 uv) const {
    return locate_from(original, glm::vec3(1.0f - uv.x - uv.y, uv.x, uv.y));
  }
  // Continues a location from any triangle of the hierarchy (a previous leaf, even a retired
  // one) given the point's barycentric weights for that triangle's vertices. This is how a
  // pixel follows its leaf as it is split. Descends in double: weights lose no precision
  // relative to the input as the levels get deeper.
  [[nodiscard]] point_location locate_from(std::uint32_t t, glm::vec3 weights) const {
    // Three scalars, never an array indexed by a corner: the descent is a chain of dependent
    // steps per pixel, and a spilled array would add a store-to-load round trip to each.
    double w0 = weights.x, w1 = weights.y, w2 = weights.z;
    for (;;) {
      const subdivision_triangle& n = tris_[t];
      if (n.child_count == 4) {  // corner child c keeps corner c in slot c; the centre child is 3
        const double a = 2.0 * w0, b = 2.0 * w1, c = 2.0 * w2;
        const std::uint32_t child = w2 >= 0.5 ? 2 : w1 >= 0.5 ? 1 : w0 >= 0.5 ? 0 : 3;
        const bool centre = child == 3;  // selects, not branches: the child is a coin toss per pixel
        w0 = centre ? 1.0 - c : child == 0 ? a - 1.0 : a;
        w1 = centre ? 1.0 - a : child == 1 ? b - 1.0 : b;
        w2 = centre ? 1.0 - b : child == 2 ? c - 1.0 : c;
        t = n.first_child + child;
      } else if (n.child_count == 2) {  // the bisected edge k runs from corner k to k + 1
        double wa, wb, wc;
        rotate_from(n.split_edge, w0, w1, w2, wa, wb, wc);
        if (wa >= wb) {
          w0 = wa - wb, w1 = 2.0 * wb, w2 = wc;
          t = n.first_child;
        } else {
          w0 = 2.0 * wa, w1 = wb - wa, w2 = wc;
          t = n.first_child + 1;
        }
      } else if (n.retired) {  // lift the weights to the parent (see the children order)
        const bool second = n.retired == 2;
        const double wa = second ? 0.5 * w0 : w0 + 0.5 * w1;
        const double wb = second ? 0.5 * w0 + w1 : 0.5 * w1;
        rotate_to(n.split_edge, wa, wb, w2, w0, w1, w2);
        t = n.parent;
      } else {
        break;
      }
    }
    return {t, glm::vec3(static_cast<float>(w0), static_cast<float>(w1), static_cast<float>(w2))};
  }

  // Appends the ids of the current leaves, ascending. O(triangle_count()); allocation: growth of out.
  void leaves(std::vector<std::uint32_t>& out) const {
    for (std::size_t t = 0; t < tris_.size(); ++t)
      if (tris_[t].is_leaf()) out.push_back(static_cast<std::uint32_t>(t));
  }
  // The current leaves as a mesh over all vertices (leaf i is the i-th leaf in id order).
  // O(V + triangle_count()); allocates the copy of the positions and the leaf triangles.
  [[nodiscard]] indexed_mesh leaf_mesh() const {
    indexed_mesh out;
    out.positions = positions_;
    out.triangles.reserve(leaf_count_);
    for (const subdivision_triangle& n : tris_)
      if (n.is_leaf()) out.triangles.push_back(n.vertices);
    return out;
  }

  // The leaves as a mesh that carries the input mesh's attributes, so that a mesh tessellated
  // for a view (§4.1) clusters, traces and upsamples like any other. `source` is the mesh
  // create() read. Each leaf's corners get the barycentric weights of their positions in the
  // leaf's original triangle (subdivision is flat, so the weights are exact up to rounding);
  // per-corner texcoords are interpolated with them within that triangle (UV seams stay
  // seams), and every new vertex's normal (renormalised) and keyframe positions within the
  // triangle it was created in. leaf_source[i] = the original triangle of leaf i, so per-
  // triangle data (cluster ids) carries over as leaf_source[i] -> data[leaf_source[i]].
  // Errors: source's vertex or triangle count differs from create()'s (bad_size); a keyframe
  // without a position per vertex (bad_size, naming it).
  // Complexity O(V + triangle_count() + V·keyframes); allocates the mesh and leaf_source.
  template <class M>
  [[nodiscard]] result<indexed_mesh> leaf_mesh(const M& source, std::vector<std::uint32_t>& leaf_source) const {
    static_assert(check_mesh<M>());
    if (mesh_vertex_count(source) != original_vertex_count_ || mesh_triangle_count(source) != original_count_)
      return make_error(errc::bad_size, no_element, "leaf_mesh: source has ", mesh_vertex_count(source), " vertices and ",
                        mesh_triangle_count(source), " triangles; the hierarchy was built from ", original_vertex_count_,
                        " and ", original_count_);
    const std::size_t nk = mesh_keyframe_count(source);
    for (std::size_t k = 0; k < nk; ++k)
      if (const std::size_t n = mesh_keyframe_vertex_count(source, k); n != original_vertex_count_)
        return make_error(errc::bad_size, k, "leaf_mesh: keyframe ", k, " has ", n, " positions for ",
                          original_vertex_count_, " vertices");
    indexed_mesh out = leaf_mesh();
    leaf_source.clear();
    leaf_source.reserve(leaf_count_);
    for (const subdivision_triangle& n : tris_)
      if (n.is_leaf()) leaf_source.push_back(n.original);
    if constexpr (textured_mesh<M>) {
      if (mesh_has_texcoords(source)) {
        out.texcoords.resize(3 * out.triangles.size());
        for (std::size_t i = 0; i < out.triangles.size(); ++i)
          for (unsigned c = 0; c < 3; ++c) {
            const glm::dvec3 w = weights_in(leaf_source[i], out.triangles[i][static_cast<int>(c)]);
            glm::dvec2 uv(0.0);
            for (unsigned k = 0; k < 3; ++k) uv += w[static_cast<int>(k)] * glm::dvec2(mesh_traits<M>::texcoord(source, leaf_source[i], k));
            out.texcoords[3 * i + c] = glm::vec2(uv);
          }
      }
    }
    const auto per_vertex = [&](auto&& value, std::vector<glm::vec3>& into, bool unit) {
      into.resize(positions_.size());
      for (std::size_t v = 0; v < positions_.size(); ++v) {
        if (v < original_vertex_count_) {
          into[v] = value(v);
          continue;
        }
        const std::uint32_t t = vertex_source_[v];
        const glm::uvec3 tri = tris_[t].vertices;
        const glm::dvec3 w = weights_in(t, static_cast<std::uint32_t>(v));
        const glm::dvec3 x = w.x * glm::dvec3(value(tri.x)) + w.y * glm::dvec3(value(tri.y)) + w.z * glm::dvec3(value(tri.z));
        const double len = glm::length(x);
        into[v] = glm::vec3(unit && len > 0.0 ? x / len : x);
      }
    };
    if constexpr (mesh_with_normals<M>) {
      if (mesh_has_normals(source))
        per_vertex([&](std::size_t v) { return glm::vec3(mesh_traits<M>::normal(source, v)); }, out.normals, true);
    }
    out.keyframes.resize(nk);
    for (std::size_t k = 0; k < nk; ++k)
      per_vertex([&](std::size_t v) { return glm::vec3(mesh_traits<M>::keyframe_position(source, k, v)); }, out.keyframes[k], false);
    return out;
  }

  // Clustering paper §4.1: splits (closure only, no propagation) every leaf for which
  // needs_split(p0, p1, p2) holds, repeatedly, until none does or the leaf reached max_level.
  // Use screen_fraction_test for the paper's criterion. Returns the number of selections.
  // Complexity O(final triangles · rounds) with rounds <= max_level. Allocation: the new
  // triangles and vertices plus a work list of leaf ids. needs_split is called serially.
  template <class NeedsSplit>
  std::size_t tessellate(NeedsSplit&& needs_split, std::uint32_t max_level = 8) {
    created_.clear();
    std::size_t selections = 0;
    std::vector<std::uint32_t> work;
    for (;;) {
      work.clear();
      for (std::size_t t = 0; t < tris_.size(); ++t) {
        const subdivision_triangle& n = tris_[t];
        if (!n.is_leaf() || n.level >= max_level) continue;
        if (needs_split(positions_[n.vertices.x], positions_[n.vertices.y], positions_[n.vertices.z]))
          work.push_back(static_cast<std::uint32_t>(t));
      }
      if (work.empty()) break;
      for (std::uint32_t t : work) {
        // A neighbour's closure may have split t 1:2 meanwhile; t wanted 1:4 (rule 3).
        if (tris_[t].child_count == 2) select(tris_[t].first_child, 0);
        else select(t, 0);
      }
      selections += work.size();
    }
    return selections;
  }

 private:
  // (a, b, c) = the weights of corners k, k + 1, k + 2 (mod 3); rotate_to is its inverse.
  static void rotate_from(std::uint8_t k, double w0, double w1, double w2, double& a, double& b, double& c) noexcept {
    if (k == 0) a = w0, b = w1, c = w2;
    else if (k == 1) a = w1, b = w2, c = w0;
    else a = w2, b = w0, c = w1;
  }
  static void rotate_to(std::uint8_t k, double a, double b, double c, double& w0, double& w1, double& w2) noexcept {
    if (k == 0) w0 = a, w1 = b, w2 = c;
    else if (k == 1) w1 = a, w2 = b, w0 = c;
    else w2 = a, w0 = b, w1 = c;
  }
  // Halves first: the sum of two coordinates near ±FLT_MAX overflows (a fuzz find); for
  // normal numbers the result is the same bits as 0.5 * (a + b).
  static glm::vec3 midpoint(glm::vec3 a, glm::vec3 b) noexcept { return 0.5f * a + 0.5f * b; }
  static constexpr std::uint32_t closure_only = std::numeric_limits<std::uint32_t>::max() / 2;

  // Barycentric weights of vertex v's position in original triangle t (least squares in the
  // triangle's plane; v lies in it). O(1).
  [[nodiscard]] glm::dvec3 weights_in(std::uint32_t t, std::uint32_t v) const {
    const glm::uvec3 tri = tris_[t].vertices;
    const glm::dvec3 a(positions_[tri.x]), e1 = glm::dvec3(positions_[tri.y]) - a, e2 = glm::dvec3(positions_[tri.z]) - a;
    const glm::dvec3 d = glm::dvec3(positions_[v]) - a;
    const double d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
    const double p1 = glm::dot(d, e1), p2 = glm::dot(d, e2), det = d11 * d22 - d12 * d12;
    const double u = (d22 * p1 - d12 * p2) / det, w = (d11 * p2 - d12 * p1) / det;
    return {1.0 - u - w, u, w};
  }
  struct pending {
    std::uint32_t triangle, depth;
  };

  void select(std::uint32_t t, std::uint32_t propagation_depth) {
    const subdivision_triangle& n = tris_[t];
    if (!n.is_leaf()) return;
    limit_ = propagation_depth;
    if (n.parent != invalid_id && tris_[n.parent].child_count == 2) resplit_green(n.parent, 0);
    else split_red(t, 0);
    close();
  }

  void close() {
    while (head_ < queue_.size()) {
      const pending p = queue_[head_++];
      const subdivision_triangle& n = tris_[p.triangle];
      if (!n.is_leaf()) continue;
      int hanging = 0, edge = 0;
      for (int k = 0; k < 3; ++k)
        if (edges_.midpoint(n.vertices[k], n.vertices[(k + 1) % 3]) != invalid_id) ++hanging, edge = k;
      if (hanging == 0) continue;
      if (n.parent != invalid_id && tris_[n.parent].child_count == 2) {
        resplit_green(n.parent, closure_only);
      } else if (hanging == 1 && !(p.depth <= limit_ &&
                                   height_width_ratio(p.triangle, edge) >= options_.bisect_ratio)) {
        split_green(p.triangle, edge);
      } else {
        split_red(p.triangle, p.depth);
      }
    }
    queue_.clear();
    head_ = 0;
  }

  [[nodiscard]] double height_width_ratio(std::uint32_t t, int k) const {
    const glm::uvec3 v = tris_[t].vertices;
    const glm::dvec3 a(positions_[v[k]]), b(positions_[v[(k + 1) % 3]]), c(positions_[v[(k + 2) % 3]]);
    const glm::dvec3 ab = b - a;
    return glm::length(glm::cross(ab, c - a)) / glm::dot(ab, ab);  // (2·area / width) / width
  }

  // The midpoint of edge (a, b) of leaf t, created when absent; the leaf on the other side of
  // a new midpoint now has a hanging vertex and is queued at depth + 1.
  std::uint32_t make_midpoint(std::uint32_t a, std::uint32_t b, std::uint32_t t, std::uint32_t depth) {
    auto& e = edges_.get(a, b);
    detail::edge_table::remove_face(e, t);
    if (e.midpoint != invalid_id) return e.midpoint;
    const auto m = static_cast<std::uint32_t>(positions_.size());
    e.midpoint = m;
    if (e.face[0] != invalid_id) queue_.push_back({e.face[0], depth + 1});
    positions_.push_back(midpoint(positions_[a], positions_[b]));
    vertex_source_.push_back(tris_[t].original);
    if (!free_vertices_.empty()) {  // a vertex freed by coarsen(): reuse its id
      const std::uint32_t r = free_vertices_.back();
      free_vertices_.pop_back();
      positions_[r] = positions_.back(), vertex_source_[r] = vertex_source_.back();
      positions_.pop_back(), vertex_source_.pop_back();
      e.midpoint = r;
      return r;
    }
    return m;
  }
  // Attaches child c to edge (a, b); queues it when (a, b) already has a midpoint.
  void attach(std::uint32_t a, std::uint32_t b, std::uint32_t c, bool may_hang) {
    auto& e = edges_.get(a, b);
    const bool ok = detail::edge_table::add_face(e, c);
    INFOLERP_ASSERT(ok);
    (void)ok;
    if (may_hang && e.midpoint != invalid_id) queue_.push_back({c, closure_only});
  }
  // A new interior edge shared by two new children.
  void attach_inner(std::uint32_t a, std::uint32_t b, std::uint32_t c0, std::uint32_t c1) {
    auto& e = edges_.get(a, b);
    e.face[0] = c0;
    e.face[1] = c1;
  }
  void detach(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    detail::edge_table::remove_face(edges_.get(a, b), c);
  }
  // The ids of n = 2 or 4 new children, consecutive: a block freed by coarsen() or new slots.
  std::uint32_t alloc_children(std::uint32_t n) {
    std::vector<std::uint32_t>& free = n == 4 ? free4_ : free2_;
    std::uint32_t first;
    if (!free.empty()) {
      first = free.back();
      free.pop_back();
    } else {
      first = static_cast<std::uint32_t>(tris_.size());
      tris_.resize(tris_.size() + n);
      retired_first_.resize(tris_.size(), invalid_id);
    }
    for (std::uint32_t i = 0; i < n; ++i) created_.push_back(first + i);
    return first;
  }
  void set_child(std::uint32_t id, std::uint32_t parent, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    subdivision_triangle n;
    n.vertices = {a, b, c};
    n.parent = parent;
    n.original = tris_[parent].original;
    // Saturates: 255 nested selections are legal input (float positions stopped changing
    // about 30 levels earlier), so the count stops instead of asserting or wrapping to 0.
    n.level = static_cast<std::uint8_t>(std::min(tris_[parent].level + 1, 255));
    tris_[id] = n;
    retired_first_[id] = invalid_id;
  }

  void split_red(std::uint32_t t, std::uint32_t depth) {
    const glm::uvec3 v = tris_[t].vertices;
    const std::uint32_t m0 = make_midpoint(v[0], v[1], t, depth);
    const std::uint32_t m1 = make_midpoint(v[1], v[2], t, depth);
    const std::uint32_t m2 = make_midpoint(v[2], v[0], t, depth);
    const std::uint32_t c0 = alloc_children(4), c1 = c0 + 1, c2 = c0 + 2, c3 = c0 + 3;
    set_child(c0, t, v[0], m0, m2);
    set_child(c1, t, m0, v[1], m1);
    set_child(c2, t, m2, m1, v[2]);
    set_child(c3, t, m0, m1, m2);
    tris_[t].first_child = c0;
    tris_[t].child_count = 4;
    leaf_count_ += 3;
    attach(v[0], m0, c0, true);
    attach(m0, v[1], c1, true);
    attach(v[1], m1, c1, true);
    attach(m1, v[2], c2, true);
    attach(v[2], m2, c2, true);
    attach(m2, v[0], c0, true);
    attach_inner(m0, m2, c0, c3);
    attach_inner(m0, m1, c1, c3);
    attach_inner(m1, m2, c2, c3);
  }

  void split_green(std::uint32_t t, int k) {
    const glm::uvec3 v = tris_[t].vertices;
    const std::uint32_t a = v[k], b = v[(k + 1) % 3], c = v[(k + 2) % 3];
    const std::uint32_t m = make_midpoint(a, b, t, closure_only);
    detach(b, c, t);
    detach(c, a, t);
    const std::uint32_t c0 = alloc_children(2), c1 = c0 + 1;
    set_child(c0, t, a, m, c);
    set_child(c1, t, m, b, c);
    tris_[t].first_child = c0;
    tris_[t].child_count = 2;
    tris_[t].split_edge = static_cast<std::uint8_t>(k);
    leaf_count_ += 1;
    attach(a, m, c0, true);
    attach(m, b, c1, true);
    attach(b, c, c1, false);
    attach(c, a, c0, false);
    attach_inner(m, c, c0, c1);
  }

  // coarsen()'s work: component_, the triangles to become leaves (none inside another's
  // subtree); subtree_, the triangles under them that are not members, retired ones included,
  // each marked with mark_clock_ (members too); vertices_, the vertices those created. The
  // triangle across a member's split edge (a, b) is the first ancestor with that edge of a leaf
  // along it. False if a predicate refuses or the edge table is not what a split leaves.
  template <class AllowTriangle, class AllowVertex>
  bool collect_component(std::uint32_t t, AllowTriangle& allow_triangle, AllowVertex& allow_vertex) {
    if (mark_.size() < tris_.size()) mark_.resize(tris_.size(), 0);
    if (++mark_clock_ == 0) std::fill(mark_.begin(), mark_.end(), 0u), mark_clock_ = 1;
    component_.clear();
    subtree_.clear();
    vertices_.clear();
    stack_.assign(1, t);
    while (!stack_.empty()) {
      std::uint32_t x = stack_.back();
      stack_.pop_back();
      while (tris_[x].parent != invalid_id && mark_[tris_[x].parent] == mark_clock_) x = tris_[x].parent;
      if (mark_[x] == mark_clock_) continue;  // a member already, or inside one's subtree
      const subdivision_triangle& n = tris_[x];
      if (n.child_count == 0 || n.retired || !allow_triangle(x)) return false;
      mark_[x] = mark_clock_;
      component_.push_back(x);
      // x's subtree (a member found earlier inside it becomes part of it; its own subtree is
      // listed already)
      walk_.assign(1, x);
      while (!walk_.empty()) {
        const std::uint32_t d = walk_.back();
        walk_.pop_back();
        const subdivision_triangle& m = tris_[d];
        if (d != x) {
          if (mark_[d] == mark_clock_) {
            if (const auto it = std::find(component_.begin(), component_.end(), d); it != component_.end())
              component_.erase(it), subtree_.push_back(d);
            continue;
          }
          if (!allow_triangle(d)) return false;
          mark_[d] = mark_clock_;
          subtree_.push_back(d);
        }
        if (retired_first_[d] != invalid_id) walk_.push_back(retired_first_[d]), walk_.push_back(retired_first_[d] + 1);
        if (m.retired || m.child_count == 0) continue;
        // The vertices d's split created (a 1:4 split's centre child, a 1:2 split's middle
        // corner), checked at once so a refusal costs little.
        const glm::uvec3 created = tris_[m.first_child + (m.child_count == 4 ? 3 : 0)].vertices;
        for (int k = m.child_count == 4 ? 0 : 1; k < (m.child_count == 4 ? 3 : 2); ++k) {
          if (!allow_vertex(created[k])) return false;
          vertices_.push_back(created[k]);
        }
        for (std::uint32_t c = m.first_child; c < m.first_child + m.child_count; ++c) walk_.push_back(c);
      }
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = n.vertices[k], b = n.vertices[(k + 1) % 3];
        if (edges_.midpoint(a, b) == invalid_id) continue;
        std::uint32_t y = invalid_id;
        if (!across(x, a, b, a, b, y)) return false;
        if (y != invalid_id) stack_.push_back(y);
      }
    }
    // The vertices the collapsed subtrees created (a midpoint shared by two splits once), less
    // any member's corner.
    std::sort(vertices_.begin(), vertices_.end());
    vertices_.erase(std::unique(vertices_.begin(), vertices_.end()), vertices_.end());
    corners_.clear();
    for (std::uint32_t x : component_)
      for (int k = 0; k < 3; ++k) corners_.push_back(tris_[x].vertices[k]);
    std::sort(corners_.begin(), corners_.end());
    vertices_.erase(std::remove_if(vertices_.begin(), vertices_.end(),
                                   [&](std::uint32_t v) { return std::binary_search(corners_.begin(), corners_.end(), v); }),
                    vertices_.end());
    return true;
  }
  // The triangle across edge (A, B) of x, found along the segment (a, b) of it: y, or invalid_id
  // on a boundary. False if the table has no entry for a segment.
  bool across(std::uint32_t x, std::uint32_t a, std::uint32_t b, std::uint32_t A, std::uint32_t B, std::uint32_t& y) const {
    const detail::edge_table::entry* e = edges_.find(a, b);
    if (!e) return false;
    if (e->midpoint != invalid_id) {
      const std::uint32_t m = e->midpoint;
      if (!across(x, a, m, A, B, y)) return false;
      return y != invalid_id || across(x, m, b, A, B, y);
    }
    for (std::uint32_t f : e->face) {
      std::uint32_t z = f;
      while (z != invalid_id && !(has_vertex(z, A) && has_vertex(z, B))) z = tris_[z].parent;
      if (z != invalid_id && z != x) {
        y = z;
        return true;
      }
    }
    return true;
  }
  [[nodiscard]] bool has_vertex(std::uint32_t t, std::uint32_t v) const noexcept {
    const glm::uvec3 w = tris_[t].vertices;
    return w.x == v || w.y == v || w.z == v;
  }
  void free_block(std::uint32_t first, std::uint32_t n, std::vector<std::uint32_t>& freed) {
    for (std::uint32_t c = first; c < first + n; ++c) {
      tris_[c] = subdivision_triangle{};
      tris_[c].retired = 3;
      freed.push_back(c);
    }
    (n == 4 ? free4_ : free2_).push_back(first);
  }

  // Rule 3: undo the 1:2 split of p and split it 1:4.
  void resplit_green(std::uint32_t p, std::uint32_t depth) {
    subdivision_triangle& n = tris_[p];
    for (std::uint32_t i = 0; i < 2; ++i) {
      subdivision_triangle& c = tris_[n.first_child + i];
      for (int k = 0; k < 3; ++k) detach(c.vertices[k], c.vertices[(k + 1) % 3], n.first_child + i);
      c.retired = static_cast<std::uint8_t>(i + 1);
      c.split_edge = n.split_edge;
    }
    for (int k = 0; k < 3; ++k) {
      auto& e = edges_.get(n.vertices[k], n.vertices[(k + 1) % 3]);
      detail::edge_table::add_face(e, p);
    }
    retired_first_[p] = n.first_child;
    n.child_count = 0;
    n.first_child = invalid_id;
    leaf_count_ -= 1;
    split_red(p, depth);
  }

  subdivision_options options_;
  std::vector<glm::vec3> positions_;
  std::vector<std::uint32_t> vertex_source_;
  std::size_t original_vertex_count_ = 0;
  std::vector<subdivision_triangle> tris_;
  detail::edge_table edges_;
  std::vector<pending> queue_;
  std::vector<std::uint32_t> retired_first_;  // per triangle resplit 1:4: its retired 1:2 children's first id
  std::vector<std::uint32_t> free4_, free2_, free_vertices_;  // freed by coarsen(), reused by splits
  std::vector<std::uint32_t> created_;        // triangles made since the last take_created()
  std::vector<std::uint32_t> component_, subtree_, vertices_, corners_, stack_, walk_;  // coarsen()'s work lists
  struct block {
    std::uint32_t first, size;
  };
  std::vector<block> blocks_;        // coarsen(): the child blocks to free
  std::vector<std::uint32_t> mark_;  // coarsen(): mark_clock_ on the members and their subtrees
  std::uint32_t mark_clock_ = 0;
  std::size_t head_ = 0;
  std::uint32_t limit_ = 0;  // propagation depth of the current selection
  std::size_t original_count_ = 0;
  std::size_t leaf_count_ = 0;
};

}  // namespace infolerp
