#pragma once
// Demo stage: view-dependent multiresolution rendering (salient-clustering paper §III.C, §IV)
// of one mesh: the --mesh mesh, or the built-in scene's torus when none is given.
//   - the mesh (seam vertices welded) gets its saliency, 10 salient clusters, the weighting map
//     and the contraction hierarchy (library defaults);
//   - one view: camera 0 of support/mesh_views.hpp around the mesh; view_dependent_lod::frame
//     from that eye with the global budget (1 − f)·T/2 contractions for f = 35% and 5%;
//   - meshoptimizer's meshopt_simplify (no options, target error FLT_MAX) to the triangle count
//     the frame produced, when the demo is built with meshoptimizer;
//   - DIR/lod.png: the reference shader's images of that view (full mesh on the left, then 35%
//     and 5%; top row the saliency LOD, bottom row meshoptimizer's), panels of min(W, H, 384)
//     pixels (at least 16);
//   - rows lod-full, lod-saliency-35, lod-meshopt-35, lod-saliency-5, lod-meshopt-5 in the
//     results (summary.csv): seconds = the frame update or the meshopt_simplify call, psnr and
//     ssim against the full mesh's image of the same view (not against the scene reference),
//     and the setting names the triangle count, the saliency-weighted mean distance and the
//     Hausdorff distance to the full mesh (support/surface_distance.hpp).
//
//   bool stage_lod(demo_context& ctx);
// Returns false (one line on stderr) when a step fails.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>
#ifdef INFOLERP_DEMO_MESHOPTIMIZER
#include <meshoptimizer.h>
#endif
#include "demo.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/view_dependent_lod.hpp"
#include "infolerp/lod/weighting_map.hpp"
#include "infolerp/saliency/cluster_importance.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"
#include "support/mesh_views.hpp"
#include "support/procedural.hpp"
#include "support/surface_distance.hpp"

namespace infolerp::demo {

namespace detail {

// One simplified index buffer: its image, the time that made it and its figures.
struct lod_panel {
  std::string method;
  std::vector<std::uint32_t> indices;
  double seconds = 0.0;
  support::image img;
};

// The mesh the LOD stage simplifies: the first object of the first --mesh file, or the built-in torus.
inline const indexed_mesh& lod_source(const demo_context& ctx) {
  for (const auto& object : ctx.scene.objects)
    if (ctx.options.mesh_paths.empty() ? object.name == "torus" : object.name.starts_with(ctx.options.mesh_paths.front()))
      return object.mesh;
  return ctx.scene.objects.back().mesh;
}

// Renders the panel's view and records its row; false on error (reported).
inline bool finish_panel(demo_context& ctx, const support::embree_device& device, const indexed_mesh& m,
                         const std::vector<double>& saliency, const support::mesh_view_options& view,
                         lod_panel& p, const support::image* full) {
  const stopwatch render_watch;
  auto imgs = support::render_mesh_views(device, m.positions, p.indices, view);
  if (!imgs) return report(imgs.error()), false;
  record_time(ctx, "LOD view " + p.method, render_watch.seconds());
  p.img = std::move((*imgs)[0]);
  method_result r{p.method, "", p.seconds, std::numeric_limits<double>::infinity(), 1.0, 1.0};
  if (full) {
    auto sim = support::compare_views({p.img}, {*full});
    if (!sim) return report(sim.error()), false;
    r.psnr = sim->psnr, r.ssim = sim->ssim;
  }
  const stopwatch metric_watch;
  progress_line metric_line("LOD metric " + p.method);
  const support::distances d = support::measure(m, saliency, p.indices, with_progress(ctx.options, metric_line));
  metric_line.finish();
  record_time(ctx, "LOD metric " + p.method, metric_watch.seconds());
  char line[200];
  std::snprintf(line, sizeof line, "triangles %zu, weighted distance %.6g, Hausdorff %.6g, PSNR/SSIM against the full mesh's view",
                p.indices.size() / 3, d.weighted, d.hausdorff);
  r.setting = line;
  std::printf("lod: %-16s %7zu triangles, %.6f s, weighted distance %.4g, Hausdorff %.4g, PSNR %.2f dB, SSIM %.4f\n",
              p.method.c_str(), p.indices.size() / 3, p.seconds, d.weighted, d.hausdorff, r.psnr, r.ssim);
  ctx.results.push_back(std::move(r));
  return true;
}

// Panels placed on a grid of `columns` × 2 (nullptr: left black).
inline support::image lod_grid(const std::vector<const support::image*>& cells, int columns, int side) {
  support::image out(columns * side, 2 * side);
  for (std::size_t k = 0; k < cells.size(); ++k) {
    if (!cells[k]) continue;
    const int ox = static_cast<int>(k % static_cast<std::size_t>(columns)) * side;
    const int oy = static_cast<int>(k / static_cast<std::size_t>(columns)) * side;
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x) out.at(ox + x, oy + y) = cells[k]->pixels[static_cast<std::size_t>(y * side + x)];
  }
  return out;
}

}  // namespace detail

