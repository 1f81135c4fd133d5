#pragma once
// Salient clustering and cluster-localised saliency (salient-clustering paper §III.B, eqs. 2–3,
// and §III.C, eq. 4), a saliency-driven variant of Sander et al.'s chartification.
//
//   1. Seeds: the λ_c·C most salient vertices form a pool; C distinct seeds are drawn from it
//      with a user seed (splitmix64, so every platform draws the same seeds).
//   2. Growth: one Dijkstra-like search per cluster, all run together through one priority
//      queue over the dual graph (triangles adjacent across an edge). The faces around a seed
//      vertex enter at cost 0 (the most salient first); moving from face f of cluster c to an
//      unassigned neighbour f' costs (eq. 2)
//        (λ_n − μ(n_c)·n_f') · |μ(S_c) − S_f'| · |S_c0 − S_f'| · |S_f − S_f'| · |x_f' − x_f|
//      with μ(n_c) the cluster's area-weighted mean normal, μ(S_c) its mean face saliency and
//      S_c0 its seed saliency, all as the cluster stands when f' is pushed.
//      Eq. 2 is 0 between faces of equal saliency, so on a flat region the first cluster to
//      arrive takes it all. flat_tie_break (default, not in the paper) prices such a step at the
//      mean cost per unit length of the growth's non-zero steps so far, times its length: flat
//      regions are shared by distance; non-zero costs stay the paper's.
//   3. Re-seeding: per cluster, a Dijkstra search from its border faces (faces next to another
//      cluster or on a mesh boundary) inwards with cost |x_f' − x_f| · S_f' / max(S_c) (eq. 3);
//      the new seed is the most salient vertex of the last face reached (a cluster without
//      border keeps its seed).
//   Seeds are distinct and each keeps a face no lower-numbered cluster's seed touches (else the
//   next candidate is taken: the next pool vertex, or the next vertex of the faces reached
//   last); growth never takes a seed's faces, so no seeded cluster ends empty.
//   4. Repeat 2–3 until the seeds repeat a previous iteration's (converged, or a cycle: the
//      paper accepts any point on a cycle; we stop at the repeat) or max_iterations.
//      How many rounds that takes is chance (the seeds), not mesh size. max_iterations trades
//      time for settling: each round costs O(T log T), and a capped call ends on the last
//      round's clusters (converged = false), whose quality varies from round to round as much
//      as the round count does (benchmarks/NOTES.md, salient clustering at 300k and 1.2M).
// Face saliency S_f is the mean of its corners' vertex saliencies; x_f the centroid; n_f the
// unit normal. Ties in every queue break by (cost, cluster, face), so the result is a function
// of the mesh, the saliency and the seed only. Faces that no seed can reach (another connected
// component of the dual graph) start extra clusters, numbered after the C seeded ones, so every
// face ends in exactly one connected cluster.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/detail/csr.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/random.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/locality_order.hpp"
#include "infolerp/mesh/topology.hpp"

