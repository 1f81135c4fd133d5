// infolerp_pareto upsample (--csv FILE | --diagnose) [--only METHOD,...] [--match TEXT] [--repeat N]
//                          [--size W H] [--threads N] [--ao N] [--soft N] [--tessellate SHARE]
// infolerp_pareto upsample --textured DIR ...   (a textured asset from disk: upsample_textured.cpp)
// infolerp_pareto upsample --path ...           (frames along a camera path, with reuse: upsample_path.cpp)
//
// Time against error of the I-Buffer upsampler and its competitors on the demo scene
// (1025x1025 by default) with the reference shader (AO 64 rays, soft shadow 16 rays, hard-shadow
// sun, textures; fixed ray sets, so the reference is exactly reproducible). Methods, in one run:
//   full_single       full per-pixel evaluation, single rays (the reference, error 0)
//   full_packets16    full per-pixel evaluation, AO and soft-shadow rays in 16-ray packets
//   lowres_bilinear   a uniform coarse grid, fully shaded, bilinear colours; grid sized so that it
//                     evaluates as many samples as the I-Buffer (feature clusters) does (matched cost)
//   joint_bilateral   primary ray + hard shadow at every pixel, AO and soft shadow on a coarse
//                     grid, joint-bilateral (same object, normal, depth) interpolation of those
//   contrast          the I-Buffer pass schedule deciding by a luminance-contrast test instead
//                     of cluster ids
//   ibuffer           the I-Buffer, 1-5 passes: the real feature clustering of the demo
//                     (support::cluster_by_features, the demo's thresholds) and three stand-ins
//                     (tests/support/demo_upsample.hpp); perspective-correct weights
//   ibuffer_linear    the same with the paper's screen-linear weights (inv_depth = 1)
//   ibuffer_probe     the I-Buffer with probes: the primary hit (and the sun ray, "+sun") at every
//                     pixel, AO and soft shadow interpolated from the sources matching the new
//                     sample's own cluster id (min_sources 1 or 2); "sun where needed": probes of the
//                     primary ray only, refined with the sun ray where two agreeing sources do not suffice;
//                     "AO+soft within T": also evaluated unless the chosen sources' AO and soft-shadow
//                     ratios differ pairwise by at most T (agree(), sample_source.hpp); "probe where
//                     sources differ": probe_every_sample off, a probe only where a new sample's
//                     sources differ (or their normals by more than an angle: smooth())
//   ibuffer_occl      the I-Buffer whose compatibility test also bounds the AO / soft-shadow
//                     difference (§4.1's extension to other high-frequency signals)
//   denoise_atrous    what engines ship: primary + sun ray, n AO and m soft-shadow rays per pixel
//                     (rotated per pixel, in 16-ray packets), 5 iterations of the edge-avoiding
//                     à-trous filter on the two visibility planes (upsample_denoise.hpp);
//                     filter_seconds: the filter alone.
//                     Then, per denoiser row, the best I-Buffer row within its time is printed.
//   full_rotated      (with denoise_atrous) the reference's ray counts with the denoiser's rotated
//                     ray sets, unfiltered: the distance of an equally converged image from the
//                     reference's fixed ray sets, i.e. the best PSNR a denoiser can reach here
// Each time is the least of --repeat N runs (default 3; the machine is shared). --only runs a
// subset (the reference always runs), --match only the upsampler and joint-bilateral rows whose
// setting contains TEXT (or one of TEXT|TEXT...). --tessellate SHARE splits the scene's triangles
// 1:4 until none covers more than SHARE of the image (clustering paper §4.1) before anything
// runs. --diagnose prints where the I-Buffer's error and time go
// (feature clusters, 3 and 4 passes) instead of writing a CSV.
// Writes the CSV (method,setting,seconds,speedup_vs_full_single,evaluated_fraction,psnr_db,ssim,
// cpu_seconds,cpu_speedup_vs_full_single,filter_seconds: wall and process CPU time, each the least of N runs)
// and FILE.png: PSNR against CPU time (gnuplot), with FILE.gp/FILE.dat next to it. For CPU
// times that mean something, run with OMP_WAIT_POLICY=passive (no spinning OpenMP workers).
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <atomic>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <string_view>
#include <vector>
#include <glm/geometric.hpp>
#include <omp.h>
#include "infolerp/upsample/upsampler.hpp"
#include "pareto.hpp"
#include "upsample_denoise.hpp"
#include "support/demo_clusters.hpp"
#include "support/demo_scene.hpp"
#include "support/demo_upsample.hpp"
#include "support/embree_tracer.hpp"
#include "support/image.hpp"
#include "support/reference_shader.hpp"
#include "support/ssim.hpp"

namespace {

namespace sup = infolerp::support;
using sample = sup::demo_sample;

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// CPU time of the whole process (all threads): less sensitive than wall time to the other
// processes of a shared machine. Run with OMP_WAIT_POLICY=passive, or OpenMP's spinning
// workers count too.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The least wall and CPU time over repeated runs.
struct stopwatch {
  double wall = 1e30, cpu = 1e30, wall0 = 0, cpu0 = 0;
  void start() {
    wall0 = now_seconds();
    cpu0 = cpu_seconds();
  }
  void stop() {
    wall = std::min(wall, now_seconds() - wall0);
    cpu = std::min(cpu, cpu_seconds() - cpu0);
  }
};

std::vector<float> luma_of(const sup::image& img) {
  std::vector<float> l(img.pixels.size());
  for (std::size_t i = 0; i < l.size(); ++i) l[i] = sup::display_luma(img.pixels[i]);
  return l;
}

struct row {
  std::string method, setting;
  double seconds = 0, cpu_seconds = 0, evaluated_fraction = 0, psnr = 0, ssim = 0;
  double filter_seconds = -1;  // denoise_atrous rows: the filter alone (least of the runs); -1: none
};

// The contrast competitor: the same pass schedule and record, but two samples may be
// interpolated when their shaded display luma differ by at most `threshold`.
struct contrast_sample {
  sample s;
  float luma = 0.0f;
  bool background() const { return s.background(); }
};
struct contrast_source {
  using sample_type = contrast_sample;
  sup::demo_ibuffer_source base;
  float threshold = 0.05f;
  contrast_sample evaluate(std::uint32_t x, std::uint32_t y) const {
    contrast_sample c{base.evaluate(x, y), 0.0f};
    c.luma = sup::display_luma(base.shade(c.s, x, y));
    return c;
  }
  bool compatible(const contrast_sample& a, const contrast_sample& b) const {
    return std::abs(a.luma - b.luma) <= threshold;
  }
  contrast_sample interpolate(const contrast_sample& a, const contrast_sample& b) const {
    return {infolerp::interpolate(a.s, b.s), 0.5f * (a.luma + b.luma)};
  }
  contrast_sample interpolate(const contrast_sample& a, const contrast_sample& b, const contrast_sample& c,
                              const contrast_sample& d) const {
    return {infolerp::interpolate(a.s, b.s, c.s, d.s), 0.25f * ((a.luma + b.luma) + (c.luma + d.luma))};
  }
  glm::vec3 shade(const contrast_sample& c, std::uint32_t x, std::uint32_t y) const { return base.shade(c.s, x, y); }
};

// The I-Buffer with the occlusion terms in the compatibility test as well (the §4.1 extension
// to "other high frequency signals"): same cluster, same light bits, and AO and soft-shadow
// ratios within `tolerance`.
struct occlusion_checked_source : sup::demo_ibuffer_source {
  float tolerance = 0.1f;
  bool compatible(const sample& a, const sample& b) const {
    return infolerp::compatible(a, b) && infolerp::occlusion_within(a, b, tolerance);
  }
};

class harness {
 public:
  harness(const sup::demo_scene& scene, const sup::shader_options& shading, int width, int height, int threads)
      : scene_(scene), shading_(shading), single_(scene, shading), w_(width), h_(height), threads_(threads) {}

