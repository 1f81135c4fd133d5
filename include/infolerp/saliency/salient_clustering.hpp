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
//   3. Re-seeding: per cluster, a Dijkstra search from its border faces (faces next to another
//      cluster or on a mesh boundary) inwards with cost |x_f' − x_f| · S_f' / max(S_c) (eq. 3);
//      the new seed is the most salient vertex of the last face reached (a cluster without
//      border keeps its seed).
//   4. Repeat 2–3 until the seeds repeat a previous iteration's seeds (converged, or a cycle:
//      the paper accepts any point on a cycle; we stop at the repeat) or max_iterations.
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
#include <queue>
#include <span>
#include <tuple>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/topology.hpp"

namespace infolerp {

// splitmix64 (Steele, Lea, Flood 2014): the same sequence on every platform and library,
// unlike std:: distributions. uniform(n) is unbiased (rejection).
struct splitmix64 {
  std::uint64_t state = 0;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  // Uniform integer in [0, n). Precondition: n > 0.
  std::uint64_t uniform(std::uint64_t n) {
    const std::uint64_t threshold = (0 - n) % n;  // 2^64 mod n
    for (;;)
      if (const std::uint64_t x = next(); x >= threshold) return x % n;
  }
};

struct salient_clustering_options {
  std::uint32_t clusters = 10;    // C, the number of seeded clusters
  double pool_multiplier = 5.0;   // λ_c: the seed pool holds the λ_c·C most salient vertices
  double normal_weight = 1.0;     // λ_n in eq. (2) (>= 1 keeps every cost non-negative)
  std::uint64_t seed = 1;         // user seed for drawing seeds from the pool
  std::uint32_t max_iterations = 50;  // growth + re-seeding rounds at most
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
struct face_data {
  std::vector<glm::dvec3> centroid, normal;  // normal unit (0 for zero-area faces)
  std::vector<double> area, saliency;
};

// One growth phase from the given seed vertices. vertex_faces: CSR faces around each vertex.
inline std::vector<std::uint32_t> grow_clusters(const face_data& fd, const mesh_topology& topo,
                                                std::span<const std::uint32_t> vf_offsets,
                                                std::span<const std::uint32_t> vf, std::span<const double> vsal,
                                                std::span<const std::uint32_t> seeds, double lambda_n) {
  const std::size_t nt = fd.area.size(), C = seeds.size();
  std::vector<std::uint32_t> label(nt, invalid_id);
  std::vector<glm::dvec3> nsum(C, glm::dvec3(0.0));
  std::vector<double> ssum(C, 0.0), s0(C);
  std::vector<std::uint32_t> nfaces(C, 0);
  using entry = std::tuple<double, double, std::uint32_t, std::uint32_t, std::uint32_t>;  // cost, −S, cluster, face, from
  std::priority_queue<entry, std::vector<entry>, std::greater<entry>> queue;
  for (std::uint32_t c = 0; c < C; ++c) {
    const std::uint32_t v = seeds[c];
    s0[c] = vsal[v];
    for (std::uint32_t k = vf_offsets[v]; k < vf_offsets[v + 1]; ++k) {
      nsum[c] += fd.normal[vf[k]] * fd.area[vf[k]];  // seed normal: the vertex's area-weighted normal
      queue.emplace(0.0, -fd.saliency[vf[k]], c, vf[k], invalid_id);
    }
  }
  while (!queue.empty()) {
    const auto [cost, neg_s, c, f, from] = queue.top();
    queue.pop();
    if (label[f] != invalid_id) continue;
    label[f] = c;
    if (nfaces[c] == 0) nsum[c] = glm::dvec3(0.0);  // from now on: the cluster's faces
    nsum[c] += fd.normal[f] * fd.area[f];
    ssum[c] += fd.saliency[f];
    ++nfaces[c];
    const double len = glm::length(nsum[c]);
    const glm::dvec3 mean_n = len > 0.0 ? nsum[c] / len : glm::dvec3(0.0);
    const double mean_s = ssum[c] / nfaces[c];
    for (std::uint32_t g : topo.neighbours_of(f)) {
      if (label[g] != invalid_id) continue;
      const double sg = fd.saliency[g];
      const double step = (lambda_n - glm::dot(mean_n, fd.normal[g])) *
                          (std::abs(mean_s - sg) * std::abs(s0[c] - sg) * std::abs(fd.saliency[f] - sg)) *
                          glm::length(fd.centroid[g] - fd.centroid[f]);
      queue.emplace(cost + std::max(step, 0.0), -sg, c, g, f);
    }
  }
  return label;
}

// Re-seeding (eq. 3): per cluster, the most salient vertex of the face reached last by a
// Dijkstra search from the cluster's border faces inward.
template <class M>
std::vector<std::uint32_t> reseed(const M& m, const face_data& fd, const mesh_topology& topo,
                                  std::span<const std::uint32_t> label, std::span<const double> vsal,
                                  std::span<const std::uint32_t> old_seeds) {
  const std::size_t nt = label.size(), C = old_seeds.size();
  std::vector<double> smax(C, 0.0);
  for (std::size_t f = 0; f < nt; ++f)
    if (label[f] < C) smax[label[f]] = std::max(smax[label[f]], fd.saliency[f]);
  using entry = std::tuple<double, std::uint32_t>;  // distance, face (clusters are disjoint)
  std::priority_queue<entry, std::vector<entry>, std::greater<entry>> queue;
  std::vector<double> dist(nt, std::numeric_limits<double>::infinity());
  for (std::size_t f = 0; f < nt; ++f) {
    if (label[f] >= C) continue;
    bool border = false;
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t e = topo.triangle_edges[3 * f + static_cast<std::size_t>(c)];
      if (e != invalid_id && topo.is_boundary_edge(e)) border = true;
    }
    for (std::uint32_t g : topo.neighbours_of(f)) border = border || label[g] != label[f];
    if (border) dist[f] = 0.0, queue.emplace(0.0, static_cast<std::uint32_t>(f));
  }
  std::vector<std::uint32_t> last(C, invalid_id);
  while (!queue.empty()) {
    const auto [d, f] = queue.top();
    queue.pop();
    if (d > dist[f]) continue;
    const std::uint32_t c = label[f];
    last[c] = f;  // popped in ascending distance: the final pop per cluster is the farthest
    const double scale = smax[c] > 0.0 ? 1.0 / smax[c] : 0.0;
    for (std::uint32_t g : topo.neighbours_of(f)) {
      if (label[g] != c) continue;
      const double step = glm::length(fd.centroid[g] - fd.centroid[f]) * (smax[c] > 0.0 ? fd.saliency[g] * scale : 1.0);
      if (d + step < dist[g]) dist[g] = d + step, queue.emplace(d + step, g);
    }
  }
  std::vector<std::uint32_t> seeds(old_seeds.begin(), old_seeds.end());
  for (std::size_t c = 0; c < C; ++c) {
    if (last[c] == invalid_id) continue;  // no border: keep the seed
    const glm::uvec3 tri = mesh_triangle(m, last[c]);
    std::uint32_t best = tri.x;
    for (int k = 1; k < 3; ++k)
      if (vsal[tri[k]] > vsal[best] || (vsal[tri[k]] == vsal[best] && tri[k] < best)) best = tri[k];
    seeds[c] = best;
  }
  return seeds;
}
}  // namespace detail

