#pragma once
// Vertex contraction into an index buffer (salient-clustering paper §IV.B, Algorithm 1), on
// the CPU through the executor instead of a fragment shader.
//
// The paper iterates a shader maxContractionLevel times, each index following one contraction
// per pass. Here the chains are resolved once per frame: walking the contractions from the last
// to the first, remap[removed] = remap[target] if the contraction is applied, removed otherwise
// (a target is removed only by a later contraction, so its entry is final when read). Then each
// chunk of the cluster-ordered index buffer (chunks never straddle clusters) replaces every index
// by its remap and drops triangles with a repeated index, writing compacted into its own slot of
// the output in parallel; a serial pass moves the chunks together and records each cluster's
// range (§IV.C binds one range per cluster). Chunk boundaries depend only on the hierarchy and
// the grain, so the output has identical bits for any executor.
// A triangle whose removing contraction (contraction_hierarchy::killer) is applied is skipped
// without reading its indices: at dependency-closed stop points (neighbour matching's output,
// or one global prefix) every earlier contraction that renamed its corners is a dependency of
// that contraction and applied too, so the triangle is degenerate. This is a precondition:
// stop points that are not dependency-closed may lose triangles that would not be degenerate.
// One vertex map serves every cluster, so a vertex on a cluster border contracts the same way
// in all of them (the paper ensures this with the shared-cluster texture).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <type_traits>
#include <vector>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"

namespace infolerp {

struct index_range {
  std::uint32_t first = 0, count = 0;  // in indices of the output buffer
};

// Indices the contraction pass may write: the full-resolution count. O(1).
inline std::size_t contracted_index_bound(const contraction_hierarchy& h) { return h.indices.size(); }

// Setup kept between frames: the vertex map and the chunk table. Build once per hierarchy
// (O(V + T / grain) allocation); the per-frame calls then allocate nothing.
struct contraction_workspace {
  std::vector<std::uint32_t> remap;         // per vertex
  std::vector<std::uint32_t> chunk_begin;   // per chunk: first triangle (cluster order), chunks + 1
  std::vector<std::uint32_t> chunk_cluster; // per chunk
  std::vector<std::uint32_t> chunk_count;   // per chunk: indices written this frame
  std::size_t grain = 0;
};

inline contraction_workspace make_contraction_workspace(const contraction_hierarchy& h, std::size_t grain = 4096) {
  contraction_workspace w;
  w.grain = std::max<std::size_t>(grain, 1);
  w.remap.resize(h.vertex_count);
  for (std::uint32_t v = 0; v < h.vertex_count; ++v) w.remap[v] = v;
  for (std::uint32_t c = 0; c < h.cluster_count; ++c)
    for (std::size_t t = h.triangle_offsets[c]; t < h.triangle_offsets[c + 1]; t += w.grain) {
      w.chunk_begin.push_back(static_cast<std::uint32_t>(t));
      w.chunk_cluster.push_back(c);
    }
  w.chunk_begin.push_back(static_cast<std::uint32_t>(h.triangle_count()));
  w.chunk_count.assign(w.chunk_cluster.size(), 0);
  return w;
}

// The vertex map of a frame: contraction i is applied iff i < stop[owner(i)]. Preconditions:
// w from this hierarchy, stop one per cluster. O(contractions), serial, no allocation.
inline void resolve_vertex_map(const contraction_hierarchy& h, std::span<const std::uint32_t> stop,
                               contraction_workspace& w) {
  const std::uint32_t* removed = h.removed.data();
  const std::uint32_t* target = h.target.data();
  const std::uint32_t* owner = h.owner.data();
  std::uint32_t* remap = w.remap.data();
  for (std::size_t i = h.contraction_count(); i-- > 0;) {
    const std::uint32_t u = removed[i];
    remap[u] = i < stop[owner[i]] ? remap[target[i]] : u;
  }
}

// Algorithm 1: the frame's index buffer into out (at least contracted_index_bound(h) entries)
// and one range per cluster. Returns the indices written. Errors: out too small or ranges not
// one per cluster (bad_size), stop not one per cluster (bad_size). Preconditions: w from this
// hierarchy; stop dependency-closed (see the top of the file). O(T / threads + chunks), no allocation unless an error is returned; identical bits
// for any executor.
template <class E = serial_executor>
result<std::size_t> contract_indices(const contraction_hierarchy& h, std::span<const std::uint32_t> stop,
                                     contraction_workspace& w, std::span<std::uint32_t> out,
                                     std::span<index_range> ranges, E&& exec = E{}) {
  static_assert(check_executor<std::remove_cvref_t<E>>());
  if (out.size() < contracted_index_bound(h))
    return make_error(errc::bad_size, out.size(), "index buffer holds ", out.size(), " indices; ",
                      contracted_index_bound(h), " needed (contracted_index_bound)");
  if (stop.size() != h.cluster_count || ranges.size() != h.cluster_count)
    return make_error(errc::bad_size, ranges.size(), "stop and ranges hold ", stop.size(), " and ", ranges.size(),
                      " entries for ", h.cluster_count, " clusters");
  resolve_vertex_map(h, stop, w);
  const std::uint32_t* remap = w.remap.data();
  const std::uint32_t* src = h.indices.data();
  const std::uint32_t* killer = h.killer.data();
  const std::uint32_t* killer_owner = h.killer_owner.data();
  const std::uint32_t* stops = stop.data();
  std::uint32_t* dst = out.data();
  exec.parallel_for(w.chunk_cluster.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      std::uint32_t* o = dst + 3 * std::size_t{w.chunk_begin[k]};
      std::uint32_t* const o0 = o;
      for (std::size_t t = w.chunk_begin[k]; t < w.chunk_begin[k + 1]; ++t) {
        if (killer[t] < stops[killer_owner[t]]) continue;  // removed (see the top of the file)
        const std::uint32_t a = remap[src[3 * t]], bb = remap[src[3 * t + 1]], c = remap[src[3 * t + 2]];
        o[0] = a, o[1] = bb, o[2] = c;
        o += (a != bb && bb != c && a != c) ? 3 : 0;
      }
      w.chunk_count[k] = static_cast<std::uint32_t>(o - o0);
    }
  });
  std::size_t at = 0;
  for (std::uint32_t c = 0; c < h.cluster_count; ++c) ranges[c] = {0, 0};
  for (std::size_t k = 0; k < w.chunk_cluster.size(); ++k) {
    const std::size_t from = 3 * std::size_t{w.chunk_begin[k]};
    index_range& r = ranges[w.chunk_cluster[k]];
    if (r.count == 0) r.first = static_cast<std::uint32_t>(at);
    if (from != at && w.chunk_count[k]) std::memmove(dst + at, dst + from, sizeof(std::uint32_t) * w.chunk_count[k]);
    at += w.chunk_count[k];
    r.count += w.chunk_count[k];
  }
  for (std::uint32_t c = 0; c < h.cluster_count; ++c)
    if (ranges[c].count == 0) ranges[c].first = static_cast<std::uint32_t>(at);
  return at;
}

}  // namespace infolerp
