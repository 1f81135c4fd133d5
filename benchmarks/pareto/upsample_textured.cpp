// infolerp_pareto upsample --textured DIR [--size W H] [--repeat N] [--threads N] [--ao N] [--soft N]
//                                         [--pictures OUT] [--csv FILE]
//
// The I-Buffer with the library's ready sample source (upsample/ray_cast_source.hpp) on a
// textured asset loaded from disk, against per-pixel evaluation with the same source, in one
// run. The asset is the tests' generator's (support/textured_asset.hpp: 52,272 triangles, six
// charts, three materials with 512² textures), written to DIR as OBJ + MTL + PNG and loaded
// back into the demo scene (support/demo_scene.hpp; image textures, trilinear mip lookup); the
// built-in scene alone gives the second set of rows. Clusters: the demo's feature clustering
// cut at UV seams (cluster/uv_seams.hpp). Every repetition renders each row once, in the same
// order (interleaved), so the rows share the machine's load; times are the min and the median
// over the repetitions (wall time, and process CPU time of all threads: run with
// OMP_WAIT_POLICY=passive), speed-ups the ratio of the mins and the median of the
// per-repetition ratios. Rows:
//   per_pixel        every pixel evaluated and shaded by the ready source (the reference image)
//   per_pixel_hand   the same with the hand-written demo source (support/demo_upsample.hpp)
//   ibuffer          the ready source, K passes
//   ibuffer_refine   the ready source with refined probes (primary ray per pixel, hard shadow where
//                    the sources cannot vouch for it, AO and soft shadow interpolated), min_sources 1;
//                    "probe where sources differ": probe_every_sample off, a probe only where the
//                    sources of a new sample differ ("or normals > 5 deg": the ready source's
//                    default smooth_angle, also 2.5 and 10 deg; without it, smooth_angle infinite)
//   *_hand           the hand-written source in the same setting (the ready source's cost ratio)
//   denoise_atrous   n AO + m soft-shadow rays per pixel and the edge-avoiding à-trous filter
//                    (upsample_denoise.hpp); --csv FILE appends every row of both scenes to FILE,
//                    with the filter's own time as filter_seconds
// PSNR (display values) and SSIM (display luma) are against per_pixel's image. With --pictures,
// OUT/reference.png, OUT/ibuffer.png (the fastest row with >= 40 dB and SSIM >= 0.98, else the
// best PSNR) and OUT/clusters.png (cluster ids, boundaries dark, texture-chart seams white),
// cropped to at most 272x272 pixels at the asset's centre, and OUT/upsample_vs_denoiser.png: the
// cheapest denoise_atrous frame (left) beside the best-PSNR I-Buffer frame that took no more time.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>
#include <omp.h>
#include "infolerp/upsample/upsampler.hpp"
#include "pareto.hpp"
#include "upsample_denoise.hpp"
#include "support/demo_clusters.hpp"
#include "support/demo_scene.hpp"
#include "support/demo_upsample.hpp"
#include "support/image.hpp"
#include "support/reference_shader.hpp"
#include "support/ssim.hpp"
#include "support/textured_asset.hpp"

namespace {

namespace sup = infolerp::support;
using sample = sup::demo_sample;

struct textured_options {
  std::filesystem::path dir, pictures, csv;
  int width = 1025, height = 1025, repeat = 5, threads = 0, ao = 64, soft = 16;
};

// One row: renders a frame into img, returns its evaluated fraction.
struct row {
  std::string method, setting;
  std::function<double(sup::image&)> render;
  std::vector<double> seconds;  // wall time per repetition
  std::vector<double> cpu{};      // process CPU time per repetition (all threads)
  double evaluated = 1.0, psnr = 0.0, ssim = 0.0;
  sup::image img{};
  std::shared_ptr<double> filter{};  // denoise_atrous rows: the least filter time of the repetitions
  static double min(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }
  static double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.size() % 2 == 1 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  }
  double min() const { return min(seconds); }
  double median() const { return median(seconds); }
};

// The median over repetitions of num's time / den's time in the same repetition.
double median_ratio(const std::vector<double>& num, const std::vector<double>& den) {
  std::vector<double> r;
  for (std::size_t k = 0; k < num.size(); ++k) r.push_back(num[k] / den[k]);
  return row::median(r);
}

