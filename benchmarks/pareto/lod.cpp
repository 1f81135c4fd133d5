// infolerp_pareto lod --csv FILE [--mesh PATH]... [--reps N] [--amplification A] [--percentile P]
//                     [--only-given] [--no-frames]
// (--amplification, --percentile: the weighting map's λ and α, defaults 100 and 30; --only-given:
// only the --mesh meshes; --no-frames: no frame rows)
//
// View-dependent multiresolution rendering (salient-clustering paper §III.C, §IV) against
// meshoptimizer's meshopt_simplify, the simplifier an engine would otherwise call.
//
// CSV: kind,mesh,method,fraction,triangles,seconds,weighted_distance,hausdorff
//   kind=simplify, per mesh (bunny00, armadillo, refined_elephant, each --mesh) and fraction
//   (0.35, 0.10, 0.05, 0.01 of the triangles): method infolerp (seconds: building the hierarchy
//   plus one selection of its global prefix to that triangle count) or meshoptimizer (one
//   meshopt_simplify call to that count, target_error FLT_MAX, no options). Both keep original
//   vertex positions. Distances, the same code for both: weighted_distance = Σ_v S(v)·d(v) / Σ S,
//   d(v) the distance from original vertex v to the simplified surface and S the mesh saliency
//   (compute_saliency, defaults); hausdorff = the larger of max_v d(v) and the largest distance
//   from a simplified triangle's vertices, edge midpoints and centroid to the original surface.
//   Closest points come from a uniform grid of triangles searched in growing shells (exact).
//   Seconds: the minimum of --reps repetitions, the methods interleaved in one loop.
//   The hierarchy is built with backstop 0.005 (half a percent of the vertices, about 1% of the
//   triangles), so that the 1% row exists, and in one global order (cluster_local_first off, as
//   §III.C simplifies "over the entire mesh"; a uniform prefix of the cluster-local order keeps
//   full-resolution bands along cluster borders); 10 salient clusters, default weighting map.
//   The frame rows use the default hierarchy (cluster-local phase first).
//   kind=frame, mesh refined_elephant_x4 (refined_elephant subdivided once 1:4 at edge
//   midpoints, 355,712 triangles), fraction 0.05, 0.35, 0.60 of the triangles: method update
//   (view_dependent_lod::frame: importance, eq. 9, matching, contraction into the index buffer;
//   serial executor; camera 2 diagonals above the box centre; global budget (1 − f)·T/2
//   contractions), memcpy (the full-resolution index buffer), meshoptimizer (meshopt_simplify to
//   the triangle count update produced, from scratch); minimum over --reps repetitions
//   interleaved in one loop. Distances are left empty for frame rows. stdout also gives the
//   update with openmp_executor{2} (checked to produce the same index buffer) and medians.
// stdout: the same rows plus memory of the hierarchy in bytes per triangle and the ratios.
#include <meshoptimizer.h>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/vertex_contraction.hpp"
#include "infolerp/lod/view_dependent_lod.hpp"
#include "infolerp/lod/weighting_map.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"
#include "pareto.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"

