#pragma once
// Progressive refinement driver: Oliveira, Santos, Proença, "Refinement Criteria for High
// Fidelity Interactive Walkthroughs", §2 (the Shading Management Agent: visibility, a vertex
// shading cache, refinement in batches of R, the image interpolated from triangle vertices)
// and §5 (the Table 1 figures: Δ, Δ_total, shading samples and time at stage 1 and stage 2).
//
// One fixed view point. Visibility comes from one primary ray per pixel through the user's
// tracer (core/tracer.hpp): the hit's triangle and barycentrics locate the pixel in the
// subdivision hierarchy, so later splits re-locate pixels without tracing again (subdivision
// is planar: the geometry does not change, only where it is sampled). A leaf's projected area
// is the number of pixels it shows. The image is rebuilt by interpolating the colours of the
// shown leaf's vertices with the pixel's barycentric weights.
//
//  stage 1: every vertex of every visible original triangle shaded once;
//  stage 2: batches of R selections (criteria.hpp), each followed by re-location and shading
//           of the new visible vertices, until the criterion selects nothing, the shading
//           budget is reached (checked after each batch, so one batch may overshoot it) or
//           max_batches ran.
//  Δ        leaves shown (visible) now;
//  Δ_total  triangles ever shown (the paper: "sent to the visualizer", which counts split ones);
//           triangles_produced additionally counts children never shown.
//
// The tracer must model infolerp::tracer; the scene's triangle ids must be the mesh's (the
// hit's geometry id is ignored). The shading callback, glm::vec3 shade(const shading_point&),
// is called once per vertex, concurrently from the executor's threads.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/refine/criteria.hpp"
#include "infolerp/refine/nld.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"

namespace infolerp {

// A pinhole camera: pixel (x, y), y down, gets the ray through its centre.
struct pinhole_camera {
  glm::vec3 eye{0.0f, 0.0f, 1.0f};     // camera position
  glm::vec3 target{0.0f};              // looked-at point
  glm::vec3 up{0.0f, 1.0f, 0.0f};      // world up (not parallel to target - eye)
  float vertical_fov_degrees = 60.0f;  // full vertical field of view
  std::uint32_t width = 320;           // image width in pixels
  std::uint32_t height = 240;          // image height in pixels

  [[nodiscard]] ray primary_ray(std::uint32_t x, std::uint32_t y) const {
    const glm::vec3 f = glm::normalize(target - eye);
    const glm::vec3 r = glm::normalize(glm::cross(f, up));
    const glm::vec3 u = glm::cross(r, f);
    const float h = std::tan(glm::radians(vertical_fov_degrees) * 0.5f);
    const float aspect = float(width) / float(height);
    const float sx = (2.0f * (float(x) + 0.5f) / float(width) - 1.0f) * h * aspect;
    const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(height)) * h;
    ray out;
    out.origin = eye;
    out.direction = glm::normalize(f + sx * r + sy * u);
    return out;
  }
};

// What the shading callback gets for one vertex.
struct shading_point {
  std::uint32_t vertex = invalid_id;     // vertex id in the subdivision mesh
  glm::vec3 position{0.0f};              // its world position
  std::uint32_t triangle = invalid_id;   // an original triangle it lies in
  glm::vec2 barycentric{0.0f};           // Embree-style (u, v) of the position in that triangle
};

struct stage_figures {
  std::size_t triangles = 0;           // Δ: leaves shown
  std::size_t triangles_total = 0;     // Δ_total: triangles ever shown
  std::size_t triangles_produced = 0;  // every triangle the hierarchy holds
  std::size_t shading_samples = 0;     // vertices shaded so far
  double seconds = 0.0;                // wall time since the run started
};

struct refinement_report {
  stage_figures stage1, stage2;
  std::size_t batches = 0;      // batches of R run in stage 2
  std::size_t selections = 0;   // triangles the criterion selected
  bool budget_reached = false;  // stage 2 stopped on the shading budget or max_batches
};

struct driver_options {
  criteria_options criteria{};                                              // which criterion and its settings
  std::size_t max_shading_samples = std::numeric_limits<std::size_t>::max();  // stop once this many vertices are shaded
  std::size_t max_batches = std::numeric_limits<std::size_t>::max();          // stop after this many batches
  glm::vec3 background{0.0f};                                              // colour of pixels without a hit
  std::size_t grain = 4096;                                                // executor grain (pixels, vertices)
};

