#pragma once
// Demo stage: view-dependent multiresolution rendering (salient-clustering paper §III.C, §IV)
// of one mesh: the --mesh mesh, or the built-in scene's torus when none is given.
//   - the mesh (seam vertices welded) gets its saliency, 10 salient clusters, the weighting map
//     and the contraction hierarchy (library defaults);
//   - one view: camera 0 of support/mesh_views.hpp around the mesh; view_dependent_lod::frame
//     from that eye drawing at most f·T triangles for f = 35% and 5%;
//   - what an engine draws instead, when the demo is built with meshoptimizer
//     (support/lod_peers.hpp): meshopt_culled (a uniform meshopt_simplify LOD culled per
//     triangle by the same test) and meshopt_meshlets (that LOD in meshlets of 124 triangles
//     culled by sphere and normal cone), each at the largest LOD that draws at most the count
//     our frame drew;
//   - DIR/lod.png: the reference shader's images of that view (full mesh on the left, then 35%
//     and 5%; rows: the saliency LOD, meshopt_culled, meshopt_meshlets), panels of min(W, H, 384)
//     pixels (at least 16), each labelled with its method, fraction, triangles and PSNR;
//   - ctx.lod_results (the LOD table and lod.csv of the summary stage): per mesh the triangle
//     count drawn, the seconds of the per-frame step (frame(), or the peer's culling pass), the
//     saliency-weighted mean distance and the Hausdorff distance to the full mesh
//     (support/surface_distance.hpp), PSNR and SSIM against the full mesh's image of the same
//     view (not the scene reference);
//   - every panel's shadow and AO rays go against the full mesh; the distances measure the
//     whole LOD (frame(): its cut, drawn and culled; a peer: its whole simplified mesh);
//   - DIR/lod_orbit.png: six cameras around the mesh (mesh_views' circle of 6), each one's
//     frame() at 5% with the default options; top row the triangles from that camera, bottom row
//     the same triangles from the opposite camera (the holes are what the camera culled). Both rows are headlight-shaded with the edges
//     of the drawn triangles overlaid (where neighbouring pixels see different triangles), so a
//     cut that follows the camera shows dense above and coarse below; labels and the printed
//     lines give each camera's triangle count and the share of them facing it (against the
//     full mesh's share).
//
//   bool stage_lod(demo_context& ctx);
// Returns false (one line on stderr) when a step fails.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <vector>
#ifdef INFOLERP_DEMO_MESHOPTIMIZER
#include "support/lod_peers.hpp"
#endif
#include "demo.hpp"
#include "draw_label.hpp"
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
  double fraction = 1.0;
  std::vector<std::uint32_t> indices;  // drawn
  double seconds = 0.0;
  support::image img;
  std::string label;  // drawn into img once every comparison with the full mesh's image is done
  std::vector<std::uint32_t> cut{};  // frame(): its whole cut, drawn and culled (the distances' mesh)
};

// The mesh the LOD stage simplifies: the first object of the first --mesh file, or the built-in torus.
inline const indexed_mesh& lod_source(const demo_context& ctx) {
  for (const auto& object : ctx.scene.objects)
    if (ctx.options.mesh_paths.empty() ? object.name == "torus" : object.name.starts_with(ctx.options.mesh_paths.front()))
      return object.mesh;
  return ctx.scene.objects.back().mesh;
}

// view_dependent_lod's eye for a support camera on a side × side viewport.
inline lod_camera lod_eye(const support::camera& c, int side) {
  const auto pixels = static_cast<std::uint32_t>(side);
  return {glm::dvec3(c.eye), glm::dvec3(c.target - c.eye), glm::dvec3(c.up),
          static_cast<double>(c.vertical_fov_degrees) * std::numbers::pi / 180.0, pixels, pixels};
}

