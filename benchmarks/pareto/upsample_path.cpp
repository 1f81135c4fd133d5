// infolerp_pareto upsample --path --csv FILE [--size W H] [--frames N] [--threads N] [--ao N] [--soft N]
//                          [--pictures DIR] [--reuse-passes P] [--refresh K] [--depth-tolerance T]
//
// Frames along a camera path through the built-in demo scene (reference shading: AO 64 rays,
// soft shadow 16 rays, hard-shadow sun; feature clusters at the demo's thresholds), every frame
// rendered by three methods in turn with the ready source (ray_cast_source.hpp), in one run:
//   per_pixel      full evaluation of every pixel (upsampler, 1 pass): the reference, error 0
//   ibuffer        the I-Buffer every frame from nothing, at its best setting with >= 40 dB
//   ibuffer_reuse  the same upsampler setting through frame_reuse.hpp (the previous frame's
//                  occlusion reused where the reprojected probe passes the §4 test)
// The path (120 frames by default): an orbit of the scene (frames 0-49), the camera standing
// still for 20 frames (50-69), then orbiting on while it moves closer (70-119).
// The I-Buffer setting: each candidate (refined probes, min 1 source; probes per sample or
// only where sources differ, with and without the 5-degree normal test; 4-6 passes) renders
// every 10th frame; the fastest whose every such frame reaches 40.5 dB is used on the whole path.
// CSV: frame,method,seconds,psnr_db,ssim,evaluated_fraction,reused_fraction (wall seconds of
// the render call, PSNR/SSIM of display luma against per_pixel; evaluated_fraction: full
// evaluations per pixel (the upsampler's count for per_pixel and ibuffer, which includes the
// cropped border; frame_reuse's for ibuffer_reuse); reused_fraction: evaluations served from
// the previous frame). FILE.png: time and PSNR per frame (gnuplot; FILE.gp next to it).
// Printed: sums over the path and the goals. --pictures DIR writes path.png there: a
// strip of every 15th frame with reuse, its evaluated pixels marked red. --reuse-passes,
// --refresh and --depth-tolerance change the reuse row's passes and frame_reuse_options.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>
#include <glm/geometric.hpp>
#include <omp.h>
#include "infolerp/core/executor.hpp"
#include "infolerp/upsample/frame_reuse.hpp"
#include "infolerp/upsample/ray_cast_source.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "pareto.hpp"
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
using refine_source = sup::demo_ray_cast_source<infolerp::probe_mode::refine>;

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The path: orbit around the scene's centre at the demo camera's height, stand, orbit closer.
sup::camera camera_at(const sup::camera& base, int frame, int frames) {
  const int stand_begin = frames * 50 / 120, stand_end = stand_begin + frames * 20 / 120;
  const float t = frame < stand_begin ? float(frame) : frame < stand_end ? float(stand_begin) : float(frame - (stand_end - stand_begin));
  const float per_frame = 0.25f * 3.14159265f / 180.0f;  // a quarter degree of orbit per frame
  const float angle = -0.2f + per_frame * t;
  const float closer = frame < stand_end ? 1.0f : 1.0f - 0.004f * float(frame - stand_end);  // to 0.8 over 50 frames
  const glm::vec3 offset = base.eye - base.target;
  const float radius = std::sqrt(offset.x * offset.x + offset.y * offset.y) * closer;
  const float start = std::atan2(offset.y, offset.x);
  sup::camera c = base;
  c.eye = base.target + glm::vec3(radius * std::cos(start + angle), radius * std::sin(start + angle), offset.z * closer);
  return c;
}

struct setting {
  std::string name;
  std::uint32_t passes = 5;
  bool probe_every_sample = false;
  float smooth_degrees = 180.0f;  // 180: no normal test
};

struct frame_result {
  double seconds = 0, psnr = 0, ssim = 0, evaluated = 0, reused = 0;
};

std::vector<float> luma_of(const std::vector<glm::vec3>& img) {
  std::vector<float> l(img.size());
  for (std::size_t i = 0; i < l.size(); ++i) l[i] = sup::display_luma(img[i]);
  return l;
}

double psnr_luma(const std::vector<float>& a, const std::vector<float>& b) {
  double se = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) se += double(a[i] - b[i]) * double(a[i] - b[i]);
  return se <= 0.0 ? 99.0 : 10.0 * std::log10(double(a.size()) / se);
}

