// infolerp_pareto walk --csv FILE [--width W --height H --frames N --loop P --shader simple|reference]
//                      [--long-path [--blocks B] [--cache-bound C|none] [--hierarchy-bound T|none]]
//
// The walkthrough of Oliveira, Santos, Proença (§2, §4.1) on the procedural walkthrough scene:
// a path of N frames from the street view into the temple view and back the same way
// (support::walkthrough_path); with --loop P the path is P frames long and walked again and
// again for N frames. With --long-path the scene is a street of B repeated blocks
// (support::make_long_street_scene, default 26) walked from the first block to the last in N
// frames, never coming back, with nld_os_cached alone, its cache bounded to C samples (default
// 40,000) and its hierarchy to T triangles (default 150,000; `none` for no bound): the refiner
// prunes what is out of view; the library's own default is no bound
// and the PSNR taken every 10th frame. Three methods, every one in this run:
//   nld_os_cached   one agent; set_view() per frame, hierarchy and shading cache kept;
//   nld_os_restart  start() per frame (hierarchy and cache thrown away);
//   rnd_cached      as nld_os_cached with the RND criterion.
// Each frame refines until the criterion stops (R = 64, 6-pixel floor, S_req = 0.05).
// Shading goes through the asynchronous interface: the agent's own calls (set_view with its
// primary rays, refine, take_requests, deliver, take_delta) are timed as agent_seconds, the
// shader on the requested samples as shader_seconds: `simple` is the scene's Lambert with one
// shadow ray, `reference` the demo's reference lighting (AO 64, soft shadow 16 rays). Before
// each method's frame the same frame's primary rays are traced alone (same tracer, same
// blocks of 256 rays) as primary_seconds. Serial executor, so all times share one core.
//
// CSV: method,frame,samples,psnr_db,agent_seconds,shader_seconds,primary_seconds,batches,
// later_batch_seconds,later_batches,relocated_pixels,memory_bytes (samples: newly shaded in the frame; psnr_db: the frame's
// final image against the per-pixel reference of that frame; batches: batches of R run in the
// frame; later_*: the frame's batches after its first, which alone builds the view's luminance
// image, and the agent time of their refine and of their requests' take, deliver and delta;
// relocated_pixels: pixels whose leaf the frame's batches changed, counted outside the timed
// calls; memory_bytes: progressive_refiner::memory_bytes() after the frame).
// Beside it: FILE.png (PSNR, new samples, agent and primary-ray time per frame, gnuplot) and
// FILE.gp (its script). Printed: the goals (cached samples against restart's, per-frame PSNR
// gap, agent time against its primary rays, agent time per batch without them, history with
// --loop), agent time per batch after a view's first, the cached agent's pixels re-located per
// batch (counted outside the timed calls), agent against shader time per frame, and Table 1 of
// the paper for the three views.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/refine/progressive_driver.hpp"
#include "infolerp/upsample/ray_cast_source.hpp"
#include "pareto.hpp"
#include "support/walkthrough_scene.hpp"

namespace {

using scene = infolerp::support::walkthrough_scene;
using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point t) { return std::chrono::duration<double>(clock_type::now() - t).count(); }

using shade_fn = std::function<glm::vec3(glm::vec3, std::uint32_t)>;

// The demo's reference lighting (AO 64 and soft shadow 16 rays) on the walkthrough scene: the
// sun as a disk of 0.03 rad seen through 16 fixed points (soft shadow) and the sky term weighted
// by 64 fixed cosine-distributed ambient-occlusion rays, all Hammersley sets, so a point
// shades to the same bits every time.
class reference_lighting {
 public:
  explicit reference_lighting(const scene& sc) : sc_(&sc), hemisphere_(infolerp::cosine_hemisphere(64)) {
    glm::vec3 t, b;
    infolerp::detail::tangent_frame(sc.to_sun, t, b);
    for (unsigned i = 0; i < 16; ++i) {
      const glm::vec2 h = infolerp::hammersley(i, 16);
      const float r = 0.03f * std::sqrt(h.x), phi = 6.2831853f * h.y;
      sun_.push_back(glm::normalize(sc.to_sun + r * std::cos(phi) * t + r * std::sin(phi) * b));
    }
  }
  glm::vec3 shade(glm::vec3 p, std::uint32_t tri) const {
    infolerp::support::enable_flush_to_zero();
    const glm::vec3 n = sc_->normal[tri];
    infolerp::ray r;
    r.origin = p + 1e-3f * n;
    r.tnear = 1e-4f;
    float sun = 0.0f;
    for (const glm::vec3& d : sun_) {
      const float c = glm::dot(n, d);
      if (c <= 0.0f) continue;
      r.direction = d;
      if (!sc_->occluded(r)) sun += c / float(sun_.size());
    }
    glm::vec3 t, b;
    infolerp::detail::tangent_frame(n, t, b);
    float open = 0.0f;
    for (const glm::vec3& h : hemisphere_) {
      r.direction = h.x * t + h.y * b + h.z * n;
      if (!sc_->occluded(r)) open += 1.0f / float(hemisphere_.size());
    }
    return sc_->albedo[tri] * (0.18f * open + 0.85f * sun);
  }