// frame() into p.indices drawing at most a fraction f of the T triangles. Returns the status of
// frame() and times it.
inline status lod_frame(view_dependent_lod& lod, const contraction_hierarchy& h, const lod_camera& eye, std::size_t nt,
                        lod_panel& p) {
  const auto budget = static_cast<std::uint64_t>(p.fraction * static_cast<double>(nt));
  std::vector<index_range> ranges(h.cluster_count);
  p.indices.resize(contracted_index_bound(h));
  const auto t0 = std::chrono::steady_clock::now();
  auto st = lod.frame(eye, budget, p.indices, ranges);
  p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!st) return st.error();
  p.indices.resize(st->indices);
  contraction_workspace w = make_contraction_workspace(h);
  p.cut.resize(contracted_index_bound(h));
  auto n = contract_indices(h, lod.stop_points(), w, p.cut, ranges);
  if (!n) return n.error();
  p.cut.resize(*n);
  return {};
}

// Renders the panel's view, records its figures and its label; false on error (reported).
inline bool finish_panel(demo_context& ctx, const support::embree_device& device, const indexed_mesh& m,
                         const std::vector<double>& saliency, const support::mesh_view_options& view,
                         lod_panel& p, const support::image* full) {
  if (p.indices.empty()) return true;  // nothing drawn (a mesh of a few triangles at 5%): the cell stays black
  char tag[64];  // e.g. "infolerp 5%", for the time lines
  std::snprintf(tag, sizeof tag, "%s %g%%", p.method.c_str(), 100.0 * p.fraction);
  const stopwatch render_watch;
  auto imgs = support::render_mesh_views(device, m.positions, p.indices, view);
  if (!imgs) return report(imgs.error()), false;
  record_time(ctx, std::string("LOD view ") + tag, render_watch.seconds());
  p.img = std::move((*imgs)[0]);
  lod_result r{p.method, p.fraction, p.indices.size() / 3, p.seconds, 0.0, 0.0, std::numeric_limits<double>::infinity(), 1.0};
  if (full) {
    auto sim = support::compare_views({p.img}, {*full});
    if (!sim) return report(sim.error()), false;
    r.psnr = sim->psnr, r.ssim = sim->ssim;
  }
  const stopwatch metric_watch;
  progress_line metric_line(std::string("LOD metric ") + tag);
  const support::distances d =
      support::measure(m, saliency, p.cut.empty() ? p.indices : p.cut, with_progress(ctx.options, metric_line));
  metric_line.finish();
  record_time(ctx, std::string("LOD metric ") + tag, metric_watch.seconds());
  r.weighted_distance = d.weighted, r.hausdorff = d.hausdorff;
  char text[160];
  if (full)
    std::snprintf(text, sizeof text, "%s %g%%\n%zu triangles\nPSNR %.2f dB", p.method.c_str(), 100.0 * p.fraction,
                  r.triangles, r.psnr);
  else
    std::snprintf(text, sizeof text, "full mesh\n%zu triangles", r.triangles);
  p.label = text;
  ctx.lod_results.push_back(std::move(r));
  return true;
}

// Panels placed on a grid of `columns` columns (nullptr: left black).
inline support::image lod_grid(const std::vector<const support::image*>& cells, int columns, int side) {
  const int rows = (static_cast<int>(cells.size()) + columns - 1) / columns;
  support::image out(columns * side, rows * side);
  for (std::size_t k = 0; k < cells.size(); ++k) {
    if (!cells[k]) continue;
    const int ox = static_cast<int>(k % static_cast<std::size_t>(columns)) * side;
    const int oy = static_cast<int>(k / static_cast<std::size_t>(columns)) * side;
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x) out.at(ox + x, oy + y) = cells[k]->pixels[static_cast<std::size_t>(y * side + x)];
  }
  return out;
}