// Not thread-safe: one call at a time per object (each call runs in parallel through the
// executor). Accessors below are O(1) and allocate nothing.
class progressive_refiner {
 public:
  // Takes over a subdivision mesh (possibly already tessellated, §4.1 of the clustering paper).
  // Errors: options out of range. O(1) besides the move; no allocation.
  static result<progressive_refiner> create(subdivision_mesh mesh, driver_options options = {}) {
    if (auto st = validate(options.criteria); !st) return st;
    if (options.grain == 0) return make_error(errc::bad_parameter, no_element, "driver_options.grain must be >= 1");
    progressive_refiner r;
    r.mesh_ = std::move(mesh);
    r.options_ = options;
    r.state_.rng = splitmix64{options.criteria.seed};
    return r;
  }

  // Stage 1 in one call: traces the primary rays, locates every pixel, shades the visible
  // vertices. Camera: any type with width, height and primary_ray(x, y) -> ray.
  // Errors: an empty image; a hit naming a triangle the mesh does not have, or with a
  // non-finite distance or barycentric (names the pixel). On error the refiner is unchanged.
  // Complexity O(pixels · (trace + level)); allocation O(pixels + triangles + vertices).
  template <class T, class Camera, class Shade, class E>
  status start(const T& tracer, const Camera& camera, Shade&& shade, E&& exec) {
    static_assert(check_tracer<T>());
    static_assert(check_executor<std::remove_cvref_t<E>>());
    static_assert(std::is_invocable_r_v<glm::vec3, Shade&, const shading_point&>,
                  "infolerp: shading callback needs `glm::vec3 shade(const infolerp::shading_point&)`");
    const auto started = std::chrono::steady_clock::now();
    const std::uint32_t width = camera.width, height = camera.height;
    const std::size_t n = std::size_t(width) * height;
    if (n == 0) return make_error(errc::empty_input, no_element, "camera image is ", width, "x", height);
    std::vector<hit> hits(n);
    for_each_chunk(exec, n, options_.grain, [&](std::size_t, std::size_t begin, std::size_t end) {
      std::vector<ray> rays(end - begin);
      for (std::size_t p = begin; p < end; ++p)
        rays[p - begin] = camera.primary_ray(static_cast<std::uint32_t>(p % width), static_cast<std::uint32_t>(p / width));
      trace_intersect(tracer, std::span<const ray>(rays), std::span<hit>(hits.data() + begin, end - begin));
    });
    for (std::size_t p = 0; p < n; ++p) {  // check every hit before changing any state
      const hit& h = hits[p];
      if (!h.valid()) continue;
      if (h.triangle >= mesh_.original_triangle_count())
        return make_error(errc::index_out_of_range, p, "pixel ", p, ": hit triangle ", h.triangle,
                          " is not in the mesh (", mesh_.original_triangle_count(), " triangles)");
      if (!std::isfinite(h.distance) || !std::isfinite(h.barycentric.x) || !std::isfinite(h.barycentric.y))
        return make_error(errc::non_finite, p, "pixel ", p, ": hit on triangle ", h.triangle,
                          " has a non-finite distance or barycentric");
    }
    started_ = started;
    width_ = width;
    height_ = height;
    pixel_leaf_.assign(n, invalid_id);
    pixel_weights_.assign(n, glm::vec3(0.0f));
    for (std::size_t p = 0; p < n; ++p) {
      if (!hits[p].valid()) continue;
      pixel_leaf_[p] = hits[p].triangle;
      const glm::vec2 b = hits[p].barycentric;
      pixel_weights_[p] = glm::vec3(1.0f - b.x - b.y, b.x, b.y);
    }
    relocate(exec);
    shade_visible(shade, exec);
    report_ = {};
    report_.stage1 = figures();
    report_.stage2 = report_.stage1;
    return {};
  }