  // features: the feature clustering at the demo's thresholds; coarser: at other thresholds.
  int run(const std::string& csv_path, const sup::scene_clustering& features, const std::vector<sup::scene_clustering>& coarser) {
    // (1) the reference: full per-pixel evaluation with single rays.
    {
      stopwatch sw;
      for (int rep = 0; rep < repeat_; ++rep) {
        sw.start();
        auto st = sup::render_reference(single_, w_, h_, reference_, threads_);
        if (!st) return fail(st.error().message());
        sw.stop();
      }
      t_full_ = sw.wall;
      cpu_full_ = sw.cpu;
      ref_luma_ = luma_of(reference_);
      add("full_single", "1 ray per call", sw, 1.0, reference_);
    }
    // (2) 16-ray packets.
    if (want("full_packets16")) {
      sup::shader_options o = shading_;
      o.packets = true;
      const sup::reference_shader packets(scene_, o);
      sup::image img;
      stopwatch sw;
      for (int rep = 0; rep < repeat_; ++rep) {
        sw.start();
        auto st = sup::render_reference(packets, w_, h_, img, threads_);
        if (!st) return fail(st.error().message());
        sw.stop();
      }
      add("full_packets16", "AO+soft shadow rays in 16-ray packets", sw, 1.0, img);
    }
    // (6) the I-Buffer with several clusterings and 1-5 passes.
    std::vector<sup::scene_clustering> clusterings;
    clusterings.push_back(sup::cluster_by_object(scene_));
    for (int cells : {1, 2, 4}) clusterings.push_back(sup::cluster_by_normal(scene_, cells));
    clusterings.insert(clusterings.end(), coarser.begin(), coarser.end());
    clusterings.push_back(features);
    std::vector<double> matched_fraction(7, 0.0);  // evaluated fraction of the feature clustering, per passes (0: row not run)
    for (const auto& c : clusterings) {
      // One pass (plain evaluation through the upsampler) only for the feature clustering; 6
      // passes only for the feature clusterings.
      const bool feature = c.name.starts_with("feature");
      for (std::uint32_t passes = &c == &clusterings.back() ? 1 : 2; passes <= (feature ? 6u : 5u) && want("ibuffer"); ++passes) {
        const sup::demo_ibuffer_source src{&single_, &c, w_, h_};
        double f = 0;
        if (!run_upsampler<sample>(src, passes, "ibuffer",
                                   c.name + " (" + std::to_string(c.count()) + " clusters), " + std::to_string(passes) + " passes", f))
          return 1;
        if (&c == &clusterings.back()) matched_fraction[passes] = f;
      }
    }
    // (6a) the feature clustering with screen-linear weights (the paper's interpolation).
    for (std::uint32_t passes = 2; passes <= 5 && want("ibuffer_linear"); ++passes) {
      const sup::demo_ibuffer_source src{&single_, &features, w_, h_, false};
      double f = 0;
      if (!run_upsampler<sample>(src, passes, "ibuffer_linear",
                                 "feature (" + std::to_string(features.count()) + " clusters), screen-linear weights, " + std::to_string(passes) + " passes", f))
        return 1;
    }
    // (6c) the I-Buffer with probes: primary hit + sun at every pixel, AO and soft shadow interpolated.
    if (want("ibuffer_probe")) {
      for (bool probe_lights : {false, true}) {
        sup::shader_options po = shading_;
        po.ao_rays = 0;
        po.soft_shadow_rays = 0;
        po.hard_shadow = probe_lights;
        const sup::reference_shader primary(scene_, po);
        // min_sources 1 needs probes that carry everything compatible() tests (a single source
        // cannot vouch for the sun bit), so only with probe_lights. The coarser clusterings
        // only with the fastest setting.
        std::vector<const sup::scene_clustering*> with{&features};
        if (probe_lights)
          for (const auto& c : coarser) with.push_back(&c);
        for (const sup::scene_clustering* c : with)
          for (std::uint32_t min_sources = probe_lights ? 1u : 2u; min_sources <= (c == &features ? 2u : 1u); ++min_sources)
            for (std::uint32_t passes = c != &features ? 4 : probe_lights && min_sources == 2 ? 2 : 3; passes <= 6; ++passes) {
              sup::demo_probe_source src;
              static_cast<sup::demo_ibuffer_source&>(src) = {&single_, c, w_, h_};
              src.primary = &primary;
              src.probe_lights = probe_lights;
              double f = 0;
              char setting[128];
              std::snprintf(setting, sizeof setting, "%s (%zu), probe primary%s, min %u src, %u passes", c->name.c_str(),
                            c->count(), probe_lights ? "+sun" : "", min_sources, passes);
              if (!run_upsampler<sample>(src, passes, "ibuffer_probe", setting, f, min_sources)) return 1;
            }
      }
      // Cheap probes (primary ray only) refined with the sun ray where two agreeing sources do not suffice.
      sup::shader_options po = shading_;
      po.ao_rays = 0;
      po.soft_shadow_rays = 0;
      const sup::reference_shader primary_sun(scene_, po);
      po.hard_shadow = false;
      const sup::reference_shader primary(scene_, po);
      auto refining = [&](sup::demo_refining_probe_source& src, const sup::scene_clustering* c) {
        static_cast<sup::demo_ibuffer_source&>(src) = {&single_, c, w_, h_};
        src.primary = &primary;
        src.probe_lights = false;
        src.primary_sun = &primary_sun;
      };
      std::vector<const sup::scene_clustering*> with{&features};
      for (const auto& c : coarser) with.push_back(&c);
      // The demo clustering with 2-6 passes (min_sources 1) and 2-4 (min_sources 2), the coarser ones with 4-6.
      for (const sup::scene_clustering* c : with)
        for (std::uint32_t min_sources = 1; min_sources <= (c == &features ? 2u : 1u); ++min_sources)
          for (std::uint32_t passes = c == &features ? 2 : 4; passes <= (min_sources == 1 ? 6u : 4u); ++passes) {
            sup::demo_refining_probe_source src;
            refining(src, c);
            double f = 0;
            char setting[128];
            std::snprintf(setting, sizeof setting, "%s (%zu), probe primary, sun where needed, min %u src, %u passes", c->name.c_str(),
                          c->count(), min_sources, passes);
            if (!run_upsampler<sample>(src, passes, "ibuffer_probe", setting, f, min_sources)) return 1;
          }
      // The same, probing only the new samples whose sources differ (probe_every_sample = false).
      for (const sup::scene_clustering* c : with)
        for (std::uint32_t min_sources = 1; min_sources <= 2; ++min_sources)
          for (std::uint32_t passes = 3; passes <= 6; ++passes) {
            sup::demo_refining_probe_source src;
            refining(src, c);
            double f = 0;
            char setting[160];
            std::snprintf(setting, sizeof setting, "%s (%zu), probe where sources differ, sun where needed, min %u src, %u passes",
                          c->name.c_str(), c->count(), min_sources, passes);
            if (!run_upsampler<sample>(src, passes, "ibuffer_probe", setting, f, min_sources, false)) return 1;
          }
      // ... and also where the sources' normals differ by more than an angle (smooth()): the demo clustering.
      for (float degrees : {10.0f, 5.0f, 2.5f})
        for (std::uint32_t passes = 4; passes <= 6; ++passes) {
          sup::demo_refining_probe_source src;
          refining(src, &features);
          src.smooth_cos = std::cos(degrees * 3.14159265f / 180.0f);
          double f = 0;
          char setting[160];
          std::snprintf(setting, sizeof setting, "%s (%zu), probe where sources differ or normals > %.1f deg, sun where needed, min 1 src, %u passes",
                        features.name.c_str(), features.count(), static_cast<double>(degrees), passes);
          if (!run_upsampler<sample>(src, passes, "ibuffer_probe", setting, f, 1, false)) return 1;
        }
      // The same, evaluating where the chosen sources' AO or soft-shadow ratios differ by more
      // than a tolerance (agree(), sample_source.hpp): the demo clustering and one coarser (159 ids).
      with.assign({&features});
      if (coarser.size() > 1) with.push_back(&coarser[1]);
      for (const sup::scene_clustering* c : with)
        for (std::uint32_t min_sources = 1; min_sources <= 2; ++min_sources)
          for (float tolerance : {0.02f, 0.04f, 0.08f, 0.16f})
            for (std::uint32_t passes = 2; passes <= 5; ++passes) {
              sup::demo_tolerant_probe_source src;
              refining(src, c);
              src.tolerance = tolerance;
              double f = 0;
              char setting[160];
              std::snprintf(setting, sizeof setting, "%s (%zu), probe primary, sun where needed, min %u src, AO+soft within %.2f, %u passes",
                            c->name.c_str(), c->count(), min_sources, static_cast<double>(tolerance), passes);
              if (!run_upsampler<sample>(src, passes, "ibuffer_probe", setting, f, min_sources)) return 1;
            }
    }
    // (6b) the I-Buffer with the occlusion terms also tested.
    for (float tolerance : {0.05f, 0.1f}) {
      if (!want("ibuffer_occl")) break;
      for (std::uint32_t passes = 3; passes <= 5; ++passes) {
        occlusion_checked_source src;
        static_cast<sup::demo_ibuffer_source&>(src) = {&single_, &features, w_, h_};
        src.tolerance = tolerance;
        double f = 0;
        char setting[96];
        std::snprintf(setting, sizeof setting, "feature + |dAO|,|dsoft| <= %.2f, %u passes", static_cast<double>(tolerance), passes);
        if (!run_upsampler<sample>(src, passes, "ibuffer_occl", setting, f)) return 1;
      }
    }
    // (5) the same schedule deciding by luminance contrast.
    for (float threshold : {0.02f, 0.05f}) {
      if (!want("contrast")) break;
      for (std::uint32_t passes = 2; passes <= 5; ++passes) {
        const contrast_source src{{&single_, &clusterings[0], w_, h_}, threshold};
        double f = 0;
        char setting[96];
        std::snprintf(setting, sizeof setting, "luma contrast <= %.2f, %u passes", static_cast<double>(threshold), passes);
        if (!run_upsampler<contrast_sample>(src, passes, "contrast", setting, f)) return 1;
      }
    }
    // (3) uniform low resolution + bilinear at the I-Buffer's evaluated fraction.
    for (std::uint32_t passes = 2; passes <= 6 && want("lowres_bilinear"); ++passes) {
      if (matched_fraction[passes] > 0) {
        lowres_bilinear(matched_fraction[passes], passes);
      } else {  // --match left out the feature row whose cost this one matches
        std::fprintf(stderr, "infolerp_pareto upsample: no lowres_bilinear row for %u passes: its feature I-Buffer row did not run\n", passes);
      }
    }
    // (4) joint-bilateral upsampling of the expensive terms from a 2^(p-1) grid.
    for (std::uint32_t passes = 2; passes <= 5 && want("joint_bilateral"); ++passes) joint_bilateral(1 << (passes - 1));
    // (7) n AO + m soft-shadow rays per pixel and the edge-avoiding à-trous filter.
    if (want("denoise_atrous")) denoise_atrous();
    equal_time();
    return write(csv_path);
  }


