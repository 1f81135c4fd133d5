#pragma once
// Boundary smoothing (clustering paper §3.3, after Sander et al. [25]).
// For each pair of neighbouring clusters A, B (seeds s_A, s_B) of one set:
//   1. the boundary: the mesh edges shared by a triangle of A and one of B. Only an open
//      boundary (one simple polyline with two end vertices) is smoothed; closed loops and
//      boundaries in several pieces are left as they are.
//   2. the band: triangles reachable from the boundary through triangles that are more similar
//      to the other side's seed (JS(t, s_other) < JS(t, s_own)). Band edges: the boundary edges
//      plus every edge of a band triangle whose two incident triangles both lie in A ∪ B (so no
//      path can touch a third cluster; mesh-border edges are left out too).
//   3. A* (Euclidean edge lengths, straight-line heuristic) through the band edges between the
//      boundary's end vertices.
//   4. A ∪ B is split along the new path; the part holding s_A becomes A, the part holding s_B
//      becomes B. The change is kept only when the path splits A ∪ B into exactly these two
//      connected parts, so clusters stay connected and third clusters are never modified.
// Pairs are processed in increasing (A, B) order; deterministic.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <utility>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/cluster/channel.hpp"
#include "infolerp/cluster/region_growing.hpp"
#include "infolerp/core/detail/csr.hpp"
#include "infolerp/core/mesh_traits.hpp"

namespace infolerp {

namespace detail {
inline std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  return (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
}
// The mesh edge shared by two triangles (vertex ids), or false.
inline bool shared_edge(glm::uvec3 p, glm::uvec3 q, std::uint32_t& a, std::uint32_t& b) {
  std::uint32_t found[2];
  int n = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (p[i] == q[j] && n < 2 && (n == 0 || found[0] != p[i])) found[n++] = p[i];
  if (n != 2) return false;
  a = found[0];
  b = found[1];
  return true;
}
// Sorts keys ascending: an LSD radix sort over the bytes in which the keys differ (edge keys
// of a mesh under 2^16 vertices differ in 4 of 8), std::sort below 256 keys. Boundaries and
// bands run to thousands of edges, where std::sort was a visible share of the clustering.
// O(n·bytes), scratch resized to n (reused by the caller).
inline void sort_keys(std::vector<std::uint64_t>& keys, std::vector<std::uint64_t>& scratch) {
  const std::size_t n = keys.size();
  if (n < 256) {
    std::sort(keys.begin(), keys.end());
    return;
  }
  std::uint64_t any = 0, all = ~std::uint64_t{0};
  for (std::uint64_t k : keys) {
    any |= k;
    all &= k;
  }
  scratch.resize(n);
  for (unsigned shift = 0; shift < 64; shift += 8) {
    if (((any ^ all) >> shift & 0xff) == 0) continue;  // the same byte in every key
    std::uint32_t start[256] = {};
    for (std::uint64_t k : keys) ++start[k >> shift & 0xff];
    std::uint32_t sum = 0;
    for (std::uint32_t& c : start) sum += std::exchange(c, sum);
    for (std::uint64_t k : keys) scratch[start[k >> shift & 0xff]++] = k;
    keys.swap(scratch);
  }
}
}  // namespace detail

// Smooths the boundaries of clustering `r` of the set `triangles` (local ids = positions) of
// mesh m, whose channel state is s and dual graph g. Returns the number of triangles moved.
// Preconditions: r from grow_regions(s, g, ...), g symmetric (a dual graph is). Complexity per
// neighbouring pair: O(min(|A|, |B|)) to find the boundary, O(band · log band) for the band and
// the path, and O(|A| + |B|) only when a new path is tried (the split). Divergences only for
// the boundary and band triangles, each JS(class, seed) once per set when clusters × classes
// <= 2^20 (else once per pair), once per representative when the state has representative();
// with the state's estimate(), estimates there, and divergences only where the two estimates'
// error intervals overlap (the same comparisons as with exact values).
// Allocation O(M·degree) (the mesh edge of each dual-graph slot is found once per call), plus
// 12·clusters·classes bytes for the memo when it is kept per set (else 24·classes); the
// per-pair buffers are reused from pair to pair.
template <class S, class M>
std::uint32_t smooth_boundaries(const S& s, const element_graph& g, const M& m, std::span<const std::uint32_t> triangles,
                                double threshold, region_growing_result& r) {
  static_assert(channel_state<S>);
  const std::size_t n = g.size();
  const std::uint32_t k = r.cluster_count();
  if (k < 2 || r.all_alike || !(threshold > 0.0 && threshold < 1.0)) return 0;
  std::vector<glm::uvec3> tri(n);
  for (std::size_t i = 0; i < n; ++i) tri[i] = mesh_triangle(m, triangles[i]);
  std::vector<std::uint32_t>& label = r.cluster_of;
  // The mesh edge (key) crossed by each graph slot, found once; no_edge when none is shared.
  constexpr std::uint64_t no_edge = ~std::uint64_t{0};
  std::vector<std::uint64_t> slot_edge(g.neighbours.size());
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t slot = g.offsets[i]; slot < g.offsets[i + 1]; ++slot) {
      std::uint32_t a, b;
      slot_edge[slot] = detail::shared_edge(tri[i], tri[g.neighbours[slot]], a, b) ? detail::edge_key(a, b) : no_edge;
    }