template <class Source>
std::function<double(sup::image&)> per_pixel(const Source& src, int threads) {
  return [&src, threads](sup::image& img) {
    const int w = img.width;
    infolerp::openmp_executor{threads}.parallel_for(static_cast<std::size_t>(img.height), 1, [&](std::size_t b, std::size_t e) {
      for (std::size_t y = b; y < e; ++y)
        for (int x = 0; x < w; ++x) {
          const auto ux = static_cast<std::uint32_t>(x), uy = static_cast<std::uint32_t>(y);
          img.at(x, static_cast<int>(y)) = src.shade(src.evaluate(ux, uy), ux, uy);
        }
    });
    return 1.0;
  };
}

template <class Source>
std::function<double(sup::image&)> ibuffer(const Source& src, std::uint32_t passes, std::uint32_t min_sources, int threads, int w, int h,
                                          bool probe_every_sample = true) {
  auto up = infolerp::upsampler<sample>::create(static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h),
                                                {.passes = passes, .max_passes = passes, .rows_per_task = 2,
                                                 .record_kinds = false, .min_sources = min_sources,
                                                 .probe_every_sample = probe_every_sample});
  if (!up) {
    std::fprintf(stderr, "infolerp_pareto upsample: %s\n", up.error().message().c_str());
    std::exit(1);
  }
  auto shared = std::make_shared<infolerp::upsampler<sample>>(std::move(*up));
  return [shared, &src, threads](sup::image& img) {
    if (auto s = shared->render(src, std::span<glm::vec3>(img.pixels), infolerp::openmp_executor{threads}); !s) {
      std::fprintf(stderr, "infolerp_pareto upsample: %s\n", s.message().c_str());
      std::exit(1);
    }
    return shared->stats().evaluated_fraction();
  };
}

// n AO + m soft-shadow rays per pixel and the à-trous filter (upsample_denoise.hpp); the
// filter's least time goes to *filter.
std::function<double(sup::image&)> denoise(const sup::reference_shader& primary_sun, const sup::reference_shader& shader, unsigned n,
                                           unsigned m, int threads, int w, int h, const std::shared_ptr<double>& filter) {
  auto d = std::make_shared<infolerp::bench::denoise_renderer>(primary_sun, shader, n, m, w, h, 5);
  return [d, threads, filter](sup::image& img) {
    *filter = std::min(*filter, d->render(img, infolerp::openmp_executor{threads}));
    return 0.0;
  };
}

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// CPU time of the whole process: less sensitive than wall time to the other processes of a
// shared machine (with OMP_WAIT_POLICY=passive, so that idle OpenMP workers do not spin).
double cpu_now() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::vector<float> luma(const sup::image& img) {
  std::vector<float> l(img.pixels.size());
  for (std::size_t i = 0; i < l.size(); ++i) l[i] = sup::display_luma(img.pixels[i]);
  return l;
}

// Runs every row `repeat` times interleaved, then scores each against rows[0]'s image.
void measure(std::vector<row>& rows, int repeat, int w, int h) {
  for (auto& r : rows) r.img = sup::image(w, h);
  for (int rep = 0; rep < repeat; ++rep)
    for (auto& r : rows) {
      const double t0 = now(), c0 = cpu_now();
      r.evaluated = r.render(r.img);
      r.seconds.push_back(now() - t0);
      r.cpu.push_back(cpu_now() - c0);
    }
  const auto ref_luma = luma(rows[0].img);
  for (auto& r : rows) {
    r.psnr = *sup::psnr(rows[0].img, r.img);
    r.ssim = *sup::ssim(ref_luma, luma(r.img), w, h);
  }
}