// Salient clustering of a mesh from per-vertex saliency (saliency/mesh_saliency.hpp).
// Errors: mesh errors as mean_curvature; saliency.size() != vertex count (bad_size); a
// non-finite or negative saliency (names the vertex); clusters == 0 or more clusters than the
// pool or the triangle count can seed; pool_multiplier < 1; normal_weight < 1 (bad_parameter).
// Complexity O(iterations · T log T); allocation O(T) (queues hold up to ~3T entries). Serial.
template <class M>
result<salient_clusters> salient_clustering(const M& m, std::span<const double> saliency,
                                            const salient_clustering_options& opt = {}) {
  static_assert(check_mesh<M>());
  if (status s = detail::check_indices_and_positions(m); !s.ok()) return s;
  const std::size_t nv = mesh_vertex_count(m), nt = mesh_triangle_count(m);
  if (saliency.size() != nv)
    return make_error(errc::bad_size, saliency.size(), "saliency has ", saliency.size(), " values for ", nv, " vertices");
  for (std::size_t v = 0; v < nv; ++v)
    if (!(saliency[v] >= 0.0) || !std::isfinite(saliency[v]))
      return make_error(errc::non_finite, v, "vertex ", v, ": saliency ", saliency[v], " is not finite and >= 0");
  if (!(opt.pool_multiplier >= 1.0) || !std::isfinite(opt.pool_multiplier))
    return make_error(errc::bad_parameter, no_element, "pool_multiplier ", opt.pool_multiplier, " must be >= 1");
  if (!(opt.normal_weight >= 1.0) || !std::isfinite(opt.normal_weight))
    return make_error(errc::bad_parameter, no_element, "normal_weight ", opt.normal_weight, " must be >= 1");
  if (opt.clusters == 0 || opt.clusters > nt)
    return make_error(errc::bad_parameter, no_element, "clusters ", opt.clusters, " must be in [1, ", nt, "]");
  auto topo = build_topology(m);
  if (!topo.ok()) return topo.error();

  // Vertices used by triangles, most salient first (ties: lower index), and faces per vertex.
  std::vector<std::uint32_t> vf_offsets(nv + 1, 0), vf(3 * nt);
  for (std::size_t t = 0; t < nt; ++t)
    for (int c = 0; c < 3; ++c) ++vf_offsets[mesh_triangle(m, t)[c] + 1];
  for (std::size_t v = 0; v < nv; ++v) vf_offsets[v + 1] += vf_offsets[v];
  {
    std::vector<std::uint32_t> cursor(vf_offsets.begin(), vf_offsets.end() - 1);
    for (std::size_t t = 0; t < nt; ++t)
      for (int c = 0; c < 3; ++c) vf[cursor[mesh_triangle(m, t)[c]]++] = static_cast<std::uint32_t>(t);
  }
  std::vector<std::uint32_t> order;
  for (std::size_t v = 0; v < nv; ++v)
    if (vf_offsets[v + 1] > vf_offsets[v]) order.push_back(static_cast<std::uint32_t>(v));
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
  for (std::uint32_t c = 0; c < opt.clusters; ++c) {  // partial Fisher–Yates over the pool
    const std::size_t k = c + static_cast<std::size_t>(rng.uniform(pool_size - c));
    std::swap(order[c], order[k]);
    seeds[c] = order[c];
  }

  detail::face_data fd;
  fd.centroid.resize(nt), fd.normal.resize(nt), fd.area.resize(nt), fd.saliency.resize(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const triangle_corners c = corners(m, t);
    fd.centroid[t] = triangle_centroid(c);
    fd.normal[t] = glm::dvec3(triangle_normal(c));
    fd.area[t] = triangle_area(c);
    const glm::uvec3 tri = mesh_triangle(m, t);
    fd.saliency[t] = (saliency[tri.x] + saliency[tri.y] + saliency[tri.z]) / 3.0;
  }

  salient_clusters out;
  std::vector<std::vector<std::uint32_t>> history;
  for (;;) {
    out.cluster = detail::grow_clusters(fd, *topo, vf_offsets, vf, saliency, seeds, opt.normal_weight);
    out.seeds = seeds;
    ++out.iterations;
    history.push_back(seeds);
    if (out.iterations >= opt.max_iterations) break;
    auto next = detail::reseed(m, fd, *topo, out.cluster, saliency, seeds);
    const auto seen = std::find(history.begin(), history.end(), next);
    if (seen != history.end()) {
      out.converged = true;
      out.cycle = seen + 1 != history.end();
      break;
    }
    seeds = std::move(next);
  }
  // Faces no seed reached (other components): one extra cluster per unreached component.
  out.count = opt.clusters;
  std::vector<std::uint32_t> stack;
  for (std::size_t f = 0; f < nt; ++f) {
    if (out.cluster[f] != invalid_id) continue;
    const std::uint32_t id = out.count++;
    out.cluster[f] = id;
    stack.push_back(static_cast<std::uint32_t>(f));
    while (!stack.empty()) {
      const std::uint32_t g = stack.back();
      stack.pop_back();
      for (std::uint32_t h : topo->neighbours_of(g))
        if (out.cluster[h] == invalid_id) out.cluster[h] = id, stack.push_back(h);
    }
  }
  return out;
}

