// infolerp_pareto walk --csv FILE [--width W --height H --frames N]
//
// The walkthrough of Oliveira, Santos, Proença (§2, §4.1) on the procedural walkthrough scene:
// a path of N frames from the street view into the temple view and back the same way
// (support::walkthrough_path). Three methods, every one in this run:
//   nld_os_cached   one agent; set_view() per frame, hierarchy and shading cache kept;
//   nld_os_restart  start() per frame (hierarchy and cache thrown away);
//   rnd_cached      as nld_os_cached with the RND criterion.
// Each frame refines until the criterion stops (R = 64, 6-pixel floor, S_req = 0.05).
// Shading goes through the asynchronous interface: the agent's own calls (set_view with its
// primary rays, refine, take_requests, deliver, take_delta) are timed as agent_seconds, the
// shader on the requested samples (Lambert + one shadow ray, Embree 3) as shader_seconds.
// Serial executor, so the two times share one core.
//
// CSV: method,frame,samples,psnr_db,agent_seconds,shader_seconds (samples: newly shaded in
// the frame; psnr_db: the frame's final image against the per-pixel reference of that frame).
// Beside it: FILE.png (PSNR and new samples per frame, gnuplot) and FILE.gp (its script).
// Printed: the goals (cached samples against restart's, per-frame PSNR gap, agent time per
// batch against shader time on that batch) and Table 1 of the paper for the three views.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/refine/progressive_driver.hpp"
#include "pareto.hpp"
#include "support/walkthrough_scene.hpp"

namespace {

using scene = infolerp::support::walkthrough_scene;
using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point t) { return std::chrono::duration<double>(clock_type::now() - t).count(); }

std::vector<glm::vec3> reference_image(const scene& sc, const infolerp::pinhole_camera& cam) {
  std::vector<glm::vec3> img(std::size_t(cam.width) * cam.height, glm::vec3(0.0f));
  infolerp::support::enable_flush_to_zero();
  for (std::size_t p = 0; p < img.size(); ++p) {
    const infolerp::ray r = cam.primary_ray(static_cast<std::uint32_t>(p % cam.width), static_cast<std::uint32_t>(p / cam.width));
    const infolerp::hit h = sc.intersect(r);
    if (h.valid()) img[p] = sc.shade(r.origin + h.distance * r.direction, h.triangle);
  }
  return img;
}

infolerp::progressive_refiner make_agent(const scene& sc, infolerp::refinement_criterion c) {
  auto sub = infolerp::subdivision_mesh::create(sc.mesh);
  infolerp::driver_options o;
  o.criteria.criterion = c;
  o.criteria.batch = 64;
  o.criteria.s_req = 0.05f;
  o.criteria.min_pixels = 6.0f;
  o.criteria.always_refine_fraction = 0.02f;
  auto r = sub.ok() ? infolerp::progressive_refiner::create(std::move(*sub), o)
                    : infolerp::result<infolerp::progressive_refiner>(sub.error());
  if (!r) {
    std::fprintf(stderr, "%s\n", r.error().message().c_str());
    std::exit(1);
  }
  return std::move(*r);
}

struct frame_row {
  std::size_t samples = 0;
  double psnr_db = 0.0, agent = 0.0, shader = 0.0;
};
struct batch_time {
  double agent = 0.0, shader = 0.0;
};

