#pragma once
// The full per-pixel reference shading of the demo scene, split in two steps so that the
// upsampler can interpolate between them:
//   evaluate(pixel) -> shading_inputs   the expensive part: primary ray, hit attributes, one
//                                       hard-shadow ray to the sun, M soft-shadow rays to the
//                                       area light, N ambient-occlusion rays
//   shade(inputs)   -> linear RGB       cheap and pure: texture lookup and lighting
// The M light points and N hemisphere directions are fixed sets (Hammersley points; the AO
// directions cosine-weighted and rotated into each pixel's tangent frame), so evaluating the
// same pixel twice gives the same bits: no Monte Carlo noise to drown interpolation error.
// Callers that evaluate from their own threads call enable_flush_to_zero() in each of them, as
// render_reference does, so that every thread rounds alike.
#include <array>
#include <cstdint>
#include <functional>
#include <vector>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "support/demo_scene.hpp"
#include "support/image.hpp"

namespace infolerp::support {

struct shader_options {
  unsigned ao_rays = 64;           // N: ambient-occlusion rays per pixel (0 = no AO, ao = 1)
  unsigned soft_shadow_rays = 16;  // M: rays to fixed points on the area light (0 = light off)
  bool packets = false;            // trace a pixel's AO and soft-shadow rays as 16-ray packets
  bool hard_shadow = true;         // trace the sun's hard-shadow ray (false: light_bits stay 0)
  float pixel_angle = 0.0f;        // radians per pixel of the rendered image (pixel_angle(camera,
                                   // height)): image textures take the mip level of the sample's
                                   // footprint, distance x pixel_angle across (isotropic: the
                                   // surface's tilt is ignored); 0: always level 0 (bilinear)
};

// What evaluate() finds at a pixel: everything shade() needs. Interpolating records (not
// colours) is what the upsampler does; all members but the ids interpolate linearly.
struct shading_inputs {
  glm::vec3 position{0.0f};    // hit point (world)
  glm::vec3 normal{0.0f};      // unit shading normal, facing the camera
  glm::vec3 view{0.0f};        // unit primary ray direction (gives the sky colour on a miss)
  glm::vec2 uv{0.0f};          // interpolated texcoords (0 for meshes without them)
  std::uint32_t geometry = invalid_id;  // scene object, invalid_id for the background
  std::uint32_t triangle = invalid_id;
  std::uint32_t light_bits = 0;  // bit 0: the sun is visible (hard shadow)
  float soft_shadow = 0.0f;      // fraction of the area light's points visible, [0, 1]
  float ao = 0.0f;               // fraction of the AO directions unoccluded, [0, 1]

  [[nodiscard]] bool hit() const { return geometry != invalid_id; }
};
inline constexpr std::uint32_t sun_light_bit = 1u;

class reference_shader {
 public:
  // Precomputes the fixed direction and light-point sets and the camera basis. The scene must
  // outlive the shader; its camera is read here.
  reference_shader(const demo_scene& scene, const shader_options& options = {});

  // Full evaluation of the pixel point (x, y) (pixel centres at +0.5) of a width x height image.
  // Adds the number of rays traced to `rays`. Thread-safe; no allocation.
  shading_inputs evaluate_pixel(float x, float y, int width, int height, std::uint64_t& rays) const;
  // The same for a given primary ray (unit direction) ...
  shading_inputs evaluate(const ray& primary, std::uint64_t& rays) const;
  // ... or for a primary ray already traced (e.g. in a 16-ray packet); does not count it.
  shading_inputs evaluate_hit(const ray& primary, const hit& h, std::uint64_t& rays) const;

  // Linear RGB of a record (pure; no rays). Thread-safe.
  glm::vec3 shade(const shading_inputs& in) const;

  // The primary ray of pixel point (x, y): scene().view.primary_ray with the camera basis
  // computed once, at construction (the shader reads the camera then).
  ray primary_ray(float x, float y, int width, int height) const { return rays_(x, y, width, height); }
  const pinhole_rays& camera_rays() const { return rays_; }

  const demo_scene& scene() const { return *scene_; }
  const shader_options& options() const { return options_; }
  // The most rays one evaluate() can trace: 1 + 1 + M + N.
  unsigned max_rays_per_pixel() const { return 2 + options_.soft_shadow_rays + options_.ao_rays; }

 private:
  // Traces `rays` (occlusion) one by one or as packets, returns how many were unoccluded.
  unsigned count_unoccluded(std::span<const ray> rays) const;

  const demo_scene* scene_;
  shader_options options_;
  pinhole_rays rays_;
  std::vector<glm::vec3> hemisphere_;    // N cosine-weighted directions around +Z
  std::vector<glm::vec3> light_points_;  // M points on the area light
  // The area light's centre, unit normal and area, read once like its points (shade() needs
  // them at every pixel; recomputing them there was a cross product and a square root each).
  glm::vec3 area_center_;
  glm::vec3 area_normal_;
  float area_area_;
};

struct render_stats {
  double seconds = 0.0;
  std::uint64_t rays = 0;
  double rays_per_second() const { return seconds > 0.0 ? static_cast<double>(rays) / seconds : 0.0; }
};

// Renders every pixel with full evaluation + shade, in parallel over rows (OpenMP, `threads`
// threads; 0 = OpenMP's default). Each worker, the calling thread included, is left with
// flush-to-zero set. The image is the same bit for
// bit for any thread count. progress(rows_done, rows_total) is called after each row, one call
// at a time (from worker threads). Errors: width or height not positive.
result<render_stats> render_reference(const reference_shader& shader, int width, int height, image& out,
                                      int threads = 0,
                                      const std::function<void(int, int)>& progress = {});

}  // namespace infolerp::support