 private:
  const scene* sc_;
  std::vector<glm::vec3> hemisphere_, sun_;
};

std::vector<glm::vec3> reference_image(const scene& sc, const infolerp::pinhole_camera& cam, const shade_fn& shade) {
  std::vector<glm::vec3> img(std::size_t(cam.width) * cam.height, glm::vec3(0.0f));
  infolerp::support::enable_flush_to_zero();
  const infolerp::pinhole_frame frame = cam.frame();
  for (std::size_t p = 0; p < img.size(); ++p) {
    const infolerp::ray r = frame.primary_ray(static_cast<std::uint32_t>(p % cam.width), static_cast<std::uint32_t>(p / cam.width));
    const infolerp::hit h = sc.intersect(r);
    if (h.valid()) img[p] = shade(r.origin + h.distance * r.direction, h.triangle);
  }
  return img;
}

infolerp::progressive_refiner make_agent(const scene& sc, infolerp::refinement_criterion c,
                                        std::size_t cache_bound = std::numeric_limits<std::size_t>::max(),
                                        std::size_t hierarchy_bound = std::numeric_limits<std::size_t>::max()) {
  auto sub = infolerp::subdivision_mesh::create(sc.mesh);
  infolerp::driver_options o;
  o.criteria.criterion = c;
  o.criteria.batch = 64;
  o.criteria.s_req = 0.05f;
  o.criteria.min_pixels = 6.0f;
  o.criteria.always_refine_fraction = 0.02f;
  o.max_cached_samples = cache_bound;
  o.max_hierarchy_triangles = hierarchy_bound;
  auto r = sub.ok() ? infolerp::progressive_refiner::create(std::move(*sub), o)
                    : infolerp::result<infolerp::progressive_refiner>(sub.error());
  if (!r) {
    std::fprintf(stderr, "%s\n", r.error().message().c_str());
    std::exit(1);
  }
  return std::move(*r);
}

struct frame_row {
  std::size_t samples = 0, batches = 0;
  double psnr_db = 0.0, agent = 0.0, shader = 0.0, primary = 0.0;
  // The batches after a view's first (its first refine() also builds the view's luminance image,
  // O(pixels)): their refine() and the take_requests, deliver and take_delta of their requests.
  std::size_t later_batches = 0;
  double later_batch_seconds = 0.0;
  std::size_t relocated_pixels = 0;  // pixels whose leaf a batch changed (counted untimed, on request)
  std::size_t memory_bytes = 0;      // the agent's, after the frame
};

// The frame's primary rays traced alone, as the agent traces them (made and traced in blocks of
// 256 rays, serial): the floor of any agent that has to know what each pixel sees.
double primary_rays_seconds(const scene& sc, const infolerp::pinhole_camera& cam) {
  constexpr std::size_t block = 256;
  const auto t = clock_type::now();
  const std::size_t n = std::size_t(cam.width) * cam.height;
  std::vector<infolerp::hit> hits(n);
  std::vector<infolerp::ray> rays(block);
  const infolerp::pinhole_frame frame = cam.frame();  // as the agent does: the basis once, not per ray
  for (std::size_t begin = 0; begin < n; begin += block) {
    const std::size_t m = std::min(block, n - begin);
    for (std::size_t i = 0; i < m; ++i)
      rays[i] = frame.primary_ray(static_cast<std::uint32_t>((begin + i) % cam.width),
                                static_cast<std::uint32_t>((begin + i) / cam.width));
    infolerp::trace_intersect(*sc.tracer, std::span<const infolerp::ray>(rays.data(), m),
                              std::span<infolerp::hit>(hits.data() + begin, m));
  }
  const double s = seconds_since(t);
  std::size_t valid = 0;  // keeps the trace observable
  for (const infolerp::hit& h : hits) valid += h.valid();
  return valid <= n ? s : 0.0;
}