void print(const std::string& scene, const std::vector<row>& rows) {
  // Speed-ups: ratio of the mins, and the median over repetitions of the per-repetition ratio
  // (the rows of one repetition ran moments apart, under about the same load); wall and CPU time.
  std::printf("\n%s\n%-19s %-20s %7s %7s %7s %7s %7s %7s %7s %6s %7s %7s\n", scene.c_str(), "method", "setting", "wall min",
              "wall med", "x(min)", "x(rep)", "cpu min", "x(min)", "x(rep)", "eval", "PSNR", "SSIM");
  const row& ref = rows[0];
  for (const auto& r : rows)
    std::printf("%-19s %-20s %7.3f %7.3f %7.2f %7.2f %7.3f %7.2f %7.2f %6.4f %7.2f %7.5f\n", r.method.c_str(), r.setting.c_str(),
                r.min(), r.median(), ref.min() / r.min(), median_ratio(ref.seconds, r.seconds), row::min(r.cpu),
                row::min(ref.cpu) / row::min(r.cpu), median_ratio(ref.cpu, r.cpu), r.evaluated, std::min(r.psnr, 99.0), r.ssim);
  // The ready source against the hand-written one, per frame, in each setting they share.
  for (const auto& hand : rows) {
    if (!hand.method.ends_with("_hand")) continue;
    for (const auto& ready : rows)
      if (ready.method + "_hand" == hand.method && ready.setting == hand.setting)
        std::printf("ready / hand-written, %s %s: wall %.3f (ratio of mins) %.3f (median of per-repetition ratios), "
                    "cpu %.3f %.3f\n", ready.method.c_str(), ready.setting.c_str(), ready.min() / hand.min(),
                    median_ratio(ready.seconds, hand.seconds), row::min(ready.cpu) / row::min(hand.cpu), median_ratio(ready.cpu, hand.cpu));
  }
  std::fflush(stdout);
}

// Appends the rows to FILE (the header first when FILE is new): wall and CPU times are the
// least of the repetitions, speed-ups against per_pixel; filter_seconds only for the denoiser.
void append_csv(const std::filesystem::path& path, const std::string& scene, const std::vector<row>& rows) {
  const bool fresh = !std::filesystem::exists(path);
  std::FILE* f = std::fopen(path.string().c_str(), "a");
  if (f == nullptr) {
    std::fprintf(stderr, "infolerp_pareto upsample: cannot write %s\n", path.string().c_str());
    return;
  }
  if (fresh) std::fprintf(f, "scene,method,setting,seconds,seconds_median,speedup_vs_per_pixel,evaluated_fraction,psnr_db,ssim,cpu_seconds,filter_seconds\n");
  for (const auto& r : rows) {
    std::fprintf(f, "\"%s\",%s,\"%s\",%.6f,%.6f,%.4f,%.6f,%.4f,%.6f,%.6f,", scene.c_str(), r.method.c_str(), r.setting.c_str(), r.min(),
                 r.median(), rows[0].min() / r.min(), r.evaluated, std::min(r.psnr, 99.0), r.ssim, row::min(r.cpu));
    if (r.filter) std::fprintf(f, "%.6f", *r.filter);
    std::fprintf(f, "\n");
  }
  std::fclose(f);
  std::printf("appended %zu rows to %s\n", rows.size(), path.string().c_str());
}

glm::vec3 id_colour(std::uint32_t k) {
  std::uint32_t x = k * 0x9e3779b9u;
  x ^= x >> 15;
  x *= 0x85ebca6bu;
  x ^= x >> 13;
  return {0.25f + 0.7f * static_cast<float>(x & 255u) / 255.0f, 0.25f + 0.7f * static_cast<float>((x >> 8) & 255u) / 255.0f,
          0.25f + 0.7f * static_cast<float>((x >> 16) & 255u) / 255.0f};
}

// The crop [x0, x1) x [y0, y1) of img.
sup::image crop(const sup::image& img, int x0, int y0, int x1, int y1) {
  sup::image out(x1 - x0, y1 - y0);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) out.at(x - x0, y - y0) = img.at(x, y);
  return out;
}

