#pragma once
// clang at -O1 (the sanitizer build) may decline the `omp simd` loops below and warns; the
// vectorisation matters only in the optimised builds that time the filter.
#if defined(__clang__)
#pragma clang diagnostic ignored "-Wpass-failed"
#endif
// The denoiser baseline of `infolerp_pareto upsample`: what engines ship for ray-traced ambient
// occlusion and soft shadows, against which the I-Buffer is compared at equal time.
//
//   atrous_filter     edge-avoiding à-trous wavelet filter (Dammertz et al. 2010, "Edge-Avoiding
//                     À-Trous Wavelet Transform for fast Global Illumination Filtering", eq. 1-3;
//                     the guide weights as in SVGF's spatial filter, Schied et al. 2017, eq. 3-5):
//                     K iterations of the 5x5 B3-spline kernel h = (1/16, 1/4, 3/8, 1/4, 1/16),
//                     taps 2^i pixels apart in iteration i, each tap weighted by
//                       w_n  = max(0, n_p . n_q)^128                       (normal)
//                       w_z  = max(0, 1 - t/4)^4 ~ exp(-t),                (depth)
//                              t = |z_p - z_q| / (sigma_z * 2^i * 2 g_p + 1e-4 z_p), g_p the
//                              pixel's depth gradient (largest one-pixel step to a same-id
//                              neighbour): the depth a plane spans over the tap distance
//                       w_id = [id_p == id_q]                               (object or cluster)
//                     The polynomial stands in for exp() so that the inner loop vectorises
//                     (one tap over a row: contiguous loads, no calls, no branches); w_id makes
//                     it impossible to mix two ids. Two channels are filtered together
//                     (demodulated: AO and soft-shadow visibility, never albedo or texture).
//   denoise_renderer  the demo's shading with n AO and m soft-shadow rays per pixel (the
//                     reference shader's hemisphere and light-point sets, Cranley-Patterson
//                     rotated by a per-pixel hash so that the error is noise, not bands; traced in
//                     16-ray packets, as the harness's fastest per-pixel row), then
//                     the filter on the two visibility planes, then shade() per pixel. The
//                     primary ray and the sun's hard-shadow ray are traced at every pixel.
//
// Allocation: both classes allocate their planes at construction; a frame allocates nothing.
// Complexity per frame: rays (n + m + 2 per pixel) plus 25 K weighted taps per pixel.
// Rows are split over an executor (include/infolerp/core/executor.hpp); every pixel's result
// depends only on the planes, so it is the same bit for bit for any executor and grain.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <utility>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/upsample/ray_cast_source.hpp"
#include "support/demo_scene.hpp"
#include "support/image.hpp"
#include "support/reference_shader.hpp"

namespace infolerp::bench {

// Per-pixel guides, row-major planes of width x height: unit normal, view depth, id.
struct atrous_guides {
  std::span<const float> nx, ny, nz, depth;
  std::span<const std::uint32_t> id;
};

struct atrous_options {
  int iterations = 5;
  float sigma_depth = 2.0f;  // the depth weight's scale, in plane depth steps over the tap distance
};

class atrous_filter {
 public:
  atrous_filter(int width, int height, atrous_options o = {})
      : w_(static_cast<std::size_t>(width)), h_(static_cast<std::size_t>(height)), o_(o),
        wsum_(w_ * h_), tmp_a_(w_ * h_), tmp_b_(w_ * h_), inv_tol_(w_ * h_) {}

  int width() const { return static_cast<int>(w_); }
  int height() const { return static_cast<int>(h_); }

  // Filters the planes a and b (width x height each) in place. Preconditions: every span holds
  // width x height values; normals are unit where they matter (a pixel with a zero normal only
  // keeps its own value).
  template <class Executor>
  void run(std::span<float> a, std::span<float> b, const atrous_guides& g, const Executor& exec) {
    exec.parallel_for(h_, 4, [&](std::size_t y0, std::size_t y1) {
      for (std::size_t y = y0; y < y1; ++y) depth_tolerance_row(g, y);
    });
    std::span<float> src_a = a, src_b = b, dst_a = tmp_a_, dst_b = tmp_b_;
    for (int i = 0; i < o_.iterations; ++i) {
      const std::size_t step = std::size_t{1} << i;
      exec.parallel_for(h_, 4, [&](std::size_t y0, std::size_t y1) {
        for (std::size_t y = y0; y < y1; ++y) filter_row(src_a, src_b, dst_a, dst_b, g, y, step);
      });
      std::swap(src_a, dst_a);
      std::swap(src_b, dst_b);
    }
    if (src_a.data() != a.data()) {  // an odd number of iterations ends in the scratch planes
      std::memcpy(a.data(), src_a.data(), a.size_bytes());
      std::memcpy(b.data(), src_b.data(), b.size_bytes());
    }
  }