inline bool stage_lod(demo_context& ctx) {
  using clk = std::chrono::steady_clock;
  std::vector<std::uint32_t> remap;
  const indexed_mesh& source = detail::lod_source(ctx);
  const indexed_mesh m = support::weld_positions(source, remap);
  // The saliency stage's values for this object (the same welded mesh), else computed here.
  std::vector<double> saliency;
  for (std::size_t g = 0; g < ctx.welded_saliency.size(); ++g)
    if (&ctx.scene.objects[g].mesh == &source) saliency = ctx.welded_saliency[g];
  if (saliency.empty()) {
    const stopwatch watch;
    progress_line line("LOD saliency");
    auto sal = compute_saliency(m, {}, with_progress(ctx.options, line));
    line.finish();
    if (!sal) return report(sal.error()), false;
    saliency = std::move(sal->saliency);
    record_time(ctx, "LOD saliency", watch.seconds());
  }
  stopwatch watch;
  // The paper's 10 clusters, or one per triangle on a mesh with fewer triangles.
  const auto clusters = static_cast<std::uint32_t>(std::min<std::size_t>(10, m.triangle_count()));
  progress_line cl_line("LOD salient clustering");
  auto cl = [&] { const heartbeat beat(cl_line); return salient_clustering(m, saliency, {.clusters = clusters}); }();
  cl_line.finish();
  if (!cl) return report(cl.error()), false;
  record_time(ctx, "LOD salient clustering (" + std::to_string(cl->iterations) + " growth rounds)", watch.seconds());
  watch = {};
  progress_line build_line("LOD build");
  std::optional<heartbeat> beat(std::in_place, build_line);
  auto w = weighting_map(m, saliency, cl->cluster, cl->count);
  if (!w) return report(w.error()), false;
  auto h = make_contraction_hierarchy(m, *w, cl->cluster, cl->count);
  if (!h) return report(h.error()), false;
  auto table = compute_cluster_attributes(m, saliency, cl->cluster, cl->count);
  if (!table) return report(table.error()), false;
  auto lod = view_dependent_lod::create(*h, *table);
  if (!lod) return report(lod.error()), false;
  beat.reset();
  build_line.finish();
  record_time(ctx, "LOD build (weights, hierarchy, table)", watch.seconds());

  const int side = std::max(16, std::min({ctx.options.width, ctx.options.height, 384}));
  const support::mesh_view_options view{side, side, 1, ctx.options.shader, ctx.options.threads};
  const support::camera cam = support::mesh_view_camera(0, 1, m.positions);
  const support::embree_device device;
  const std::size_t nt = m.triangle_count();
  const auto* full_idx = reinterpret_cast<const std::uint32_t*>(m.triangles.data());
  detail::lod_panel full{"lod-full", {full_idx, full_idx + 3 * nt}, 0.0, {}};
  if (!detail::finish_panel(ctx, device, m, saliency, view, full, nullptr)) return false;

  std::vector<detail::lod_panel> panels;
  std::vector<index_range> ranges(h->cluster_count);
  for (const auto& [f, label] : {std::pair{0.35, "35"}, std::pair{0.05, "5"}}) {
    const auto budget = std::min<std::uint64_t>(lod->capacity(), static_cast<std::uint64_t>((1.0 - f) * static_cast<double>(nt) / 2.0));
    detail::lod_panel ours{std::string("lod-saliency-") + label, std::vector<std::uint32_t>(contracted_index_bound(*h)), 0.0, {}};
    const auto t0 = clk::now();
    const lod_camera eye{glm::dvec3(cam.eye), glm::dvec3(cam.target - cam.eye), glm::dvec3(cam.up),
                         static_cast<double>(cam.vertical_fov_degrees) * 3.141592653589793 / 180.0, static_cast<std::uint32_t>(side),
                         static_cast<std::uint32_t>(side)};
    auto st = lod->frame(eye, budget, ours.indices, ranges);
    ours.seconds = std::chrono::duration<double>(clk::now() - t0).count();
    if (!st) return report(st.error()), false;
    ours.indices.resize(st->indices);
    if (!detail::finish_panel(ctx, device, m, saliency, view, ours, &full.img)) return false;
    panels.push_back(std::move(ours));
#ifdef INFOLERP_DEMO_MESHOPTIMIZER
    detail::lod_panel theirs{std::string("lod-meshopt-") + label, std::vector<std::uint32_t>(3 * nt), 0.0, {}};
    const auto t1 = clk::now();
    const std::size_t k = meshopt_simplify(theirs.indices.data(), full_idx, 3 * nt, &m.positions[0].x, m.vertex_count(),
                                           sizeof(glm::vec3), st->indices, std::numeric_limits<float>::max(), 0, nullptr);
    theirs.seconds = std::chrono::duration<double>(clk::now() - t1).count();
    theirs.indices.resize(k);
    if (!detail::finish_panel(ctx, device, m, saliency, view, theirs, &full.img)) return false;
    panels.push_back(std::move(theirs));
#else
    panels.push_back({});
#endif
  }
  // Grid: full | 35% | 5%, saliency LOD on top, meshoptimizer below.
  const auto cell = [&](std::size_t k) { return panels[k].indices.empty() ? nullptr : &panels[k].img; };
  const support::image grid = detail::lod_grid({&full.img, cell(0), cell(2), &full.img, cell(1), cell(3)}, 3, side);
  return save_png(ctx, grid, "lod.png");
}

}  // namespace infolerp::demo
