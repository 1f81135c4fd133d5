#pragma once
// What the demo's stages share. main.cpp parses the options, builds the scene and renders the
// per-pixel reference; later stages (clusters, saliency, upsampler) are functions taking a
// demo_context, declared in examples/demo/stage_<name>.hpp and called from main.cpp in order.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>
#include <glm/geometric.hpp>
#if __has_include(<unistd.h>)
#include <unistd.h>
#endif
#ifdef _OPENMP
#include <omp.h>
#endif
#include "infolerp/core/executor.hpp"
#include "support/demo_scene.hpp"
#include "support/demo_upsample.hpp"
#include "support/embree_tracer.hpp"
#include "support/image.hpp"
#include "support/mesh_io.hpp"
#include "support/reference_shader.hpp"
#include "support/ssim.hpp"

namespace infolerp::demo {

struct demo_options {
  int width = 1025;                  // --size W H
  int height = 1025;
  int threads = 0;                   // --threads N (0 = all cores); every stage uses this many
  std::filesystem::path out_dir = "infolerp-out";  // --out DIR
  std::vector<std::string> mesh_paths;  // --mesh FILE, repeatable (none: built-in scene only)
  std::vector<std::string> mesh_groups;  // per mesh path: the --group NAME before it ("" when none)
  bool z_up = false;                 // --up z: the assets are Z-up (default y: Y-up)
  float tessellate = 0.0f;           // --tessellate SHARE: triangles split until none covers more of the image
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

// Wall time of one stage (printed as it ends, listed again at the end of the run).
struct stage_time {
  std::string stage;
  double seconds = 0.0;
};

// One simplified mesh of the LOD stage, for the LOD table and lod.csv.
struct lod_result {
  std::string method;                // "full", "infolerp" (view_dependent_lod::frame), "meshopt_culled", "meshopt_meshlets"
  double fraction = 1.0;             // of the full mesh's triangles asked for
  std::size_t triangles = 0;         // drawn
  double seconds = 0.0;              // the per-frame step: frame(), or the peer's culling pass
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
  std::vector<stage_time> times{};        // wall time of every stage so far, in order
  std::vector<std::vector<double>> welded_saliency{};  // per object: saliency over its welded vertices
                                                       // (saliency stage; the LOD stage reuses it)
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

// Progress of a long stage on stderr, quiet for its first two seconds: then on a terminal one
// line rewritten in place ('\r', at most four times a second), otherwise a line at each 10%
// step (at most one a second; every 10 s for elapsed()). Call it with (done, total) from any
// thread (a mutex, try-locked, so no caller waits for another's print), or elapsed() where no
// fraction is known; finish() ends the line. `loop` > 0 names which of a stage's parallel
// loops the figure is for (see progress_executor).
class progress_line {
 public:
  using clock = std::chrono::steady_clock;
  explicit progress_line(std::string label) : label_(std::move(label)) {}
  progress_line(const progress_line&) = delete;
  progress_line& operator=(const progress_line&) = delete;
  ~progress_line() { finish(); }

  void operator()(std::size_t done, std::size_t total, unsigned loop = 0) {
    const int percent = total > 0 ? static_cast<int>(100 * std::min(done, total) / total) : 100;
    char text[64];
    std::snprintf(text, sizeof text, loop > 0 ? "%3d%% (parallel loop %u)" : "%3d%%", percent, loop);
    print(static_cast<unsigned long long>(percent / 10) + 11ull * loop, std::chrono::seconds(1), text);  // a new loop is a new step
  }
  void elapsed() {
    const auto tens = std::chrono::duration_cast<std::chrono::seconds>(clock::now() - start_).count() / 10;
    print(static_cast<unsigned long long>(tens), std::chrono::seconds(0), "running");
  }
  void finish() {
    const std::lock_guard lock(mutex_);
    if (wrote_) std::fputc('\n', stderr);
    wrote_ = false;
  }

