// infolerp_pareto lod_dag --csv FILE [--mesh PATH]... [--only-given] [--fraction F] [--group N]
//                         [--cluster N] [--error max|sum] [--partition recursive|kway] [--reps N]
// (--group: clusters per METIS part, default 4; --cluster: triangles per cluster, default 128;
// --error: a group's error is the largest of its own simplification error and its children's
// (max, default) or their sum; --partition: METIS_PartGraphRecursive (default) or
// METIS_PartGraphKway; --reps: repetitions of the timed cut, default 21)
//
// A reference cluster DAG built only from outside parts, to learn whether a cluster DAG of the
// quality builders reach (meshoptimizer's clusterlod and Nanite, Karis, SIGGRAPH 2021) beats a
// uniform LOD given the same per-triangle culling at the same drawn triangle count (issue 50's
// question; benchmarks/NOTES.md "A cluster DAG ... with METIS grouping"). Not the library's
// code: meshoptimizer 0.18 and METIS only, nothing of include/ but the culling test.
//
// Build (the clusterlod recipe on meshoptimizer 0.18): level 0 = meshopt_buildMeshlets of the
// mesh (at most 128 vertices and --cluster triangles, cone weight 0); each level partitions the
// pending clusters' adjacency graph (an edge per pair of clusters sharing mesh edges, weighted by
// their number) with METIS into parts of about --group clusters, simplifies each part's
// triangles to half with meshopt_simplify(meshopt_SimplifyLockBorder) on a compacted copy of its
// vertices (so that the group border, whose edges have no partner in the part, stays where it
// is), and cuts the result into new clusters with meshopt_buildMeshlets. A part that keeps more
// than 85% of its triangles is terminal (its clusters stay roots). Per group: a sphere containing
// its children's spheres and an error max(children's, own) (own: meshopt's relative error times
// meshopt_simplifyScale of the part), so errors and spheres never decrease up the DAG. No
// saliency: meshopt_simplify 0.18 takes no per-vertex weights.
//
// Cut (per camera): cluster c is drawn when err(self) <= τ < err(parent), err(g) = g.error ·
// focal / max(distance from the eye to g's sphere, znear) (view cut; znear 1% of the box
// diagonal; level-0 clusters have self error 0; roots parent error +inf) or err(g) = g.error
// (uniform cut, the same for every camera). τ is chosen among the groups' errors by bisection so
// that the DRAWN count after per-triangle culling is nearest the fraction's triangle count.
// Culling = the library's own test (lod/hidden_triangles.hpp: hidden_triangle), back faces
// hidden where the FULL mesh's part is closed (a vertex on a closed part of the full mesh; a
// triangle whose three vertices are), and none when the eye is inside a closed part.
// Peer: meshopt_simplify of the whole mesh (target_error FLT_MAX, no options) at the target whose
// output, culled the same way, draws the count nearest the DAG cut's (bisection on the target).
//
// CSV (kind=view): kind,mesh,method,fraction,view,triangles,cut_triangles,open_edges,psnr_db,ssim,tau
//   method dag_view, peer_view (meshopt at dag_view's drawn count), dag_uniform, peer_uniform
//   (at dag_uniform's); triangles: drawn (after culling); cut_triangles: before culling;
//   open_edges: directed edges of the unculled cut (peer rows: meshopt's whole output) that are
//   repeated or lack their reverse (0 on a closed manifold surface; a crack or a non-manifold
//   edge counts). psnr_db, ssim: that camera's 256x256
//   reference-shader image (support/mesh_views.hpp; primary hits and normals from the drawn
//   triangles, shadow and AO rays against the full mesh, as benchmarks/pareto/lod.cpp's view rows)
//   against the full mesh's. Cameras: lod.cpp's 8 orbit and 8 close ones.
// CSV (kind=timing, own header): kind,mesh,view,fraction,triangles,cut_min_s,cut_median_s,
//   exact_min_s,exact_median_s,memcpy_min_s,memcpy_median_s
//   cut: one frame's selection at a known τ (group errors, cluster test, per-triangle culling of
//   the selected clusters, indices written); exact: the frame with τ bisected to the count
//   (culling every DAG triangle once); memcpy: the full index buffer; --reps interleaved
//   repetitions, each timed call after an untimed one.
// CSV (kind=build, own header): kind,mesh,triangles,clusters,groups,levels,terminal_groups,
//   coarsest_triangles,seconds
// stdout: the same rows, per level the clusters, triangles and share of locked vertices, and per
// mesh, fraction and camera set the mean and worst PSNR differences.
#include <meshoptimizer.h>
#include <metis.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/lod/hidden_triangles.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "pareto.hpp"
#include "support/lod_peers.hpp"
#include "support/mesh_io.hpp"
#include "support/mesh_views.hpp"