// One frame: a new view (or a restart), then request/shade/deliver/refine until the criterion
// stops. Every agent call is timed apart from the shader.
frame_row walk_frame(infolerp::progressive_refiner& agent, const scene& sc, const infolerp::pinhole_camera& cam,
                     bool restart, const std::vector<glm::vec3>& reference, std::vector<batch_time>& batches) {
  infolerp::serial_executor ex;
  frame_row row;
  const std::size_t before = restart ? 0 : agent.samples_delivered();
  auto t = clock_type::now();
  if (auto st = restart ? agent.start(*sc.tracer, cam, ex) : agent.set_view(*sc.tracer, cam, ex); !st) {
    std::fprintf(stderr, "%s\n", st.message().c_str());
    std::exit(1);
  }
  infolerp::display_delta delta;
  agent.take_delta(delta);
  double batch_agent = seconds_since(t);
  std::vector<infolerp::shading_point> req;
  std::vector<std::uint32_t> ids;
  std::vector<glm::vec3> colours;
  for (;;) {
    t = clock_type::now();
    req.clear();
    agent.take_requests(req);
    batch_agent += seconds_since(t);
    t = clock_type::now();
    ids.resize(req.size());
    colours.resize(req.size());
    infolerp::support::enable_flush_to_zero();
    for (std::size_t i = 0; i < req.size(); ++i) ids[i] = req[i].vertex, colours[i] = sc.shade(req[i].position, req[i].triangle);
    const double shader = seconds_since(t);
    t = clock_type::now();
    if (auto st = agent.deliver(ids, colours); !st) {
      std::fprintf(stderr, "%s\n", st.message().c_str());
      std::exit(1);
    }
    agent.take_delta(delta);
    const infolerp::refine_progress p = agent.refine({}, ex);
    batch_agent += seconds_since(t);
    row.agent += batch_agent;
    row.shader += shader;
    if (!req.empty()) batches.push_back({batch_agent, shader});
    batch_agent = 0.0;
    if (p != infolerp::refine_progress::refined) break;
  }
  row.samples = agent.samples_delivered() - before;
  std::vector<glm::vec3> img(reference.size());
  agent.reconstruct(img);
  row.psnr_db = linear_psnr(img, reference);
  return row;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int pareto_walk(int argc, char** argv) {
  std::string csv_path = "walk.csv";
  std::uint32_t width = 320, height = 240, frames = 120;
  for (int i = 1; i < argc; ++i) {
    const auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (!std::strcmp(argv[i], "--csv")) csv_path = next();
    else if (!std::strcmp(argv[i], "--width")) width = static_cast<std::uint32_t>(std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--height")) height = static_cast<std::uint32_t>(std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--frames")) frames = static_cast<std::uint32_t>(std::atoi(next().c_str()));
    else {
      std::fprintf(stderr, "usage: infolerp_pareto walk --csv FILE [--width W] [--height H] [--frames N]\n");
      return 2;
    }
  }
  if (frames < 2 || width == 0 || height == 0) {
    std::fprintf(stderr, "walk: need frames >= 2 and a non-empty image\n");
    return 2;
  }
  const std::string stem = csv_path.substr(0, csv_path.rfind('.'));
  auto built = infolerp::support::make_walkthrough_scene();
  if (!built) {
    std::fprintf(stderr, "%s\n", built.error().message().c_str());
    return 1;
  }
  const scene& sc = *built;

  const char* names[3] = {"nld_os_cached", "nld_os_restart", "rnd_cached"};
  infolerp::progressive_refiner agents[3] = {make_agent(sc, infolerp::refinement_criterion::nld_os),
                                             make_agent(sc, infolerp::refinement_criterion::nld_os),
                                             make_agent(sc, infolerp::refinement_criterion::rnd)};
  std::vector<frame_row> rows[3];
  std::vector<batch_time> batches[3];
  for (std::uint32_t f = 0; f < frames; ++f) {
    const infolerp::pinhole_camera cam = infolerp::support::walkthrough_path(f, frames, width, height);
    const std::vector<glm::vec3> reference = reference_image(sc, cam);
    for (int m = 0; m < 3; ++m)  // interleaved per frame
      rows[m].push_back(walk_frame(agents[m], sc, cam, m == 1, reference, batches[m]));
  }

  std::FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (!csv) {
    std::fprintf(stderr, "cannot write %s\n", csv_path.c_str());
    return 1;
  }
  std::fprintf(csv, "method,frame,samples,psnr_db,agent_seconds,shader_seconds\n");
  for (int m = 0; m < 3; ++m)
    for (std::uint32_t f = 0; f < frames; ++f)
      std::fprintf(csv, "%s,%u,%zu,%.3f,%.6f,%.6f\n", names[m], f, rows[m][f].samples, rows[m][f].psnr_db,
                   rows[m][f].agent, rows[m][f].shader);
  std::fclose(csv);

  std::printf("walk: %u frames at %ux%u, street -> temple -> street, R = 64, 6-pixel floor\n", frames, width, height);
  std::size_t total[3] = {0, 0, 0};
  double worst_gap = -1e9;
  std::uint32_t worst_frame = 0, frames_within = 0;
  for (int m = 0; m < 3; ++m)
    for (const frame_row& r : rows[m]) total[m] += r.samples;
  for (std::uint32_t f = 0; f < frames; ++f) {
    const double gap = rows[1][f].psnr_db - rows[0][f].psnr_db;  // restart minus cached
    if (gap <= 0.5) ++frames_within;
    if (gap > worst_gap) worst_gap = gap, worst_frame = f;
  }
  std::printf("samples over the path: nld_os_cached %zu, nld_os_restart %zu, rnd_cached %zu\n", total[0], total[1], total[2]);
  std::printf("cached / restart samples: %.1f%% (goal <= 25%%)\n", 100.0 * double(total[0]) / double(total[1]));
  std::printf("frames with cached PSNR within 0.5 dB of restart's or above: %u of %u (goal: all); worst frame %u, "
              "restart - cached = %.3f dB\n",
              frames_within, frames, worst_frame, worst_gap);
  for (int m = 0; m < 3; ++m) {
    double mean_db = 0.0;
    for (const frame_row& r : rows[m]) mean_db += r.psnr_db / double(frames);
    std::vector<double> ratio;
    std::size_t within = 0;
    for (const batch_time& b : batches[m]) {
      ratio.push_back(b.shader > 0.0 ? b.agent / b.shader : 1e9);
      if (b.agent <= 0.1 * b.shader) ++within;
    }
    std::vector<double> sorted = ratio;
    std::sort(sorted.begin(), sorted.end());
    std::printf("%-15s mean PSNR %.2f dB; agent/shader time per batch: min %.3f, median %.3f, max %.3f; "
                "%zu of %zu batches <= 0.10 (goal: all)\n",
                names[m], mean_db, sorted.empty() ? 0.0 : sorted.front(), median(ratio), sorted.empty() ? 0.0 : sorted.back(),
                within, ratio.size());
  }

  // Table 1 of the paper for the three kinds of view (NLD_OS from a fresh agent each).
  std::printf("Table 1, NLD_OS, fresh agent per view:\n%-8s %-16s %12s %12s\n", "view", "", "S1", "S2");
  const char* view_names[3] = {"street", "wall", "temple"};
  for (int v = 0; v < 3; ++v) {
    infolerp::progressive_refiner a = make_agent(sc, infolerp::refinement_criterion::nld_os);
    const auto shade = [&](const infolerp::shading_point& sp) { return sc.shade(sp.position, sp.triangle); };
    const auto cam = infolerp::support::walkthrough_camera(static_cast<infolerp::support::walkthrough_view>(v), width, height);
    auto rep = a.run(*sc.tracer, cam, shade, infolerp::serial_executor{});
    if (!rep) continue;
    std::printf("%-8s %-16s %12.3f %12.3f\n", view_names[v], "T (secs)", rep->stage1.seconds, rep->stage2.seconds);
    std::printf("%-8s %-16s %12zu %12zu\n", "", "Delta", rep->stage1.triangles, rep->stage2.triangles);
    std::printf("%-8s %-16s %12zu %12zu\n", "", "Delta_total", rep->stage1.triangles_total, rep->stage2.triangles_total);
    std::printf("%-8s %-16s %12zu %12zu\n", "", "samples", rep->stage1.shading_samples, rep->stage2.shading_samples);
  }

  const std::string gp = stem + ".gp", png = stem + ".png";
  if (std::FILE* g = std::fopen(gp.c_str(), "w")) {
    std::fprintf(g,
                 "set terminal pngcairo noenhanced size 900,800\nset output '%s'\nset datafile separator ','\n"
                 "set multiplot layout 2,1\nset grid\nset key bottom right\nset xlabel 'frame'\n"
                 "set ylabel 'PSNR (dB)'\nset title 'walkthrough %ux%u: street -> temple -> street'\n"
                 "plot for [m in 'nld_os_cached nld_os_restart rnd_cached'] '%s' using (strcol(1) eq m ? $2 : 1/0):4 "
                 "with lines title m\n"
                 "set logscale y\nset ylabel 'new samples'\nset title ''\nset key top right\n"
                 "plot for [m in 'nld_os_cached nld_os_restart rnd_cached'] '%s' using (strcol(1) eq m ? $2 : 1/0):($3 > 0 ? $3 : 0.5) "
                 "with lines title m\nunset multiplot\n",
                 png.c_str(), width, height, csv_path.c_str(), csv_path.c_str());
    std::fclose(g);
    const std::string cmd = "gnuplot '" + gp + "'";
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed; the script is %s\n", gp.c_str());
  }
  std::printf("wrote %s and %s\n", csv_path.c_str(), png.c_str());
  return 0;
}