namespace infolerp {

struct salient_clustering_options {
  std::uint32_t clusters = 10;    // C, the number of seeded clusters
  double pool_multiplier = 5.0;   // λ_c: the seed pool holds the λ_c·C most salient vertices
  double normal_weight = 1.0;     // λ_n in eq. (2) (>= 1 keeps every cost non-negative)
  std::uint64_t seed = 1;         // user seed for drawing seeds from the pool
  std::uint32_t max_iterations = 50;  // growth + re-seeding rounds at most
  bool flat_tie_break = true;     // where eq. (2) costs 0, cost distance (see the top of this file)
};

struct salient_clusters {
  std::vector<std::uint32_t> cluster;     // per triangle: its cluster, 0..count-1
  std::vector<std::uint32_t> seeds;       // seed vertex of each seeded cluster (the last growth's)
  std::uint32_t count = 0;                // seeded clusters + extra ones for unreached components
  std::uint32_t iterations = 0;           // growth phases run
  bool converged = false;                 // seeds repeated (a fixed point or a cycle)
  bool cycle = false;                     // the repeat was of an older iteration, not the last
};

namespace detail {
// The dual graph with per-face data, faces renumbered along a Morton curve of their centroids so
// that neighbours are close in memory (the growth and re-seeding loops are memory-bound; mesh
// files often list faces in no spatial order). Every tie-break uses the original face index,
// so the renumbering does not change any result.
struct face_data {
  struct hot_part {     // what a neighbour visit reads, in one place
    glm::dvec3 normal;  // unit (0 for zero-area faces)
    double saliency;    // mean of the corners' vertex saliency
  };
  std::vector<hot_part> hot;
  std::vector<double> area;
  std::vector<std::uint32_t> original;     // internal face -> the mesh's face index
  std::vector<std::uint32_t> nb_offsets;   // CSR dual graph in internal indices
  std::vector<std::uint32_t> nb;
  std::vector<double> step_length;         // per dual edge: |x_g − x_f| (centroids)
  std::vector<char> on_boundary;           // per face: has a mesh-boundary edge
  std::vector<std::uint32_t> vf_offsets;   // CSR: internal faces around each vertex
  std::vector<std::uint32_t> vf;
};

template <class M>
face_data make_face_data(const M& m, const mesh_topology& topo, std::span<const double> saliency) {
  const std::size_t nt = mesh_triangle_count(m), nv = mesh_vertex_count(m);
  std::vector<glm::dvec3> centroid(nt);
  for (std::size_t t = 0; t < nt; ++t) centroid[t] = triangle_centroid(corners(m, t));
  face_data fd;
  fd.original = morton_order(centroid);
  std::vector<std::uint32_t> internal(nt);
  for (std::size_t i = 0; i < nt; ++i) internal[fd.original[i]] = static_cast<std::uint32_t>(i);
  fd.hot.resize(nt), fd.area.resize(nt), fd.on_boundary.assign(nt, 0);
  fd.nb_offsets.assign(nt + 1, 0);
  fd.nb.reserve(topo.neighbours.size()), fd.step_length.reserve(topo.neighbours.size());
  for (std::size_t i = 0; i < nt; ++i) {
    const std::uint32_t t = fd.original[i];
    const triangle_corners c = corners(m, t);
    fd.hot[i].normal = glm::dvec3(triangle_normal(c));
    fd.area[i] = triangle_area(c);
    const glm::uvec3 tri = mesh_triangle(m, t);
    fd.hot[i].saliency = (saliency[tri.x] + saliency[tri.y] + saliency[tri.z]) / 3.0;
    for (std::uint32_t g : topo.neighbours_of(t))
      fd.nb.push_back(internal[g]), fd.step_length.push_back(glm::length(centroid[g] - centroid[t]));
    fd.nb_offsets[i + 1] = static_cast<std::uint32_t>(fd.nb.size());
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t e = topo.triangle_edges[3 * t + k];
      if (e != invalid_id && topo.is_boundary_edge(e)) fd.on_boundary[i] = 1;
    }
  }
  // Corner 3t + c of triangle t lists internal[t] under its vertex.
  detail::group_by_key(
      nv, 3 * nt, [&](std::size_t k) { return std::uint32_t{mesh_triangle(m, k / 3)[static_cast<int>(k % 3)]}; },
      [&](std::size_t k) { return internal[k / 3]; }, fd.vf_offsets, fd.vf);
  return fd;
}

// Buffers reused by every growth and re-seeding round (no allocation per round).
struct clustering_workspace {
  struct grow_entry {
    double cost, neg_s;
    std::uint32_t cluster, face;  // internal face
  };
  struct dist_entry {
    double dist;
    std::uint32_t face;  // internal face
  };
  struct grow_state {  // growth, per face: what a neighbour visit reads and writes, in one place
    double cost;            // of the face's best push so far; −∞ for a face around a seed vertex
    std::uint32_t cluster;  // of that push
    std::uint32_t label;    // the cluster that took the face, or invalid_id
  };
  std::vector<grow_entry> grow_heap;
  std::vector<grow_state> grow;                     // growth: per face
  std::vector<std::vector<dist_entry>> dist_heaps;  // re-seeding: one per cluster
  std::vector<double> dist;                         // re-seeding: per face
  std::vector<std::uint32_t> border_key, border_offsets, border;  // re-seeding: border faces by cluster
  std::vector<char> is_seed;                        // per vertex: chosen as a seed (seed selection)
};

// Whether v can seed the next cluster, given the seeds already chosen (marked in is_seed): v is
// not one of them and some face around v touches none of them. O(valence).
template <class M>
bool can_seed(const M& m, const face_data& fd, std::uint32_t v, const std::vector<char>& is_seed) {
  if (is_seed[v] || fd.vf_offsets[v] == fd.vf_offsets[v + 1]) return false;
  for (std::uint32_t k = fd.vf_offsets[v]; k < fd.vf_offsets[v + 1]; ++k) {
    const glm::uvec3 c = mesh_triangle(m, fd.original[fd.vf[k]]);
    if (!is_seed[c.x] && !is_seed[c.y] && !is_seed[c.z]) return true;
  }
  return false;
}

// The first vertex (by index) that can seed the next cluster, or invalid_id. O(V + T).
template <class M>
std::uint32_t first_free_seed(const M& m, const face_data& fd, const std::vector<char>& is_seed) {
  for (std::size_t v = 0; v + 1 < fd.vf_offsets.size(); ++v)
    if (can_seed(m, fd, static_cast<std::uint32_t>(v), is_seed)) return static_cast<std::uint32_t>(v);
  return invalid_id;
}

// The most salient corner of internal face f that can seed the next cluster (ties: lower
// index), or invalid_id.
template <class M>
std::uint32_t best_free_corner(const M& m, const face_data& fd, std::uint32_t f, std::span<const double> vsal,
                               const std::vector<char>& is_seed) {
  const glm::uvec3 tri = mesh_triangle(m, fd.original[f]);
  std::uint32_t best = invalid_id;
  for (int k = 0; k < 3; ++k) {
    const std::uint32_t v = tri[k];
    if (!can_seed(m, fd, v, is_seed)) continue;
    if (best == invalid_id || vsal[v] > vsal[best] || (vsal[v] == vsal[best] && v < best)) best = v;
  }
  return best;
}

// One growth phase from the given seed vertices; label gets each internal face's cluster.
// Queue order: (cost, −S_f', cluster, original face index).
inline void grow_clusters(const face_data& fd, std::span<const double> vsal, std::span<const std::uint32_t> seeds,
                          double lambda_n, bool flat_tie_break, clustering_workspace& ws,
                          std::vector<std::uint32_t>& label) {
  using entry = clustering_workspace::grow_entry;
  const std::size_t nt = fd.area.size(), C = seeds.size();
  std::vector<glm::dvec3> nsum(C, glm::dvec3(0.0));
  std::vector<double> ssum(C, 0.0), s0(C);
  std::vector<std::uint32_t> nfaces(C, 0);
  double positive_cost = 0.0, positive_length = 0.0;  // the non-zero eq. 2 steps pushed so far
  auto& heap = ws.grow_heap;
  heap.clear();
  const auto greater = [&](const entry& x, const entry& y) {
    if (x.cost != y.cost) return x.cost > y.cost;
    if (x.neg_s != y.neg_s) return x.neg_s > y.neg_s;
    if (x.cluster != y.cluster) return x.cluster > y.cluster;
    return fd.original[x.face] > fd.original[y.face];
  };
  // A face is pushed only when (cost, cluster) beats its earlier pushes: a worse entry for the
  // same face would be popped after the better one, when the face is already labelled.
  auto& state = ws.grow;
  state.assign(nt, {std::numeric_limits<double>::infinity(), invalid_id, invalid_id});
  auto push = [&](double cost, std::uint32_t c, std::uint32_t g) {
    if (cost > state[g].cost || (cost == state[g].cost && c >= state[g].cluster)) return;
    state[g].cost = cost, state[g].cluster = c;
    heap.push_back({cost, -fd.hot[g].saliency, c, g});
    std::push_heap(heap.begin(), heap.end(), greater);
  };
  for (std::uint32_t c = 0; c < C; ++c) {
    const std::uint32_t v = seeds[c];
    s0[c] = vsal[v];
    for (std::uint32_t k = fd.vf_offsets[v]; k < fd.vf_offsets[v + 1]; ++k) {
      nsum[c] += fd.hot[fd.vf[k]].normal * fd.area[fd.vf[k]];  // seed normal: the vertex's area-weighted normal
      push(0.0, c, fd.vf[k]);
    }
  }
  for (std::uint32_t c = 0; c < C; ++c)  // from now on no growth takes a seed's face
    for (std::uint32_t k = fd.vf_offsets[seeds[c]]; k < fd.vf_offsets[seeds[c] + 1]; ++k)
      state[fd.vf[k]].cost = -std::numeric_limits<double>::infinity();
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), greater);
    const entry top = heap.back();
    heap.pop_back();
    const std::uint32_t c = top.cluster, f = top.face;
    if (state[f].label != invalid_id) continue;
    state[f].label = c;
    if (nfaces[c] == 0) nsum[c] = glm::dvec3(0.0);  // from now on: the cluster's faces
    nsum[c] += fd.hot[f].normal * fd.area[f];
    ssum[c] += fd.hot[f].saliency;
    ++nfaces[c];
    const double len = glm::length(nsum[c]);
    const glm::dvec3 mean_n = len > 0.0 ? nsum[c] / len : glm::dvec3(0.0);
    const double mean_s = ssum[c] / nfaces[c];
    for (std::uint32_t k = fd.nb_offsets[f]; k < fd.nb_offsets[f + 1]; ++k) {
      const std::uint32_t g = fd.nb[k];
      if (state[g].label != invalid_id) continue;
      const double sg = fd.hot[g].saliency;
      double step = std::max(0.0, (lambda_n - glm::dot(mean_n, fd.hot[g].normal)) *
                                      (std::abs(mean_s - sg) * std::abs(s0[c] - sg) * std::abs(fd.hot[f].saliency - sg)) *
                                      fd.step_length[k]);
      if (step > 0.0)
        positive_cost += step, positive_length += fd.step_length[k];
      else if (flat_tie_break && positive_length > 0.0)
        step = positive_cost / positive_length * fd.step_length[k];
      push(top.cost + step, c, g);
    }
  }
  label.resize(nt);
  for (std::size_t f = 0; f < nt; ++f) label[f] = state[f].label;
}