// The triangles `tris` (the geometry of `scene`) seen from c on a side × side image: grey
// shaded by a headlight (0.35 + 0.65·|n·d|, as render_false_colour), sky black, and the edges of
// the drawn triangles (pixels whose right or lower neighbour sees another triangle) in dark blue.
inline support::image wireframe_view([[maybe_unused]] const demo_context& ctx, const support::embree_scene& scene,
                                     std::span<const glm::vec3> positions, std::span<const glm::uvec3> tris,
                                     const support::camera& c, int side) {
  const auto n = static_cast<std::size_t>(side);
  std::vector<std::uint32_t> id(n * n, invalid_id);
  support::image img(side, side);
  const support::pinhole_rays rays = c.rays();
#pragma omp parallel for schedule(dynamic, 4) num_threads(omp_threads(ctx.options))
  for (int y = 0; y < side; ++y) {
    support::enable_flush_to_zero();
    for (int x = 0; x < side; ++x) {
      const ray r = rays(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, side, side);
      const hit h = scene.intersect(r);
      if (!h.valid()) continue;
      const glm::uvec3 t = tris[h.triangle];
      const glm::vec3 nrm = glm::normalize(glm::cross(positions[t.y] - positions[t.x], positions[t.z] - positions[t.x]));
      img.at(x, y) = glm::vec3(0.8f * (0.35f + 0.65f * std::abs(glm::dot(nrm, r.direction))));
      id[img.index(x, y)] = h.triangle;
    }
  }
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const std::size_t p = img.index(x, y);
      if ((x + 1 < side && id[p + 1] != id[p]) || (y + 1 < side && id[p + n] != id[p]))
        img.pixels[p] = {0.02f, 0.06f, 0.35f};
    }
  return img;
}

// The share of the triangles that face the eye (their normal toward it, counter-clockwise).
inline double facing_share(const indexed_mesh& m, std::span<const glm::uvec3> tris, const glm::vec3& eye) {
  std::size_t facing = 0;
  for (const glm::uvec3& t : tris) {
    const glm::vec3 a = m.positions[t.x], b = m.positions[t.y], c = m.positions[t.z];
    facing += glm::dot(glm::cross(b - a, c - a), eye - a) > 0.0f ? 1 : 0;
  }
  return tris.empty() ? 0.0 : static_cast<double>(facing) / static_cast<double>(tris.size());
}

// DIR/lod_orbit.png: frame() at 5% from six cameras around the mesh (see the prologue).
inline bool lod_orbit(demo_context& ctx, const support::embree_device& device, view_dependent_lod& lod,
                      const contraction_hierarchy& h, const indexed_mesh& m, int side) {
  constexpr unsigned cameras = 6;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<support::image> images(2 * cameras);
  std::printf("lod_orbit: infolerp 5%% from %u cameras around the mesh\n", cameras);
  for (unsigned k = 0; k < cameras; ++k) {
    const support::camera c = support::mesh_view_camera(k, cameras, m.positions);
    const support::camera behind = support::mesh_view_camera((k + cameras / 2) % cameras, cameras, m.positions);
    lod_panel p{"infolerp", 0.05, {}, 0.0, {}, {}, {}};
    if (auto s = lod_frame(lod, h, lod_eye(c, side), m.triangle_count(), p); !s) return report(s), false;
    if (p.indices.empty()) {  // the coarsest cut of a mesh of a few triangles may draw none
      images[k] = images[cameras + k] = support::image(side, side);
      std::printf("  camera %u: no triangle drawn\n", k);
      continue;
    }
    std::vector<glm::uvec3> tris(p.indices.size() / 3);
    for (std::size_t t = 0; t < tris.size(); ++t) tris[t] = {p.indices[3 * t], p.indices[3 * t + 1], p.indices[3 * t + 2]};
    support::embree_scene scene(device);
    if (auto id = scene.add_triangles(m.positions, tris); !id) return report(id.error()), false;
    if (auto s = scene.commit(); !s) return report(s), false;
    images[k] = wireframe_view(ctx, scene, m.positions, tris, c, side);
    images[cameras + k] = wireframe_view(ctx, scene, m.positions, tris, behind, side);
    const double facing = facing_share(m, tris, c.eye), facing_full = facing_share(m, m.triangles, c.eye);
    char text[200];
    std::snprintf(text, sizeof text, "camera %u: azimuth %u deg, %s\ninfolerp 5%%: %zu triangles\n%.0f%% face it (full mesh %.0f%%)",
                  k, 360 * k / cameras, k % 2 == 0 ? "above" : "below", tris.size(), 100.0 * facing, 100.0 * facing_full);
    draw_label(images[k], 0, 0, text, label_scale(side));
    std::snprintf(text, sizeof text, "camera %u's triangles\nfrom the opposite side:\nthe holes are what it culled", k);
    draw_label(images[cameras + k], 0, 0, text, label_scale(side));
    std::printf("  camera %u: %zu triangles, %.0f%% facing it (full mesh: %.0f%%)\n", k, tris.size(), 100.0 * facing,
                100.0 * facing_full);
  }
  std::vector<const support::image*> cells;
  for (const auto& img : images) cells.push_back(&img);
  const support::image grid = lod_grid(cells, cameras, side);
  std::printf("lod_orbit: %.3f s for the %u frames and %u images\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), cameras, 2 * cameras);
  return save_png(ctx, grid, "lod_orbit.png");
}

}  // namespace detail