 private:
  // 1 / (sigma_z * 2 g_p + 1e-4 z_p): g_p the largest one-pixel depth step to a same-id 4-neighbour.
  void depth_tolerance_row(const atrous_guides& g, std::size_t y) {
    const std::size_t row = y * w_;
    for (std::size_t x = 0; x < w_; ++x) {
      const std::size_t p = row + x;
      float grad = 0.0f;
      auto look = [&](std::size_t q) {
        if (g.id[q] == g.id[p]) grad = std::max(grad, std::abs(g.depth[q] - g.depth[p]));
      };
      if (x > 0) look(p - 1);
      if (x + 1 < w_) look(p + 1);
      if (y > 0) look(p - w_);
      if (y + 1 < h_) look(p + w_);
      inv_tol_[p] = 1.0f / (o_.sigma_depth * 2.0f * grad + 1e-4f * std::abs(g.depth[p]) + 1e-20f);
    }
  }

  // One output row of one iteration: the 25 taps, each a vectorisable pass over the row.
  void filter_row(std::span<const float> sa, std::span<const float> sb, std::span<float> da, std::span<float> db,
                  const atrous_guides& g, std::size_t y, std::size_t step) {
    static constexpr std::array<float, 5> kernel{1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};
    const std::size_t row = y * w_;
    float* __restrict ws = wsum_.data() + row;
    float* __restrict oa = da.data() + row;
    float* __restrict ob = db.data() + row;
    std::fill_n(ws, w_, 0.0f);
    std::fill_n(oa, w_, 0.0f);
    std::fill_n(ob, w_, 0.0f);
    const float* __restrict pnx = g.nx.data() + row;
    const float* __restrict pny = g.ny.data() + row;
    const float* __restrict pnz = g.nz.data() + row;
    const float* __restrict pz = g.depth.data() + row;
    const std::uint32_t* __restrict pid = g.id.data() + row;
    const float* __restrict tol = inv_tol_.data() + row;
    const float inv_step = 1.0f / static_cast<float>(step);
    const auto s = static_cast<std::ptrdiff_t>(step), w = static_cast<std::ptrdiff_t>(w_);
    for (std::ptrdiff_t dy = -2; dy <= 2; ++dy) {
      const std::ptrdiff_t yy = static_cast<std::ptrdiff_t>(y) + dy * s;
      if (yy < 0 || yy >= static_cast<std::ptrdiff_t>(h_)) continue;
      for (std::ptrdiff_t dx = -2; dx <= 2; ++dx) {
        const std::ptrdiff_t off = dx * s;
        const std::ptrdiff_t x0 = std::max<std::ptrdiff_t>(0, -off), x1 = std::min(w, w - off);
        if (x0 >= x1) continue;
        const float hk = kernel[static_cast<std::size_t>(dy + 2)] * kernel[static_cast<std::size_t>(dx + 2)];
        // The tap of pixel x0 + i is q0 + i: pointers start at the first tap inside the row, never
        // before the buffer (pointer arithmetic past its start is undefined even when unread).
        const std::size_t q0 = static_cast<std::size_t>(yy * w + off + x0);
        const float* __restrict qnx = g.nx.data() + q0;
        const float* __restrict qny = g.ny.data() + q0;
        const float* __restrict qnz = g.nz.data() + q0;
        const float* __restrict qz = g.depth.data() + q0;
        const std::uint32_t* __restrict qid = g.id.data() + q0;
        const float* __restrict qa = sa.data() + q0;
        const float* __restrict qb = sb.data() + q0;
#pragma omp simd
        for (std::ptrdiff_t i = 0; i < x1 - x0; ++i) {
          const std::ptrdiff_t x = x0 + i;
          float c = pnx[x] * qnx[i] + pny[x] * qny[i] + pnz[x] * qnz[i];
          c = 0.5f * (c + std::abs(c));  // max(c, 0) without a compare (one that may trap does not if-convert)
          c *= c, c *= c, c *= c, c *= c, c *= c, c *= c, c *= c;  // ^128
          const float t = std::abs(pz[x] - qz[i]) * tol[x] * inv_step;
          float wz = 1.0f - 0.25f * t;
          wz = 0.5f * (wz + std::abs(wz));
          wz *= wz, wz *= wz;
          const float same = static_cast<float>(pid[x] == qid[i]);  // a select, not a branch
          const float wt = hk * c * wz * same;
          ws[x] += wt;
          oa[x] += wt * qa[i];
          ob[x] += wt * qb[i];
        }
      }
    }
    const float* __restrict ca = sa.data() + row;
    const float* __restrict cb = sb.data() + row;
#pragma omp simd
    for (std::size_t x = 0; x < w_; ++x) {
      // No weight (a zero normal): the sums are 0 and the pixel keeps its value.
      const float inv = 1.0f / (ws[x] + 1e-30f), none = static_cast<float>(ws[x] == 0.0f);
      oa[x] = oa[x] * inv + none * ca[x];
      ob[x] = ob[x] * inv + none * cb[x];
    }
  }