namespace {

using namespace infolerp;
using clk = std::chrono::steady_clock;

double seconds_since(clk::time_point t0) { return std::chrono::duration<double>(clk::now() - t0).count(); }

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection §5.1.5).
glm::dvec3 closest_on_triangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Exact point-to-surface distance through a uniform grid of triangle boxes.
class surface_distance {
 public:
  surface_distance(const std::vector<glm::vec3>& pos, std::span<const std::uint32_t> idx) : pos_(pos), idx_(idx) {
    bounding_box box;
    for (std::uint32_t v : idx) box.extend(glm::dvec3(pos[v]));
    lo_ = box.lo;
    const std::size_t nt = idx.size() / 3;
    const glm::dvec3 ext = box.hi - box.lo;
    h_ = std::max(std::cbrt(ext.x * ext.y * ext.z / std::max<double>(1.0, static_cast<double>(nt))), 1e-9 * box.diagonal());
    for (int a = 0; a < 3; ++a) n_[a] = std::max(1, static_cast<int>(std::ceil(ext[a] / h_)));
    cells_.resize(static_cast<std::size_t>(n_[0]) * static_cast<std::size_t>(n_[1]) * static_cast<std::size_t>(n_[2]));
    for (std::size_t t = 0; t < nt; ++t) {
      glm::dvec3 l(std::numeric_limits<double>::max()), u(-std::numeric_limits<double>::max());
      for (int j = 0; j < 3; ++j) {
        l = glm::min(l, glm::dvec3(pos[idx[3 * t + static_cast<std::size_t>(j)]]));
        u = glm::max(u, glm::dvec3(pos[idx[3 * t + static_cast<std::size_t>(j)]]));
      }
      const glm::ivec3 cl = cell(l), cu = cell(u);
      for (int x = cl.x; x <= cu.x; ++x)
        for (int y = cl.y; y <= cu.y; ++y)
          for (int z = cl.z; z <= cu.z; ++z) cells_[index(x, y, z)].push_back(static_cast<std::uint32_t>(t));
    }
    seen_.assign(nt, 0);
  }
  double operator()(const glm::dvec3& p) {
    const glm::ivec3 c = cell(p);
    double best = std::numeric_limits<double>::max();
    ++stamp_;
    const int rmax = std::max({n_[0], n_[1], n_[2]});
    for (int r = 0; r <= rmax; ++r) {
      for (int x = c.x - r; x <= c.x + r; ++x)
        for (int y = c.y - r; y <= c.y + r; ++y)
          for (int z = c.z - r; z <= c.z + r; ++z) {
            if (std::max({std::abs(x - c.x), std::abs(y - c.y), std::abs(z - c.z)}) != r) continue;
            if (x < 0 || y < 0 || z < 0 || x >= n_[0] || y >= n_[1] || z >= n_[2]) continue;
            for (std::uint32_t t : cells_[index(x, y, z)]) {
              if (seen_[t] == stamp_) continue;
              seen_[t] = stamp_;
              const glm::dvec3 q = closest_on_triangle(p, glm::dvec3(pos_[idx_[3 * t]]), glm::dvec3(pos_[idx_[3 * t + 1]]),
                                                       glm::dvec3(pos_[idx_[3 * t + 2]]));
              best = std::min(best, glm::length(q - p));
            }
          }
      if (best <= static_cast<double>(r) * h_) break;  // unsearched cells are at least r·h away
    }
    return best;
  }

 private:
  glm::ivec3 cell(const glm::dvec3& p) const {
    glm::ivec3 c;
    for (int a = 0; a < 3; ++a) c[a] = std::clamp(static_cast<int>(std::floor((p[a] - lo_[a]) / h_)), 0, n_[a] - 1);
    return c;
  }
  std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(x) * static_cast<std::size_t>(n_[1]) + static_cast<std::size_t>(y)) * static_cast<std::size_t>(n_[2]) +
           static_cast<std::size_t>(z);
  }
  const std::vector<glm::vec3>& pos_;
  std::span<const std::uint32_t> idx_;
  glm::dvec3 lo_{0.0};
  double h_ = 1.0;
  int n_[3] = {1, 1, 1};
  std::vector<std::vector<std::uint32_t>> cells_;
  std::vector<std::uint32_t> seen_;
  std::uint32_t stamp_ = 0;
};

struct distances {
  double weighted = 0.0, hausdorff = 0.0;
};

distances measure(const indexed_mesh& m, const std::vector<double>& saliency, std::span<const std::uint32_t> simplified) {
  distances out;
  surface_distance to_simplified(m.positions, simplified);
  std::vector<char> used(m.vertex_count(), 0);
  for (const auto& t : m.triangles) used[t.x] = used[t.y] = used[t.z] = 1;
  double num = 0.0, den = 0.0;
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    if (!used[v]) continue;
    const double d = to_simplified(glm::dvec3(m.positions[v]));
    num += saliency[v] * d, den += saliency[v];
    out.hausdorff = std::max(out.hausdorff, d);
  }
  out.weighted = den > 0.0 ? num / den : 0.0;
  const std::span<const std::uint32_t> original(reinterpret_cast<const std::uint32_t*>(m.triangles.data()), 3 * m.triangle_count());
  surface_distance to_original(m.positions, original);
  for (std::size_t k = 0; k < simplified.size(); k += 3) {
    const glm::dvec3 a(m.positions[simplified[k]]), b(m.positions[simplified[k + 1]]), c(m.positions[simplified[k + 2]]);
    for (const glm::dvec3& p : {a, b, c, 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a), (a + b + c) / 3.0})
      out.hausdorff = std::max(out.hausdorff, to_original(p));
  }
  return out;
}