// reference.png, ibuffer.png and clusters.png of the asset (objects first.. of the scene).
void write_pictures(const textured_options& o, const sup::demo_scene& scene, const sup::textured_asset& asset, std::uint32_t first,
                    const sup::scene_clustering& clusters, const std::vector<row>& rows) {
  const int w = o.width, h = o.height;
  std::vector<std::uint32_t> id(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), infolerp::invalid_id), chart(id);
  sup::image img(w, h);
  int x0 = w, y0 = h, x1 = 0, y1 = 0;
  const auto rays = scene.view.rays();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto r = rays(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, w, h);
      const auto hh = scene.tracer.intersect(r);
      if (!hh.valid()) continue;
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      const auto& m = scene.objects[hh.geometry].mesh;
      id[i] = clusters.ids[hh.geometry][hh.triangle];
      const glm::vec3 n = glm::normalize(glm::cross(m.positions[m.triangles[hh.triangle].y] - m.positions[m.triangles[hh.triangle].x],
                                                    m.positions[m.triangles[hh.triangle].z] - m.positions[m.triangles[hh.triangle].x]));
      img.at(x, y) = (0.35f + 0.65f * std::abs(glm::dot(n, r.direction))) * id_colour(id[i]);
      if (hh.geometry < first) continue;
      const float u = hh.barycentric.x, v = hh.barycentric.y;
      const glm::vec2 uv = (1.0f - u - v) * m.texcoord(hh.triangle, 0) + u * m.texcoord(hh.triangle, 1) + v * m.texcoord(hh.triangle, 2);
      chart[i] = asset.chart_at(uv, hh.geometry - first);
      x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x + 1), y1 = std::max(y1, y + 1);
    }
  for (int y = 0; y + 1 < h; ++y)
    for (int x = 0; x + 1 < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      const std::size_t right = i + 1, down = i + static_cast<std::size_t>(w);
      const auto seam = [&](std::size_t j) { return chart[i] != infolerp::invalid_id && chart[j] != infolerp::invalid_id && chart[i] != chart[j]; };
      if (seam(right) || seam(down)) img.at(x, y) = glm::vec3(1.0f);
      else if (id[i] != id[right] || id[i] != id[down]) img.at(x, y) *= 0.3f;
    }
  // At most 272 x 272 pixels around the asset's centre (small files, full resolution).
  const int cx = (x0 + x1) / 2, cy = (y0 + y1) / 2, half = 136;
  x0 = std::max({0, x0, cx - half}), y0 = std::max({0, y0, cy - half}), x1 = std::min({w, x1, cx + half}), y1 = std::min({h, y1, cy + half});
  const row* best = nullptr;
  for (const auto& r : rows) {
    if (r.method != "ibuffer" && r.method != "ibuffer_refine") continue;
    const bool good = r.psnr >= 40.0 && r.ssim >= 0.98;
    const bool best_good = best != nullptr && best->psnr >= 40.0 && best->ssim >= 0.98;
    if (best == nullptr || (good && (!best_good || r.min() < best->min())) || (!good && !best_good && r.psnr > best->psnr)) best = &r;
  }
  std::filesystem::create_directories(o.pictures);
  const auto save = [&](const sup::image& full, const char* name) {
    const auto path = (o.pictures / name).string();
    if (auto s = sup::write_png(crop(full, x0, y0, x1, y1), path); !s) std::fprintf(stderr, "%s\n", s.message().c_str());
    else std::printf("wrote %s\n", path.c_str());
  };
  save(rows[0].img, "reference.png");
  if (best != nullptr) {
    std::printf("ibuffer.png: %s %s\n", best->method.c_str(), best->setting.c_str());
    save(best->img, "ibuffer.png");
  }
  save(img, "clusters.png");
  // The cheapest denoiser row beside the best-PSNR I-Buffer row that took no more time (min wall).
  const row* denoised = nullptr;
  for (const auto& r : rows)
    if (r.method == "denoise_atrous" && (denoised == nullptr || r.min() < denoised->min())) denoised = &r;
  const row* equal = nullptr;
  for (const auto& r : rows)
    if (denoised != nullptr && (r.method == "ibuffer" || r.method == "ibuffer_refine") && r.min() <= denoised->min() &&
        (equal == nullptr || r.psnr > equal->psnr))
      equal = &r;
  if (equal == nullptr) return;
  std::printf("upsample_vs_denoiser.png: left %s %s (%.3f s, %.2f dB), right %s %s (%.3f s, %.2f dB)\n", denoised->setting.c_str(),
              denoised->method.c_str(), denoised->min(), denoised->psnr, equal->method.c_str(), equal->setting.c_str(), equal->min(), equal->psnr);
  const sup::image a = crop(denoised->img, x0, y0, x1, y1), b = crop(equal->img, x0, y0, x1, y1);
  sup::image both(2 * a.width + 4, a.height);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) both.at(x, y) = a.at(x, y), both.at(a.width + 4 + x, y) = b.at(x, y);
  const auto path = (o.pictures / "upsample_vs_denoiser.png").string();
  if (auto st = sup::write_png(both, path); !st) std::fprintf(stderr, "%s\n", st.message().c_str());
  else std::printf("wrote %s\n", path.c_str());
}

