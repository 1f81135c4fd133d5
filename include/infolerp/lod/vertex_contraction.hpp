#pragma once
// Vertex contraction into an index buffer (salient-clustering paper §IV.B, Algorithm 1), on
// the CPU through the executor instead of a fragment shader.
//
// The paper iterates a shader maxContractionLevel times, each index following one contraction
// per pass. Here the chains are resolved once per frame: walking the contractions from the last
// to the first, remap[removed] = remap[target] if the contraction is applied, removed otherwise
// (a target is removed only by a later contraction, so its entry is final when read); between
// frames only the contractions whose state changed are redone, with the chains through them.
// Triangles are not tested one by one for removal: inside each cluster the hierarchy orders them
// in runs by the owner of their removing contraction (contraction_hierarchy::killer), latest
// removal first, so the triangles a frame keeps are a prefix of each run, found by binary search. At dependency-closed stop points (neighbour matching's
// output, or one global prefix) a triangle whose removing contraction is applied is degenerate:
// every earlier contraction that renamed its corners is a dependency of that contraction and
// applied too. This is a precondition: stop points that are not dependency-closed may lose
// triangles that would not be degenerate. Only the kept prefixes are read: each index replaced
// by its remap, triangles with a repeated index dropped, written in parallel by fixed chunks
// (never straddling a run) at offsets from a serial prefix sum; a serial pass closes the gaps
// that dropped triangles leave and records each cluster's range (§IV.C binds one range per
// cluster). Chunk boundaries depend only on the hierarchy and the grain, so the output has
// identical bits for any executor.
// contract_visible_indices also drops each triangle the camera cannot see (hidden_triangles.hpp),
// tested in the same parallel pass by blocks of kept triangles whose corners are gathered into
// arrays per coordinate (one instruction tests several; the frustum planes are skipped when the
// box of all positions lies inside them); a first pass sums the signed crossings
// of a ray from the eye with the closed parts' kept triangles, and back faces are kept when the
// eye is inside.
// One vertex map serves every cluster, so a vertex on a cluster border contracts the same way
// in all of them (the paper ensures this with the shared-cluster texture).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <span>
#include <type_traits>
#include <vector>
#include <glm/common.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/hidden_triangles.hpp"