// After a re-seeding search (distances in ws.dist): the best free corner of cluster c's faces in
// the reverse of the search's order (farthest first), or invalid_id. O(T log T); used only
// when the last face's corners are all taken.
template <class M>
std::uint32_t latest_free_seed(const M& m, const face_data& fd, std::span<const std::uint32_t> label, std::uint32_t c,
                               std::span<const double> vsal, const clustering_workspace& ws) {
  std::vector<std::uint32_t> faces;
  for (std::size_t f = 0; f < label.size(); ++f)
    if (label[f] == c) faces.push_back(static_cast<std::uint32_t>(f));
  std::sort(faces.begin(), faces.end(), [&](std::uint32_t a, std::uint32_t b) {
    return ws.dist[a] != ws.dist[b] ? ws.dist[a] > ws.dist[b] : fd.original[a] > fd.original[b];
  });
  for (std::uint32_t f : faces)
    if (const std::uint32_t v = best_free_corner(m, fd, f, vsal, ws.is_seed); v != invalid_id) return v;
  return invalid_id;
}

// Re-seeding's search for cluster c (eq. 3 costs): Dijkstra from its border faces
// (ws.border_offsets/border) inward over its own faces; distances go to ws.dist (only c's
// faces are written, so clusters may run concurrently, each with its own heap). Returns the
// face popped last (the farthest; ties: original face index), or invalid_id without border.
inline std::uint32_t farthest_from_border(const face_data& fd, std::span<const std::uint32_t> label, std::uint32_t c,
                                          double smax, clustering_workspace& ws,
                                          std::vector<clustering_workspace::dist_entry>& heap) {
  using entry = clustering_workspace::dist_entry;
  const auto greater = [&](const entry& x, const entry& y) {
    return x.dist != y.dist ? x.dist > y.dist : fd.original[x.face] > fd.original[y.face];
  };
  heap.clear();
  for (std::uint32_t k = ws.border_offsets[c]; k < ws.border_offsets[c + 1]; ++k)
    ws.dist[ws.border[k]] = 0.0, heap.push_back({0.0, ws.border[k]});
  std::make_heap(heap.begin(), heap.end(), greater);
  const double scale = smax > 0.0 ? 1.0 / smax : 0.0;
  std::uint32_t last = invalid_id;
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), greater);
    const auto [d, f] = heap.back();
    heap.pop_back();
    if (d > ws.dist[f]) continue;
    last = f;  // popped in ascending distance: the final pop is the farthest
    for (std::uint32_t k = fd.nb_offsets[f]; k < fd.nb_offsets[f + 1]; ++k) {
      const std::uint32_t g = fd.nb[k];
      if (label[g] != c) continue;
      const double step = fd.step_length[k] * (smax > 0.0 ? fd.hot[g].saliency * scale : 1.0);
      if (d + step < ws.dist[g]) {
        ws.dist[g] = d + step;
        heap.push_back({d + step, g});
        std::push_heap(heap.begin(), heap.end(), greater);
      }
    }
  }
  return last;
}