class path_harness {
 public:
  path_harness(sup::demo_scene& scene, const sup::scene_clustering& clusters, sup::shader_options shading, int w, int h,
               int threads, int frames)
      : scene_(scene), clusters_(clusters), shading_(shading), w_(w), h_(h), exec_{threads}, frames_(frames),
        base_(scene.view) {}

  // Per frame f: the reference shader (its camera read at construction) and sources for that view.
  struct view {
    sup::reference_shader shader;
    infolerp::pinhole_frame frame;
  };
  view view_at(int f) {
    scene_.view = camera_at(base_, f, frames_);
    view v{sup::reference_shader(scene_, shading_), sup::pinhole_frame_of(scene_.view, std::uint32_t(w_), std::uint32_t(h_))};
    scene_.view = base_;
    return v;
  }
  refine_source source(const view& v, const setting& s) const {
    auto src = sup::make_demo_ray_cast_source<infolerp::probe_mode::refine>(
        v.shader, clusters_, w_, h_, true, std::numeric_limits<float>::infinity(), s.smooth_degrees * 3.14159265f / 180.0f);
    if (!src) {
      std::fprintf(stderr, "infolerp_pareto upsample --path: %s\n", src.error().message().c_str());
      std::exit(1);
    }
    return std::move(*src);
  }
  // keep: keep the I-Buffer (frame_reuse needs it; the per-frame I-Buffer does not pay for it).
  infolerp::upsampler<sample> upsampler_for(const setting& s, bool keep = false) const {
    auto up = infolerp::upsampler<sample>::create(std::uint32_t(w_), std::uint32_t(h_),
                                                  {.passes = s.passes, .max_passes = s.passes, .record_kinds = false,
                                                   .keep_ibuffer = keep, .min_sources = 1,
                                                   .probe_every_sample = s.probe_every_sample});
    if (!up) {
      std::fprintf(stderr, "infolerp_pareto upsample --path: %s\n", up.error().message().c_str());
      std::exit(1);
    }
    return std::move(*up);
  }

  // The reference of frame f (per_pixel) and its time.
  frame_result per_pixel(const view& v, std::vector<glm::vec3>& out) {
    auto src = sup::make_demo_ray_cast_source(v.shader, clusters_, w_, h_);
    auto up = infolerp::upsampler<sample>::create(std::uint32_t(w_), std::uint32_t(h_), {.passes = 1, .max_passes = 1, .record_kinds = false});
    out.assign(std::size_t(w_) * std::size_t(h_), glm::vec3(0.0f));
    const double t0 = now_seconds();
    check(up->render(*src, std::span<glm::vec3>(out), exec_));
    frame_result r;
    r.seconds = now_seconds() - t0;
    r.psnr = 99.0;
    r.ssim = 1.0;
    r.evaluated = up->stats().evaluated_fraction();
    return r;
  }

  frame_result measure(double seconds, const std::vector<glm::vec3>& img, const std::vector<float>& ref_luma) const {
    frame_result r;
    r.seconds = seconds;
    const auto l = luma_of(img);
    r.psnr = psnr_luma(l, ref_luma);
    r.ssim = *sup::ssim(ref_luma, l, w_, h_);
    return r;
  }

  frame_result ibuffer(const view& v, const setting& s, infolerp::upsampler<sample>& up, std::vector<glm::vec3>& out,
                       const std::vector<float>& ref_luma) {
    const auto src = source(v, s);
    out.assign(std::size_t(w_) * std::size_t(h_), glm::vec3(0.0f));
    const double t0 = now_seconds();
    check(up.render(src, std::span<glm::vec3>(out), exec_));
    frame_result r = measure(now_seconds() - t0, out, ref_luma);
    r.evaluated = up.stats().evaluated_fraction();
    return r;
  }

  frame_result reuse(const view& v, const setting& s, infolerp::upsampler<sample>& up, infolerp::frame_reuse<sample>& fr,
                     std::vector<glm::vec3>& out, const std::vector<float>& ref_luma) {
    const auto src = source(v, s);
    out.assign(std::size_t(w_) * std::size_t(h_), glm::vec3(0.0f));
    const double t0 = now_seconds();
    check(fr.render(up, src, v.frame, std::span<glm::vec3>(out), exec_));
    frame_result r = measure(now_seconds() - t0, out, ref_luma);
    r.evaluated = fr.stats().evaluated_fraction();
    r.reused = fr.stats().reused_fraction();
    return r;
  }

  static void check(const infolerp::status& s) {
    if (!s) {
      std::fprintf(stderr, "infolerp_pareto upsample --path: %s\n", s.message().c_str());
      std::exit(1);
    }
  }