struct prepared {
  std::vector<double> saliency;
  salient_clusters clusters;
  std::vector<double> weights;
};

weighting_map_options g_weighting;  // --amplification, --percentile

bool prepare(const indexed_mesh& m, prepared& p) {
  auto sal = compute_saliency(m);
  if (!sal.ok()) return std::fprintf(stderr, "saliency: %s\n", sal.error().message().c_str()), false;
  p.saliency = sal->saliency;
  auto cl = salient_clustering(m, p.saliency, {.clusters = 10});
  if (!cl.ok()) return std::fprintf(stderr, "clustering: %s\n", cl.error().message().c_str()), false;
  p.clusters = std::move(*cl);
  auto w = weighting_map(m, p.saliency, p.clusters.cluster, p.clusters.count, g_weighting);
  if (!w.ok()) return std::fprintf(stderr, "weighting map: %s\n", w.error().message().c_str()), false;
  p.weights = std::move(*w);
  return true;
}

// Contractions of the global prefix that bring the triangle count to <= target.
std::uint32_t prefix_for(const contraction_hierarchy& h, std::size_t target) {
  std::size_t tris = h.triangle_count();
  std::uint32_t k = 0;
  while (tris > target && k < h.contraction_count()) tris -= h.faces_removed[k++];
  return k;
}

void row(std::FILE* csv, const char* kind, const std::string& mesh, const char* method, double f, std::size_t tris,
         double sec, const distances* d) {
  for (std::FILE* o : {csv, stdout}) {
    std::fprintf(o, "%s,%s,%s,%.2f,%zu,%.6g,", kind, mesh.c_str(), method, f, tris, sec);
    if (d) std::fprintf(o, "%.6g,%.6g\n", d->weighted, d->hausdorff);
    else std::fprintf(o, ",\n");
  }
  std::fflush(csv);
}

void simplify_rows(std::FILE* csv, const std::string& name, const indexed_mesh& m, int reps) {
  prepared p;
  if (!prepare(m, p)) return;
  const std::size_t nt = m.triangle_count();
  const std::array<double, 4> fractions{0.35, 0.10, 0.05, 0.01};
  const auto* idx = reinterpret_cast<const std::uint32_t*>(m.triangles.data());
  std::vector<double> build_s(static_cast<std::size_t>(reps)), mo_s(fractions.size() * static_cast<std::size_t>(reps)), sel_s(mo_s.size());
  std::vector<std::vector<std::uint32_t>> mo_out(fractions.size()), our_out(fractions.size());
  contraction_hierarchy h;
  for (int r = 0; r < reps; ++r) {
    auto t0 = clk::now();
    auto built = build_contraction_hierarchy(m, p.weights, p.clusters.cluster, p.clusters.count, {.backstop = 0.005, .cluster_local_first = false});
    build_s[static_cast<std::size_t>(r)] = seconds_since(t0);
    if (!built.ok()) return void(std::fprintf(stderr, "%s: %s\n", name.c_str(), built.error().message().c_str()));
    h = std::move(*built);
    contraction_workspace w = make_contraction_workspace(h);
    std::vector<index_range> ranges(h.cluster_count);
    for (std::size_t i = 0; i < fractions.size(); ++i) {
      const auto target = static_cast<std::size_t>(std::lround(fractions[i] * static_cast<double>(nt)));
      auto& ours = our_out[i];
      ours.resize(contracted_index_bound(h));
      t0 = clk::now();
      const std::vector<std::uint32_t> stop(h.cluster_count, prefix_for(h, target));
      auto n = contract_indices(h, stop, w, ours, ranges);
      sel_s[i * static_cast<std::size_t>(reps) + static_cast<std::size_t>(r)] = seconds_since(t0);
      ours.resize(n.ok() ? *n : 0);
      auto& mo = mo_out[i];
      mo.resize(3 * nt);
      t0 = clk::now();
      const std::size_t k = meshopt_simplify(mo.data(), idx, 3 * nt, &m.positions[0].x, m.vertex_count(), sizeof(glm::vec3),
                                             3 * target, std::numeric_limits<float>::max(), 0, nullptr);
      mo_s[i * static_cast<std::size_t>(reps) + static_cast<std::size_t>(r)] = seconds_since(t0);
      mo.resize(k);
    }
  }
  const double build_min = *std::min_element(build_s.begin(), build_s.end());
  std::printf("# %s: %zu triangles, %zu contractions, build min %.4f s median %.4f s, hierarchy %.2f bytes/triangle\n",
              name.c_str(), nt, h.contraction_count(), build_min,
              [&] { auto v = build_s; std::sort(v.begin(), v.end()); return v[v.size() / 2]; }(),
              static_cast<double>(h.memory_bytes()) / static_cast<double>(nt));
  for (std::size_t i = 0; i < fractions.size(); ++i) {
    auto mn = [&](const std::vector<double>& s) {
      return *std::min_element(s.begin() + static_cast<long>(i) * reps, s.begin() + static_cast<long>(i + 1) * reps);
    };
    const distances ours = measure(m, p.saliency, our_out[i]);
    const distances theirs = measure(m, p.saliency, mo_out[i]);
    row(csv, "simplify", name, "infolerp", fractions[i], our_out[i].size() / 3, build_min + mn(sel_s), &ours);
    row(csv, "simplify", name, "meshoptimizer", fractions[i], mo_out[i].size() / 3, mn(mo_s), &theirs);
  }
}