// Cluster-localised saliency (eq. 4), per triangle corner (a vertex on a cluster border has one
// value per cluster): S_ci = (S_i − min S_c) / (max S_c − min S_c) + μ(S_c), with min, max and
// mean over the vertices of cluster c's triangles (each vertex once); the first term is 0 when
// max S_c = min S_c.
// Errors: mesh errors as mean_curvature; saliency.size() != V or cluster.size() != T
// (bad_size); a non-finite or negative saliency (names the vertex); a cluster id >=
// cluster_count (names the triangle). Complexity O(V + T); allocation O(T + V + clusters).
template <class M>
result<std::vector<double>> cluster_localized_saliency(const M& m, std::span<const double> saliency,
                                                       std::span<const std::uint32_t> cluster,
                                                       std::uint32_t cluster_count) {
  static_assert(check_mesh<M>());
  if (status s = detail::check_indices_and_positions(m); !s.ok()) return s;
  const std::size_t nt = mesh_triangle_count(m), nv = mesh_vertex_count(m);
  if (saliency.size() != nv)
    return make_error(errc::bad_size, saliency.size(), "saliency has ", saliency.size(), " values for ", nv, " vertices");
  if (cluster.size() != nt)
    return make_error(errc::bad_size, cluster.size(), "cluster has ", cluster.size(), " ids for ", nt, " triangles");
  for (std::size_t v = 0; v < nv; ++v)
    if (!(saliency[v] >= 0.0) || !std::isfinite(saliency[v]))
      return make_error(errc::non_finite, v, "vertex ", v, ": saliency ", saliency[v], " is not finite and >= 0");
  for (std::size_t t = 0; t < nt; ++t)
    if (cluster[t] >= cluster_count)
      return make_error(errc::index_out_of_range, t, "triangle ", t, ": cluster ", cluster[t], " >= cluster count ",
                        cluster_count);
  std::vector<double> lo(cluster_count, std::numeric_limits<double>::infinity()),
      hi(cluster_count, -std::numeric_limits<double>::infinity()), sum(cluster_count, 0.0);
  std::vector<double> count(cluster_count, 0.0);
  std::vector<std::uint32_t> last_seen(nv, invalid_id);  // per vertex: last cluster that counted it
  // Visit triangles cluster by cluster so "each vertex once per cluster" needs O(V) memory.
  std::vector<std::uint32_t> by_cluster(nt), offsets(cluster_count + 1, 0);
  for (std::size_t t = 0; t < nt; ++t) ++offsets[cluster[t] + 1];
  for (std::size_t c = 0; c < cluster_count; ++c) offsets[c + 1] += offsets[c];
  {
    std::vector<std::uint32_t> cursor(offsets.begin(), offsets.end() - 1);
    for (std::size_t t = 0; t < nt; ++t) by_cluster[cursor[cluster[t]]++] = static_cast<std::uint32_t>(t);
  }
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