// One frame: a new view (or a restart), then request/shade/deliver/refine until the criterion
// stops. Every agent call is timed apart from the shader.
frame_row walk_frame(infolerp::progressive_refiner& agent, const scene& sc, const infolerp::pinhole_camera& cam,
                     bool restart, const std::vector<glm::vec3>& reference, const shade_fn& shade, bool count_relocated) {
  infolerp::serial_executor ex;
  frame_row row;
  row.primary = primary_rays_seconds(sc, cam);
  const std::size_t before = restart ? 0 : agent.samples_delivered();
  auto t = clock_type::now();
  if (auto st = restart ? agent.start(*sc.tracer, cam, ex) : agent.set_view(*sc.tracer, cam, ex); !st) {
    std::fprintf(stderr, "%s\n", st.message().c_str());
    std::exit(1);
  }
  infolerp::display_delta delta;
  agent.take_delta(delta);
  row.agent += seconds_since(t);
  std::vector<infolerp::shading_point> req;
  std::vector<std::uint32_t> ids;
  std::vector<glm::vec3> colours;
  int batch = 0;  // the batch whose requests this iteration takes (0: the view's)
  std::vector<std::uint32_t> leaves_before;
  for (;;) {
    t = clock_type::now();
    req.clear();
    agent.take_requests(req);
    double spent = seconds_since(t);
    t = clock_type::now();
    ids.resize(req.size());
    colours.resize(req.size());
    infolerp::support::enable_flush_to_zero();
    for (std::size_t i = 0; i < req.size(); ++i) ids[i] = req[i].vertex, colours[i] = shade(req[i].position, req[i].triangle);
    row.shader += seconds_since(t);
    t = clock_type::now();
    if (auto st = agent.deliver(ids, colours); !st) {
      std::fprintf(stderr, "%s\n", st.message().c_str());
      std::exit(1);
    }
    agent.take_delta(delta);
    spent += seconds_since(t);
    if (batch >= 2) row.later_batch_seconds += spent;
    if (count_relocated) leaves_before.assign(agent.pixel_leaves().begin(), agent.pixel_leaves().end());
    t = clock_type::now();
    const infolerp::refine_progress p = agent.refine({}, ex);
    const double refining = seconds_since(t);
    if (count_relocated && p == infolerp::refine_progress::refined)
      for (std::size_t i = 0; i < leaves_before.size(); ++i) row.relocated_pixels += leaves_before[i] != agent.pixel_leaves()[i];
    row.agent += spent + refining;
    if (p != infolerp::refine_progress::refined) break;
    if (++batch >= 2) row.later_batch_seconds += refining, ++row.later_batches;
  }
  row.samples = agent.samples_delivered() - before;
  row.batches = agent.report().batches;
  row.memory_bytes = agent.memory_bytes();
  row.psnr_db = std::numeric_limits<double>::quiet_NaN();
  if (reference.empty()) return row;
  std::vector<glm::vec3> img(reference.size());
  agent.reconstruct(img);
  row.psnr_db = linear_psnr(img, reference);
  return row;
}