void frame_rows(std::FILE* csv, int reps) {
  auto base = support::load_mesh(support::cgal_mesh("refined_elephant"));
  if (!base.ok()) return void(std::fprintf(stderr, "%s\n", base.error().message().c_str()));
  const indexed_mesh m = support::subdivide_midpoint(*base);
  prepared p;
  if (!prepare(m, p)) return;
  const auto t0 = clk::now();
  auto h = build_contraction_hierarchy(m, p.weights, p.clusters.cluster, p.clusters.count);
  const double build = seconds_since(t0);
  if (!h.ok()) return void(std::fprintf(stderr, "%s\n", h.error().message().c_str()));
  auto table = compute_cluster_attributes(m, p.saliency, p.clusters.cluster, p.clusters.count);
  if (!table.ok()) return void(std::fprintf(stderr, "%s\n", table.error().message().c_str()));
  auto lod = view_dependent_lod::create(*h, *table);
  if (!lod.ok()) return void(std::fprintf(stderr, "%s\n", lod.error().message().c_str()));
  const std::size_t nt = m.triangle_count();
  std::printf("# refined_elephant_x4: %zu triangles, %zu vertices, hierarchy built in %.3f s, %.2f bytes/triangle\n", nt,
              m.vertex_count(), build, static_cast<double>(h->memory_bytes()) / static_cast<double>(nt));
  const bounding_box box = mesh_bounds(m);
  const glm::dvec3 camera = box.center() + glm::dvec3(0.0, 0.0, 2.0 * box.diagonal());
  const auto* idx = reinterpret_cast<const std::uint32_t*>(m.triangles.data());
  std::vector<std::uint32_t> out(contracted_index_bound(*h)), out2(out.size()), copy(3 * nt), mo(3 * nt);
  std::vector<index_range> ranges(h->cluster_count);
  for (double f : {0.05, 0.35, 0.60}) {
    const auto budget = std::min<std::uint64_t>(lod->capacity(),
                                                static_cast<std::uint64_t>((1.0 - f) * static_cast<double>(nt) / 2.0));
    double upd = 1e30, upd2 = 1e30, cp = 1e30, ms = 1e30;
    std::vector<double> upd_all, cp_all;
    std::size_t tris = 0, mo_tris = 0;
    for (int r = 0; r < reps; ++r) {
      auto t = clk::now();
      auto st = lod->frame(camera, budget, out, ranges);
      upd = std::min(upd, seconds_since(t));
      upd_all.push_back(seconds_since(t));
      if (!st.ok()) return void(std::fprintf(stderr, "%s\n", st.error().message().c_str()));
      tris = st->indices / 3;
      if (r == 0)
        std::printf("# fraction %.2f: budget %llu contractions, eq. 9 gave %llu, applied after matching %llu (%u sweeps, %zu cross-cluster dependencies)\n",
                    f, static_cast<unsigned long long>(budget), static_cast<unsigned long long>(st->budgeted),
                    static_cast<unsigned long long>(st->applied), st->matching_sweeps, h->cross.size());
      t = clk::now();
      std::memcpy(copy.data(), idx, sizeof(std::uint32_t) * 3 * nt);
      cp = std::min(cp, seconds_since(t));
      cp_all.push_back(seconds_since(t));
      t = clk::now();
      auto st2 = lod->frame(camera, budget, out2, ranges, openmp_executor{2});
      upd2 = std::min(upd2, seconds_since(t));
      if (!st2.ok() || st2->indices != st->indices || !std::equal(out.begin(), out.begin() + static_cast<long>(st->indices), out2.begin()))
        return void(std::fprintf(stderr, "two threads gave another index buffer\n"));
      if (copy[static_cast<std::size_t>(r % 7)] != idx[r % 7]) std::abort();  // keeps the copy
      t = clk::now();
      mo_tris = meshopt_simplify(mo.data(), idx, 3 * nt, &m.positions[0].x, m.vertex_count(), sizeof(glm::vec3), 3 * tris,
                                 std::numeric_limits<float>::max(), 0, nullptr) / 3;
      ms = std::min(ms, seconds_since(t));
    }
    row(csv, "frame", "refined_elephant_x4", "update", f, tris, upd, nullptr);
    row(csv, "frame", "refined_elephant_x4", "memcpy", f, nt, cp, nullptr);
    row(csv, "frame", "refined_elephant_x4", "meshoptimizer", f, mo_tris, ms, nullptr);
    auto median = [](std::vector<double> v) { std::sort(v.begin(), v.end()); return v[v.size() / 2]; };
    std::printf("# fraction %.2f: update/memcpy %.2f (medians %.2f), meshoptimizer/update %.1f; update with 2 OpenMP threads %.6g s, "
                "/memcpy %.2f (identical index buffer)\n",
                f, upd / cp, median(upd_all) / median(cp_all), ms / upd, upd2, upd2 / cp);
  }
}

}  // namespace