// Re-seeding (eq. 3): per cluster, the most salient vertex of the face reached last by a
// Dijkstra search from the cluster's border faces inward (ties: original face index), among
// the vertices that can seed it (can_seed; otherwise the faces reached before, latest first).
// The clusters' searches run through exec, largest cluster first; the result does not depend
// on the executor.
template <class M, class E = serial_executor>
std::vector<std::uint32_t> reseed(const M& m, const face_data& fd, std::span<const std::uint32_t> label,
                                  std::span<const double> vsal, std::span<const std::uint32_t> old_seeds,
                                  clustering_workspace& ws, E&& exec = E{}) {
  const std::size_t nt = label.size(), C = old_seeds.size();
  std::vector<double> smax(C, 0.0);
  std::vector<std::uint32_t> size(C, 0);
  for (std::size_t f = 0; f < nt; ++f)
    if (label[f] < C) smax[label[f]] = std::max(smax[label[f]], fd.hot[f].saliency), ++size[label[f]];
  ws.dist.assign(nt, std::numeric_limits<double>::infinity());
  // Border faces grouped by cluster: each cluster's search stays inside the cluster.
  auto& border_key = ws.border_key;
  border_key.assign(nt, no_bucket);
  for (std::size_t f = 0; f < nt; ++f) {
    if (label[f] >= C) continue;
    bool is_border = fd.on_boundary[f] != 0;
    for (std::uint32_t k = fd.nb_offsets[f]; k < fd.nb_offsets[f + 1]; ++k) is_border = is_border || label[fd.nb[k]] != label[f];
    if (is_border) border_key[f] = label[f];
  }
  group_by_key(
      C, nt, [&](std::size_t f) { return border_key[f]; }, [](std::size_t f) { return static_cast<std::uint32_t>(f); },
      ws.border_offsets, ws.border);
  std::vector<std::uint32_t> order(C), last(C, invalid_id);
  for (std::uint32_t c = 0; c < C; ++c) order[c] = c;
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return size[a] > size[b]; });
  ws.dist_heaps.resize(C);
  exec.parallel_for(C, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t c = order[i];
      last[c] = farthest_from_border(fd, label, c, smax[c], ws, ws.dist_heaps[c]);
    }
  });
  std::vector<std::uint32_t> seeds(old_seeds.begin(), old_seeds.end());
  ws.is_seed.assign(fd.vf_offsets.size() - 1, 0);
  for (std::size_t c = 0; c < C; ++c) {
    std::uint32_t v = invalid_id;
    if (last[c] == invalid_id)  // no border: keep the seed
      v = can_seed(m, fd, old_seeds[c], ws.is_seed) ? old_seeds[c] : invalid_id;
    else
      v = best_free_corner(m, fd, last[c], vsal, ws.is_seed);
    if (v == invalid_id) v = latest_free_seed(m, fd, label, static_cast<std::uint32_t>(c), vsal, ws);
    if (v == invalid_id) v = first_free_seed(m, fd, ws.is_seed);
    if (v == invalid_id) v = old_seeds[c];  // unreachable: a cluster's own seed always qualified
    seeds[c] = v;
    ws.is_seed[v] = 1;
  }
  return seeds;
}
}  // namespace detail