namespace {

using namespace infolerp;
using clk = std::chrono::steady_clock;
constexpr double inf = std::numeric_limits<double>::infinity();

double seconds_since(clk::time_point t0) { return std::chrono::duration<double>(clk::now() - t0).count(); }

struct dag_options {
  std::size_t group = 4;           // clusters per METIS part
  std::size_t cluster = 128;       // triangles per cluster
  bool error_sum = false;          // group error: children's + own (else max)
  bool kway = false;               // METIS_PartGraphKway (else Recursive)
};

struct bounds {
  glm::dvec3 center{0.0};
  double radius = 0.0, error = 0.0;
};

struct cluster_dag {
  std::vector<std::uint32_t> indices;  // every cluster's triangles, global vertex ids
  std::vector<std::uint32_t> first;    // cluster c: triangles [first[c], first[c + 1])
  std::vector<std::int32_t> self;      // the group that made c, -1 at level 0
  std::vector<std::int32_t> parent;    // the group c was simplified in, -1 for a root
  std::vector<bounds> own;             // c's self bounds (level 0: its sphere, error 0; else its group's)
  std::vector<bounds> group;
  std::size_t levels = 0, terminal = 0;
  std::size_t clusters() const { return first.size() - 1; }
  std::size_t triangles(std::size_t c) const { return first[c + 1] - first[c]; }
};

// Adds the meshlets of `idx` (vertex ids into pos) as clusters whose triangles name
// global[local id]; returns how many. Each meshlet's sphere from meshopt_computeClusterBounds.
std::size_t add_clusters(cluster_dag& d, const std::vector<std::uint32_t>& idx, const std::vector<glm::vec3>& pos,
                         const std::vector<std::uint32_t>* global, std::size_t max_triangles, std::int32_t self,
                         const bounds& self_bounds) {
  const std::size_t max_vertices = 128;
  std::vector<meshopt_Meshlet> ml(meshopt_buildMeshletsBound(idx.size(), max_vertices, max_triangles));
  std::vector<unsigned> mv(ml.size() * max_vertices);
  std::vector<unsigned char> mt(ml.size() * max_triangles * 3);
  ml.resize(meshopt_buildMeshlets(ml.data(), mv.data(), mt.data(), idx.data(), idx.size(), &pos[0].x, pos.size(),
                                  sizeof(glm::vec3), max_vertices, max_triangles, 0.0f));
  for (const meshopt_Meshlet& m : ml) {
    for (std::size_t j = 0; j < 3 * std::size_t{m.triangle_count}; ++j) {
      const std::uint32_t local = mv[m.vertex_offset + mt[m.triangle_offset + j]];
      d.indices.push_back(global ? (*global)[local] : local);
    }
    d.first.push_back(static_cast<std::uint32_t>(d.indices.size() / 3));
    d.self.push_back(self);
    d.parent.push_back(-1);
    if (self < 0) {
      const std::uint32_t* tri = d.indices.data() + 3 * std::size_t{d.first[d.first.size() - 2]};
      const meshopt_Bounds b = meshopt_computeClusterBounds(tri, 3 * std::size_t{m.triangle_count}, &pos[0].x, pos.size(), sizeof(glm::vec3));
      d.own.push_back({glm::dvec3(b.center[0], b.center[1], b.center[2]), static_cast<double>(b.radius), 0.0});
    } else {
      d.own.push_back(self_bounds);
    }
  }
  return ml.size();
}

// Parts of about opt.group clusters of `pending` (METIS over shared-edge counts).
std::vector<std::vector<std::uint32_t>> partition(const cluster_dag& d, const std::vector<std::uint32_t>& pending,
                                                  const dag_options& opt) {
  const std::size_t n = pending.size();
  const auto nparts = static_cast<idx_t>((n + opt.group - 1) / opt.group);
  if (nparts <= 1) return {pending};
  struct edge_of {
    std::uint64_t key;
    std::uint32_t node;
  };
  std::vector<edge_of> edges;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t c = pending[i];
    for (std::uint32_t t = d.first[c]; t < d.first[c + 1]; ++t)
      for (std::size_t j = 0; j < 3; ++j) {
        const std::uint32_t a = d.indices[3 * std::size_t{t} + j], b = d.indices[3 * std::size_t{t} + (j + 1) % 3];
        edges.push_back({std::uint64_t{std::min(a, b)} << 32 | std::max(a, b), i});
      }
  }
  std::sort(edges.begin(), edges.end(), [](const edge_of& x, const edge_of& y) { return x.key < y.key || (x.key == y.key && x.node < y.node); });
  std::vector<std::uint64_t> pairs;  // a << 32 | b, a != b, both directions
  for (std::size_t i = 0, e = 0; i < edges.size(); i = e) {
    while (e < edges.size() && edges[e].key == edges[i].key) ++e;
    for (std::size_t a = i; a < e; ++a)
      for (std::size_t b = i; b < e; ++b)
        if (edges[a].node != edges[b].node) pairs.push_back(std::uint64_t{edges[a].node} << 32 | edges[b].node);
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<idx_t> xadj(n + 1, 0), adjncy, adjwgt;
  for (std::size_t i = 0, e = 0; i < pairs.size(); i = e) {
    while (e < pairs.size() && pairs[e] == pairs[i]) ++e;
    adjncy.push_back(static_cast<idx_t>(pairs[i] & 0xffffffffu));
    adjwgt.push_back(static_cast<idx_t>(e - i));
    ++xadj[(pairs[i] >> 32) + 1];
  }
  for (std::size_t i = 0; i < n; ++i) xadj[i + 1] += xadj[i];
  idx_t nv = static_cast<idx_t>(n), ncon = 1, parts = nparts, cut = 0;
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;
  std::vector<idx_t> part(n, 0);
  if (adjncy.empty()) adjncy.push_back(0), adjwgt.push_back(0);  // METIS reads the arrays even when empty
  const int st = opt.kway ? METIS_PartGraphKway(&nv, &ncon, xadj.data(), adjncy.data(), nullptr, nullptr, adjwgt.data(), &parts,
                                                nullptr, nullptr, options, &cut, part.data())
                          : METIS_PartGraphRecursive(&nv, &ncon, xadj.data(), adjncy.data(), nullptr, nullptr, adjwgt.data(),
                                                     &parts, nullptr, nullptr, options, &cut, part.data());
  if (st != METIS_OK) std::fprintf(stderr, "METIS failed (%d)\n", st), std::exit(1);
  std::vector<std::vector<std::uint32_t>> out(static_cast<std::size_t>(nparts));
  for (std::size_t i = 0; i < n; ++i) out[static_cast<std::size_t>(part[i])].push_back(pending[i]);
  out.erase(std::remove_if(out.begin(), out.end(), [](const auto& g) { return g.empty(); }), out.end());
  return out;
}

bounds merge(const cluster_dag& d, const std::vector<std::uint32_t>& g) {
  bounds r;
  double w = 0.0;
  for (std::uint32_t c : g) r.center += d.own[c].center * d.own[c].radius, w += d.own[c].radius;
  r.center = w > 0.0 ? r.center / w : d.own[g[0]].center;
  for (std::uint32_t c : g) {
    r.radius = std::max(r.radius, glm::length(d.own[c].center - r.center) + d.own[c].radius);
    r.error = std::max(r.error, d.own[c].error);
  }
  r.radius *= 1.0 + 1e-6;  // contains the children's spheres despite rounding
  return r;
}

cluster_dag build_dag(const indexed_mesh& m, const dag_options& opt) {
  cluster_dag d;
  d.first.push_back(0);
  const std::vector<std::uint32_t> all(reinterpret_cast<const std::uint32_t*>(m.triangles.data()),
                                       reinterpret_cast<const std::uint32_t*>(m.triangles.data()) + 3 * m.triangle_count());
  add_clusters(d, all, m.positions, nullptr, opt.cluster, -1, {});
  std::vector<std::uint32_t> pending(d.clusters());
  for (std::uint32_t c = 0; c < pending.size(); ++c) pending[c] = c;
  std::vector<std::uint32_t> local_of(m.vertex_count(), ~0u), groups_of(m.vertex_count(), 0), stamp(m.vertex_count(), ~0u);
  while (pending.size() > 1 && d.levels < 64) {
    const auto parts = partition(d, pending, opt);
    // Locked share: vertices of the pending clusters that lie in more than one part.
    std::size_t verts = 0, locked = 0, tris = 0;
    for (std::size_t g = 0; g < parts.size(); ++g)
      for (std::uint32_t c : parts[g])
        for (std::uint32_t i = 3 * d.first[c]; i < 3 * d.first[c + 1]; ++i) {
          const std::uint32_t v = d.indices[i];
          if (stamp[v] == g) continue;
          if (stamp[v] == ~0u) ++verts, groups_of[v] = 0;
          stamp[v] = static_cast<std::uint32_t>(g);
          if (++groups_of[v] == 2) ++locked;
        }
    for (std::uint32_t c : pending) {
      tris += d.triangles(c);
      for (std::uint32_t i = 3 * d.first[c]; i < 3 * d.first[c + 1]; ++i) stamp[d.indices[i]] = ~0u;
    }
    std::printf("# level %zu: %zu clusters, %zu triangles, %zu parts, locked vertices %.1f%%\n", d.levels, pending.size(), tris,
                parts.size(), 100.0 * static_cast<double>(locked) / static_cast<double>(std::max<std::size_t>(verts, 1)));
    std::vector<std::uint32_t> next;
    for (const auto& g : parts) {
      std::vector<std::uint32_t> local, global;
      std::vector<glm::vec3> pos;
      for (std::uint32_t c : g)
        for (std::uint32_t i = 3 * d.first[c]; i < 3 * d.first[c + 1]; ++i) {
          const std::uint32_t v = d.indices[i];
          if (local_of[v] == ~0u) local_of[v] = static_cast<std::uint32_t>(global.size()), global.push_back(v), pos.push_back(m.positions[v]);
          local.push_back(local_of[v]);
        }
      for (std::uint32_t v : global) local_of[v] = ~0u;
      const std::size_t merged = local.size() / 3;
      std::vector<std::uint32_t> simplified(local.size());
      float rel = 0.0f;
      simplified.resize(meshopt_simplify(simplified.data(), local.data(), local.size(), &pos[0].x, pos.size(), sizeof(glm::vec3),
                                         3 * (merged / 2), std::numeric_limits<float>::max(), meshopt_SimplifyLockBorder, &rel));
      if (static_cast<double>(simplified.size() / 3) > 0.85 * static_cast<double>(merged)) {
        ++d.terminal;
        continue;
      }
      if (std::getenv("INFOLERP_DAG_CHECK")) {  // the part's border edges must come out unchanged
        auto border = [](const std::vector<std::uint32_t>& idx, const std::vector<std::uint32_t>& to_global) {
          std::vector<std::uint64_t> e, b;
          for (std::size_t i = 0; i < idx.size(); i += 3)
            for (std::size_t j = 0; j < 3; ++j)
              e.push_back(std::uint64_t{to_global[idx[i + j]]} << 32 | to_global[idx[i + (j + 1) % 3]]);
          std::sort(e.begin(), e.end());
          for (std::uint64_t x : e)
            if (!std::binary_search(e.begin(), e.end(), (x & 0xffffffffu) << 32 | x >> 32)) b.push_back(x);
          return b;
        };
        const auto bi = border(local, global), bo = border(simplified, global);
        if (bi != bo) std::printf("# level %zu part of %zu triangles: border %zu edges in, %zu out\n", d.levels, merged, bi.size(), bo.size());
      }
      bounds b = merge(d, g);
      const double own = static_cast<double>(rel) * static_cast<double>(meshopt_simplifyScale(&pos[0].x, pos.size(), sizeof(glm::vec3)));
      b.error = opt.error_sum ? b.error + own : std::max(b.error, own);
      const auto gid = static_cast<std::int32_t>(d.group.size());
      d.group.push_back(b);
      for (std::uint32_t c : g) d.parent[c] = gid;
      const std::size_t before = d.clusters();
      add_clusters(d, simplified, pos, &global, opt.cluster, gid, b);
      for (std::size_t c = before; c < d.clusters(); ++c) next.push_back(static_cast<std::uint32_t>(c));
    }
    ++d.levels;
    pending = std::move(next);
  }
  return d;
}

// Per-vertex: on a closed part of the full mesh (hidden_triangles.hpp's closed_part_triangles).
std::vector<std::uint8_t> closed_vertices(const indexed_mesh& m, std::span<const std::uint32_t> all) {
  const std::vector<std::uint8_t> closed = closed_part_triangles(all, m.positions);
  std::vector<std::uint8_t> v(m.vertex_count(), 1);
  for (std::size_t t = 0; t < closed.size(); ++t)
    if (!closed[t])
      for (std::size_t j = 0; j < 3; ++j) v[all[3 * t + j]] = 0;
  return v;
}

struct culler {
  view_frustum frustum;
  const std::vector<std::uint8_t>* closed = nullptr;
  const std::vector<glm::vec3>* pos = nullptr;
  bool back_hidden = true;
  bool hidden(const std::uint32_t* f) const {
    const std::vector<glm::vec3>& p = *pos;
    const bool one_sided = back_hidden && (*closed)[f[0]] && (*closed)[f[1]] && (*closed)[f[2]];
    return hidden_triangle(frustum, p[f[0]], p[f[1]], p[f[2]], one_sided);
  }
};

culler make_culler(const lod_camera& cam, const indexed_mesh& m, std::span<const std::uint32_t> all,
                   const std::vector<std::uint8_t>& closed) {
  culler c{make_view_frustum(cam), &closed, &m.positions, true};
  long winding = 0;  // the eye inside a closed part: back faces may be seen
  for (std::size_t t = 0; t < all.size() / 3; ++t)
    if (closed[all[3 * t]] && closed[all[3 * t + 1]] && closed[all[3 * t + 2]])
      winding += eye_ray_crossing(c.frustum, m.positions[all[3 * t]], m.positions[all[3 * t + 1]], m.positions[all[3 * t + 2]]);
  c.back_hidden = winding == 0;
  return c;
}

// err(g) per group for the camera (view) or the groups' errors (uniform). The distance is
// clamped below at znear (as clusterlod's demo clamps it at the near plane), which keeps the
// order of the errors, so that a group whose sphere holds the eye can still be coarsened.
void group_errors(const cluster_dag& d, const glm::dvec3& eye, double focal, double znear, bool view, std::vector<double>& err) {
  err.resize(d.group.size());
  for (std::size_t g = 0; g < d.group.size(); ++g) {
    const bounds& b = d.group[g];
    if (!view || b.error == 0.0) {
      err[g] = b.error;
      continue;
    }
    err[g] = b.error * focal / std::max(glm::length(b.center - eye) - b.radius, znear);
  }
}

inline bool drawn_at(const cluster_dag& d, const std::vector<double>& err, std::size_t c, double tau) {
  const double s = d.self[c] < 0 ? 0.0 : err[static_cast<std::size_t>(d.self[c])];
  const double p = d.parent[c] < 0 ? inf : err[static_cast<std::size_t>(d.parent[c])];
  return s <= tau && p > tau;
}

// The cut at τ, culled, into out (drawn) and, if whole, unculled. Returns drawn triangles.
std::size_t write_cut(const cluster_dag& d, const std::vector<double>& err, double tau, const culler& cl, std::uint32_t* out,
                      std::vector<std::uint32_t>* whole) {
  std::size_t n = 0;
  if (whole) whole->clear();
  for (std::size_t c = 0; c < d.clusters(); ++c) {
    if (!drawn_at(d, err, c, tau)) continue;
    for (std::uint32_t t = d.first[c]; t < d.first[c + 1]; ++t) {
      const std::uint32_t* f = d.indices.data() + 3 * std::size_t{t};
      if (whole) whole->insert(whole->end(), f, f + 3);
      if (cl.hidden(f)) continue;
      out[3 * n] = f[0], out[3 * n + 1] = f[1], out[3 * n + 2] = f[2];
      ++n;
    }
  }
  return n;
}

// τ among {0} ∪ the groups' finite errors whose culled cut draws the count nearest `target`.
// visible[c]: c's triangles the camera may see. O(G log G + C log G).
double bisect_tau(const cluster_dag& d, const std::vector<double>& err, const std::vector<std::uint32_t>& visible,
                  std::size_t target, std::vector<double>& cand) {
  cand.assign(1, 0.0);
  for (double e : err)
    if (std::isfinite(e)) cand.push_back(e);
  std::sort(cand.begin(), cand.end());
  cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
  auto count = [&](double tau) {
    std::size_t n = 0;
    for (std::size_t c = 0; c < d.clusters(); ++c) n += drawn_at(d, err, c, tau) ? visible[c] : 0u;
    return n;
  };
  std::size_t lo = 0, hi = cand.size() - 1;  // count(cand[lo]) > target >= count(cand[hi]) once bracketed
  if (count(cand[lo]) <= target) return cand[lo];
  if (count(cand[hi]) > target) return cand[hi];
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    (count(cand[mid]) > target ? lo : hi) = mid;
  }
  const std::size_t a = count(cand[lo]), b = count(cand[hi]);
  return a - target < target - b ? cand[lo] : cand[hi];
}