int pareto_lod(int argc, char** argv) {
  std::string csv_path;
  std::vector<std::string> extra;
  int reps = 5;
  bool builtin = true, frames = true;
  for (int i = 1; i < argc; ++i) {
    const auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (!std::strcmp(argv[i], "--csv")) csv_path = next();
    else if (!std::strcmp(argv[i], "--mesh")) extra.push_back(next());
    else if (!std::strcmp(argv[i], "--reps")) reps = std::max(1, std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--amplification")) g_weighting.amplification = std::atof(next().c_str());
    else if (!std::strcmp(argv[i], "--percentile")) g_weighting.amplify_percentile = std::atof(next().c_str());
    else if (!std::strcmp(argv[i], "--only-given")) builtin = false;
    else if (!std::strcmp(argv[i], "--no-frames")) frames = false;
    else {
      std::fprintf(stderr, "usage: infolerp_pareto lod --csv FILE [--mesh PATH]... [--reps N] [--amplification A]"
                   " [--percentile P] [--only-given] [--no-frames]\n");
      return 2;
    }
  }
  if (csv_path.empty()) {
    std::fprintf(stderr, "usage: infolerp_pareto lod --csv FILE [--mesh PATH]... [--reps N]\n");
    return 2;
  }
  std::FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (!csv) return std::fprintf(stderr, "cannot write %s\n", csv_path.c_str()), 1;
  std::fprintf(csv, "kind,mesh,method,fraction,triangles,seconds,weighted_distance,hausdorff\n");
  std::vector<std::pair<std::string, std::string>> meshes;
  if (builtin)
    for (const char* name : {"bunny00", "armadillo", "refined_elephant"}) meshes.emplace_back(name, support::cgal_mesh(name));
  for (const std::string& path : extra) {
    const std::size_t slash = path.find_last_of('/'), dot = path.find_last_of('.');
    const std::size_t b = slash == std::string::npos ? 0 : slash + 1;
    meshes.emplace_back(path.substr(b, dot == std::string::npos || dot < b ? std::string::npos : dot - b), path);
  }
  for (const auto& [name, path] : meshes) {
    auto m = support::load_mesh(path);
    if (!m.ok()) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), m.error().message().c_str());
      continue;
    }
    simplify_rows(csv, name, *m, reps);
  }
  if (frames) frame_rows(csv, reps);
  std::fclose(csv);
  return 0;
}