  int w() const { return w_; }
  int h() const { return h_; }

 private:
  sup::demo_scene& scene_;
  const sup::scene_clustering& clusters_;
  sup::shader_options shading_;
  int w_, h_;
  infolerp::openmp_executor exec_;
  int frames_;
  sup::camera base_;
};

// Marks evaluated pixels red on a copy of img (reuse_mark::evaluated or refreshed).
sup::image marked(const std::vector<glm::vec3>& img, std::span<const std::uint8_t> marks, int w, int h) {
  sup::image out(w, h);
  out.pixels = img;
  for (std::size_t i = 0; i < out.pixels.size(); ++i)
    if (marks[i] >= std::uint8_t(infolerp::reuse_mark::evaluated)) out.pixels[i] = {1.0f, 0.0f, 0.0f};
  return out;
}

int write_plot(const std::string& csv, int w, int h) {
  const std::string base = csv.size() > 4 && csv.ends_with(".csv") ? csv.substr(0, csv.size() - 4) : csv;
  std::ofstream gp(base + ".gp");
  gp << "set terminal pngcairo size 1000,800 noenhanced\nset output '" << base << ".png'\n"
     << "set datafile separator ','\nset multiplot layout 2,1 title 'Demo scene " << w << "x" << h
     << " along a camera path (standing still in frames 50-69)'\n"
     << "set xlabel 'frame'\nset ylabel 'seconds (log)'\nset logscale y\nset grid\nset key outside right\n"
     << "plot '" << csv << "' using 1:(stringcolumn(2) eq 'per_pixel' ? $3 : 1/0) with points pt 7 ps 0.4 title 'per_pixel', "
     << "'' using 1:(stringcolumn(2) eq 'ibuffer' ? $3 : 1/0) with points pt 7 ps 0.4 title 'ibuffer', "
     << "'' using 1:(stringcolumn(2) eq 'ibuffer_reuse' ? $3 : 1/0) with points pt 7 ps 0.4 title 'ibuffer_reuse'\n"
     << "unset logscale y\nset ylabel 'PSNR dB vs per_pixel'\n"
     << "plot '" << csv << "' using 1:(stringcolumn(2) eq 'ibuffer' ? $4 : 1/0) with points pt 7 ps 0.4 title 'ibuffer', "
     << "'' using 1:(stringcolumn(2) eq 'ibuffer_reuse' ? $4 : 1/0) with points pt 7 ps 0.4 title 'ibuffer_reuse', 40 with lines dt 2 title '40 dB'\n"
     << "unset multiplot\n";
  gp.close();
  const std::string cmd = "gnuplot '" + base + ".gp'";
  if (std::system(cmd.c_str()) == 0) std::printf("wrote %s.png\n", base.c_str());
  else std::fprintf(stderr, "infolerp_pareto upsample --path: gnuplot failed\n");
  return 0;
}

}  // namespace

int pareto_upsample_path(int argc, char** argv) {
  std::string csv, pictures;
  int width = 640, height = 480, threads = 0, ao = 64, soft = 16, frames = 120, reuse_passes = 0;
  infolerp::frame_reuse_options reuse_options;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "upsample" || a == "--path") continue;
    if (a == "--csv" && i + 1 < argc) csv = argv[++i];
    else if (a == "--pictures" && i + 1 < argc) pictures = argv[++i];
    else if (a == "--size" && i + 2 < argc) width = std::atoi(argv[++i]), height = std::atoi(argv[++i]);
    else if (a == "--frames" && i + 1 < argc) frames = std::atoi(argv[++i]);
    else if (a == "--threads" && i + 1 < argc) threads = std::atoi(argv[++i]);
    else if (a == "--ao" && i + 1 < argc) ao = std::atoi(argv[++i]);
    else if (a == "--soft" && i + 1 < argc) soft = std::atoi(argv[++i]);
    else if (a == "--reuse-passes" && i + 1 < argc) reuse_passes = std::atoi(argv[++i]);
    else if (a == "--refresh" && i + 1 < argc) reuse_options.refresh_period = std::uint32_t(std::atoi(argv[++i]));
    else if (a == "--depth-tolerance" && i + 1 < argc) reuse_options.depth_tolerance = std::strtof(argv[++i], nullptr);
    else {
      std::fprintf(stderr, "usage: infolerp_pareto upsample --path --csv FILE [--size W H] [--frames N] [--threads N] [--ao N] "
                           "[--soft N] [--pictures DIR] [--reuse-passes P] [--refresh K] [--depth-tolerance T]\n");
      return 2;
    }
  }
  if (csv.empty() || width < 16 || height < 16 || frames < 24 || ao < 0 || soft < 0 || threads < 0) {
    std::fprintf(stderr, "infolerp_pareto upsample --path: --csv FILE is required; sizes >= 16, frames >= 24\n");
    return 2;
  }
  sup::enable_flush_to_zero();