std::vector<std::uint32_t> visible_counts(const cluster_dag& d, const culler& cl) {
  std::vector<std::uint32_t> v(d.clusters(), 0);
  for (std::size_t c = 0; c < d.clusters(); ++c)
    for (std::uint32_t t = d.first[c]; t < d.first[c + 1]; ++t) v[c] += cl.hidden(d.indices.data() + 3 * std::size_t{t}) ? 0u : 1u;
  return v;
}

// Edges of a triangle list not shared by exactly two triangles of opposite winding.
std::size_t open_edges(const std::vector<std::uint32_t>& idx) {
  std::vector<std::uint64_t> e;  // directed
  for (std::size_t t = 0; t < idx.size() / 3; ++t)
    for (std::size_t j = 0; j < 3; ++j) e.push_back(std::uint64_t{idx[3 * t + j]} << 32 | idx[3 * t + (j + 1) % 3]);
  std::sort(e.begin(), e.end());
  std::size_t bad = 0;
  for (std::size_t i = 0; i < e.size(); ++i) {
    const bool dup = (i > 0 && e[i - 1] == e[i]);
    const std::uint64_t rev = (e[i] & 0xffffffffu) << 32 | e[i] >> 32;
    if (dup || !std::binary_search(e.begin(), e.end(), rev)) ++bad;
  }
  return bad;
}