  std::size_t w_, h_;
  atrous_options o_;
  std::vector<float> wsum_, tmp_a_, tmp_b_, inv_tol_;
};

// n AO rays and m soft-shadow rays per pixel, the à-trous filter on the two visibility planes,
// shade(). `primary_sun` traces the primary and the sun ray only (shader_options with
// ao_rays = soft_shadow_rays = 0); `shading` supplies shade() (the reference's materials).
class denoise_renderer {
 public:
  denoise_renderer(const support::reference_shader& primary_sun, const support::reference_shader& shading, unsigned ao_rays,
                   unsigned soft_rays, int width, int height, int iterations, bool filter = true)
      : primary_(&primary_sun), shading_(&shading), ao_rays_(ao_rays), soft_rays_(soft_rays), filter_on_(filter),
        w_(width), h_(height), n_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height)),
        filter_(width, height, {.iterations = iterations}), inputs_(n_), ao_(n_), soft_(n_), nx_(n_), ny_(n_), nz_(n_),
        depth_(n_), id_(n_) {}

  // Renders a frame into out (width x height); returns the filter's wall seconds.
  template <class Executor>
  double render(support::image& out, const Executor& exec) {
    exec.parallel_for(static_cast<std::size_t>(h_), 1, [&](std::size_t y0, std::size_t y1) {
      support::enable_flush_to_zero();
      for (std::size_t y = y0; y < y1; ++y) trace_row(static_cast<int>(y));
    });
    const auto t0 = std::chrono::steady_clock::now();
    if (filter_on_) filter_.run(ao_, soft_, {nx_, ny_, nz_, depth_, id_}, exec);
    const double filter_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    exec.parallel_for(static_cast<std::size_t>(h_), 4, [&](std::size_t y0, std::size_t y1) {
      for (std::size_t i = y0 * static_cast<std::size_t>(w_); i < y1 * static_cast<std::size_t>(w_); ++i) {
        support::shading_inputs in = inputs_[i];
        in.ao = ao_[i];
        in.soft_shadow = soft_[i];
        out.pixels[i] = shading_->shade(in);
      }
    });
    return filter_seconds;
  }

 private:
  // A per-pixel offset in [0,1)² (integer hash of the pixel), for Cranley-Patterson rotation.
  static glm::vec2 rotation(int x, int y) {
    auto mix = [](std::uint32_t v) {
      v ^= v >> 16, v *= 0x7feb352du, v ^= v >> 15, v *= 0x846ca68bu, v ^= v >> 16;
      return v;
    };
    const std::uint32_t a = mix(static_cast<std::uint32_t>(x) * 0x9e3779b1u ^ mix(static_cast<std::uint32_t>(y)));
    const std::uint32_t b = mix(a ^ 0x68e31da4u);
    return {static_cast<float>(a >> 8) * 0x1p-24f, static_cast<float>(b >> 8) * 0x1p-24f};
  }
  static float wrap(float v) { return v >= 1.0f ? v - 1.0f : v; }

  void trace_row(int y) {
    constexpr float pi = 3.14159265358979323846f;
    const support::demo_scene& scene = primary_->scene();
    const support::pinhole_rays& cam = primary_->camera_rays();
    ray_batch batch{&scene.tracer};
    for (int x = 0; x < w_; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(x);
      std::uint64_t rays = 0;
      support::shading_inputs in = primary_->evaluate_pixel(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, w_, h_, rays);
      inputs_[i] = in;
      nx_[i] = in.normal.x, ny_[i] = in.normal.y, nz_[i] = in.normal.z;
      id_[i] = in.geometry;
      depth_[i] = in.hit() ? glm::dot(in.position - cam.eye, cam.forward) : 0.0f;
      ao_[i] = 1.0f, soft_[i] = 0.0f;
      if (!in.hit()) continue;
      // The geometric normal facing the camera, as the reference shader's secondary rays leave.
      const indexed_mesh& m = scene.objects[in.geometry].mesh;
      const glm::uvec3 tri = m.triangles[in.triangle];
      glm::vec3 ng = glm::normalize(glm::cross(m.positions[tri.y] - m.positions[tri.x], m.positions[tri.z] - m.positions[tri.x]));
      if (glm::dot(ng, in.view) > 0.0f) ng = -ng;
      const glm::vec3 origin = in.position + scene.ray_offset * ng;
      const glm::vec2 rot = rotation(x, y);
      if (soft_rays_ > 0) {
        const glm::vec3 light_normal = scene.area.normal();
        for (unsigned k = 0; k < soft_rays_; ++k) {
          const glm::vec2 s = hammersley(k, soft_rays_);
          const glm::vec3 d = scene.area.point(wrap(s.x + rot.x), wrap(s.y + rot.y)) - origin;
          if (glm::dot(d, ng) <= 0.0f || glm::dot(d, light_normal) >= 0.0f) continue;
          batch.push(ray{origin, 0.0f, d, 0.9999f});
        }
        soft_[i] = static_cast<float>(batch.unoccluded()) / static_cast<float>(soft_rays_);
      }
      if (ao_rays_ > 0) {
        glm::vec3 t, b;
        detail::tangent_frame(ng, t, b);
        for (unsigned k = 0; k < ao_rays_; ++k) {
          const glm::vec2 s = hammersley(k, ao_rays_);
          const float u = wrap(s.x + rot.x), r = std::sqrt(u), phi = 2.0f * pi * wrap(s.y + rot.y);
          const glm::vec3 d = r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0f, 1.0f - u)) * ng;
          batch.push(ray{origin, 0.0f, d, scene.ao_radius});
        }
        ao_[i] = static_cast<float>(batch.unoccluded()) / static_cast<float>(ao_rays_);
      }
    }
  }

  // A pixel's rays of one kind, traced through the tracer's batch call (16-ray packets, as the
  // harness's full_packets16 traces the reference's rays); one per row, on the row's thread.
  struct ray_batch {
    const support::embree_scene* tracer;
    std::array<ray, 64> rays{};
    std::size_t count = 0;
    unsigned visible = 0;
    void push(const ray& r) {
      if (count == rays.size()) flush();
      rays[count++] = r;
    }
    void flush() {
      if (count == 0) return;
      std::array<std::uint8_t, 64> occluded{};
      tracer->occluded(std::span<const ray>(rays.data(), count), std::span<std::uint8_t>(occluded.data(), count));
      for (std::size_t k = 0; k < count; ++k) visible += occluded[k] ? 0u : 1u;
      count = 0;
    }
    unsigned unoccluded() {  // of the rays pushed since the last call
      flush();
      return std::exchange(visible, 0u);
    }
  };

  const support::reference_shader* primary_;
  const support::reference_shader* shading_;
  unsigned ao_rays_, soft_rays_;
  bool filter_on_;
  int w_, h_;
  std::size_t n_;
  atrous_filter filter_;
  std::vector<support::shading_inputs> inputs_;
  std::vector<float> ao_, soft_, nx_, ny_, nz_, depth_;
  std::vector<std::uint32_t> id_;
};

}  // namespace infolerp::bench