// The rows of one scene: per-pixel (ready, hand-written), the I-Buffer plain and with refined
// probes (ready), and the hand-written source in two I-Buffer settings.
int run_scene(const std::string& title, const sup::demo_scene& scene, const textured_options& o, const sup::textured_asset* asset,
              std::uint32_t first) {
  const double t0 = now();
  auto clustered = sup::cluster_by_features(scene, infolerp::openmp_executor{o.threads});
  if (!clustered) return std::fprintf(stderr, "%s\n", clustered.error().message().c_str()), 1;
  auto split = sup::split_at_texture_seams(scene, *clustered);
  if (!split) return std::fprintf(stderr, "%s\n", split.error().message().c_str()), 1;
  const sup::scene_clustering& clusters = *split;
  std::printf("%s: %zu clusters, %zu after the UV-seam split (%.1f s)\n", title.c_str(), clustered->count(), clusters.count(), now() - t0);
  sup::shader_options so{.ao_rays = static_cast<unsigned>(o.ao), .soft_shadow_rays = static_cast<unsigned>(o.soft)};
  so.pixel_angle = sup::pixel_angle(scene.view, o.height);
  const sup::reference_shader shader(scene, so);
  sup::shader_options po = so;
  po.ao_rays = 0;
  po.soft_shadow_rays = 0;
  const sup::reference_shader primary_sun(scene, po);
  po.hard_shadow = false;
  const sup::reference_shader primary(scene, po);
  auto ready = sup::make_demo_ray_cast_source(shader, clusters, o.width, o.height);
  auto refine = sup::make_demo_ray_cast_source<infolerp::probe_mode::refine>(shader, clusters, o.width, o.height);
  auto refine_flat = sup::make_demo_ray_cast_source<infolerp::probe_mode::refine>(
      shader, clusters, o.width, o.height, true, std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity());
  // smooth_angle 2.5 and 10 degrees beside the default (5), for the default's choice.
  constexpr float degree = 3.14159265f / 180.0f;
  auto refine_fine = sup::make_demo_ray_cast_source<infolerp::probe_mode::refine>(
      shader, clusters, o.width, o.height, true, std::numeric_limits<float>::infinity(), 2.5f * degree);
  auto refine_coarse = sup::make_demo_ray_cast_source<infolerp::probe_mode::refine>(
      shader, clusters, o.width, o.height, true, std::numeric_limits<float>::infinity(), 10.0f * degree);
  if (!ready || !refine || !refine_flat || !refine_fine || !refine_coarse) return std::fprintf(stderr, "ray_cast_source failed\n"), 1;
  const sup::demo_ibuffer_source hand{&shader, &clusters, o.width, o.height};
  sup::demo_refining_probe_source hand_refine;
  static_cast<sup::demo_ibuffer_source&>(hand_refine) = hand;
  hand_refine.primary = &primary;
  hand_refine.probe_lights = false;
  hand_refine.primary_sun = &primary_sun;

  std::vector<row> rows;
  rows.push_back({"per_pixel", "all pixels", per_pixel(*ready, o.threads), {}});
  rows.push_back({"per_pixel_hand", "all pixels", per_pixel(hand, o.threads), {}});
  for (std::uint32_t p : {3u, 4u, 5u})
    rows.push_back({"ibuffer", std::to_string(p) + " passes", ibuffer(*ready, p, 2, o.threads, o.width, o.height), {}});
  for (std::uint32_t p : {4u, 5u, 6u})
    rows.push_back({"ibuffer_refine", std::to_string(p) + " passes, min 1 src", ibuffer(*refine, p, 1, o.threads, o.width, o.height), {}});
  for (std::uint32_t p : {3u, 4u, 5u, 6u})
    rows.push_back({"ibuffer_refine", std::to_string(p) + " passes, min 1 src, probe where sources differ or normals > 5 deg",
                    ibuffer(*refine, p, 1, o.threads, o.width, o.height, false), {}});
  for (std::uint32_t p : {4u, 5u, 6u})
    rows.push_back({"ibuffer_refine", std::to_string(p) + " passes, min 1 src, probe where sources differ",
                    ibuffer(*refine_flat, p, 1, o.threads, o.width, o.height, false), {}});
  for (const auto& [src, angle] : {std::pair{&*refine_fine, "2.5"}, {&*refine_coarse, "10"}})
    for (std::uint32_t p : {4u, 5u, 6u})
      rows.push_back({"ibuffer_refine", std::to_string(p) + " passes, min 1 src, probe where sources differ or normals > " + angle + " deg",
                      ibuffer(*src, p, 1, o.threads, o.width, o.height, false), {}});
  rows.push_back({"ibuffer_hand", "4 passes", ibuffer(hand, 4, 2, o.threads, o.width, o.height), {}});
  rows.push_back({"ibuffer_refine_hand", "5 passes, min 1 src", ibuffer(hand_refine, 5, 1, o.threads, o.width, o.height), {}});
  for (const auto& [n, m] : {std::pair{1u, 1u}, {2u, 1u}, {4u, 1u}, {4u, 2u}, {8u, 2u}, {16u, 4u}}) {
    auto filter = std::make_shared<double>(1e30);
    rows.push_back({"denoise_atrous", std::to_string(n) + " AO + " + std::to_string(m) + " soft rays, 5 iterations",
                    denoise(primary_sun, shader, n, m, o.threads, o.width, o.height, filter), {}});
    rows.back().filter = filter;
  }
  measure(rows, o.repeat, o.width, o.height);
  print(title, rows);
  if (!o.csv.empty()) append_csv(o.csv, title, rows);
  if (asset != nullptr && !o.pictures.empty()) write_pictures(o, scene, *asset, first, clusters, rows);
  return 0;
}

}  // namespace