  // One batch of stage 2: the criterion selects up to R leaves, they are split, pixels are
  // re-located and new visible vertices shaded. Returns false when nothing was selected, the
  // shading budget is reached or max_batches ran (then stage 2's figures are final).
  // Preconditions: start() succeeded. Complexity: the criterion's selection (criteria.hpp) +
  // O(R) splits + O(pixels of the split leaves) re-location + the new vertices' shading.
  // Allocation: the split triangles and vertices, the visible-set rebuild (O(visible)).
  template <class Shade, class E>
  bool refine_batch(Shade&& shade, E&& exec) {
    if (done()) {
      report_.budget_reached = !finished_;
      return false;
    }
    if (options_.criteria.criterion == refinement_criterion::nld_is) luminance_image(exec);
    selected_.clear();
    const refinement_frame f = frame();
    select_for_refinement(f, options_.criteria, state_, selected_);
    if (selected_.empty()) {
      finished_ = true;
      report_.stage2 = figures();
      return false;
    }
    for (std::uint32_t t : selected_) {
      const status st = mesh_.split(t);
      INFOLERP_ASSERT(st.ok());
      (void)st;
    }
    ++report_.batches;
    report_.selections += selected_.size();
    relocate(exec);
    shade_visible(shade, exec);
    report_.stage2 = figures();
    if (done()) {
      report_.budget_reached = true;
      return false;
    }
    return true;
  }

  // start() then batches until done. Returns the Table 1 figures. Errors, complexity and
  // allocation: those of start() plus every refine_batch().
  template <class T, class Camera, class Shade, class E>
  result<refinement_report> run(const T& tracer, const Camera& camera, Shade&& shade, E&& exec) {
    if (auto st = start(tracer, camera, shade, exec); !st) return st;
    while (refine_batch(shade, exec)) {
    }
    return report_;
  }

  // The current image: per pixel the shown leaf's vertex colours interpolated, or the
  // background. Preconditions: image.size() == width·height, start() succeeded.
  // O(pixels), no allocation.
  void reconstruct(std::span<glm::vec3> image) const {
    for (std::size_t p = 0; p < pixel_leaf_.size() && p < image.size(); ++p) image[p] = pixel_colour(p);
  }

  [[nodiscard]] const refinement_report& report() const noexcept { return report_; }
  [[nodiscard]] const subdivision_mesh& mesh() const noexcept { return mesh_; }
  [[nodiscard]] std::span<const std::uint32_t> pixel_leaves() const noexcept { return pixel_leaf_; }
  [[nodiscard]] std::span<const std::uint32_t> visible_leaves() const noexcept { return visible_; }
  [[nodiscard]] std::span<const std::uint32_t> leaf_pixels() const noexcept { return leaf_pixels_; }
  // Shaded colour of a vertex (meaningful when vertex_shaded(v)).
  [[nodiscard]] glm::vec3 vertex_colour(std::size_t v) const { return colour_[v]; }
  [[nodiscard]] bool vertex_shaded(std::size_t v) const { return v < shaded_.size() && shaded_[v] != 0; }
  // The frame the criteria see (pixel luminances filled only for NLD_IS).
  [[nodiscard]] refinement_frame frame() const {
    refinement_frame f;
    f.width = width_;
    f.height = height_;
    f.mesh = &mesh_;
    f.pixel_leaf = pixel_leaf_;
    f.pixel_luminance = pixel_luminance_;
    f.leaf_pixels = leaf_pixels_;
    f.visible = visible_;
    f.vertex_luminance = luminance_;
    f.l_max = l_max_;
    return f;
  }

 private:
  [[nodiscard]] bool done() const {
    return finished_ || report_.stage2.shading_samples >= options_.max_shading_samples ||
           report_.batches >= options_.max_batches;
  }

  [[nodiscard]] glm::vec3 pixel_colour(std::size_t p) const {
    const std::uint32_t leaf = pixel_leaf_[p];
    if (leaf == invalid_id) return options_.background;
    const glm::uvec3 v = mesh_.triangle(leaf).vertices;
    const glm::vec3 w = pixel_weights_[p];
    return w.x * colour_[v.x] + w.y * colour_[v.y] + w.z * colour_[v.z];
  }

  [[nodiscard]] stage_figures figures() const {
    stage_figures s;
    s.triangles = visible_.size();
    s.triangles_total = ever_shown_count_;
    s.triangles_produced = mesh_.triangle_count();
    s.shading_samples = samples_;
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    return s;
  }

