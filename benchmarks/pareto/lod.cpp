// infolerp_pareto lod --csv FILE [--mesh PATH]... [--reps N] [--amplification A] [--percentile P]
//                     [--only-given] [--no-frames] [--no-simplify] [--no-views] [--fraction F]
//                     [--clusters N] [--hidden W] [--silhouette W] [--near F]
// (--amplification, --percentile: the weighting map's λ and α, defaults 1 and 30; --only-given:
// only the --mesh meshes; --no-frames, --no-simplify, --no-views: leave out those rows;
// --fraction: view rows of that fraction only; --clusters: salient clusters, default 10 as the
// paper; --hidden, --silhouette, --near: view_weight_options of the default selection)
//
// View-dependent multiresolution rendering (salient-clustering paper §III.C, §IV) against
// meshoptimizer's meshopt_simplify, the simplifier an engine would otherwise call.
//
// CSV: kind,mesh,method,fraction,triangles,seconds,weighted_distance,hausdorff,psnr,ssim
//   kind=simplify, per mesh (bunny00, armadillo, refined_elephant, each --mesh) and fraction
//   (0.35, 0.10, 0.05, 0.01 of the triangles): method infolerp (seconds: building the hierarchy
//   plus one selection of its global prefix to that triangle count) or meshoptimizer (one
//   meshopt_simplify call to that count, target_error FLT_MAX, no options). Both keep original
//   vertex positions. Distances, the same code for both: weighted_distance = Σ_v S(v)·d(v) / Σ S,
//   d(v) the distance from original vertex v to the simplified surface and S the mesh saliency
//   (compute_saliency, defaults); hausdorff = the larger of max_v d(v) and the largest distance
//   from a simplified triangle's vertices, edge midpoints and centroid to the original surface
//   (support/surface_distance.hpp). psnr, ssim: the means over 8 views of the reference shader's
//   256x256 images (AO 16, soft shadow 4 rays) of the simplified mesh against the full mesh's
//   (support/mesh_views.hpp); empty for frame rows.
//   Seconds: the minimum of --reps repetitions, the methods interleaved in one loop.
//   The hierarchy is built with backstop 0.005 (half a percent of the vertices, about 1% of the
//   triangles), so that the 1% row exists, and in one global order (cluster_local_first off, as
//   §III.C simplifies "over the entire mesh"; a uniform prefix of the cluster-local order keeps
//   full-resolution bands along cluster borders); 10 salient clusters, default weighting map.
//   The frame rows use the default hierarchy (one global order).
//   kind=frame, mesh refined_elephant_x4 (refined_elephant subdivided once 1:4 at edge
//   midpoints, 355,712 triangles), fraction 0.05, 0.35, 0.60 of the triangles: method update
//   (view_dependent_lod::frame at most that fraction of the triangles drawn: selection, culling,
//   contraction into the index buffer; serial executor; camera 2 diagonals above the box
//   centre), memcpy (the full-resolution index buffer), meshoptimizer (meshopt_simplify to the
//   triangle count update produced, from scratch); minimum over --reps repetitions interleaved
//   in one loop, each timed update and memcpy right after an untimed one (warm). Distances are
//   left empty for frame rows. stdout also gives the update with openmp_executor{2} (checked to
//   produce the same index buffer) and medians.
//   kind=motion (a header line of its own: kind,mesh,motion,fraction,frames,
//   update_over_memcpy_mean,update_over_memcpy_worst): frame() at 5% of refined_elephant_x4 for
//   a camera that moves every frame (motion_rows below: repeat, orbit5, walk), each frame's
//   update over the fastest memcpy of the full index buffer, per frame the minimum over --reps
//   passes of the path; mean and worst frame.
//   kind=view (a second header line gives its columns: kind,mesh,method,fraction,view,triangles,
//   psnr_db,ssim,weighted_distance,salient_distance,seconds,psnr_self_db), per mesh, fraction and camera:
//   cameras orbit0..7 (those of support/mesh_views.hpp, whole mesh in frame) and close0..7
//   (between them, at 1.2 bounding radii from the box centre: the mesh overflows the frustum);
//   methods, all at the triangle count infolerp drew for that camera:
//     infolerp          what a user gets from the default entry point: view_dependent_lod::frame
//                       with default options (culling included) on the default hierarchy (backstop
//                       0.005), at most the fraction's count of triangles drawn;
//     infolerp_paper    lod_selection::paper on a cluster-local-first hierarchy, its budget
//                       searched so that it draws at most infolerp's count;
//     meshopt_culled    the goal's peer: a uniform meshopt_simplify LOD culled per triangle by
//                       the same test (support/lod_peers.hpp), the largest that draws at most
//                       infolerp's count;
//     meshopt_meshlets  that LOD in meshlets (64 vertices / 124 triangles, cone weight 0.25),
//                       culled per meshlet by sphere-frustum and normal cone: a mesh-shader engine;
//     meshoptimizer     context only: meshopt_simplify of the whole mesh to infolerp's count,
//                       drawn whole (no culling).
//   triangles: drawn. psnr_db, ssim: that camera's 256x256
//   reference-shader image against the full mesh's, primary hits and shading normals from the
//   method's drawn triangles, shadow and AO rays against the full mesh for every method alike;
//   (their back faces ignored, so that a coarse surface just inside the full one is not shadowed
//   by it); psnr_self_db: those rays against the drawn triangles (both faces), against the full
//   mesh's image made alike; weighted_distance and salient_distance measure the whole LOD (the
//   frame's cut, drawn and culled; a peer's whole simplified mesh; meshoptimizer's mesh);
//   weighted_distance: Σ S(v)·d(v) / Σ S over the vertices, salient_distance: the same
//   over the 10% most salient vertices (d: distance to the simplified surface); seconds: the
//   per-frame step (one frame() call; a peer's culling pass over its LOD; meshopt_simplify for
//   meshoptimizer).
// stdout: the same rows plus memory of the hierarchy in bytes per triangle and the ratios, and
// the mean PSNR per mesh, fraction and camera set.
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
#include <optional>
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
#include "support/lod_peers.hpp"
#include "support/mesh_io.hpp"
#include "support/mesh_views.hpp"
#include "support/procedural.hpp"
#include "support/surface_distance.hpp"

