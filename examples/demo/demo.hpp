#pragma once
// What the demo's stages share. main.cpp parses the options, builds the scene and renders the
// per-pixel reference; later stages (clusters, saliency, upsampler) are functions taking a
// demo_context, declared in examples/demo/stage_<name>.hpp and called from main.cpp in order.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>
#include <glm/geometric.hpp>
#ifdef _OPENMP
#include <omp.h>
#endif
#include "support/demo_scene.hpp"
#include "support/demo_upsample.hpp"
#include "support/embree_tracer.hpp"
#include "support/image.hpp"
#include "support/reference_shader.hpp"
#include "support/ssim.hpp"

namespace infolerp::demo {

struct demo_options {
  int width = 1025;                  // --size W H
  int height = 1025;
  int threads = 0;                   // --threads N (0 = all cores); every stage uses this many
  std::filesystem::path out_dir = "infolerp-out";  // --out DIR
  std::vector<std::string> mesh_paths;  // --mesh FILE, repeatable (none: built-in scene only)
  support::shader_options shader;    // --ao N, --soft N
  std::uint32_t passes = 4;          // --passes K: I-Buffer passes of ibuffer.png; 0 = auto (pass controller)
  std::map<std::string, float> thresholds;  // --threshold CHANNEL=VALUE: channel (visibility,
                                            // orientation, stretch) -> JS threshold in [0, 1], for the clusters stage
};

// One rendering method's result against the reference, for the table, summary.csv and tradeoff.png.
struct method_result {
  std::string method;        // e.g. "reference", "ibuffer-3"
  std::string setting;       // human-readable settings
  double seconds = 0.0;      // wall time of the frame
  double psnr = 0.0;         // dB against the reference (+inf when identical)
  double ssim = 1.0;         // mean SSIM of the display luma (NaN for images below 11x11)
  double evaluated = 1.0;    // fully evaluated samples per pixel
};

// One simplified mesh of the LOD stage, for the LOD table and lod.csv.
struct lod_result {
  std::string method;                // "full", "infolerp" (view_dependent_lod::frame), "meshoptimizer"
  double fraction = 1.0;             // of the full mesh's triangles asked for
  std::size_t triangles = 0;         // drawn
  double seconds = 0.0;              // the frame() update or the meshopt_simplify call
  double weighted_distance = 0.0;    // saliency-weighted mean distance to the full mesh
  double hausdorff = 0.0;            // Hausdorff distance to the full mesh
  double psnr = 0.0, ssim = 1.0;     // of its image against the full mesh's image of the same view
};

struct demo_context {
  demo_options options;
  const support::demo_scene& scene;
  const support::reference_shader& shader;
  support::image reference;               // the full per-pixel render (filled by the first stage)
  support::render_stats reference_stats;  // its time and ray count
  std::vector<method_result> results;     // every method run so far, the reference first
  std::vector<lod_result> lod_results{};  // the LOD stage's meshes, the full mesh first
};

// Display luma of every pixel (what SSIM compares).
inline std::vector<float> luma_of(const support::image& img) {
  std::vector<float> l(img.pixels.size());
  for (std::size_t i = 0; i < l.size(); ++i) l[i] = support::display_luma(img.pixels[i]);
  return l;
}

// Records a method's frame: PSNR and SSIM against ctx.reference (sizes match by construction).
inline const method_result& add_result(demo_context& ctx, std::string method, std::string setting, double seconds,
                                       double evaluated, const support::image& img) {
  method_result r{std::move(method), std::move(setting), seconds, 0.0, std::nan(""), evaluated};
  const auto p = support::psnr(ctx.reference, img);
  r.psnr = p ? *p : std::nan("");
  const auto s = support::ssim(luma_of(ctx.reference), luma_of(img), img.width, img.height);
  if (s) r.ssim = *s;
  ctx.results.push_back(std::move(r));
  return ctx.results.back();
}

// OpenMP threads for a stage: --threads N, or OpenMP's default.
inline int omp_threads(const demo_options& o) {
#ifdef _OPENMP
  return o.threads > 0 ? o.threads : omp_get_max_threads();
#else
  return o.threads > 0 ? o.threads : 1;
#endif
}

// A one-line progress bar on stderr: call with (done, total); prints only when the
// bar grows and ends the line at 100%. Not thread-safe (callers serialise).
class progress_bar {
 public:
  explicit progress_bar(std::string label) : label_(std::move(label)) {}
  void operator()(int done, int total) {
    const int percent = total > 0 ? 100 * done / total : 100;
    const int filled = percent / 2;
    if (filled == last_) return;  // at most 51 updates
    last_ = filled;
    std::fprintf(stderr, "\r%s [%.*s%*s] %3d%%", label_.c_str(), filled, "##################################################",
                 50 - filled, "", percent);
    if (percent == 100) std::fputc('\n', stderr);
    std::fflush(stderr);
  }

 private:
  std::string label_;
  int last_ = -1;
};

// One line on stderr for a failed status (without the library's "infolerp: " prefix).
inline void report(const status& s) {
  std::string_view m = s.message();
  if (m.starts_with("infolerp: ")) m.remove_prefix(10);
  std::fprintf(stderr, "infolerp_demo: %.*s\n", static_cast<int>(m.size()), m.data());
}

// Writes img as DIR/name, reporting failure on stderr. Returns success.
inline bool save_png(const demo_context& ctx, const support::image& img, const std::string& name) {
  const std::string path = (ctx.options.out_dir / name).string();
  if (auto s = support::write_png(img, path); !s) {
    report(s);
    return false;
  }
  std::printf("wrote %s\n", path.c_str());
  return true;
}

// An image of the scene coloured per surface point: colour(geometry, triangle, barycentric) for
// each primary hit, dimmed by a headlight term so shapes stay readable; sky pixels are black.
// Used by the clusters and saliency stages. Parallel over rows (OpenMP, --threads).
inline support::image render_false_colour(
    const demo_context& ctx, const std::function<glm::vec3(std::uint32_t, std::uint32_t, glm::vec2)>& colour) {
  const int w = ctx.options.width, h = ctx.options.height;
  support::image img(w, h);
#pragma omp parallel for schedule(dynamic, 4) num_threads(omp_threads(ctx.options))
  for (int y = 0; y < h; ++y) {
    support::enable_flush_to_zero();
    for (int x = 0; x < w; ++x) {
      const ray r = ctx.scene.view.primary_ray(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, w, h);
      const hit hh = ctx.scene.tracer.intersect(r);
      glm::vec3 c(0.0f);
      if (hh.valid()) {
        const auto& m = ctx.scene.objects[hh.geometry].mesh;
        const glm::uvec3 t = m.triangles[hh.triangle];
        const glm::vec3 n = glm::normalize(glm::cross(m.positions[t.y] - m.positions[t.x], m.positions[t.z] - m.positions[t.x]));
        const float light = 0.35f + 0.65f * std::abs(glm::dot(n, r.direction));
        c = light * colour(hh.geometry, hh.triangle, hh.barycentric);
      }
      img.at(x, y) = c;
    }
  }
  return img;
}

}  // namespace infolerp::demo