namespace infolerp {

struct index_range {
  std::uint32_t first = 0, count = 0;  // in indices of the output buffer
};

// Indices the contraction pass may write: the full-resolution count. O(1).
inline std::size_t contracted_index_bound(const contraction_hierarchy& h) { return h.indices.size(); }

// Setup kept between frames: the vertex map, the runs and the chunk table. Build once per
// hierarchy (O(V + T / grain) allocation, O(T)); the per-frame calls then allocate nothing.
struct contraction_workspace {
  std::vector<std::uint32_t> remap;          // per vertex
  std::vector<std::uint32_t> run_begin;      // per run (triangles of one cluster removed by one owner), runs + 1
  std::vector<std::uint32_t> run_owner;      // per run: the cluster owning its triangles' removing contractions
  std::vector<std::uint32_t> run_kept;       // per run, this frame: one past its last kept triangle
  std::vector<std::uint32_t> chunk_begin;    // per chunk (at most grain triangles of one run), chunks + 1
  std::vector<std::uint32_t> chunk_run;      // per chunk
  std::vector<std::uint32_t> chunk_cluster;  // per chunk
  std::vector<std::size_t> chunk_at;         // per chunk, this frame: output offset if nothing is dropped
  std::vector<std::uint32_t> chunk_count;    // per chunk, this frame: indices written
  std::vector<std::int32_t> chunk_winding;   // per chunk, this frame (culling): signed crossings of a ray from the eye
  glm::dvec3 lo{0.0}, hi{-1.0};              // the box of h.positions (empty without them): of every cut
  bool back_faces_hidden = false;            // this frame (culling): the eye outside every closed part of the cut
  // resolve_vertex_map between frames: the stop points remap holds (empty: none yet), per vertex
  // the contractions whose target it is (CSR), scratch for the contractions to redo and a stack.
  std::vector<std::uint32_t> resolved_stop, child_offsets, children, toggled, stack;
  std::size_t grain = 0;
};

inline contraction_workspace make_contraction_workspace(const contraction_hierarchy& h, std::size_t grain = 4096) {
  contraction_workspace w;
  w.grain = std::max<std::size_t>(grain, 1);
  w.remap.resize(h.vertex_count);
  for (std::uint32_t v = 0; v < h.vertex_count; ++v) w.remap[v] = v;
  const auto run_of = [&](std::size_t t) { return h.killer[t] == invalid_id ? 0 : h.owner[h.killer[t]]; };
  for (std::uint32_t c = 0; c < h.cluster_count; ++c)
    for (std::size_t t = h.triangle_offsets[c], e = t; t < h.triangle_offsets[c + 1]; t = e) {
      while (e < h.triangle_offsets[c + 1] && run_of(e) == run_of(t)) ++e;
      for (std::size_t k = 0, chunks = chunk_count(e - t, w.grain); k < chunks; ++k) {
        w.chunk_begin.push_back(static_cast<std::uint32_t>(t + chunk_at(e - t, w.grain, k).begin));
        w.chunk_run.push_back(static_cast<std::uint32_t>(w.run_owner.size()));
        w.chunk_cluster.push_back(c);
      }
      w.run_begin.push_back(static_cast<std::uint32_t>(t));
      w.run_owner.push_back(run_of(t));
    }
  w.run_begin.push_back(static_cast<std::uint32_t>(h.triangle_count()));
  w.chunk_begin.push_back(static_cast<std::uint32_t>(h.triangle_count()));
  w.run_kept.assign(w.run_owner.size(), 0);
  w.chunk_at.assign(w.chunk_run.size(), 0);
  w.chunk_count.assign(w.chunk_run.size(), 0);
  w.chunk_winding.assign(w.chunk_run.size(), 0);
  w.child_offsets.assign(std::size_t{h.vertex_count} + 1, 0);
  for (std::uint32_t v : h.target) ++w.child_offsets[v + 1];
  for (std::uint32_t v = 0; v < h.vertex_count; ++v) w.child_offsets[v + 1] += w.child_offsets[v];
  w.children.resize(h.contraction_count());
  std::vector<std::uint32_t> at(w.child_offsets.begin(), w.child_offsets.end() - 1);
  for (std::uint32_t i = 0; i < h.contraction_count(); ++i) w.children[at[h.target[i]]++] = i;
  w.toggled.resize(h.contraction_count() / 8);
  w.stack.resize(h.vertex_count);
  w.resolved_stop.reserve(h.cluster_count);
  if (!h.positions.empty()) w.lo = w.hi = glm::dvec3(h.positions[0]);
  for (const glm::vec3& p : h.positions) w.lo = glm::min(w.lo, glm::dvec3(p)), w.hi = glm::max(w.hi, glm::dvec3(p));
  return w;
}

namespace detail {
// The vertex map for stop from the one for w.resolved_stop: the contractions whose state
// differs are redone from the last to the first, each giving its removed vertex and every vertex
// whose applied chain passes through it (a walk down the children) their new end; the chains of
// all other vertices are unchanged. False (nothing done) when no map is held or more than
// w.toggled.size() contractions differ.
inline bool update_vertex_map(const contraction_hierarchy& h, std::span<const std::uint32_t> stop,
                              contraction_workspace& w) {
  if (w.resolved_stop.size() != stop.size()) return false;
  std::size_t n = 0;
  for (std::uint32_t c = 0; c < h.cluster_count; ++c) {
    const std::uint32_t a = std::min(stop[c], w.resolved_stop[c]), z = std::max(stop[c], w.resolved_stop[c]);
    if (a == z) continue;
    const auto end = h.cluster_contractions.begin() + h.cluster_offsets[c + 1];
    const auto b = std::lower_bound(h.cluster_contractions.begin() + h.cluster_offsets[c], end, a);
    const auto e = std::lower_bound(b, end, z);
    if (static_cast<std::size_t>(e - b) > w.toggled.size() - n) return false;
    n = static_cast<std::size_t>(std::copy(b, e, w.toggled.begin() + static_cast<long>(n)) - w.toggled.begin());
  }
  std::sort(w.toggled.begin(), w.toggled.begin() + static_cast<long>(n), std::greater<>());
  std::uint32_t* remap = w.remap.data();
  std::uint32_t* stack = w.stack.data();
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t i = w.toggled[k], u = h.removed[i];
    const std::uint32_t r = i < stop[h.owner[i]] ? remap[h.target[i]] : u;  // final: set by later contractions
    remap[u] = r;
    std::size_t top = 0;
    stack[top++] = u;
    while (top > 0) {
      const std::uint32_t x = stack[--top];
      for (std::uint32_t q = w.child_offsets[x]; q < w.child_offsets[x + 1]; ++q)
        if (const std::uint32_t j = w.children[q]; j < stop[h.owner[j]]) remap[h.removed[j]] = r, stack[top++] = h.removed[j];
    }
  }
  return true;
}
}  // namespace detail