  // --diagnose: where the I-Buffer's error and time go, for the feature clustering at 3 and 4
  // passes. Error: PSNR of the I-Buffer frame with one group of its record replaced by the
  // reference's values at every pixel (what is left is the other groups' error), and the
  // squared-error share of evaluated / interpolated / reused pixels. Time: evaluate() calls
  // (timed inside the source), shading of the final I-Buffer alone, the rest (R/I decisions,
  // interpolation, copies, bookkeeping); and the per-pixel cost of a full evaluation, of a
  // primary ray + sun ray, and of a primary ray alone.
  int diagnose(const sup::scene_clustering& clusters) {
    const std::size_t n = static_cast<std::size_t>(w_) * static_cast<std::size_t>(h_);
    const int nthreads = threads_ > 0 ? threads_ : omp_get_max_threads();
    std::vector<sup::shading_inputs> ref(n);
    sup::image refimg(w_, h_);
    double t0 = now_seconds();
#pragma omp parallel for schedule(dynamic, 2) num_threads(nthreads)
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x) {
        std::uint64_t rays = 0;
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(x);
        ref[i] = single_.evaluate_pixel(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, w_, h_, rays);
        refimg.pixels[i] = single_.shade(ref[i]);
      }
    const double t_full = now_seconds() - t0;
    sup::shader_options po = shading_;
    po.ao_rays = 0;
    po.soft_shadow_rays = 0;
    const sup::reference_shader primary(scene_, po);
    double sink = 0;
    t0 = now_seconds();
#pragma omp parallel for schedule(dynamic, 2) num_threads(nthreads) reduction(+ : sink)
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x) {
        std::uint64_t rays = 0;
        sink += static_cast<double>(primary.evaluate_pixel(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, w_, h_, rays).normal.x);
      }
    const double t_primary_sun = now_seconds() - t0;
    t0 = now_seconds();
#pragma omp parallel for schedule(dynamic, 2) num_threads(nthreads) reduction(+ : sink)
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x)
        sink += scene_.tracer.intersect(scene_.view.primary_ray(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, w_, h_)).valid() ? 1.0 : 0.0;
    const double t_primary = now_seconds() - t0;
    std::printf("per-pixel cost (%d threads, wall): full %.0f ns, primary+sun %.0f ns (%.3f of full), primary %.0f ns (%.3f of full)  [%g]\n",
                nthreads, 1e9 * t_full / static_cast<double>(n), 1e9 * t_primary_sun / static_cast<double>(n), t_primary_sun / t_full,
                1e9 * t_primary / static_cast<double>(n), t_primary / t_full, sink > 0 ? 1.0 : 0.0);

    struct timed_source : sup::demo_ibuffer_source {
      std::atomic<long long>* eval_ns = nullptr;
      sample evaluate(std::uint32_t x, std::uint32_t y) const {
        const auto a = std::chrono::steady_clock::now();
        sample s = sup::demo_ibuffer_source::evaluate(x, y);
        *eval_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - a).count();
        return s;
      }
    };
    for (std::uint32_t passes : {3u, 4u}) {
      std::atomic<long long> eval_ns{0};
      timed_source src;
      static_cast<sup::demo_ibuffer_source&>(src) = {&single_, &clusters, w_, h_};
      src.eval_ns = &eval_ns;
      auto up = infolerp::upsampler<sample>::create(static_cast<std::uint32_t>(w_), static_cast<std::uint32_t>(h_),
                                                    {.passes = passes, .max_passes = passes, .rows_per_task = 2, .keep_ibuffer = true});
      if (!up) return fail(up.error().message());
      sup::image img(w_, h_);
      if (auto s = up->render(src, std::span<glm::vec3>(img.pixels), infolerp::openmp_executor{threads_}); !s) return fail(s.message());
      const auto& st = up->stats();
      const auto buf = up->ibuffer();
      sup::image shaded(w_, h_);
      t0 = now_seconds();
#pragma omp parallel for schedule(static) num_threads(nthreads)
      for (int y = 0; y < h_; ++y)
        for (int x = 0; x < w_; ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(x);
          shaded.pixels[i] = src.shade(buf[i], static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y));
        }
      const double t_shade = now_seconds() - t0;
      const double t_eval = 1e-9 * static_cast<double>(eval_ns.load()) / nthreads;
      std::printf("\n%u passes, %s (%zu clusters): frame %.3f s (x%.2f), evaluated %.4f, PSNR %.2f dB\n", passes,
                  clusters.name.c_str(), clusters.count(), st.seconds, t_full / st.seconds, st.evaluated_fraction(), *sup::psnr(refimg, img));
      std::printf("  time: evaluate %.3f s (%.0f%%; %.0f ns per evaluation per thread), shade %.3f s (%.0f%%), rest (R/I tests, interpolation) %.3f s (%.0f%%)\n",
                  t_eval, 100 * t_eval / st.seconds, 1e9 * t_eval * nthreads / static_cast<double>(st.evaluated()), t_shade,
                  100 * t_shade / st.seconds, st.seconds - t_eval - t_shade, 100 * (st.seconds - t_eval - t_shade) / st.seconds);
      for (std::uint32_t p = 0; p < st.passes; ++p)
        std::printf("  pass %u: %ux%u R %zu I %zu E %zu %.3f s\n", p + 1, st.pass[p].width, st.pass[p].height, st.pass[p].reused,
                    st.pass[p].interpolated, st.pass[p].evaluated, st.pass[p].seconds);
      // Error groups: replace one group by the reference at every pixel.
      enum group { geometry, normal, texcoord, lights, occlusion, count };
      const char* names[] = {"object/position", "normal", "texcoords", "sun bit", "AO+soft"};
      auto variant = [&](int fixed_mask) {
        sup::image v(w_, h_);
#pragma omp parallel for schedule(static) num_threads(nthreads)
        for (int y = 0; y < h_; ++y)
          for (int x = 0; x < w_; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(x);
            sup::shading_inputs in = src.to_inputs(buf[i], static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y));
            const sup::shading_inputs& r = ref[i];
            if (r.hit() != in.hit() || ((fixed_mask & (1 << geometry)) && r.hit())) {
              if (r.hit() != in.hit()) in = r;
              in.geometry = r.geometry;
              in.position = r.position;
            }
            if (r.hit() && in.hit()) {
              if (fixed_mask & (1 << normal)) in.normal = r.normal;
              if (fixed_mask & (1 << texcoord)) in.uv = r.uv;
              if ((fixed_mask & (1 << count)) && glm::length(in.uv - r.uv) > 0.05f) in.uv = r.uv;  // only texcoord jumps (seams)
              if (fixed_mask & (1 << lights)) in.light_bits = r.light_bits;
              if (fixed_mask & (1 << occlusion)) {
                in.ao = r.ao;
                in.soft_shadow = r.soft_shadow;
              }
            }
            v.pixels[i] = single_.shade(in);
          }
        return *sup::psnr(refimg, v);
      };
      std::printf("  PSNR with one group exact (the rest as interpolated):");
      for (int g = 0; g < count; ++g) std::printf(" %s %.2f,", names[g], variant(1 << g));
      std::printf("\n  PSNR with only one group interpolated (the rest exact):");
      for (int g = 0; g < count; ++g) std::printf(" %s %.2f,", names[g], variant(((1 << count) - 1) & ~(1 << g)));
      std::printf("\n  PSNR with texcoords exact where they are off by > 0.05 (seams), the rest as interpolated: %.2f", variant(1 << count));
      std::printf("\n  PSNR with exact primary hit + sun (object, position, normal, texcoords, sun bit), AO+soft as interpolated: %.2f\n",
                  variant(((1 << count) - 1) & ~(1 << occlusion)));
      // Squared error by kind.
      std::array<double, 3> se{}, cnt{};
      const auto kinds = up->kinds();
      for (std::size_t i = 0; i < n; ++i) {
        const glm::vec3 d = glm::clamp(img.pixels[i], 0.0f, 1.0f) - glm::clamp(refimg.pixels[i], 0.0f, 1.0f);
        se[static_cast<std::size_t>(kinds[i])] += static_cast<double>(glm::dot(d, d));
        cnt[static_cast<std::size_t>(kinds[i])] += 1;
      }
      const double tot = se[0] + se[1] + se[2];
      std::printf("  squared-error share (linear, clamped): E %.1f%% of %g px, I %.1f%% of %g px, R %.1f%% of %g px\n", 100 * se[0] / tot,
                  cnt[0], 100 * se[1] / tot, cnt[1], 100 * se[2] / tot, cnt[2]);
    }
    return 0;
  }

 private:
  // --only METHOD[,METHOD...]: run only these methods (and the reference).
  bool want(const std::string& method) const {
    if (only_.empty()) return true;
    return ("," + only_ + ",").find("," + method + ",") != std::string::npos;
  }

  // --match TEXT[|TEXT...]: run only the upsampler and joint-bilateral rows whose setting contains one of them.
  bool matches(const std::string& setting) const {
    if (match_.empty()) return true;
    for (std::size_t b = 0;;) {
      const std::size_t e = std::min(match_.find('|', b), match_.size());
      if (e > b && setting.find(match_.substr(b, e - b)) != std::string::npos) return true;
      if (e == match_.size()) return false;
      b = e + 1;
    }
  }

  static int fail(const std::string& message) {
    std::fprintf(stderr, "infolerp_pareto upsample: %s\n", message.c_str());
    return 1;
  }

  void add(const std::string& method, const std::string& setting, const stopwatch& time, double evaluated_fraction,
           const sup::image& img) {
    row r{method, setting, time.wall, time.cpu, evaluated_fraction, 0, 0};
    r.psnr = *sup::psnr(reference_, img);
    r.ssim = *sup::ssim(ref_luma_, luma_of(img), w_, h_);
    std::printf("%-16s %-56s %7.3f s x%6.2f  cpu %7.3f s x%6.2f  eval %.4f  PSNR %6.2f dB  SSIM %.5f\n", method.c_str(),
                setting.c_str(), time.wall, t_full_ / time.wall, time.cpu, cpu_full_ / time.cpu, evaluated_fraction, r.psnr,
                r.ssim);
    std::fflush(stdout);
    rows_.push_back(r);
  }

  template <class Sample, class Source>
  bool run_upsampler(const Source& src, std::uint32_t passes, const std::string& method, const std::string& setting,
                     double& evaluated_fraction, std::uint32_t min_sources = 2, bool probe_every_sample = true) {
    if (!matches(setting)) return true;
    auto up = infolerp::upsampler<Sample>::create(static_cast<std::uint32_t>(w_), static_cast<std::uint32_t>(h_),
                                                  {.passes = passes, .max_passes = passes, .rows_per_task = 2,
                                                   .record_kinds = false, .min_sources = min_sources,
                                                   .probe_every_sample = probe_every_sample});
    if (!up) return fail(up.error().message()) == 0;
    sup::image img(w_, h_);
    stopwatch t;
    for (int rep = 0; rep < repeat_; ++rep) {
      t.start();
      auto s = up->render(src, std::span<glm::vec3>(img.pixels), infolerp::openmp_executor{threads_});
      t.stop();
      if (!s) return fail(s.message()) == 0;
    }
    evaluated_fraction = up->stats().evaluated_fraction();
    add(method, setting, t, evaluated_fraction, img);
    return true;
  }

  void lowres_bilinear(double fraction, std::uint32_t passes) {
    // A gw x gh grid spanning the image corners with about fraction * W * H samples.
    const double spacing = 1.0 / std::sqrt(std::max(fraction, 1e-6));
    const int gw = std::max(2, static_cast<int>(std::lround((w_ - 1) / spacing)) + 1);
    const int gh = std::max(2, static_cast<int>(std::lround((h_ - 1) / spacing)) + 1);
    const float sx = static_cast<float>(w_ - 1) / static_cast<float>(gw - 1);
    const float sy = static_cast<float>(h_ - 1) / static_cast<float>(gh - 1);
    std::vector<glm::vec3> grid(static_cast<std::size_t>(gw) * static_cast<std::size_t>(gh));
    sup::image img(w_, h_);
    stopwatch t;
    for (int rep = 0; rep < repeat_; ++rep) {
    t.start();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads_ > 0 ? threads_ : omp_get_max_threads())
    for (int j = 0; j < gh; ++j)
      for (int i = 0; i < gw; ++i) {
        std::uint64_t rays = 0;
        const auto in = single_.evaluate_pixel(static_cast<float>(i) * sx + 0.5f, static_cast<float>(j) * sy + 0.5f, w_, h_, rays);
        grid[static_cast<std::size_t>(j) * static_cast<std::size_t>(gw) + static_cast<std::size_t>(i)] = single_.shade(in);
      }
#pragma omp parallel for schedule(static) num_threads(threads_ > 0 ? threads_ : omp_get_max_threads())
    for (int y = 0; y < h_; ++y) {
      const float gy = static_cast<float>(y) / sy;
      const int j = std::min(static_cast<int>(gy), gh - 2);
      const float fy = gy - static_cast<float>(j);
      for (int x = 0; x < w_; ++x) {
        const float gx = static_cast<float>(x) / sx;
        const int i = std::min(static_cast<int>(gx), gw - 2);
        const float fx = gx - static_cast<float>(i);
        auto g = [&](int a, int b) { return grid[static_cast<std::size_t>(b) * static_cast<std::size_t>(gw) + static_cast<std::size_t>(a)]; };
        img.at(x, y) = (1 - fy) * ((1 - fx) * g(i, j) + fx * g(i + 1, j)) + fy * ((1 - fx) * g(i, j + 1) + fx * g(i + 1, j + 1));
      }
    }
    t.stop();
    }
    char setting[96];
    std::snprintf(setting, sizeof setting, "%dx%d grid (matches ibuffer feature, %u passes)", gw, gh, passes);
    add("lowres_bilinear", setting, t, static_cast<double>(grid.size()) / (static_cast<double>(w_) * h_), img);
  }

  void joint_bilateral(int step) {
    char setting[96];
    std::snprintf(setting, sizeof setting, "AO+soft on a 1/%d grid, primary+sun per pixel", step);
    if (!matches(setting)) return;
    // Primary-only shader: primary ray + the hard-shadow ray; AO and soft shadow come from the grid.
    sup::shader_options po = shading_;
    po.ao_rays = 0;
    po.soft_shadow_rays = 0;
    const sup::reference_shader primary(scene_, po);
    const int gw = (w_ - 1 + step - 1) / step + 1, gh = (h_ - 1 + step - 1) / step + 1;
    std::vector<sup::shading_inputs> grid(static_cast<std::size_t>(gw) * static_cast<std::size_t>(gh));
    sup::image img(w_, h_);
    const int nthreads = threads_ > 0 ? threads_ : omp_get_max_threads();
    long long fallbacks = 0;
    const glm::vec3 eye = scene_.view.eye;
    stopwatch t;
    for (int rep = 0; rep < repeat_; ++rep) {
    fallbacks = 0;
    t.start();
#pragma omp parallel for schedule(dynamic, 1) num_threads(nthreads)
    for (int j = 0; j < gh; ++j)
      for (int i = 0; i < gw; ++i) {
        std::uint64_t rays = 0;
        grid[static_cast<std::size_t>(j) * static_cast<std::size_t>(gw) + static_cast<std::size_t>(i)] =
            single_.evaluate_pixel(static_cast<float>(i * step) + 0.5f, static_cast<float>(j * step) + 0.5f, w_, h_, rays);
      }
#pragma omp parallel for schedule(dynamic, 2) num_threads(nthreads) reduction(+ : fallbacks)
    for (int y = 0; y < h_; ++y) {
      const int j = y / step;
      const float fy = static_cast<float>(y - j * step) / static_cast<float>(step);
      for (int x = 0; x < w_; ++x) {
        std::uint64_t rays = 0;
        sup::shading_inputs in =
            primary.evaluate_pixel(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, w_, h_, rays);
        if (in.hit()) {
          const int i = x / step;
          const float fx = static_cast<float>(x - i * step) / static_cast<float>(step);
          const float depth = glm::length(in.position - eye);
          float wsum = 0, ao = 0, soft = 0;
          for (int b = 0; b < 2; ++b)
            for (int a = 0; a < 2; ++a) {
              const int gi = std::min(i + a, gw - 1), gj = std::min(j + b, gh - 1);
              const auto& c = grid[static_cast<std::size_t>(gj) * static_cast<std::size_t>(gw) + static_cast<std::size_t>(gi)];
              if (c.geometry != in.geometry) continue;
              const float wb = (a ? fx : 1 - fx) * (b ? fy : 1 - fy) + 1e-6f;
              const float wn = std::exp(-(1.0f - glm::dot(c.normal, in.normal)) / 0.05f);
              const float wd = std::exp(-std::abs(glm::length(c.position - eye) - depth) / (0.02f * depth));
              const float wt = wb * wn * wd;
              wsum += wt;
              ao += wt * c.ao;
              soft += wt * c.soft_shadow;
            }
          if (wsum > 1e-4f) {
            in.ao = ao / wsum;
            in.soft_shadow = soft / wsum;
          } else {  // no similar coarse sample: evaluate this pixel fully
            in = single_.evaluate_pixel(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, w_, h_, rays);
            ++fallbacks;
          }
        }
        img.at(x, y) = single_.shade(in);
      }
    }
    t.stop();
    }
    add("joint_bilateral", setting, t,
        (static_cast<double>(grid.size()) + static_cast<double>(fallbacks)) / (static_cast<double>(w_) * h_), img);
  }

  // The denoiser baseline (upsample_denoise.hpp) for the (n, m) settings, 5 iterations;
  // its time includes the rays, the filter and shade(); the filter alone is filter_seconds.
  void denoise_atrous() {
    sup::shader_options po = shading_;
    po.ao_rays = 0;
    po.soft_shadow_rays = 0;
    const sup::reference_shader primary_sun(scene_, po);
    for (const auto& [n, m] : {std::pair{1u, 1u}, {2u, 1u}, {4u, 1u}, {4u, 2u}, {8u, 2u}, {16u, 4u}}) {
      char setting[96];
      std::snprintf(setting, sizeof setting, "%u AO + %u soft rays, 5 iterations, object id", n, m);
      if (!matches(setting)) continue;
      infolerp::bench::denoise_renderer d(primary_sun, single_, n, m, w_, h_, 5);
      sup::image img(w_, h_);
      stopwatch t;
      double filter = 1e30;
      for (int rep = 0; rep < repeat_; ++rep) {
        t.start();
        const double f = d.render(img, infolerp::openmp_executor{threads_});
        t.stop();
        filter = std::min(filter, f);
      }
      add("denoise_atrous", setting, t, 0.0, img);
      rows_.back().filter_seconds = filter;
      const double mpix = 1e-6 * static_cast<double>(w_) * static_cast<double>(h_);
      std::printf("  per megapixel (wall): filter %.4f s, rays + shade %.4f s\n", filter / mpix, (t.wall - filter) / mpix);
    }
    // The reference's ray counts with the denoiser's per-pixel rotated sets and no filter: how far
    // an equally converged estimate with other rays lies from the reference's fixed sets (the
    // PSNR a denoiser could reach at best against this reference).
    infolerp::bench::denoise_renderer d(primary_sun, single_, shading_.ao_rays, shading_.soft_shadow_rays, w_, h_, 0, false);
    sup::image img(w_, h_);
    stopwatch t;
    t.start();
    d.render(img, infolerp::openmp_executor{threads_});
    t.stop();
    add("full_rotated", "the reference's ray counts, rays rotated per pixel, no filter", t, 1.0, img);
  }

  // For each denoiser row, the I-Buffer row (any mode) of the best PSNR that takes no more wall
  // time, and the fastest I-Buffer row at >= its PSNR + 3 dB with higher SSIM.
  // The fastest I-Buffer rows at >= 40 dB and at >= 45 dB (SSIM >= 0.98) against full_single and
  // full_packets16 (same run, wall time); then, per denoiser row, the best I-Buffer row within its time.
  void equal_time() const {
    const row* packets = nullptr;
    for (const auto& r : rows_)
      if (r.method == "full_packets16") packets = &r;
    for (const double floor_db : {40.0, 45.0}) {
      const row* fastest = nullptr;
      for (const auto& r : rows_)
        if (r.method.starts_with("ibuffer") && r.psnr >= floor_db && r.ssim >= 0.98 && (fastest == nullptr || r.seconds < fastest->seconds))
          fastest = &r;
      if (fastest == nullptr) continue;
      std::printf("speed: fastest I-Buffer row at >= %.0f dB and SSIM >= 0.98: %s %s (%.3f s, %.2f dB, SSIM %.5f), x%.2f full_single",
                  floor_db, fastest->method.c_str(), fastest->setting.c_str(), fastest->seconds, fastest->psnr, fastest->ssim,
                  t_full_ / fastest->seconds);
      if (packets != nullptr) std::printf(", x%.2f full_packets16", packets->seconds / fastest->seconds);
      std::printf("\n");
    }
    for (const auto& d : rows_) {
      if (d.method != "denoise_atrous") continue;
      const row *best = nullptr, *fastest_win = nullptr;
      for (const auto& r : rows_) {
        if (!r.method.starts_with("ibuffer")) continue;
        if (r.seconds <= d.seconds && (best == nullptr || r.psnr > best->psnr)) best = &r;
        if (r.psnr >= d.psnr + 3.0 && r.ssim > d.ssim && (fastest_win == nullptr || r.seconds < fastest_win->seconds)) fastest_win = &r;
      }
      std::printf("equal time: %s (%.3f s, %.2f dB, SSIM %.4f)\n", d.setting.c_str(), d.seconds, d.psnr, d.ssim);
      if (best) std::printf("  best I-Buffer row within its time: %s %s (%.3f s, %.2f dB, SSIM %.4f): %s\n", best->method.c_str(),
                            best->setting.c_str(), best->seconds, best->psnr, best->ssim,
                            best->psnr >= d.psnr + 3.0 && best->ssim > d.ssim ? "beaten (+3 dB, higher SSIM)" : "NOT beaten");
      else std::printf("  no I-Buffer row within its time\n");
      if (fastest_win) std::printf("  fastest I-Buffer row at +3 dB and higher SSIM: %s %s (%.3f s, x%.2f of the denoiser's time)\n",
                                   fastest_win->method.c_str(), fastest_win->setting.c_str(), fastest_win->seconds,
                                   fastest_win->seconds / d.seconds);
    }
  }

  int write(const std::string& csv_path) {
    std::ofstream csv(csv_path);
    if (!csv) return fail("cannot write " + csv_path);
    csv << "method,setting,seconds,speedup_vs_full_single,evaluated_fraction,psnr_db,ssim,cpu_seconds,cpu_speedup_vs_full_single,filter_seconds\n";
    char line[512];
    for (const auto& r : rows_) {
      std::snprintf(line, sizeof line, "%s,\"%s\",%.6f,%.4f,%.6f,%.4f,%.6f,%.6f,%.4f,", r.method.c_str(), r.setting.c_str(),
                    r.seconds, t_full_ / r.seconds, r.evaluated_fraction, r.psnr, r.ssim, r.cpu_seconds, cpu_full_ / r.cpu_seconds);
      csv << line;
      if (r.filter_seconds >= 0) {
        std::snprintf(line, sizeof line, "%.6f", r.filter_seconds);
        csv << line;
      }
      csv << "\n";
    }
    csv.close();
    std::printf("wrote %s\n", csv_path.c_str());
    // Plot: PSNR (capped at 60 dB for the exact methods) against seconds, one series per method.
    const std::string base = csv_path.size() > 4 && csv_path.ends_with(".csv") ? csv_path.substr(0, csv_path.size() - 4) : csv_path;
    std::ofstream dat(base + ".dat");
    // One data block per method that has rows (gnuplot numbers the blocks, so an empty block
    // for a method left out by --only would shift every later title onto the wrong points).
    std::vector<const char*> methods;
    for (const char* m : {"full_single", "full_packets16", "lowres_bilinear", "joint_bilateral", "contrast", "ibuffer",
                          "ibuffer_linear", "ibuffer_probe", "ibuffer_occl", "denoise_atrous", "full_rotated"})
      if (std::any_of(rows_.begin(), rows_.end(), [&](const auto& r) { return r.method == m; })) methods.push_back(m);
    for (const char* m : methods) {
      dat << "# " << m << "\n";
      for (const auto& r : rows_)
        if (r.method == m) dat << r.cpu_seconds << " " << std::min(r.psnr, 60.0) << " " << r.ssim << "\n";
      dat << "\n\n";
    }
    dat.close();
    std::ofstream gp(base + ".gp");
    gp << "set terminal pngcairo size 1000,650 noenhanced\nset output '" << base << ".png'\n"
       << "set title 'Demo scene " << w_ << "x" << h_ << ": PSNR against render time (exact methods drawn at 60 dB)'\n"
       << "set xlabel 'CPU seconds, all threads (log)'\nset ylabel 'PSNR dB vs full per-pixel evaluation'\nset logscale x\nset grid\n"
       << "set key bottom right\nplot ";
    for (std::size_t i = 0; i < methods.size(); ++i)
      gp << (i ? ", " : "") << "'" << base << ".dat' index " << i << " using 1:2 with points pt " << (i + 4)
         << " title '" << methods[i] << "'";
    gp << "\n";
    gp.close();
    const std::string cmd = "gnuplot '" + base + ".gp'";
    if (std::system(cmd.c_str()) == 0) std::printf("wrote %s.png\n", base.c_str());
    else std::fprintf(stderr, "infolerp_pareto upsample: gnuplot failed; the data is in %s.dat\n", base.c_str());
    return 0;
  }

  const sup::demo_scene& scene_;
  sup::shader_options shading_;
  sup::reference_shader single_;
  int w_, h_, threads_;
  sup::image reference_;
  std::vector<float> ref_luma_;
  double t_full_ = 0, cpu_full_ = 0;
  std::vector<row> rows_;

 public:
  std::string only_;
  std::string match_;
  int repeat_ = 3;  // --repeat N: each method's time is the least of N runs (the machine is shared)
};