  // Neighbouring cluster pairs, ascending.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j : g.neighbours_of(i))
      if (label[i] < label[j]) pairs.emplace_back(label[i], label[j]);
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());

  // Elements of each cluster (kept up to date as pairs are smoothed).
  std::vector<std::vector<std::uint32_t>> members_of(k);
  for (std::uint32_t i = 0; i < n; ++i) members_of[label[i]].push_back(i);

  std::uint32_t moved = 0;
  std::vector<std::uint32_t> region(n, invalid_id), stack, members;
  // Per-pair buffers, reused (cleared, not reallocated) from pair to pair.
  std::vector<std::uint64_t> boundary, edges, path, end_keys, key_scratch;
  std::vector<std::uint32_t> frontier, far_side, ends, endpoints, band, verts, end_vertex, adj_offsets, adj, from;
  std::vector<std::pair<std::uint32_t, int>> degree;  // (vertex, degree) sorted
  std::vector<std::uint8_t> in_band(n, 0);           // all 0 between pairs
  std::vector<glm::dvec3> pos;
  std::vector<double> dist;
  using item = std::pair<double, std::uint32_t>;
  std::vector<item> heap;
  // A 2^16-bit filter of the path's edge keys, so the split's flood fill rarely needs the
  // binary search in `path` (all 0 between pairs; allocated at the first split tried).
  std::vector<std::uint64_t> path_filter;
  auto filter_bit = [](std::uint64_t key) { return static_cast<std::uint32_t>((key * 0x9E3779B97F4A7C15ull) >> 48); };
  // JS(class, seed of a cluster), memoised per (cluster, class) over all pairs when
  // clusters × classes <= 2^20 (binned direct channels), else per (side of the pair, class)
  // for the current pair only (an entry is valid when its stamp is `valid`).
  // With the state's estimate() (error err), an entry first holds the estimate (exact[e] == 0)
  // and is made exact only when the two estimates cannot decide the comparison.
  const std::size_t u = s.class_count();
  const bool dense = std::size_t{k} * u <= (std::size_t{1} << 20);
  std::vector<double> js((dense ? k : 2) * u);
  std::vector<std::uint32_t> stamp(js.size(), 0);
  const double err = detail::estimate_error_of(s);
  const bool estimated = err < std::numeric_limits<double>::infinity();
  std::vector<std::uint8_t> exact(estimated ? js.size() : 0);
  std::uint32_t pair_index = 0;
  for (const auto& pair : pairs) {
    // Plain variables, not a structured binding: the lambda below captures them, which
    // clang before 16 rejects for structured bindings.
    const std::uint32_t ca = pair.first, cb = pair.second;
    ++pair_index;
    // 1. Boundary edges (the mesh edges of A's graph slots into B) and the triangles on them,
    // found from the smaller cluster's side: the graph is symmetric, and a slot has a shared
    // edge exactly when its reverse slot has one.
    const bool from_a = members_of[ca].size() <= members_of[cb].size();
    const std::uint32_t near = from_a ? ca : cb, far = from_a ? cb : ca;
    boundary.clear();
    frontier.clear();
    far_side.clear();
    for (std::uint32_t i : members_of[near]) {
      bool on = false;
      for (std::uint32_t slot = g.offsets[i]; slot < g.offsets[i + 1]; ++slot) {
        const std::uint32_t j = g.neighbours[slot];
        if (label[j] != far || slot_edge[slot] == no_edge) continue;
        on = true;
        far_side.push_back(j);
        if (from_a) {
          boundary.push_back(slot_edge[slot]);
        } else {  // A's slot back to i, with A's edge key (a triangle may share 3 vertices with i)
          for (std::uint32_t back = g.offsets[j]; back < g.offsets[j + 1]; ++back)
            if (g.neighbours[back] == i) boundary.push_back(slot_edge[back]);
        }
      }
      if (on) frontier.push_back(i);
    }
    std::sort(far_side.begin(), far_side.end());
    far_side.erase(std::unique(far_side.begin(), far_side.end()), far_side.end());
    frontier.insert(frontier.end(), far_side.begin(), far_side.end());
    detail::sort_keys(boundary, key_scratch);
    boundary.erase(std::unique(boundary.begin(), boundary.end()), boundary.end());
    degree.clear();
    {
      ends.clear();
      for (auto e : boundary) {
        ends.push_back(static_cast<std::uint32_t>(e >> 32));
        ends.push_back(static_cast<std::uint32_t>(e & 0xffffffffu));
      }
      std::sort(ends.begin(), ends.end());
      for (std::size_t i = 0; i < ends.size();) {
        std::size_t j = i;
        while (j < ends.size() && ends[j] == ends[i]) ++j;
        degree.emplace_back(ends[i], static_cast<int>(j - i));
        i = j;
      }
    }
    endpoints.clear();
    bool simple = degree.size() == boundary.size() + 1;
    for (const auto& [v, d] : degree) {
      if (d == 1) endpoints.push_back(v);
      else if (d != 2) simple = false;
    }
    if (!simple || endpoints.size() != 2) continue;

    // 2. The band.
    const std::uint32_t cluster_a = ca, cluster_b = cb;  // clang++ 14 cannot capture a structured binding
    const std::uint32_t valid = dense ? 1u : pair_index;
    // The memo slot of JS(class c, seed of cluster), filled (estimate or exact) on first use.
    auto memo_slot = [&](std::uint32_t c, std::uint32_t cluster, std::uint32_t side) {
      const std::size_t e = (dense ? cluster : side) * u + c;
      if (stamp[e] != valid) {
        stamp[e] = valid;
        if constexpr (detail::has_estimate<S>)
          if (estimated) {
            js[e] = s.estimate(c, s.class_of(r.seeds[cluster]));
            exact[e] = 0;
            return e;
          }
        js[e] = s.divergence(c, s.class_of(r.seeds[cluster]));
      }
      return e;
    };
    auto make_exact = [&](std::size_t e, std::uint32_t c, std::uint32_t cluster) {
      if (estimated && !exact[e]) {
        js[e] = s.divergence(c, s.class_of(r.seeds[cluster]));
        exact[e] = 1;
      }
    };
    auto prefers_other = [&](std::uint32_t i) {
      std::uint32_t c = s.class_of(i);
      if constexpr (detail::has_representative<S>) c = s.representative(c);  // bit-identical JS
      const std::size_t ea = memo_slot(c, cluster_a, 0), eb = memo_slot(c, cluster_b, 1);
      if (estimated) {  // decided when the error intervals do not overlap
        const double sa = exact[ea] ? 0.0 : err, sb = exact[eb] ? 0.0 : err;
        if (js[eb] + sb < js[ea] - sa) return label[i] == cluster_a;
        if (js[ea] + sa < js[eb] - sb) return label[i] != cluster_a;
        make_exact(ea, c, cluster_a);
        make_exact(eb, c, cluster_b);
      }
      const double js_a = js[ea], js_b = js[eb];
      return label[i] == cluster_a ? js_b < js_a : js_a < js_b;
    };
    band.clear();
    // With the state's prefetch(), the rows of the triangles tested next are asked for ahead
    // (they are far apart in memory; a hint without effect on results).
    auto prefetch = [&](std::uint32_t i) {
      if constexpr (detail::has_prefetch<S>) s.prefetch(s.class_of(i));
    };
    for (std::size_t f = 0; f < frontier.size(); ++f) {
      if (f + 4 < frontier.size()) prefetch(frontier[f + 4]);
      if (prefers_other(frontier[f])) {
        in_band[frontier[f]] = 1;
        band.push_back(frontier[f]);
      }
    }
    for (std::size_t q = 0; q < band.size(); ++q) {
      if (q + 1 < band.size())
        for (std::uint32_t j : g.neighbours_of(band[q + 1])) prefetch(j);
      for (std::uint32_t j : g.neighbours_of(band[q]))
        if (!in_band[j] && label[j] == label[band[q]] && prefers_other(j)) {
          in_band[j] = 1;
          band.push_back(j);
        }
    }
    for (std::uint32_t i : band) in_band[i] = 0;
    edges.assign(boundary.begin(), boundary.end());
    for (std::uint32_t i : band)
      for (int c = 0; c < 3; ++c) {
        const std::uint64_t key = detail::edge_key(tri[i][c], tri[i][(c + 1) % 3]);
        int across = 0;
        bool inside = true;
        for (std::uint32_t slot = g.offsets[i]; slot < g.offsets[i + 1]; ++slot)
          if (slot_edge[slot] == key) {
            ++across;
            inside = inside && (label[g.neighbours[slot]] == ca || label[g.neighbours[slot]] == cb);
          }
        if (across == 1 && inside) edges.push_back(key);
      }
    detail::sort_keys(edges, key_scratch);
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    if (edges.size() == boundary.size()) continue;  // nothing to choose from

    // 3. A* between the end vertices over the band edges.
    // Local vertex ids, ascending with the mesh ids: the edge ends (vertex in the high half,
    // end slot 2e or 2e + 1 in the low half) sorted and numbered in one pass.
    end_keys.clear();
    for (std::size_t e = 0; e < edges.size(); ++e) {
      end_keys.push_back((edges[e] & ~std::uint64_t{0xffffffffu}) | (2 * e));
      end_keys.push_back((edges[e] << 32) | (2 * e + 1));
    }
    detail::sort_keys(end_keys, key_scratch);
    verts.clear();
    end_vertex.resize(end_keys.size());
    for (std::uint64_t key : end_keys) {
      const auto v = static_cast<std::uint32_t>(key >> 32);
      if (verts.empty() || verts.back() != v) verts.push_back(v);
      end_vertex[key & 0xffffffffu] = static_cast<std::uint32_t>(verts.size() - 1);
    }
    auto vid = [&](std::uint32_t v) {
      return static_cast<std::uint32_t>(std::lower_bound(verts.begin(), verts.end(), v) - verts.begin());
    };
    // Adjacency (CSR, each vertex's neighbours in `edges` order).
    // End 2e + j of edge e lists the other end, 2e + 1 - j, under its own vertex.
    detail::group_by_key(
        verts.size(), end_vertex.size(), [&](std::size_t i) { return end_vertex[i]; },
        [&](std::size_t i) { return end_vertex[i ^ 1]; }, adj_offsets, adj);
    pos.resize(verts.size());
    for (std::size_t i = 0; i < verts.size(); ++i) pos[i] = glm::dvec3(mesh_position(m, verts[i]));
    const std::uint32_t start = vid(endpoints[0]), goal = vid(endpoints[1]);
    dist.assign(verts.size(), std::numeric_limits<double>::infinity());
    from.assign(verts.size(), invalid_id);
    // Open list: a min-heap on (f, vertex) in `heap`.
    auto push = [&](double f, std::uint32_t v) {
      heap.emplace_back(f, v);
      std::push_heap(heap.begin(), heap.end(), std::greater<item>{});
    };
    heap.clear();
    dist[start] = 0.0;
    push(glm::distance(pos[start], pos[goal]), start);
    while (!heap.empty()) {
      std::pop_heap(heap.begin(), heap.end(), std::greater<item>{});
      const auto [f, v] = heap.back();
      heap.pop_back();
      if (v == goal) break;
      if (f > dist[v] + glm::distance(pos[v], pos[goal])) continue;  // stale entry
      for (std::uint32_t slot = adj_offsets[v]; slot < adj_offsets[v + 1]; ++slot) {
        const std::uint32_t w = adj[slot];
        const double d = dist[v] + glm::distance(pos[v], pos[w]);
        if (d < dist[w]) {
          dist[w] = d;
          from[w] = v;
          push(d + glm::distance(pos[w], pos[goal]), w);
        }
      }
    }
    if (from[goal] == invalid_id) continue;
    path.clear();
    for (std::uint32_t v = goal; v != start; v = from[v]) path.push_back(detail::edge_key(verts[v], verts[from[v]]));
    detail::sort_keys(path, key_scratch);
    if (path == boundary) continue;
    if (path_filter.empty()) path_filter.assign(1024, 0);
    for (auto e : path) path_filter[filter_bit(e) >> 6] |= std::uint64_t{1} << (filter_bit(e) & 63);
    auto on_path = [&](std::uint64_t e) {
      return (path_filter[filter_bit(e) >> 6] >> (filter_bit(e) & 63) & 1) && std::binary_search(path.begin(), path.end(), e);
    };

    // 4. Split A ∪ B along the path.
    members.resize(members_of[ca].size() + members_of[cb].size());
    std::merge(members_of[ca].begin(), members_of[ca].end(), members_of[cb].begin(), members_of[cb].end(),
               members.begin());
    // Flood fill of A ∪ B (members marked `unvisited`) without crossing the path, stopped as
    // soon as the split cannot be kept: a first region holding both seeds, or a third region.
    constexpr std::uint32_t unvisited = invalid_id - 1;
    for (std::uint32_t i : members) region[i] = unvisited;
    std::uint32_t regions = 0;
    bool two_parts = true;
    for (std::uint32_t i : members) {
      if (region[i] != unvisited) continue;
      if (regions == 2) {
        two_parts = false;
        break;
      }
      region[i] = regions;
      stack.push_back(i);
      while (!stack.empty()) {
        const std::uint32_t t = stack.back();
        stack.pop_back();
        for (std::uint32_t slot = g.offsets[t]; slot < g.offsets[t + 1]; ++slot) {
          const std::uint32_t j = g.neighbours[slot];
          if (region[j] != unvisited) continue;
          if (slot_edge[slot] != no_edge && on_path(slot_edge[slot])) continue;
          region[j] = regions;
          stack.push_back(j);
        }
      }
      if (region[r.seeds[ca]] == regions && region[r.seeds[cb]] == regions) {
        two_parts = false;
        break;
      }
      ++regions;
    }
    const std::uint32_t ra = region[r.seeds[ca]];
    if (two_parts && regions == 2) {
      for (std::uint32_t i : members) {
        const std::uint32_t want = region[i] == ra ? ca : cb;
        if (label[i] != want) {
          label[i] = want;
          ++moved;
        }
      }
      members_of[ca].clear();
      members_of[cb].clear();
      for (std::uint32_t i : members) members_of[label[i]].push_back(i);
    }
    for (std::uint32_t i : members) region[i] = invalid_id;
    for (auto e : path) path_filter[filter_bit(e) >> 6] = 0;
  }
  return moved;
}

}  // namespace infolerp