// meshopt_simplify of the whole mesh whose culled output draws the count nearest `goal`
// (bisection on the target, interpolation steps alternating with halvings); out: the drawn triangles.
std::size_t peer_at(const indexed_mesh& m, std::span<const std::uint32_t> all, const culler& cl, std::size_t goal,
                    std::vector<std::uint32_t>& out, std::vector<std::uint32_t>* whole = nullptr) {
  const std::size_t nt = m.triangle_count();
  std::vector<std::uint32_t> simp(all.size());
  auto drawn = [&](std::size_t k, std::vector<std::uint32_t>* keep) {
    const std::size_t n = meshopt_simplify(simp.data(), all.data(), all.size(), &m.positions[0].x, m.vertex_count(), sizeof(glm::vec3),
                                           3 * k, std::numeric_limits<float>::max(), 0, nullptr);
    std::size_t c = 0;
    if (keep) keep->clear();
    if (keep && whole) whole->assign(simp.begin(), simp.begin() + static_cast<long>(n));
    for (std::size_t t = 0; t < n / 3; ++t)
      if (!cl.hidden(simp.data() + 3 * t)) {
        ++c;
        if (keep) keep->insert(keep->end(), simp.data() + 3 * t, simp.data() + 3 * t + 3);
      }
    return c;
  };
  std::size_t lo = goal, hi = nt;  // drawn(lo) <= goal (drawn <= output <= target); find drawn(hi) >= goal
  std::size_t dlo = drawn(lo, nullptr), dhi = drawn(hi, nullptr);
  if (dlo >= goal) return drawn(lo, &out);
  if (dhi <= goal) return drawn(hi, &out);
  for (int step = 0; hi - lo > 1; ++step) {
    std::size_t k = (lo + hi) / 2;
    if (step % 2 == 0 && dhi > dlo)
      k = std::clamp(lo + static_cast<std::size_t>(static_cast<double>(goal - dlo) * static_cast<double>(hi - lo) / static_cast<double>(dhi - dlo)),
                     lo + 1, hi - 1);
    const std::size_t dk = drawn(k, nullptr);
    if (dk == goal) return drawn(k, &out);
    if (dk < goal) lo = k, dlo = dk;
    else hi = k, dhi = dk;
  }
  return drawn(goal - dlo <= dhi - goal ? lo : hi, &out);
}