  // Pixels whose leaf was split follow it down; projected areas and the visible set are rebuilt.
  template <class E>
  void relocate(E&& exec) {
    const std::size_t n = pixel_leaf_.size();
    exec.parallel_for(n, options_.grain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t p = begin; p < end; ++p) {
        const std::uint32_t leaf = pixel_leaf_[p];
        if (leaf == invalid_id || mesh_.is_leaf(leaf)) continue;
        const point_location loc = mesh_.locate_from(leaf, pixel_weights_[p]);
        pixel_leaf_[p] = loc.leaf;
        pixel_weights_[p] = loc.weights;
      }
    });
    leaf_pixels_.assign(mesh_.triangle_count(), 0);
    ever_shown_.resize(mesh_.triangle_count(), 0);
    visible_.clear();
    for (std::uint32_t leaf : pixel_leaf_)
      if (leaf != invalid_id && leaf_pixels_[leaf]++ == 0) visible_.push_back(leaf);
    std::sort(visible_.begin(), visible_.end());
    for (std::uint32_t t : visible_)
      if (!ever_shown_[t]) ever_shown_[t] = 1, ++ever_shown_count_;
  }

  // The vertex shading cache: every vertex of a visible leaf is shaded exactly once.
  template <class Shade, class E>
  void shade_visible(Shade& shade, E&& exec) {
    const std::size_t nv = mesh_.vertex_count();
    shaded_.resize(nv, 0);
    colour_.resize(nv, glm::vec3(0.0f));
    luminance_.resize(nv, 0.0f);
    pending_.clear();
    for (std::uint32_t t : visible_) {
      const glm::uvec3 v = mesh_.triangle(t).vertices;
      for (int c = 0; c < 3; ++c)
        if (!shaded_[v[c]]) shaded_[v[c]] = 1, pending_.push_back(v[c]);
    }
    exec.parallel_for(pending_.size(), 256, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t v = pending_[i];
        colour_[v] = shade(point_of(v));
        luminance_[v] = luminance(colour_[v]);
      }
    });
    for (std::uint32_t v : pending_) l_max_ = std::max(l_max_, luminance_[v]);
    samples_ += pending_.size();
  }

  [[nodiscard]] shading_point point_of(std::uint32_t v) const {
    shading_point sp;
    sp.vertex = v;
    sp.position = mesh_.position(v);
    sp.triangle = mesh_.vertex_source(v);
    const glm::uvec3 o = mesh_.triangle(sp.triangle).vertices;  // original triangles keep their ids
    const glm::dvec3 a(mesh_.position(o.x)), b(mesh_.position(o.y)), c(mesh_.position(o.z)), p(sp.position);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double nn = glm::dot(n, n);
    sp.barycentric = glm::vec2(static_cast<float>(glm::dot(glm::cross(p - a, c - a), n) / nn),
                               static_cast<float>(glm::dot(glm::cross(b - a, p - a), n) / nn));
    return sp;
  }

  template <class E>
  void luminance_image(E&& exec) {
    pixel_luminance_.resize(pixel_leaf_.size());
    exec.parallel_for(pixel_leaf_.size(), options_.grain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t p = begin; p < end; ++p) pixel_luminance_[p] = luminance(pixel_colour(p));
    });
  }

  subdivision_mesh mesh_;
  driver_options options_;
  criterion_state state_;
  std::uint32_t width_ = 0, height_ = 0;
  std::vector<std::uint32_t> pixel_leaf_;
  std::vector<glm::vec3> pixel_weights_;
  std::vector<float> pixel_luminance_;
  std::vector<std::uint32_t> leaf_pixels_;
  std::vector<std::uint32_t> visible_;
  std::vector<std::uint8_t> ever_shown_;
  std::size_t ever_shown_count_ = 0;
  std::vector<std::uint8_t> shaded_;
  std::vector<glm::vec3> colour_;
  std::vector<float> luminance_;
  std::vector<std::uint32_t> pending_;
  std::vector<std::uint32_t> selected_;
  float l_max_ = 0.0f;
  std::size_t samples_ = 0;
  bool finished_ = false;
  refinement_report report_;
  std::chrono::steady_clock::time_point started_{};
};

}  // namespace infolerp