#pragma omp parallel num_threads(threads > 0 ? threads : omp_get_max_threads())
  sup::enable_flush_to_zero();
  const sup::embree_device device;
  auto scene = sup::make_demo_scene(device);
  if (!scene) {
    std::fprintf(stderr, "infolerp_pareto upsample --path: %s\n", scene.error().message().c_str());
    return 1;
  }
  const double t0 = now_seconds();
  auto clustered = sup::cluster_by_features(*scene, infolerp::openmp_executor{threads});
  if (!clustered) return std::fprintf(stderr, "%s\n", clustered.error().message().c_str()), 1;
  auto split = sup::split_at_texture_seams(*scene, *clustered);
  if (!split) return std::fprintf(stderr, "%s\n", split.error().message().c_str()), 1;
  const sup::scene_clustering& clusters = *split;
  std::printf("demo scene %dx%d, %d frames, AO %d, soft %d, threads %d; feature clusters %zu ids (%.1f s)\n", width, height,
              frames, ao, soft, threads > 0 ? threads : omp_get_max_threads(), clusters.count(), now_seconds() - t0);
  const sup::shader_options shading{.ao_rays = unsigned(ao), .soft_shadow_rays = unsigned(soft)};
  path_harness h(*scene, clusters, shading, width, height, threads, frames);

  // Calibration: the fastest candidate whose every 10th frame reaches 40.5 dB.
  std::vector<setting> candidates;
  for (std::uint32_t p : {4u, 5u, 6u}) {
    candidates.push_back({std::to_string(p) + " passes, refined probes, min 1 src, probe where sources differ", p, false, 180.0f});
    candidates.push_back({std::to_string(p) + " passes, refined probes, min 1 src, probe where sources differ or normals > 5 deg", p, false, 5.0f});
    candidates.push_back({std::to_string(p) + " passes, refined probes, min 1 src, probe per sample", p, true, 180.0f});
  }
  std::vector<double> cal_seconds(candidates.size(), 0.0), cal_min_psnr(candidates.size(), 99.0);
  std::vector<glm::vec3> ref, img;
  for (int f = 0; f < frames; f += 10) {
    const auto v = h.view_at(f);
    (void)h.per_pixel(v, ref);
    const auto ref_luma = luma_of(ref);
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      auto up = h.upsampler_for(candidates[c]);
      double best = 1e30;
      frame_result r;
      for (int rep = 0; rep < 2; ++rep) {
        r = h.ibuffer(v, candidates[c], up, img, ref_luma);
        best = std::min(best, r.seconds);
      }
      cal_seconds[c] += best;
      cal_min_psnr[c] = std::min(cal_min_psnr[c], r.psnr);
    }
  }
  std::size_t chosen = candidates.size();
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    std::printf("calibration: %-90s %.3f s  min %.2f dB\n", candidates[c].name.c_str(), cal_seconds[c], cal_min_psnr[c]);
    if (cal_min_psnr[c] >= 40.5 && (chosen == candidates.size() || cal_seconds[c] < cal_seconds[chosen])) chosen = c;
  }
  if (chosen == candidates.size()) {
    std::fprintf(stderr, "infolerp_pareto upsample --path: no candidate reaches 40.5 dB on every calibration frame\n");
    return 1;
  }
  const setting& s = candidates[chosen];
  std::printf("ibuffer setting: %s\n", s.name.c_str());

  // The path: per frame per_pixel, ibuffer and ibuffer_reuse in turn.
  auto up_plain = h.upsampler_for(s);
  setting rs = s;
  if (reuse_passes > 0) rs.passes = std::uint32_t(reuse_passes), rs.name += ", reuse with " + std::to_string(reuse_passes) + " passes";
  auto up_reuse = h.upsampler_for(rs, true);
  auto reuse = infolerp::frame_reuse<sample>::create(std::uint32_t(width), std::uint32_t(height), reuse_options);
  if (!reuse) return std::fprintf(stderr, "%s\n", reuse.error().message().c_str()), 1;
  std::ofstream out(csv);
  if (!out) return std::fprintf(stderr, "cannot write %s\n", csv.c_str()), 1;
  out << "frame,method,seconds,psnr_db,ssim,evaluated_fraction,reused_fraction\n";
  double sum_pp = 0, sum_ib = 0, sum_re = 0, worst_gap = -1e30, min_psnr = 99.0, stand_eval = 0.0;
  int worst_gap_frame = -1, min_psnr_frame = -1;
  const int stand_begin = frames * 50 / 120, stand_end = stand_begin + frames * 20 / 120;
  std::vector<sup::image> strip;
  for (int f = 0; f < frames; ++f) {
    const auto v = h.view_at(f);
    const frame_result pp = h.per_pixel(v, ref);
    const auto ref_luma = luma_of(ref);
    const frame_result ib = h.ibuffer(v, s, up_plain, img, ref_luma);
    const frame_result re = h.reuse(v, rs, up_reuse, *reuse, img, ref_luma);
    if (!pictures.empty() && f % 15 == 0) strip.push_back(marked(img, reuse->marks(), width, height));
    char line[256];
    for (const auto& [name, r] : {std::pair<const char*, const frame_result&>{"per_pixel", pp}, {"ibuffer", ib}, {"ibuffer_reuse", re}}) {
      std::snprintf(line, sizeof line, "%d,%s,%.6f,%.4f,%.6f,%.6f,%.6f\n", f, name, r.seconds, r.psnr, r.ssim, r.evaluated, r.reused);
      out << line;
    }
    sum_pp += pp.seconds;
    sum_ib += ib.seconds;
    sum_re += re.seconds;
    if (re.psnr < min_psnr) min_psnr = re.psnr, min_psnr_frame = f;
    if (ib.psnr - re.psnr > worst_gap) worst_gap = ib.psnr - re.psnr, worst_gap_frame = f;
    if (f > stand_begin && f < stand_end) stand_eval = std::max(stand_eval, re.evaluated);
    std::printf("frame %3d  per_pixel %.3f s  ibuffer %.4f s %.2f dB eval %.4f  reuse %.4f s %.2f dB eval %.4f reused %.4f\n", f,
                pp.seconds, ib.seconds, ib.psnr, ib.evaluated, re.seconds, re.psnr, re.evaluated, re.reused);
    std::fflush(stdout);
  }
  out.close();
  std::printf("wrote %s\n", csv.c_str());
  std::printf("sums over %d frames: per_pixel %.3f s, ibuffer %.3f s, ibuffer_reuse %.3f s\n", frames, sum_pp, sum_ib, sum_re);
  std::printf("goal: reuse vs per-frame ibuffer x%.2f (>= 2), vs per_pixel x%.2f (>= 50)\n", sum_ib / sum_re, sum_pp / sum_re);
  std::printf("goal: lowest reuse PSNR %.2f dB at frame %d (>= 40); largest drop below ibuffer %.2f dB at frame %d (<= 0.5)\n",
              min_psnr, min_psnr_frame, worst_gap, worst_gap_frame);
  std::printf("goal: standing frames %d-%d evaluate at most %.4f%% of their pixels (<= 1%%; the first frame of the stand is "
              "still a moved one)\n", stand_begin + 1, stand_end - 1, 100.0 * stand_eval);
  if (!pictures.empty() && !strip.empty()) {
    // Every 15th frame side by side at half size.
    const int sw = width / 2, sh = height / 2;
    sup::image sheet(sw * int(strip.size()), sh);
    for (std::size_t k = 0; k < strip.size(); ++k)
      for (int y = 0; y < sh; ++y)
        for (int x = 0; x < sw; ++x) {
          // The 2x2 pixels' mean, red when one of them was evaluated.
          glm::vec3 c(0.0f);
          bool red = false;
          for (int k2 = 0; k2 < 4; ++k2) {
            const glm::vec3 p = strip[k].pixels[std::size_t(2 * y + k2 / 2) * std::size_t(width) + std::size_t(2 * x + k2 % 2)];
            red = red || p == glm::vec3(1.0f, 0.0f, 0.0f);
            c += 0.25f * p;
          }
          sheet.pixels[std::size_t(y) * std::size_t(sheet.width) + k * std::size_t(sw) + std::size_t(x)] =
              red ? glm::vec3(1.0f, 0.0f, 0.0f) : c;
        }
    const std::string path = pictures + "/path.png";
    if (auto st = sup::write_png(sheet, path); !st) std::fprintf(stderr, "%s\n", st.message().c_str());
    else std::printf("wrote %s\n", path.c_str());
  }
  return write_plot(csv, width, height);
}