struct stats {
  double sum = 0.0, worst = inf;
  void add(double x) { sum += x, worst = std::min(worst, x); }
};

double g_fraction = 0.0;  // --fraction: only this one
int g_reps = 21;

void mesh_rows(std::FILE* csv, const support::embree_device& device, const std::string& name, const indexed_mesh& m,
               const dag_options& opt) {
  const std::size_t nt = m.triangle_count();
  const std::span<const std::uint32_t> all(reinterpret_cast<const std::uint32_t*>(m.triangles.data()), 3 * nt);
  auto t0 = clk::now();
  const cluster_dag d = build_dag(m, opt);
  const double build_s = seconds_since(t0);
  std::size_t coarsest = 0;
  for (std::size_t c = 0; c < d.clusters(); ++c) coarsest += d.parent[c] < 0 ? d.triangles(c) : 0;
  for (std::FILE* o : {csv, stdout})
    std::fprintf(o, "build,%s,%zu,%zu,%zu,%zu,%zu,%zu,%.4f\n", name.c_str(), nt, d.clusters(), d.group.size(), d.levels, d.terminal,
                 coarsest, build_s);
  const std::vector<std::uint8_t> closed = closed_vertices(m, all);
  const std::vector<support::camera> cams = support::lod_view_cameras(m);
  support::mesh_view_options with_full;
  with_full.occluders = all;
  std::vector<support::image> full;
  for (const support::camera& c : cams) {
    auto img = support::render_mesh_views(device, m.positions, all, std::span<const support::camera>(&c, 1), with_full);
    if (!img) return void(std::fprintf(stderr, "views: %s\n", img.error().message().c_str()));
    full.push_back(std::move((*img)[0]));
  }
  const auto size = static_cast<std::uint32_t>(with_full.width);
  const double znear = 0.01 * mesh_bounds(m).diagonal();
  std::vector<std::uint32_t> out(d.indices.size()), whole, peer, peer_whole;
  std::vector<double> err, cand;
  for (double f : {0.10, 0.05, 0.01}) {
    if (g_fraction > 0.0 && std::abs(f - g_fraction) > 1e-9) continue;
    const auto target = static_cast<std::size_t>(std::lround(f * static_cast<double>(nt)));
    stats view_peer, uni_peer, view_uni;
    for (std::size_t v = 0; v < cams.size(); ++v) {
      const lod_camera cam = support::to_lod_camera(cams[v], size);
      const culler cl = make_culler(cam, m, all, closed);
      const double focal = 0.5 * static_cast<double>(size) / std::tan(0.5 * cam.vertical_fov);
      const std::string view = (v < 8 ? "orbit" : "close") + std::to_string(v % 8);
      const std::vector<std::uint32_t> visible = visible_counts(d, cl);
      double psnr[4] = {0, 0, 0, 0};
      for (int uniform = 0; uniform < 2; ++uniform) {
        group_errors(d, cam.position, focal, znear, uniform == 0, err);
        const double tau = bisect_tau(d, err, visible, target, cand);
        const std::size_t n = write_cut(d, err, tau, cl, out.data(), &whole);
        const std::size_t open = open_edges(whole);
        const std::size_t pn = peer_at(m, all, cl, n, peer, &peer_whole);
        const std::size_t peer_open = open_edges(peer_whole);
        for (int peer_side = 0; peer_side < 2; ++peer_side) {
          const std::span<const std::uint32_t> idx = peer_side ? std::span<const std::uint32_t>(peer) : std::span<const std::uint32_t>(out.data(), 3 * n);
          auto img = support::render_mesh_views(device, m.positions, idx, std::span<const support::camera>(&cams[v], 1), with_full);
          if (!img) return void(std::fprintf(stderr, "views: %s\n", img.error().message().c_str()));
          auto sim = support::compare_views(*img, std::vector<support::image>{full[v]});
          if (!sim) return void(std::fprintf(stderr, "views: comparison failed\n"));
          psnr[2 * uniform + peer_side] = sim->psnr;
          static const char* names[] = {"dag_view", "peer_view", "dag_uniform", "peer_uniform"};
          for (std::FILE* o : {csv, stdout})
            std::fprintf(o, "view,%s,%s,%.2f,%s,%zu,%zu,%zu,%.4f,%.6f,%.6g\n", name.c_str(), names[2 * uniform + peer_side], f, view.c_str(),
                         peer_side ? pn : n, peer_side ? pn : whole.size() / 3, peer_side ? peer_open : open, sim->psnr, sim->ssim,
                         peer_side ? 0.0 : tau);
          std::fflush(csv);
        }
      }
      view_peer.add(psnr[0] - psnr[1]), uni_peer.add(psnr[2] - psnr[3]), view_uni.add(psnr[0] - psnr[2]);
      if (v == 7 || v == 15) {
        std::printf("# %s %.2f %s: dag_view - peer mean %+.2f worst %+.2f; dag_uniform - peer mean %+.2f worst %+.2f; "
                    "dag_view - dag_uniform mean %+.2f worst %+.2f dB\n",
                    name.c_str(), f, v == 7 ? "orbit" : "close", view_peer.sum / 8, view_peer.worst, uni_peer.sum / 8, uni_peer.worst,
                    view_uni.sum / 8, view_uni.worst);
        view_peer = uni_peer = view_uni = stats{};
      }
    }
  }
  // Timing at 5%: one frame's selection at a known τ, the exact frame, a memcpy of the index buffer.
  const auto target = static_cast<std::size_t>(std::lround(0.05 * static_cast<double>(nt)));
  std::vector<std::uint32_t> copy(all.size());
  for (std::size_t v : {std::size_t{0}, std::size_t{8}}) {
    const lod_camera cam = support::to_lod_camera(cams[v], size);
    const double focal = 0.5 * static_cast<double>(size) / std::tan(0.5 * cam.vertical_fov);
    const culler cl = make_culler(cam, m, all, closed);
    group_errors(d, cam.position, focal, znear, true, err);
    const double tau = bisect_tau(d, err, visible_counts(d, cl), target, cand);
    std::vector<double> cut_s, exact_s, cp_s;
    std::size_t n = 0;
    for (int r = 0; r < g_reps; ++r) {
      for (int warm = 0; warm < 2; ++warm) {
        t0 = clk::now();
        group_errors(d, cam.position, focal, znear, true, err);
        n = write_cut(d, err, tau, cl, out.data(), nullptr);
        if (warm) cut_s.push_back(seconds_since(t0));
      }
      for (int warm = 0; warm < 2; ++warm) {
        t0 = clk::now();
        group_errors(d, cam.position, focal, znear, true, err);
        const double tt = bisect_tau(d, err, visible_counts(d, cl), target, cand);
        n = write_cut(d, err, tt, cl, out.data(), nullptr);
        if (warm) exact_s.push_back(seconds_since(t0));
      }
      for (int warm = 0; warm < 2; ++warm) {
        t0 = clk::now();
        std::memcpy(copy.data(), all.data(), sizeof(std::uint32_t) * all.size());
        if (warm) cp_s.push_back(seconds_since(t0));
        if (copy[static_cast<std::size_t>(r) % copy.size()] != all[static_cast<std::size_t>(r) % copy.size()]) std::abort();
      }
    }
    auto mn = [](std::vector<double> s) { return *std::min_element(s.begin(), s.end()); };
    auto med = [](std::vector<double> s) { std::sort(s.begin(), s.end()); return s[s.size() / 2]; };
    const std::string view = v < 8 ? "orbit0" : "close0";
    for (std::FILE* o : {csv, stdout})
      std::fprintf(o, "timing,%s,%s,0.05,%zu,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", name.c_str(), view.c_str(), n, mn(cut_s), med(cut_s),
                   mn(exact_s), med(exact_s), mn(cp_s), med(cp_s));
    std::printf("# %s %s: cut/memcpy min %.2f median %.2f; exact/memcpy min %.2f median %.2f\n", name.c_str(), view.c_str(),
                mn(cut_s) / mn(cp_s), med(cut_s) / med(cp_s), mn(exact_s) / mn(cp_s), med(exact_s) / med(cp_s));
  }
}

}  // namespace