namespace {

using namespace infolerp;
using clk = std::chrono::steady_clock;
using support::distances;
using support::measure;

double seconds_since(clk::time_point t0) { return std::chrono::duration<double>(clk::now() - t0).count(); }

struct prepared {
  std::vector<double> saliency;
  salient_clusters clusters;
  std::vector<double> weights;
};

weighting_map_options g_weighting;  // --amplification, --percentile
std::uint32_t g_clusters = 10;      // --clusters: salient clusters (the paper: 10)

bool prepare(const indexed_mesh& m, prepared& p) {
  auto sal = compute_saliency(m);
  if (!sal.ok()) return std::fprintf(stderr, "saliency: %s\n", sal.error().message().c_str()), false;
  p.saliency = sal->saliency;
  auto cl = salient_clustering(m, p.saliency, {.clusters = g_clusters});
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
         double sec, const distances* d, const support::view_similarity* v = nullptr) {
  for (std::FILE* o : {csv, stdout}) {
    std::fprintf(o, "%s,%s,%s,%.2f,%zu,%.6g,", kind, mesh.c_str(), method, f, tris, sec);
    if (d) std::fprintf(o, "%.6g,%.6g,", d->weighted, d->hausdorff);
    else std::fprintf(o, ",,");
    if (v) std::fprintf(o, "%.4f,%.6f\n", v->psnr, v->ssim);
    else std::fprintf(o, ",\n");
  }
  std::fflush(csv);
}

// Mean PSNR / SSIM of the 8 reference-shader views of a simplified index buffer against those
// of the full mesh (support/mesh_views.hpp); nothing when rendering fails (reported).
std::optional<support::view_similarity> view_scores(const support::embree_device& device, const indexed_mesh& m,
                                                    std::span<const std::uint32_t> simplified,
                                                    const std::vector<support::image>& full) {
  auto views = support::render_mesh_views(device, m.positions, simplified);
  if (!views) return std::fprintf(stderr, "views: %s\n", views.error().message().c_str()), std::nullopt;
  auto sim = support::compare_views(*views, full);
  if (!sim) return std::fprintf(stderr, "views: %s\n", sim.error().message().c_str()), std::nullopt;
  return *sim;
}

void simplify_rows(std::FILE* csv, const support::embree_device& device, const std::string& name, const indexed_mesh& m,
                   int reps) {
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
    auto built = make_contraction_hierarchy(m, p.weights, p.clusters.cluster, p.clusters.count, {.backstop = 0.005, .cluster_local_first = false});
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
  const std::span<const std::uint32_t> original(reinterpret_cast<const std::uint32_t*>(m.triangles.data()), 3 * nt);
  auto full_views = support::render_mesh_views(device, m.positions, original);
  if (!full_views) return void(std::fprintf(stderr, "views: %s\n", full_views.error().message().c_str()));
  for (std::size_t i = 0; i < fractions.size(); ++i) {
    auto mn = [&](const std::vector<double>& s) {
      return *std::min_element(s.begin() + static_cast<long>(i) * reps, s.begin() + static_cast<long>(i + 1) * reps);
    };
    const distances ours = measure(m, p.saliency, our_out[i]);
    const distances theirs = measure(m, p.saliency, mo_out[i]);
    const auto our_views = view_scores(device, m, our_out[i], *full_views);
    const auto their_views = view_scores(device, m, mo_out[i], *full_views);
    row(csv, "simplify", name, "infolerp", fractions[i], our_out[i].size() / 3, build_min + mn(sel_s), &ours,
        our_views ? &*our_views : nullptr);
    row(csv, "simplify", name, "meshoptimizer", fractions[i], mo_out[i].size() / 3, mn(mo_s), &theirs,
        their_views ? &*their_views : nullptr);
  }
}

// kind=motion rows: frame() at 5% for a camera that moves every frame, each frame's update
// against a memcpy of the full index buffer timed beside it. Paths: repeat (the frame rows'
// camera, 72 frames), orbit5 (72 frames around the box centre at 2 diagonals, 5° a frame) and
// walk (120 frames: the eye travels 1% of the diagonal a frame towards and past the mesh, the
// view turning 1° a frame). Frame 0 of each repetition sets the state and is not timed; per
// frame the minimum over repetitions; mean and worst over the frames.
void motion_rows(std::FILE* csv, view_dependent_lod& lod, const indexed_mesh& m, int reps) {
  const bounding_box box = mesh_bounds(m);
  const glm::dvec3 c = box.center();
  const double diag = box.diagonal(), deg = 3.141592653589793 / 180.0;
  const std::size_t nt = m.triangle_count();
  const auto budget = static_cast<std::uint64_t>(0.05 * static_cast<double>(nt));
  const auto* idx = reinterpret_cast<const std::uint32_t*>(m.triangles.data());
  std::vector<std::uint32_t> out(3 * nt + 3), copy(3 * nt);
  std::vector<index_range> ranges(lod.stop_points().size());
  struct path {
    const char* name;
    std::vector<lod_camera> cams;
  };
  std::vector<path> paths(3);
  paths[0].name = "repeat", paths[1].name = "orbit5", paths[2].name = "walk";
  const glm::dvec3 still = c + glm::dvec3(0.0, 0.0, 2.0 * diag);
  for (int i = 0; i < 72; ++i) {
    paths[0].cams.push_back({still, c - still, {0.0, 1.0, 0.0}, 0.7, 1024, 1024});
    const double a = 5.0 * deg * i;
    const glm::dvec3 eye = c + 2.0 * diag * glm::dvec3(std::sin(a), 0.3, std::cos(a));
    paths[1].cams.push_back({eye, c - eye, {0.0, 1.0, 0.0}, 0.7, 1024, 1024});
  }
  const glm::dvec3 start = c + diag * glm::dvec3(0.3, 0.1, 1.5), look = c - start;
  for (int i = 0; i < 120; ++i) {
    const double a = deg * i;
    const glm::dvec3 fwd(look.x * std::cos(a) + look.z * std::sin(a), look.y, -look.x * std::sin(a) + look.z * std::cos(a));
    paths[2].cams.push_back({start + glm::dvec3(0.0, 0.0, -0.01 * diag * i), fwd, {0.0, 1.0, 0.0}, 0.7, 1024, 1024});
  }
  auto median = [](std::vector<double> v) { std::sort(v.begin(), v.end()); return v[v.size() / 2]; };
  for (const path& pth : paths) {
    const std::size_t n = pth.cams.size();
    std::vector<double> upd(n, 1e30), cp_all;
    std::vector<std::vector<double>> upd_all(n);
    for (int r = 0; r < reps; ++r)
      for (std::size_t i = 0; i < n; ++i) {
        auto t = clk::now();
        auto st = lod.frame(pth.cams[i], budget, out, ranges);
        const double u = seconds_since(t);
        if (!st.ok()) return void(std::fprintf(stderr, "%s\n", st.error().message().c_str()));
        std::memcpy(copy.data(), idx, sizeof(std::uint32_t) * 3 * nt);
        if (copy[i % 5] != idx[i % 5]) std::abort();  // keeps the copy
        t = clk::now();
        std::memcpy(copy.data(), idx, sizeof(std::uint32_t) * 3 * nt);
        cp_all.push_back(seconds_since(t));
        if (copy[i % 7] != idx[i % 7]) std::abort();
        if (i == 0) continue;  // sets the state
        upd[i] = std::min(upd[i], u);
        upd_all[i].push_back(u);
      }
    const double cp = *std::min_element(cp_all.begin(), cp_all.end()), cp_med = median(cp_all);
    double mean = 0.0, worst = 0.0, mean_med = 0.0, worst_med = 0.0;
    for (std::size_t i = 1; i < n; ++i) {
      mean += upd[i] / cp / static_cast<double>(n - 1), worst = std::max(worst, upd[i] / cp);
      const double um = median(upd_all[i]) / cp_med;
      mean_med += um / static_cast<double>(n - 1), worst_med = std::max(worst_med, um);
    }
    for (std::FILE* o : {csv, stdout})
      std::fprintf(o, "motion,refined_elephant_x4,%s,0.05,%zu,%.4f,%.4f\n", pth.name, n, mean, worst);
    std::printf("# motion %s: update/memcpy mean %.2f worst %.2f (minima over %d repetitions); medians: mean %.2f worst %.2f\n",
                pth.name, mean, worst, reps, mean_med, worst_med);
    std::fflush(csv);
  }
}

void frame_rows(std::FILE* csv, int reps) {
  auto base = support::load_mesh(support::cgal_mesh("refined_elephant"));
  if (!base.ok()) return void(std::fprintf(stderr, "%s\n", base.error().message().c_str()));
  const indexed_mesh m = support::subdivide_midpoint(*base);
  prepared p;
  if (!prepare(m, p)) return;
  const auto t0 = clk::now();
  auto h = make_contraction_hierarchy(m, p.weights, p.clusters.cluster, p.clusters.count);
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
  const glm::dvec3 eye = box.center() + glm::dvec3(0.0, 0.0, 2.0 * box.diagonal());
  const lod_camera camera{eye, box.center() - eye, {0.0, 1.0, 0.0}, 0.7, 1024, 1024};
  const auto* idx = reinterpret_cast<const std::uint32_t*>(m.triangles.data());
  std::vector<std::uint32_t> out(contracted_index_bound(*h)), out2(out.size()), copy(3 * nt), mo(3 * nt);
  std::vector<index_range> ranges(h->cluster_count);
  for (double f : {0.05, 0.35, 0.60}) {
    const auto budget = static_cast<std::uint64_t>(f * static_cast<double>(nt));
    double upd = 1e30, upd2 = 1e30, cp = 1e30, ms = 1e30;
    std::vector<double> upd_all, cp_all;
    std::size_t tris = 0, mo_tris = 0;
    for (int r = 0; r < reps; ++r) {
      // Each timed call follows an untimed one of the same kind, so update and memcpy both run
      // with their data as warm as a frame loop leaves it (meshopt_simplify, which reads the
      // same index buffer as memcpy but evicts the hierarchy, must not favour one of them).
      if (!lod->frame(camera, budget, out, ranges).ok()) return void(std::fprintf(stderr, "frame failed\n"));
      auto t = clk::now();
      auto st = lod->frame(camera, budget, out, ranges);
      upd = std::min(upd, seconds_since(t));
      upd_all.push_back(seconds_since(t));
      if (!st.ok()) return void(std::fprintf(stderr, "%s\n", st.error().message().c_str()));
      tris = st->indices / 3;
      if (r == 0)
        std::printf("# fraction %.2f: budget %llu triangles, %llu contractions before matching, applied %llu (%u selection rounds, %zu cross-cluster dependencies)\n",
                    f, static_cast<unsigned long long>(budget), static_cast<unsigned long long>(st->budgeted),
                    static_cast<unsigned long long>(st->applied), st->matching_sweeps, h->cross.size());
      std::memcpy(copy.data(), idx, sizeof(std::uint32_t) * 3 * nt);
      if (copy[static_cast<std::size_t>(r % 5)] != idx[r % 5]) std::abort();  // keeps the copy
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
  motion_rows(csv, *lod, m, reps);
}

// Original vertex → simplified surface distances: saliency-weighted mean over all vertices and
// over the 10% most salient (one direction only; measure() adds the Hausdorff distance).
struct view_distances {
  double weighted = 0.0, salient = 0.0;
};

view_distances vertex_distances(const indexed_mesh& m, const std::vector<double>& saliency, double salient_cut,
                                std::span<const std::uint32_t> simplified) {
  support::surface_distance to_simplified(m.positions, simplified);
  double num = 0.0, den = 0.0, snum = 0.0, sden = 0.0;
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    if (saliency[v] <= 0.0) continue;
    const double d = to_simplified(glm::dvec3(m.positions[v]));
    num += saliency[v] * d, den += saliency[v];
    if (saliency[v] >= salient_cut) snum += saliency[v] * d, sden += saliency[v];
  }
  return {den > 0.0 ? num / den : 0.0, sden > 0.0 ? snum / sden : 0.0};
}

double g_view_fraction = 0.0;  // --fraction: only this one (0: all)
lod_options g_lod;             // --hidden, --silhouette, --near: the view weights of the default selection

// The largest budget whose frame draws at most `drawn` triangles (the paper's selection at our
// drawn count): secant steps on the drawn share, then bisection.
result<std::uint64_t> budget_drawing(view_dependent_lod& l, const lod_camera& cam, std::size_t nt, std::size_t drawn,
                                      std::vector<std::uint32_t>& out, std::vector<index_range>& ranges) {
  std::uint64_t lo = 0, hi = nt + 1, b = drawn, best = 0;
  for (int step = 0; step < 40 && hi - lo > std::max<std::uint64_t>(1, drawn / 1000); ++step) {
    auto st = l.frame(cam, b, out, ranges);
    if (!st.ok()) return st.error();
    const std::uint64_t got = st->indices / 3;
    if (got <= drawn) lo = b, best = b;
    else hi = b;
    if (got == drawn || (got <= drawn && b >= nt)) break;
    std::uint64_t next = step < 4 && got > 0 ? static_cast<std::uint64_t>(static_cast<double>(b) * static_cast<double>(drawn) / static_cast<double>(got)) : (lo + hi) / 2;
    if (next <= lo || next >= hi) next = lo + (hi - lo) / 2;
    if (next == lo) break;
    b = next;
  }
  return best;
}

// kind=view rows (see the top of the file).
void view_rows(std::FILE* csv, const support::embree_device& device, const std::string& name, const indexed_mesh& m) {
  prepared p;
  if (!prepare(m, p)) return;
  const std::size_t nt = m.triangle_count();
  auto table = compute_cluster_attributes(m, p.saliency, p.clusters.cluster, p.clusters.count);
  if (!table.ok()) return void(std::fprintf(stderr, "%s\n", table.error().message().c_str()));
  auto t0 = clk::now();
  auto h = make_contraction_hierarchy(m, p.weights, p.clusters.cluster, p.clusters.count, {.backstop = 0.005, .cluster_local_first = false});
  const double build = seconds_since(t0);
  auto hp = make_contraction_hierarchy(m, p.weights, p.clusters.cluster, p.clusters.count, {.backstop = 0.005, .cluster_local_first = true});
  if (!h.ok() || !hp.ok()) return void(std::fprintf(stderr, "%s: hierarchy failed\n", name.c_str()));
  auto lod = view_dependent_lod::create(*h, *table, g_lod);
  auto lodp = view_dependent_lod::create(*hp, *table, lod_options{.selection = lod_selection::paper, .view = {}});
  if (!lod.ok() || !lodp.ok()) return void(std::fprintf(stderr, "%s: lod failed\n", name.c_str()));
  const support::cull_source peers = support::make_cull_source(m);
  std::vector<double> sorted = p.saliency;
  std::sort(sorted.begin(), sorted.end());
  const double salient_cut = sorted[static_cast<std::size_t>(0.9 * static_cast<double>(sorted.size()))];
  const std::vector<support::camera> cams = support::lod_view_cameras(m);
  const support::mesh_view_options vopt;  // shadow and AO rays against the drawn triangles
  const std::span<const std::uint32_t> original(reinterpret_cast<const std::uint32_t*>(m.triangles.data()), 3 * nt);
  support::mesh_view_options with_full = vopt;  // ... against the full mesh
  with_full.occluders = original;
  std::vector<support::image> full, full_self;
  for (const support::camera& c : cams) {
    auto img = support::render_mesh_views(device, m.positions, original, std::span<const support::camera>(&c, 1), with_full);
    auto self = support::render_mesh_views(device, m.positions, original, std::span<const support::camera>(&c, 1), vopt);
    if (!img || !self) return void(std::fprintf(stderr, "views: %s\n", (img ? self : img).error().message().c_str()));
    full.push_back(std::move((*img)[0]));
    full_self.push_back(std::move((*self)[0]));
  }
  std::printf("# %s view rows: hierarchy %.3f s, %u clusters\n", name.c_str(), build, p.clusters.count);
  std::vector<std::uint32_t> out(contracted_index_bound(*h)), cut(out.size()), outp(contracted_index_bound(*hp)),
      cutp(outp.size()), mo(3 * nt), mo_cut(3 * nt);
  std::vector<index_range> ranges(h->cluster_count), cut_ranges(h->cluster_count);
  contraction_workspace work = make_contraction_workspace(*h), workp = make_contraction_workspace(*hp);
  static const char* names[] = {"infolerp", "infolerp_paper", "meshopt_culled", "meshopt_meshlets", "meshoptimizer"};
  constexpr int methods = 5;
  for (double f : {0.35, 0.10, 0.05, 0.01}) {
    if (g_view_fraction > 0.0 && std::abs(f - g_view_fraction) > 1e-9) continue;
    const auto target = static_cast<std::size_t>(std::lround(f * static_cast<double>(nt)));
    double psnr_sum[methods] = {}, salient_sum[methods] = {}, worst_culled = 1e30, worst_meshlets = 1e30;
    for (std::size_t v = 0; v < cams.size(); ++v) {
      const lod_camera cam = support::to_lod_camera(cams[v], static_cast<std::uint32_t>(vopt.width));
      const std::string view = (v < 8 ? "orbit" : "close") + std::to_string(v % 8);
      std::size_t drawn = 0;
      double psnr[methods] = {};
      for (int method = 0; method < methods; ++method) {
        std::span<const std::uint32_t> idx, whole;  // drawn; the whole LOD (for the distances)
        double sec = 0.0;
        if (method == 0) {  // what a user gets from the default entry point
          t0 = clk::now();
          auto st = lod->frame(cam, target, out, ranges);
          sec = seconds_since(t0);
          if (!st.ok()) return void(std::fprintf(stderr, "%s: %s\n", name.c_str(), st.error().message().c_str()));
          idx = std::span<const std::uint32_t>(out.data(), st->indices);
          drawn = st->indices / 3;
          auto n = contract_indices(*h, lod->stop_points(), work, cut, cut_ranges);
          if (!n.ok()) return void(std::fprintf(stderr, "%s: %s\n", name.c_str(), n.error().message().c_str()));
          whole = std::span<const std::uint32_t>(cut.data(), *n);
        } else if (method == 1) {  // the paper's eqs. 5-9 at our drawn count
          auto budget = budget_drawing(*lodp, cam, nt, drawn, outp, ranges);
          if (!budget.ok()) return void(std::fprintf(stderr, "%s: %s\n", name.c_str(), budget.error().message().c_str()));
          t0 = clk::now();
          auto st = lodp->frame(cam, *budget, outp, ranges);
          sec = seconds_since(t0);
          if (!st.ok()) return void(std::fprintf(stderr, "%s: %s\n", name.c_str(), st.error().message().c_str()));
          idx = std::span<const std::uint32_t>(outp.data(), st->indices);
          auto n = contract_indices(*hp, lodp->stop_points(), workp, cutp, cut_ranges);
          if (!n.ok()) return void(std::fprintf(stderr, "%s: %s\n", name.c_str(), n.error().message().c_str()));
          whole = std::span<const std::uint32_t>(cutp.data(), *n);
        } else if (method < 4) {  // a uniform LOD with the same culling, per triangle or per meshlet
          support::peer_frame pf = method == 2 ? support::meshopt_culled(peers, cam, drawn) : support::meshopt_meshlets(peers, cam, drawn);
          std::copy(pf.drawn.begin(), pf.drawn.end(), mo.begin());
          std::copy(pf.lod.begin(), pf.lod.end(), mo_cut.begin());
          idx = std::span<const std::uint32_t>(mo.data(), pf.drawn.size());
          whole = std::span<const std::uint32_t>(mo_cut.data(), pf.lod.size());
          sec = pf.cull_seconds;
        } else {  // context only: the whole uniform LOD at our drawn count, nothing culled
          const auto* in = reinterpret_cast<const std::uint32_t*>(m.triangles.data());
          t0 = clk::now();
          const std::size_t k = meshopt_simplify(mo.data(), in, 3 * nt, &m.positions[0].x, m.vertex_count(), sizeof(glm::vec3),
                                                 3 * drawn, std::numeric_limits<float>::max(), 0, nullptr);
          sec = seconds_since(t0);
          idx = whole = std::span<const std::uint32_t>(mo.data(), k);
        }
        // The camera's picture: primary hits and normals from the drawn triangles, shadow and AO
        // rays against the full mesh (as a shadow map or a separate BVH gives an engine); and
        // the self-occluded picture (those rays against the drawn triangles too).
        auto img = support::render_mesh_views(device, m.positions, idx, std::span<const support::camera>(&cams[v], 1), with_full);
        auto self = support::render_mesh_views(device, m.positions, idx, std::span<const support::camera>(&cams[v], 1), vopt);
        if (!img || !self) return void(std::fprintf(stderr, "views: %s\n", (img ? self : img).error().message().c_str()));
        auto sim = support::compare_views(*img, std::vector<support::image>{full[v]});
        auto sim_self = support::compare_views(*self, std::vector<support::image>{full_self[v]});
        if (!sim || !sim_self) return void(std::fprintf(stderr, "views: comparison failed\n"));
        const view_distances d = vertex_distances(m, p.saliency, salient_cut, whole);
        psnr[method] = sim->psnr;
        psnr_sum[method] += sim->psnr, salient_sum[method] += d.salient;
        for (std::FILE* o : {csv, stdout})
          std::fprintf(o, "view,%s,%s,%.2f,%s,%zu,%.4f,%.6f,%.6g,%.6g,%.6g,%.4f\n", name.c_str(), names[method], f,
                       view.c_str(), idx.size() / 3, sim->psnr, sim->ssim, d.weighted, d.salient, sec, sim_self->psnr);
        std::fflush(csv);
      }
      worst_culled = std::min(worst_culled, psnr[0] - psnr[2]);
      worst_meshlets = std::min(worst_meshlets, psnr[0] - psnr[3]);
      if (v == 7 || v == 15) {
        std::printf("# %s %.2f %s: mean PSNR infolerp %.2f, paper %.2f, meshopt_culled %.2f, meshopt_meshlets %.2f, "
                    "meshoptimizer (unculled) %.2f dB; infolerp - meshopt_culled mean %+.2f, worst view %+.2f dB; "
                    "- meshopt_meshlets mean %+.2f, worst %+.2f dB; salient distance infolerp / meshopt_culled %.3f\n",
                    name.c_str(), f, v == 7 ? "orbit" : "close", psnr_sum[0] / 8, psnr_sum[1] / 8, psnr_sum[2] / 8,
                    psnr_sum[3] / 8, psnr_sum[4] / 8, (psnr_sum[0] - psnr_sum[2]) / 8, worst_culled,
                    (psnr_sum[0] - psnr_sum[3]) / 8, worst_meshlets, salient_sum[2] > 0.0 ? salient_sum[0] / salient_sum[2] : 0.0);
        for (int k = 0; k < methods; ++k) psnr_sum[k] = salient_sum[k] = 0.0;
        worst_culled = worst_meshlets = 1e30;
      }
    }
  }
}

}  // namespace

int pareto_lod(int argc, char** argv) {
  std::string csv_path;
  std::vector<std::string> extra;
  int reps = 5;
  bool builtin = true, frames = true, simplify = true, views = true;
  for (int i = 1; i < argc; ++i) {
    const auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (!std::strcmp(argv[i], "--csv")) csv_path = next();
    else if (!std::strcmp(argv[i], "--mesh")) extra.push_back(next());
    else if (!std::strcmp(argv[i], "--reps")) reps = std::max(1, std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--amplification")) g_weighting.amplification = std::atof(next().c_str());
    else if (!std::strcmp(argv[i], "--percentile")) g_weighting.amplify_percentile = std::atof(next().c_str());
    else if (!std::strcmp(argv[i], "--only-given")) builtin = false;
    else if (!std::strcmp(argv[i], "--no-frames")) frames = false;
    else if (!std::strcmp(argv[i], "--no-simplify")) simplify = false;
    else if (!std::strcmp(argv[i], "--no-views")) views = false;
    else if (!std::strcmp(argv[i], "--fraction")) g_view_fraction = std::atof(next().c_str());
    else if (!std::strcmp(argv[i], "--clusters")) g_clusters = static_cast<std::uint32_t>(std::max(1, std::atoi(next().c_str())));
    else if (!std::strcmp(argv[i], "--hidden")) g_lod.view.hidden_weight = std::atof(next().c_str());
    else if (!std::strcmp(argv[i], "--silhouette")) g_lod.view.silhouette_weight = std::atof(next().c_str());
    else if (!std::strcmp(argv[i], "--near")) g_lod.view.near_fraction = std::atof(next().c_str());
    else {
      std::fprintf(stderr, "usage: infolerp_pareto lod --csv FILE [--mesh PATH]... [--reps N] [--amplification A]"
                   " [--percentile P] [--only-given] [--no-frames] [--no-simplify] [--no-views] [--fraction F] [--hidden W]"
                   " [--silhouette W] [--near F] [--clusters N]\n");
      return 2;
    }
  }
  if (csv_path.empty()) {
    std::fprintf(stderr, "usage: infolerp_pareto lod --csv FILE [--mesh PATH]... [--reps N]\n");
    return 2;
  }
  std::FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (!csv) return std::fprintf(stderr, "cannot write %s\n", csv_path.c_str()), 1;
  std::fprintf(csv, "kind,mesh,method,fraction,triangles,seconds,weighted_distance,hausdorff,psnr,ssim\n");
  if (views)
    std::fprintf(csv, "kind,mesh,method,fraction,view,triangles,psnr_db,ssim,weighted_distance,salient_distance,seconds,"
                 "psnr_self_db\n");
  if (frames) std::fprintf(csv, "kind,mesh,motion,fraction,frames,update_over_memcpy_mean,update_over_memcpy_worst\n");
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
    if (simplify) simplify_rows(csv, device, name, *m, reps);
    if (views) view_rows(csv, device, name, *m);
  }
  if (frames) frame_rows(csv, reps);
  std::fclose(csv);
  return 0;
}