int pareto_upsample_textured(int argc, char** argv) {
  textured_options o;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    const bool has1 = i + 1 < argc, has2 = i + 2 < argc;
    auto num = [&](int k) { return std::atoi(argv[i + k]); };
    if (a == "--textured" && has1) o.dir = argv[++i];
    else if (a == "--pictures" && has1) o.pictures = argv[++i];
    else if (a == "--csv" && has1) o.csv = argv[++i];
    else if (a == "--size" && has2) o.width = num(1), o.height = num(2), i += 2;
    else if (a == "--repeat" && has1) o.repeat = num(1), ++i;
    else if (a == "--threads" && has1) o.threads = num(1), ++i;
    else if (a == "--ao" && has1) o.ao = num(1), ++i;
    else if (a == "--soft" && has1) o.soft = num(1), ++i;
    else {
      std::fprintf(stderr, "usage: infolerp_pareto upsample --textured DIR [--size W H] [--repeat N] [--threads N] [--ao N] [--soft N] [--pictures OUT] [--csv FILE]\n");
      return 2;
    }
  }
  if (o.width < 16 || o.height < 16 || o.repeat < 1 || o.ao < 0 || o.soft < 0 || o.threads < 0) {
    std::fprintf(stderr, "infolerp_pareto upsample: --size needs W H >= 16, --repeat >= 1, counts >= 0\n");
    return 2;
  }
  sup::enable_flush_to_zero();
#pragma omp parallel num_threads(o.threads > 0 ? o.threads : omp_get_max_threads())
  sup::enable_flush_to_zero();
  std::error_code ec;
  std::filesystem::create_directories(o.dir, ec);
  const auto asset = sup::make_textured_asset();
  const auto path = sup::write_obj(asset, o.dir, "textured_asset");
  if (!path) return std::fprintf(stderr, "infolerp_pareto upsample: %s\n", path.error().message().c_str()), 1;
  std::printf("%dx%d, AO %d rays, soft shadow %d rays, threads %d, %d interleaved repetitions; asset %s (%zu triangles)\n",
              o.width, o.height, o.ao, o.soft, o.threads > 0 ? o.threads : omp_get_max_threads(), o.repeat, path->c_str(),
              asset.mesh.triangle_count());
  const sup::embree_device device;
  auto textured = sup::make_demo_scene(device, {.mesh_paths = {*path}, .mesh_size = 2.4f});
  if (!textured) return std::fprintf(stderr, "infolerp_pareto upsample: %s\n", textured.error().message().c_str()), 1;
  const std::uint32_t first = static_cast<std::uint32_t>(textured->objects.size()) - asset.materials;
  if (int rc = run_scene("textured asset loaded from disk (+ built-in scene)", *textured, o, &asset, first); rc != 0) return rc;
  auto builtin = sup::make_demo_scene(device);
  if (!builtin) return std::fprintf(stderr, "infolerp_pareto upsample: %s\n", builtin.error().message().c_str()), 1;
  return run_scene("built-in scene", *builtin, o, nullptr, 0);
}