// Salient clustering of a mesh from per-vertex saliency (saliency/mesh_saliency.hpp).
// Errors: mesh errors as mean_curvature; saliency.size() != vertex count (bad_size); a
// non-finite (non_finite) or negative (bad_parameter) saliency (names the vertex); clusters == 0
// or more clusters than the pool or the triangle count can seed, or more than the mesh has room for (each seed needs a
// face no other seed touches); pool_multiplier < 1; normal_weight < 1 (bad_parameter).
// Complexity O(T log T) setup (faces are renumbered along a Morton curve for memory locality)
// plus O(iterations · T log T); allocation O(T), made once (queues hold up to ~3T entries and are
// reused by every round). The growth is serial; re-seeding's per-cluster searches run through
// exec (at most C at once), with the same result for every executor and thread count.
// Pure: concurrent calls on the same mesh are safe.
template <class M, class E = serial_executor>
result<salient_clusters> salient_clustering(const M& m, std::span<const double> saliency,
                                            const salient_clustering_options& opt = {}, E&& exec = E{}) {
  static_assert(check_mesh<M>());
  static_assert(check_executor<std::remove_cvref_t<E>>());
  if (status s = detail::check_indices_and_positions(m); !s.ok()) return s;
  const std::size_t nv = mesh_vertex_count(m), nt = mesh_triangle_count(m);
  if (saliency.size() != nv)
    return make_error(errc::bad_size, saliency.size(), "saliency has ", saliency.size(), " values for ", nv, " vertices");
  for (std::size_t v = 0; v < nv; ++v)
    if (!(saliency[v] >= 0.0) || !std::isfinite(saliency[v]))
      return make_error(non_negative_errc(saliency[v]), v, "vertex ", v, ": saliency ", saliency[v], " is not finite and >= 0");
  if (!(opt.pool_multiplier >= 1.0) || !std::isfinite(opt.pool_multiplier))
    return make_error(errc::bad_parameter, no_element, "pool_multiplier ", opt.pool_multiplier, " must be >= 1");
  if (!(opt.normal_weight >= 1.0) || !std::isfinite(opt.normal_weight))
    return make_error(errc::bad_parameter, no_element, "normal_weight ", opt.normal_weight, " must be >= 1");
  if (opt.clusters == 0 || opt.clusters > nt)
    return make_error(errc::bad_parameter, no_element, "clusters ", opt.clusters, " must be in [1, ", nt, "]");
  auto topo = make_topology(m);
  if (!topo.ok()) return topo.error();

  // Vertices used by triangles, most salient first (ties: lower index).
  const detail::face_data fd = detail::make_face_data(m, *topo, saliency);
  std::vector<std::uint32_t> order;
  for (std::size_t v = 0; v < nv; ++v)
    if (fd.vf_offsets[v + 1] > fd.vf_offsets[v]) order.push_back(static_cast<std::uint32_t>(v));
  const auto pool_size = static_cast<std::size_t>(
      std::min<double>(static_cast<double>(order.size()), std::ceil(opt.pool_multiplier * opt.clusters)));
  if (pool_size < opt.clusters)
    return make_error(errc::bad_parameter, no_element, "clusters ", opt.clusters, " exceed the ", order.size(),
                      " vertices that triangles use");
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(pool_size), order.end(),
                    [&](std::uint32_t a, std::uint32_t b) {
                      return saliency[a] != saliency[b] ? saliency[a] > saliency[b] : a < b;
                    });
  order.resize(pool_size);
  splitmix64 rng{opt.seed};
  std::vector<std::uint32_t> seeds(opt.clusters);
  detail::clustering_workspace ws;
  ws.is_seed.assign(nv, 0);
  std::size_t drawn = 0;
  for (std::uint32_t c = 0; c < opt.clusters; ++c) {  // partial Fisher–Yates over the pool
    seeds[c] = invalid_id;
    while (seeds[c] == invalid_id && drawn < pool_size) {
      const std::size_t k = drawn + static_cast<std::size_t>(rng.uniform(pool_size - drawn));
      std::swap(order[drawn], order[k]);
      if (detail::can_seed(m, fd, order[drawn], ws.is_seed)) seeds[c] = order[drawn];
      ++drawn;
    }
    if (seeds[c] == invalid_id) seeds[c] = detail::first_free_seed(m, fd, ws.is_seed);
    if (seeds[c] == invalid_id)
      return make_error(errc::bad_parameter, no_element, "clusters ", opt.clusters,
                        ": the mesh has no room for that many seeds, each with a face of its own");
    ws.is_seed[seeds[c]] = 1;
  }

  salient_clusters out;
  std::vector<std::vector<std::uint32_t>> history;
  std::vector<std::uint32_t> label;  // per internal face
  for (;;) {
    detail::grow_clusters(fd, saliency, seeds, opt.normal_weight, opt.flat_tie_break, ws, label);
    out.seeds = seeds;
    ++out.iterations;
    history.push_back(seeds);
    if (out.iterations >= opt.max_iterations) break;
    auto next = detail::reseed(m, fd, label, saliency, seeds, ws, exec);
    const auto seen = std::find(history.begin(), history.end(), next);
    if (seen != history.end()) {
      out.converged = true;
      out.cycle = seen + 1 != history.end();
      break;
    }
    seeds = std::move(next);
  }
  out.cluster.resize(nt);
  for (std::size_t i = 0; i < nt; ++i) out.cluster[fd.original[i]] = label[i];
  // Faces no seed reached (other components): one extra cluster per unreached component.
  out.count = label_unlabelled_components(
      out.cluster, opt.clusters, [&](std::uint32_t f) { return topo->neighbours_of(f); }, [](std::uint32_t) {});
  return out;
}