// --long-path's report: memory and agent time along a walk that never comes back.
int report_long_path(const std::vector<frame_row>& rows, std::uint32_t frames, std::uint32_t blocks, std::uint32_t width,
                     std::uint32_t height, std::size_t cache_bound, std::size_t hierarchy_bound, const std::string& csv_path) {
  const auto bound = [](std::size_t b) { return b == std::numeric_limits<std::size_t>::max() ? std::string("none") : std::to_string(b); };
  std::printf("walk --long-path: %u frames at %ux%u down a street of %u blocks, nld_os_cached, cache bound %s, hierarchy "
              "bound %s\n",
              frames, width, height, blocks, bound(cache_bound).c_str(), bound(hierarchy_bound).c_str());
  double agent = 0.0, primary = 0.0, db = 0.0;
  std::size_t samples = 0, batches = 0, relocated = 0, measured = 0;
  for (const frame_row& r : rows) {
    agent += r.agent, primary += r.primary, samples += r.samples, batches += r.batches, relocated += r.relocated_pixels;
    if (!std::isnan(r.psnr_db)) db += r.psnr_db, ++measured;
  }
  std::printf("samples %zu, batches %zu, mean PSNR %.2f dB over %zu measured frames; agent %.3f s, primary rays alone "
              "%.3f s: agent / primary %.3f; pixels re-located per batch %.1f\n",
              samples, batches, measured ? db / double(measured) : 0.0, measured, agent, primary, agent / primary,
              batches ? double(relocated) / double(batches) : 0.0);
  for (std::uint32_t f : {0u, 119u, 499u, 999u, 1499u, frames - 1})
    if (f < frames) std::printf("memory_bytes after frame %u: %zu\n", f + 1, rows[f].memory_bytes);
  if (frames >= 500)
    std::printf("memory at frame %u / at frame 500: %.3f (goal <= 1.25 at frame 2000)\n", frames,
                double(rows[frames - 1].memory_bytes) / double(rows[499].memory_bytes));
  if (frames >= 320) {
    double first = 0.0, last = 0.0;
    for (std::uint32_t f = 120; f < 220; ++f) first += rows[f].agent;
    for (std::uint32_t f = frames - 100; f < frames; ++f) last += rows[f].agent;
    std::printf("history: agent over the last 100 frames %.4f s, over frames 120-219 %.4f s: ratio %.3f (goal <= 1.2)\n",
                last, first, last / first);
  }
  std::printf("wrote %s\n", csv_path.c_str());
  return 0;
}

}  // namespace