bool parse_int(const char* text, int lo, int hi, int& out) {
  const std::string_view s(text);
  int v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size() || v < lo || v > hi) return false;
  out = v;
  return true;
}

}  // namespace

int pareto_upsample(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)  // the textured-asset mode (upsample_textured.cpp)
    if (std::string_view(argv[i]) == "--textured" && pareto_upsample_textured != nullptr) return pareto_upsample_textured(argc, argv);
  for (int i = 1; i < argc; ++i)  // frames along a camera path (upsample_path.cpp)
    if (std::string_view(argv[i]) == "--path" && pareto_upsample_path != nullptr) return pareto_upsample_path(argc, argv);
  std::string csv;
  bool diagnose = false;
  std::string only, match;
  int repeat = 3;
  int width = 1025, height = 1025, threads = 0, ao = 64, soft = 16;
  sup::demo_scene_options scene_options;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    const bool has1 = i + 1 < argc, has2 = i + 2 < argc;
    if (a == "--csv" && has1) {
      csv = argv[++i];
    } else if (a == "--size" && has2 && parse_int(argv[i + 1], 16, 16384, width) && parse_int(argv[i + 2], 16, 16384, height)) {
      i += 2;
    } else if (a == "--only" && has1) {
      only = argv[++i];
    } else if (a == "--match" && has1) {
      match = argv[++i];
    } else if (a == "--repeat" && has1 && parse_int(argv[i + 1], 1, 100, repeat)) {
      ++i;
    } else if (a == "--diagnose") {
      diagnose = true;
    } else if (a == "--threads" && has1 && parse_int(argv[i + 1], 1, 1024, threads)) {
      ++i;
    } else if (a == "--ao" && has1 && parse_int(argv[i + 1], 0, 4096, ao)) {
      ++i;
    } else if (a == "--soft" && has1 && parse_int(argv[i + 1], 0, 4096, soft)) {
      ++i;
    } else if (char* end = nullptr; a == "--tessellate" && has1 &&
                                      (scene_options.tessellate = std::strtof(argv[i + 1], &end), *end == '\0' && end != argv[i + 1])) {
      ++i;
    } else {
      std::fprintf(stderr, "usage: infolerp_pareto upsample (--csv FILE | --diagnose) [--only METHOD,...] [--match TEXT] [--repeat N] [--size W H] [--threads N] [--ao N] [--soft N] [--tessellate SHARE]\n");
      return 2;
    }
  }
  if (csv.empty() && !diagnose) {
    std::fprintf(stderr, "infolerp_pareto upsample: --csv FILE is required\n");
    return 2;
  }
  // Flush-to-zero on every OpenMP worker (the reference renderer sets it on its own workers).
  sup::enable_flush_to_zero();