namespace detail {
// Inputs of the per-cluster functions (eq. 4 here, attributes in cluster_importance.hpp): a
// valid mesh, one finite non-negative saliency per vertex, one cluster id < cluster_count per
// triangle. Names the offending vertex or triangle. O(V + T), no allocation.
template <class M>
status check_cluster_inputs(const M& m, std::span<const double> saliency, std::span<const std::uint32_t> cluster,
                            std::uint32_t cluster_count) {
  if (status s = check_indices_and_positions(m); !s.ok()) return s;
  const std::size_t nt = mesh_triangle_count(m), nv = mesh_vertex_count(m);
  if (saliency.size() != nv)
    return make_error(errc::bad_size, saliency.size(), "saliency has ", saliency.size(), " values for ", nv, " vertices");
  if (cluster.size() != nt)
    return make_error(errc::bad_size, cluster.size(), "cluster has ", cluster.size(), " ids for ", nt, " triangles");
  for (std::size_t v = 0; v < nv; ++v)
    if (!(saliency[v] >= 0.0) || !std::isfinite(saliency[v]))
      return make_error(non_negative_errc(saliency[v]), v, "vertex ", v, ": saliency ", saliency[v], " is not finite and >= 0");
  for (std::size_t t = 0; t < nt; ++t)
    if (cluster[t] >= cluster_count)
      return make_error(errc::index_out_of_range, t, "triangle ", t, ": cluster ", cluster[t], " >= cluster count ",
                        cluster_count);
  return {};
}
}  // namespace detail