int pareto_walk(int argc, char** argv) {
  std::string csv_path = "walk.csv", shader_name = "simple";
  std::uint32_t width = 320, height = 240, frames = 120, loop = 0, blocks = 26;
  bool long_path = false;
  constexpr std::size_t unbounded = std::numeric_limits<std::size_t>::max();
  std::optional<std::size_t> cache_given, hierarchy_given;
  const auto read_bound = [](const std::string& v) {
    return v == "none" ? unbounded : static_cast<std::size_t>(std::max(0LL, std::atoll(v.c_str())));
  };
  for (int i = 1; i < argc; ++i) {
    const auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (!std::strcmp(argv[i], "--csv")) csv_path = next();
    else if (!std::strcmp(argv[i], "--width")) width = static_cast<std::uint32_t>(std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--height")) height = static_cast<std::uint32_t>(std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--frames")) frames = static_cast<std::uint32_t>(std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--loop")) loop = static_cast<std::uint32_t>(std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--shader")) shader_name = next();
    else if (!std::strcmp(argv[i], "--long-path")) long_path = true;
    else if (!std::strcmp(argv[i], "--blocks")) blocks = static_cast<std::uint32_t>(std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--cache-bound")) cache_given = read_bound(next());
    else if (!std::strcmp(argv[i], "--hierarchy-bound")) hierarchy_given = read_bound(next());
    else {
      std::fprintf(stderr, "usage: infolerp_pareto walk --csv FILE [--width W] [--height H] [--frames N] [--loop P] "
                           "[--shader simple|reference] [--long-path [--blocks B] [--cache-bound C|none] [--hierarchy-bound T|none]]\n");
      return 2;
    }
  }
  if (frames < 2 || width == 0 || height == 0 || loop == 1 || (shader_name != "simple" && shader_name != "reference") ||
      blocks == 0 || cache_given == 0u || hierarchy_given == 0u || (long_path && loop != 0)) {
    std::fprintf(stderr, "walk: need frames >= 2, a non-empty image, --loop 0 or >= 2 (not with --long-path), "
                         "--shader simple|reference, --blocks >= 1, bounds >= 1 or none\n");
    return 2;
  }
  const std::size_t cache_bound = cache_given.value_or(long_path ? 40'000 : unbounded);
  const std::size_t hierarchy_bound = hierarchy_given.value_or(long_path ? 150'000 : unbounded);
  const std::uint32_t period = loop == 0 ? frames : loop;
  const std::string stem = csv_path.substr(0, csv_path.rfind('.'));
  auto built = long_path ? infolerp::support::make_long_street_scene(blocks) : infolerp::support::make_walkthrough_scene();
  if (!built) {
    std::fprintf(stderr, "%s\n", built.error().message().c_str());
    return 1;
  }
  const scene& sc = *built;
  const reference_lighting lighting(sc);
  const shade_fn shade = shader_name == "simple" ? shade_fn{[&](glm::vec3 p, std::uint32_t t) { return sc.shade(p, t); }}
                                                 : shade_fn{[&](glm::vec3 p, std::uint32_t t) { return lighting.shade(p, t); }};

  const char* names[3] = {"nld_os_cached", "nld_os_restart", "rnd_cached"};
  infolerp::progressive_refiner agents[3] = {make_agent(sc, infolerp::refinement_criterion::nld_os, cache_bound, hierarchy_bound),
                                             make_agent(sc, infolerp::refinement_criterion::nld_os),
                                             make_agent(sc, infolerp::refinement_criterion::rnd)};
  const int methods = long_path ? 1 : 3;
  std::vector<frame_row> rows[3];
  for (std::uint32_t f = 0; f < frames; ++f) {
    const infolerp::pinhole_camera cam = long_path ? infolerp::support::long_street_path(f, frames, blocks, width, height)
                                                   : infolerp::support::walkthrough_path(f % period, period, width, height);
    const std::vector<glm::vec3> reference = !long_path || f % 10 == 0 ? reference_image(sc, cam, shade) : std::vector<glm::vec3>{};
    for (int m = 0; m < methods; ++m)  // interleaved per frame
      rows[m].push_back(walk_frame(agents[m], sc, cam, m == 1, reference, shade, true));
  }

  std::FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (!csv) {
    std::fprintf(stderr, "cannot write %s\n", csv_path.c_str());
    return 1;
  }
  std::fprintf(csv, "method,frame,samples,psnr_db,agent_seconds,shader_seconds,primary_seconds,batches,"
                   "later_batch_seconds,later_batches,relocated_pixels,memory_bytes\n");
  for (int m = 0; m < methods; ++m)
    for (std::uint32_t f = 0; f < frames; ++f)
      std::fprintf(csv, "%s,%u,%zu,%.3f,%.6f,%.6f,%.6f,%zu,%.6f,%zu,%zu,%zu\n", names[m], f, rows[m][f].samples,
                   rows[m][f].psnr_db, rows[m][f].agent, rows[m][f].shader, rows[m][f].primary, rows[m][f].batches,
                   rows[m][f].later_batch_seconds, rows[m][f].later_batches, rows[m][f].relocated_pixels,
                   rows[m][f].memory_bytes);
  std::fclose(csv);
  if (long_path) return report_long_path(rows[0], frames, blocks, width, height, cache_bound, hierarchy_bound, csv_path);

  std::printf("walk: %u frames at %ux%u, street -> temple -> street%s, R = 64, 6-pixel floor, %s shader\n", frames, width,
              height, loop ? (", looped every " + std::to_string(loop) + " frames").c_str() : "", shader_name.c_str());
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
    double mean_db = 0.0, agent = 0.0, primary = 0.0, shader = 0.0, later = 0.0;
    std::size_t nb = 0, nl = 0;
    for (const frame_row& r : rows[m])
      mean_db += r.psnr_db / double(frames), agent += r.agent, primary += r.primary, shader += r.shader, nb += r.batches,
          later += r.later_batch_seconds, nl += r.later_batches;
    // A view's own set-up (stage 1) counts as one batch of the frame.
    const double per_batch = (agent - primary) / double(nb + frames);
    std::printf("%-15s mean PSNR %.2f dB; agent %.4f s, its frames' primary rays alone %.4f s: agent / primary %.3f "
                "(goal <= 1.5 for nld_os_cached); shader %.4f s; agent excluding primary rays per batch %.2f us "
                "(%zu batches + %u views)\n",
                names[m], mean_db, agent, primary, agent / primary, shader, 1e6 * per_batch, nb, frames);
    std::printf("%-15s agent per batch after a view's first (refine, take_requests, deliver, take_delta): %.2f us over %zu "
                "batches\n",
                names[m], nl ? 1e6 * later / double(nl) : 0.0, nl);
    if (m == 0) {
      std::size_t relocated = 0;
      for (const frame_row& r : rows[m]) relocated += r.relocated_pixels;
      std::printf("%-15s pixels re-located per batch (a split leaf's pixels follow it down): %.1f\n", names[m],
                  nb ? double(relocated) / double(nb) : 0.0);
    }
  }
  // History: the agent over the last 100 frames against the first 100 after the first loop.
  if (loop != 0 && frames >= loop + 200) {
    for (int m : {0, 2}) {
      double first = 0.0, last = 0.0;
      for (std::uint32_t f = loop; f < loop + 100; ++f) first += rows[m][f].agent;
      for (std::uint32_t f = frames - 100; f < frames; ++f) last += rows[m][f].agent;
      std::printf("%-15s history: agent over the last 100 frames %.4f s, over frames %u-%u %.4f s: ratio %.3f "
                  "(goal <= 1.2 for nld_os_cached)\n",
                  names[m], last, loop, loop + 99, first, last / first);
    }
  }
  // Report (no goal): agent time against shading time per frame.
  for (int m = 0; m < 3; ++m) {
    std::vector<double> ratio;
    for (const frame_row& r : rows[m])
      if (r.shader > 0.0) ratio.push_back(r.agent / r.shader);
    std::sort(ratio.begin(), ratio.end());
    if (!ratio.empty())
      std::printf("%-15s agent / shader per frame (frames that shaded): min %.3f, median %.3f, max %.3f over %zu frames\n",
                  names[m], ratio.front(), ratio[ratio.size() / 2], ratio.back(), ratio.size());
  }

  // Table 1 of the paper for the three kinds of view (NLD_OS from a fresh agent each).
  std::printf("Table 1, NLD_OS, fresh agent per view:\n%-8s %-16s %12s %12s\n", "view", "", "S1", "S2");
  const char* view_names[3] = {"street", "wall", "temple"};
  for (int v = 0; v < 3; ++v) {
    infolerp::progressive_refiner a = make_agent(sc, infolerp::refinement_criterion::nld_os);
    const auto shade_point = [&](const infolerp::shading_point& sp) { return shade(sp.position, sp.triangle); };
    const auto cam = infolerp::support::walkthrough_camera(static_cast<infolerp::support::walkthrough_view>(v), width, height);
    auto rep = a.run(*sc.tracer, cam, shade_point, infolerp::serial_executor{});
    if (!rep) continue;
    std::printf("%-8s %-16s %12.3f %12.3f\n", view_names[v], "T (secs)", rep->stage1.seconds, rep->stage2.seconds);
    std::printf("%-8s %-16s %12zu %12zu\n", "", "Delta", rep->stage1.triangles, rep->stage2.triangles);
    std::printf("%-8s %-16s %12zu %12zu\n", "", "Delta_total", rep->stage1.triangles_total, rep->stage2.triangles_total);
    std::printf("%-8s %-16s %12zu %12zu\n", "", "samples", rep->stage1.shading_samples, rep->stage2.shading_samples);
  }

  const std::string gp = stem + ".gp", png = stem + ".png";
  if (std::FILE* g = std::fopen(gp.c_str(), "w")) {
    std::fprintf(g,
                 "set terminal pngcairo noenhanced size 900,1150\nset output '%s'\nset datafile separator ','\n"
                 "set multiplot layout 3,1\nset grid\nset key bottom right\nset xlabel 'frame'\n"
                 "set ylabel 'PSNR (dB)'\nset title 'walkthrough %ux%u: street -> temple -> street'\n"
                 "plot for [m in 'nld_os_cached nld_os_restart rnd_cached'] '%s' using (strcol(1) eq m ? $2 : 1/0):4 "
                 "with lines title m\n"
                 "set logscale y\nset ylabel 'new samples'\nset title ''\nset key top right\n"
                 "plot for [m in 'nld_os_cached nld_os_restart rnd_cached'] '%s' using (strcol(1) eq m ? $2 : 1/0):($3 > 0 ? $3 : 0.5) "
                 "with lines title m\n"
                 "set ylabel 'seconds per frame'\n"
                 "plot for [m in 'nld_os_cached nld_os_restart rnd_cached'] '%s' using (strcol(1) eq m ? $2 : 1/0):5 "
                 "with lines title m.' agent', '%s' using (strcol(1) eq 'nld_os_cached' ? $2 : 1/0):7 with lines dt 2 "
                 "title 'primary rays alone'\nunset multiplot\n",
                 png.c_str(), width, height, csv_path.c_str(), csv_path.c_str(), csv_path.c_str(), csv_path.c_str());
    std::fclose(g);
    const std::string cmd = "gnuplot '" + gp + "'";
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed; the script is %s\n", gp.c_str());
  }
  std::printf("wrote %s and %s\n", csv_path.c_str(), png.c_str());
  return 0;
}