 private:
  std::string label_;
  clock::time_point start_ = clock::now(), last_{};
  std::mutex mutex_;
  bool tty_ = stderr_is_terminal();
  bool wrote_ = false;  // a terminal line is open
  unsigned long long step_ = ~0ull;

  // Prints "LABEL: TEXT, S s" when due: after 2 s, then on a terminal every quarter second,
  // otherwise when `step` changes and `gap` has passed since the last line.
  void print(unsigned long long step, clock::duration gap, const char* text) {
    const auto now = clock::now();
    if (now - start_ < std::chrono::seconds(2)) return;
    const std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock()) return;
    if (tty_ ? now - last_ < std::chrono::milliseconds(250) : step == step_ || now - last_ < gap) return;
    last_ = now, step_ = step;
    std::fprintf(stderr, "%s%s: %s, %.1f s%s", tty_ ? "\r" : "", label_.c_str(), text,
                 std::chrono::duration<double>(now - start_).count(), tty_ ? "   " : "\n");
    std::fflush(stderr);
    wrote_ = tty_;
  }
  static bool stderr_is_terminal() {
#if __has_include(<unistd.h>)
    return isatty(2) != 0;
#else
    return false;
#endif
  }
};

// For a stage that reports nothing (a serial library call): a thread that shows the elapsed
// time on `line` four times a second until the heartbeat is destroyed.
class heartbeat {
 public:
  explicit heartbeat(progress_line& line)
      : thread_([this, &line] {
          std::unique_lock lock(mutex_);
          while (!stopped_.wait_for(lock, std::chrono::milliseconds(250), [this] { return stop_; })) line.elapsed();
        }) {}
  heartbeat(const heartbeat&) = delete;
  heartbeat& operator=(const heartbeat&) = delete;
  ~heartbeat() {
    {
      const std::lock_guard lock(mutex_);
      stop_ = true;
    }
    stopped_.notify_one();
    thread_.join();
  }

 private:
  std::mutex mutex_;
  std::condition_variable stopped_;
  bool stop_ = false;
  std::thread thread_;  // last: starts once the members it uses exist
};

// An executor that runs on E and reports each finished range to a progress_line: what a
// stage's library calls do shows without the library printing anything. Each parallel_for is
// one loop (numbered from 1); done counts its finished elements. The cost is one atomic add
// and one clock read per range.
template <class E>
struct progress_executor {
  E inner;
  progress_line* line;
  std::shared_ptr<std::atomic<unsigned>> loops = std::make_shared<std::atomic<unsigned>>(0);

  template <class F>
  void parallel_for(std::size_t n, std::size_t grain, F&& fn) const {
    const unsigned loop = ++*loops;
    std::atomic<std::size_t> done{0};
    inner.parallel_for(n, grain, [&](std::size_t b, std::size_t e) {
      fn(b, e);
      (*line)(done.fetch_add(e - b) + (e - b), n, loop);
    });
  }
};

// The executor every stage uses: OpenMP over --threads workers when built with OpenMP.
#ifdef _OPENMP
using stage_executor = openmp_executor;
inline stage_executor make_executor(const demo_options& o) { return openmp_executor{o.threads}; }
#else
using stage_executor = serial_executor;
inline stage_executor make_executor(const demo_options&) { return {}; }
#endif

// The stage executor reporting to `line`.
inline progress_executor<stage_executor> with_progress(const demo_options& o, progress_line& line) {
  return {make_executor(o), &line};
}

// Wall time since construction (steady clock).
struct stopwatch {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
};

// Prints a stage's wall time ("time: STAGE  S s") and keeps it for the closing list.
inline void record_time(demo_context& ctx, std::string stage, double seconds) {
  std::printf("time: %-40s %9.3f s\n", stage.c_str(), seconds);
  std::fflush(stdout);
  ctx.times.push_back({std::move(stage), seconds});
}

// One line on stderr for a failed status (without the library's "infolerp: " prefix).
inline void report(const status& s) {
  const std::string_view m = support::bare_message(s);
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