// Cluster-localised saliency (eq. 4), per triangle corner (a vertex on a cluster border has one
// value per cluster): S_ci = (S_i − min S_c) / (max S_c − min S_c) + μ(S_c), with min, max and
// mean over the vertices of cluster c's triangles (each vertex once); the first term is 0 when
// max S_c = min S_c.
// Errors: mesh errors as mean_curvature; saliency.size() != V or cluster.size() != T
// (bad_size); a non-finite (non_finite) or negative (bad_parameter) saliency (names the
// vertex); a cluster id >= cluster_count (names the triangle). Complexity O(V + T); allocation O(T + V + clusters).
// Serial; pure.
template <class M>
result<std::vector<double>> cluster_localized_saliency(const M& m, std::span<const double> saliency,
                                                       std::span<const std::uint32_t> cluster,
                                                       std::uint32_t cluster_count) {
  static_assert(check_mesh<M>());
  if (status s = detail::check_cluster_inputs(m, saliency, cluster, cluster_count); !s.ok()) return s;
  const std::size_t nt = mesh_triangle_count(m), nv = mesh_vertex_count(m);
  std::vector<double> lo(cluster_count, std::numeric_limits<double>::infinity()),
      hi(cluster_count, -std::numeric_limits<double>::infinity()), sum(cluster_count, 0.0);
  std::vector<double> count(cluster_count, 0.0);
  std::vector<std::uint32_t> last_seen(nv, invalid_id);  // per vertex: last cluster that counted it
  // Visit triangles cluster by cluster so "each vertex once per cluster" needs O(V) memory.
  std::vector<std::uint32_t> by_cluster, offsets;
  detail::group_by_key(
      cluster_count, nt, [&](std::size_t t) { return cluster[t]; }, [](std::size_t t) { return static_cast<std::uint32_t>(t); },
      offsets, by_cluster);
  for (std::uint32_t c = 0; c < cluster_count; ++c)
    for (std::uint32_t k = offsets[c]; k < offsets[c + 1]; ++k) {
      const glm::uvec3 tri = mesh_triangle(m, by_cluster[k]);
      for (int j = 0; j < 3; ++j) {
        const std::uint32_t v = tri[j];
        if (last_seen[v] == c) continue;
        last_seen[v] = c;
        lo[c] = std::min(lo[c], saliency[v]), hi[c] = std::max(hi[c], saliency[v]);
        sum[c] += saliency[v], count[c] += 1.0;
      }
    }
  std::vector<double> out(3 * nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const std::uint32_t c = cluster[t];
    const glm::uvec3 tri = mesh_triangle(m, t);
    const double range = hi[c] - lo[c], mean = sum[c] / count[c];
    for (int j = 0; j < 3; ++j)
      out[3 * t + static_cast<std::size_t>(j)] = (range > 0.0 ? (saliency[tri[j]] - lo[c]) / range : 0.0) + mean;
  }
  return out;
}

}  // namespace infolerp