inline bool stage_lod(demo_context& ctx) {
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
  auto cl = [&] {
    const heartbeat beat(cl_line);
    return salient_clustering(m, saliency, {.clusters = clusters}, make_executor(ctx.options));
  }();
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
  const std::size_t nt = m.triangle_count();
  const auto* full_idx = reinterpret_cast<const std::uint32_t*>(m.triangles.data());
  // Shadow and AO rays against the full mesh for every panel (frame() draws what the camera
  // sees; the occluders come from elsewhere, as a shadow map or a BVH gives an engine).
  support::mesh_view_options view{side, side, 1, ctx.options.shader, ctx.options.threads};
  view.occluders = std::span<const std::uint32_t>(full_idx, 3 * nt);
  const support::camera cam = support::mesh_view_camera(0, 1, m.positions);
  const support::embree_device device;
  detail::lod_panel full{"full", 1.0, {full_idx, full_idx + 3 * nt}, 0.0, {}, {}, {}};
  if (!detail::finish_panel(ctx, device, m, saliency, view, full, nullptr)) return false;

  std::vector<detail::lod_panel> panels;
#ifdef INFOLERP_DEMO_MESHOPTIMIZER
  const support::cull_source peers = support::make_cull_source(m);
#endif
  for (const double f : {0.35, 0.05}) {
    detail::lod_panel ours{"infolerp", f, {}, 0.0, {}, {}, {}};
    if (auto s = detail::lod_frame(*lod, *h, detail::lod_eye(cam, side), nt, ours); !s) return report(s), false;
    if (!detail::finish_panel(ctx, device, m, saliency, view, ours, &full.img)) return false;
#ifdef INFOLERP_DEMO_MESHOPTIMIZER
    // What an engine draws instead: a uniform LOD with the same culling, per triangle or per
    // meshlet, at the count our frame drew (support/lod_peers.hpp).
    for (const bool meshlets : {false, true}) {
      const std::size_t drawn = ours.indices.size() / 3;
      support::peer_frame pf = meshlets ? support::meshopt_meshlets(peers, detail::lod_eye(cam, side), drawn)
                                        : support::meshopt_culled(peers, detail::lod_eye(cam, side), drawn);
      detail::lod_panel theirs{meshlets ? "meshopt_meshlets" : "meshopt_culled", f, std::move(pf.drawn), pf.cull_seconds,
                               {}, {}, std::move(pf.lod)};
      if (!detail::finish_panel(ctx, device, m, saliency, view, theirs, &full.img)) return false;
      panels.push_back(std::move(theirs));
    }
    panels.insert(panels.end() - 2, std::move(ours));
#else
    panels.push_back(std::move(ours));
    panels.resize(panels.size() + 2);
#endif
  }
  for (auto& p : panels)
    if (!p.img.pixels.empty()) draw_label(p.img, 0, 0, p.label, label_scale(side));
  draw_label(full.img, 0, 0, full.label, label_scale(side));
  // Grid: full | 35% | 5%; rows: the saliency LOD, meshopt_culled, meshopt_meshlets.
  const auto cell = [&](std::size_t k) { return panels[k].indices.empty() ? nullptr : &panels[k].img; };
  const support::image grid =
      detail::lod_grid({&full.img, cell(0), cell(3), &full.img, cell(1), cell(4), &full.img, cell(2), cell(5)}, 3, side);
  return save_png(ctx, grid, "lod.png") && detail::lod_orbit(ctx, device, *lod, *h, m, side);
}

}  // namespace infolerp::demo