#pragma omp parallel num_threads(threads > 0 ? threads : omp_get_max_threads())
  sup::enable_flush_to_zero();
  const sup::embree_device device;
  auto scene = sup::make_demo_scene(device, scene_options);
  if (!scene) {
    std::fprintf(stderr, "infolerp_pareto upsample: %s\n", scene.error().message().c_str());
    return 1;
  }
  std::size_t triangles = 0;
  for (const auto& object : scene->objects) triangles += object.mesh.triangle_count();
  std::printf("scene: %zu triangles (tessellated to %g of the image per triangle: %s)\n", triangles,
              static_cast<double>(scene_options.tessellate), scene_options.tessellate > 0.0f ? "yes" : "no");
  // lowres_bilinear's grids are sized to the ibuffer rows' evaluated fractions.
  const auto listed = [&](const char* m) { return ("," + only + ",").find("," + std::string(m) + ",") != std::string::npos; };
  if (!only.empty() && listed("lowres_bilinear") && !listed("ibuffer")) {
    std::fprintf(stderr, "infolerp_pareto upsample: --only lowres_bilinear needs ibuffer too (its grids match the ibuffer rows' cost)\n");
    return 2;
  }
  const sup::shader_options shading{.ao_rays = static_cast<unsigned>(ao), .soft_shadow_rays = static_cast<unsigned>(soft)};
  std::printf("demo scene %dx%d, AO %d rays, soft shadow %d rays, threads %d\n", width, height, ao, soft,
              threads > 0 ? threads : omp_get_max_threads());
  const double t0 = now_seconds();
  auto clustered = sup::cluster_by_features(*scene, infolerp::openmp_executor{threads});
  if (!clustered) {
    std::fprintf(stderr, "infolerp_pareto upsample: %s\n", clustered.error().message().c_str());
    return 1;
  }
  const auto split = sup::split_at_texture_seams(*scene, *clustered);
  if (!split) {
    std::fprintf(stderr, "infolerp_pareto upsample: %s\n", split.error().message().c_str());
    return 1;
  }
  const sup::scene_clustering& features = *split;
  std::printf("feature clustering (demo thresholds): %zu clusters, %zu ids after the texture-seam split, %.1f s\n",
              clustered->count(), features.count(), now_seconds() - t0);
  // Coarser thresholds (fewer clusters): the paper's Fig. 8 setting (110 clusters there) and one between.
  std::vector<sup::scene_clustering> coarser;
  for (const sup::cluster_thresholds& th : {sup::cluster_thresholds{{"visibility", 0.54f}, {"orientation", 0.3f}, {"stretch", 0.1f}},
                                            sup::cluster_thresholds{{"visibility", 0.54f}, {"orientation", 0.2f}, {"stretch", 0.1f}},
                                            sup::cluster_thresholds{{"visibility", 0.48f}, {"orientation", 0.3f}, {"stretch", 0.1f}},
                                            sup::cluster_thresholds{{"visibility", 0.6f}, {"orientation", 0.3f}, {"stretch", 0.1f}},
                                            sup::cluster_thresholds{{"visibility", 0.48f}, {"orientation", 0.15f}, {"stretch", 0.1f}}}) {
    if (diagnose) break;
    auto r = sup::cluster_by_features(*scene, infolerp::openmp_executor{threads}, th);
    if (!r) {
      std::fprintf(stderr, "infolerp_pareto upsample: %s\n", r.error().message().c_str());
      return 1;
    }
    auto coarse = sup::split_at_texture_seams(*scene, *r);
    if (!coarse) {
      std::fprintf(stderr, "infolerp_pareto upsample: %s\n", coarse.error().message().c_str());
      return 1;
    }
    coarser.push_back(std::move(*coarse));
    char name[96];
    std::snprintf(name, sizeof name, "feature V%.2f O%.2f S%.2f", static_cast<double>(th.at("visibility")),
                  static_cast<double>(th.at("orientation")), static_cast<double>(th.at("stretch")));
    coarser.back().name = name;
    std::printf("%s: %zu clusters, %zu ids\n", name, r->count(), coarser.back().count());
  }
  harness h(*scene, shading, width, height, threads);
  h.only_ = only;
  h.match_ = match;
  h.repeat_ = repeat;
  return diagnose ? h.diagnose(features) : h.run(csv, features, coarser);
}