// The vertex map of a frame: contraction i is applied iff i < stop[owner(i)]. Between frames
// only the contractions whose state changed and the chains through them are redone (at most
// contractions / 8 of them, else all). Preconditions: w from this hierarchy, stop one per
// cluster. O(changed contractions · log + the vertices whose chains pass through them), at most
// O(contractions); serial, no allocation.
inline void resolve_vertex_map(const contraction_hierarchy& h, std::span<const std::uint32_t> stop,
                               contraction_workspace& w) {
  if (!detail::update_vertex_map(h, stop, w)) {
    const std::uint32_t* removed = h.removed.data();
    const std::uint32_t* target = h.target.data();
    const std::uint32_t* owner = h.owner.data();
    std::uint32_t* remap = w.remap.data();
    for (std::size_t i = h.contraction_count(); i-- > 0;) {
      // A mask instead of a branch: per-cluster stop points make "applied" unpredictable.
      const std::uint32_t u = removed[i], applied = 0u - static_cast<std::uint32_t>(i < stop[owner[i]]);
      remap[u] = (remap[target[i]] & applied) | (u & ~applied);
    }
  }
  w.resolved_stop.assign(stop.begin(), stop.end());
}

namespace detail {
// Algorithm 1 (see contract_indices), dropping the triangles hidden_triangle() finds hidden when
// `view` is not null (one_sided: one flag per triangle of h.indices).
template <class E>
result<std::size_t> contract_indices(const contraction_hierarchy& h, std::span<const std::uint32_t> stop,
                                     contraction_workspace& w, const view_frustum* view,
                                     std::span<const std::uint8_t> one_sided, std::span<std::uint32_t> out,
                                     std::span<index_range> ranges, E&& exec) {
  static_assert(check_executor<std::remove_cvref_t<E>>());
  if (out.size() < contracted_index_bound(h))
    return make_error(errc::bad_size, out.size(), "index buffer holds ", out.size(), " indices; ",
                      contracted_index_bound(h), " needed (contracted_index_bound)");
  if (stop.size() != h.cluster_count || ranges.size() != h.cluster_count)
    return make_error(errc::bad_size, ranges.size(), "stop and ranges hold ", stop.size(), " and ", ranges.size(),
                      " entries for ", h.cluster_count, " clusters");
  resolve_vertex_map(h, stop, w);
  for (std::size_t r = 0; r < w.run_owner.size(); ++r) {  // kept: removing contraction >= the owner's stop
    const std::uint32_t s = stop[w.run_owner[r]];
    const auto b = h.killer.begin() + w.run_begin[r], e = h.killer.begin() + w.run_begin[r + 1];
    w.run_kept[r] = static_cast<std::uint32_t>(std::partition_point(b, e, [s](std::uint32_t k) { return k >= s; }) -
                                               h.killer.begin());
  }
  std::size_t planned = 0;
  for (std::size_t k = 0; k < w.chunk_run.size(); ++k) {
    w.chunk_at[k] = planned;
    const std::uint32_t e = std::min(w.chunk_begin[k + 1], w.run_kept[w.chunk_run[k]]);
    planned += 3 * std::size_t{e > w.chunk_begin[k] ? e - w.chunk_begin[k] : 0};
  }
  const std::uint32_t* remap = w.remap.data();
  const std::uint32_t* src = h.indices.data();
  const glm::vec3* pos = h.positions.data();
  std::uint32_t* dst = out.data();
  bool back_faces_hidden = view != nullptr;
  if (view && view->may_be_inside_closed()) {  // the eye inside a closed part of the cut sees its back faces: cull none
    exec.parallel_for(w.chunk_run.size(), 1, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        std::int32_t n = 0;
        const std::size_t end = std::min(w.chunk_begin[k + 1], w.run_kept[w.chunk_run[k]]);
        for (std::size_t t = w.chunk_begin[k]; t < end; ++t)
          if (one_sided[t])
            n += eye_ray_crossing(*view, pos[remap[src[3 * t]]], pos[remap[src[3 * t + 1]]], pos[remap[src[3 * t + 2]]]);
        w.chunk_winding[k] = n;
      }
    });
    std::int64_t winding = 0;
    for (std::size_t k = 0; k < w.chunk_run.size(); ++k) winding += w.chunk_winding[k];
    back_faces_hidden = winding == 0;
  }
  w.back_faces_hidden = back_faces_hidden;
  const bool frustum = view && !box_inside_frustum(*view, w.lo, w.hi);
  exec.parallel_for(w.chunk_run.size(), 1, [&](std::size_t b, std::size_t e) {
    triangle_block corners;  // culling: blocks of triangles, remapped and gathered, tested, then written
    std::uint32_t ids[3 * hidden_block_size];
    std::int32_t hidden[hidden_block_size];
    for (std::size_t k = b; k < e; ++k) {
      std::uint32_t* o = dst + w.chunk_at[k];
      std::uint32_t* const o0 = o;
      const std::size_t end = std::min(w.chunk_begin[k + 1], w.run_kept[w.chunk_run[k]]);
      if (!frustum) {  // no culling, or every triangle inside the frustum: only the facing test, branch-free
        for (std::size_t t = w.chunk_begin[k]; t < end; ++t) {
          const std::uint32_t a = remap[src[3 * t]], bb = remap[src[3 * t + 1]], c = remap[src[3 * t + 2]];
          o[0] = a, o[1] = bb, o[2] = c;
          const bool back = back_faces_hidden && one_sided[t] == closed_face && facing_away(*view, pos[a], pos[bb], pos[c]);
          o += ((a != bb) & (bb != c) & (a != c) & !back) ? 3 : 0;
        }
      }
      for (std::size_t t0 = w.chunk_begin[k]; frustum && t0 < end; t0 += hidden_block_size) {
        const std::size_t n = std::min(hidden_block_size, end - t0);
        for (std::size_t i = 0; i < n; ++i) {
          const std::size_t t = t0 + i;
          for (std::size_t j = 0; j < 3; ++j) {
            const glm::vec3& p = pos[ids[3 * i + j] = remap[src[3 * t + j]]];
            corners.x[j][i] = p.x, corners.y[j][i] = p.y, corners.z[j][i] = p.z;
          }
          corners.one_sided[i] = back_faces_hidden & (one_sided[t] == closed_face);
        }
        hidden_block(*view, corners, n, hidden);
        for (std::size_t i = 0; i < n; ++i) {
          const std::uint32_t a = ids[3 * i], bb = ids[3 * i + 1], c = ids[3 * i + 2];
          o[0] = a, o[1] = bb, o[2] = c;
          o += a != bb && bb != c && a != c && !hidden[i] ? 3 : 0;
        }
      }
      w.chunk_count[k] = static_cast<std::uint32_t>(o - o0);
    }
  });
  std::size_t at = 0;
  for (std::uint32_t c = 0; c < h.cluster_count; ++c) ranges[c] = {0, 0};
  for (std::size_t k = 0; k < w.chunk_run.size(); ++k) {
    index_range& r = ranges[w.chunk_cluster[k]];
    if (r.count == 0) r.first = static_cast<std::uint32_t>(at);
    if (w.chunk_at[k] != at && w.chunk_count[k])
      std::memmove(dst + at, dst + w.chunk_at[k], sizeof(std::uint32_t) * w.chunk_count[k]);
    at += w.chunk_count[k];
    r.count += w.chunk_count[k];
  }
  for (std::uint32_t c = 0; c < h.cluster_count; ++c)
    if (ranges[c].count == 0) ranges[c].first = static_cast<std::uint32_t>(at);
  return at;
}
}  // namespace detail