int pareto_lod_dag(int argc, char** argv) {
  std::string csv_path;
  std::vector<std::string> extra;
  bool builtin = true;
  dag_options opt;
  for (int i = 1; i < argc; ++i) {
    const auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (!std::strcmp(argv[i], "--csv")) csv_path = next();
    else if (!std::strcmp(argv[i], "--mesh")) extra.push_back(next());
    else if (!std::strcmp(argv[i], "--only-given")) builtin = false;
    else if (!std::strcmp(argv[i], "--fraction")) g_fraction = std::atof(next().c_str());
    else if (!std::strcmp(argv[i], "--reps")) g_reps = std::max(1, std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--group")) opt.group = static_cast<std::size_t>(std::max(2, std::atoi(next().c_str())));
    else if (!std::strcmp(argv[i], "--cluster")) opt.cluster = static_cast<std::size_t>(std::clamp(std::atoi(next().c_str()) / 4 * 4, 16, 512));
    else if (!std::strcmp(argv[i], "--error")) opt.error_sum = next() == "sum";
    else if (!std::strcmp(argv[i], "--partition")) opt.kway = next() == "kway";
    else csv_path.clear(), i = argc;
  }
  if (csv_path.empty()) {
    std::fprintf(stderr, "usage: infolerp_pareto lod_dag --csv FILE [--mesh PATH]... [--only-given] [--fraction F] [--group N]"
                 " [--cluster N] [--error max|sum] [--partition recursive|kway] [--reps N]\n");
    return 2;
  }
  std::FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (!csv) return std::fprintf(stderr, "cannot write %s\n", csv_path.c_str()), 1;
  std::fprintf(csv, "kind,mesh,triangles,clusters,groups,levels,terminal_groups,coarsest_triangles,seconds\n");
  std::fprintf(csv, "kind,mesh,method,fraction,view,triangles,cut_triangles,open_edges,psnr_db,ssim,tau\n");
  std::fprintf(csv, "kind,mesh,view,fraction,triangles,cut_min_s,cut_median_s,exact_min_s,exact_median_s,memcpy_min_s,memcpy_median_s\n");
  std::printf("# group %zu clusters, cluster %zu triangles, error %s, METIS %s\n", opt.group, opt.cluster, opt.error_sum ? "sum" : "max",
              opt.kway ? "kway" : "recursive");
  std::vector<std::pair<std::string, std::string>> meshes;
  if (builtin)
    for (const char* name : {"bunny00", "armadillo", "refined_elephant"}) meshes.emplace_back(name, support::cgal_mesh(name));
  for (const std::string& path : extra) {
    const std::size_t slash = path.find_last_of('/'), dot = path.find_last_of('.');
    const std::size_t b = slash == std::string::npos ? 0 : slash + 1;
    meshes.emplace_back(path.substr(b, dot == std::string::npos || dot < b ? std::string::npos : dot - b), path);
  }
  support::enable_flush_to_zero();
  const support::embree_device device;
  for (const auto& [name, path] : meshes) {
    auto m = support::load_mesh(path);
    if (!m.ok()) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), m.error().message().c_str());
      continue;
    }
    mesh_rows(csv, device, name, *m, opt);
  }
  std::fclose(csv);
  return 0;
}