// Algorithm 1: the frame's index buffer into out (at least contracted_index_bound(h) entries)
// and one range per cluster. Returns the indices written. Errors: out too small or ranges not
// one per cluster (bad_size), stop not one per cluster (bad_size). Preconditions: w from this
// hierarchy; stop dependency-closed (see the top of the file). O(resolve_vertex_map + runs · log T +
// kept triangles / threads + chunks), no allocation unless an error is returned; identical bits
// for any executor.
template <class E = serial_executor>
result<std::size_t> contract_indices(const contraction_hierarchy& h, std::span<const std::uint32_t> stop,
                                     contraction_workspace& w, std::span<std::uint32_t> out,
                                     std::span<index_range> ranges, E&& exec = E{}) {
  return detail::contract_indices(h, stop, w, nullptr, {}, out, ranges, exec);
}

// The same without the triangles the camera of `view` cannot see (hidden_triangles.hpp):
// one_sided holds closed_part_triangles(h.indices, h.positions), with two_sided_face where back
// faces may be seen on a closed part (hidden_triangles.hpp). Errors: those of contract_indices; one_sided not one per triangle or h without its
// positions (bad_size). Cost: that of contract_indices plus a test per kept triangle.
template <class E = serial_executor>
result<std::size_t> contract_visible_indices(const contraction_hierarchy& h, std::span<const std::uint32_t> stop,
                                             contraction_workspace& w, const view_frustum& view,
                                             std::span<const std::uint8_t> one_sided, std::span<std::uint32_t> out,
                                             std::span<index_range> ranges, E&& exec = E{}) {
  if (one_sided.size() != h.triangle_count() || h.positions.size() != h.vertex_count)
    return make_error(errc::bad_size, one_sided.size(), "one_sided holds ", one_sided.size(), " flags for ",
                      h.triangle_count(), " triangles and the hierarchy ", h.positions.size(), " positions for ",
                      h.vertex_count, " vertices");
  return detail::contract_indices(h, stop, w, &view, one_sided, out, ranges, exec);
}

}  // namespace infolerp
