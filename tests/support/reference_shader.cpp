#include "support/reference_shader.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <glm/geometric.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/upsample/ray_cast_source.hpp"

namespace infolerp::support {

namespace {
constexpr float pi = 3.14159265358979323846f;

// The fixed sample sets and the tangent frame are the ready sample source's
// (upsample/ray_cast_source.hpp), so both trace the same rays.
using infolerp::detail::tangent_frame;

}  // namespace

reference_shader::reference_shader(const demo_scene& scene, const shader_options& options)
    : scene_(&scene), options_(options), rays_(scene.view.rays()), area_center_(scene.area.center()),
      area_normal_(scene.area.normal()), area_area_(scene.area.area()) {
  hemisphere_ = cosine_hemisphere(options_.ao_rays);  // cosine-weighted, Malley's method on Hammersley points
  for (unsigned i = 0; i < options_.soft_shadow_rays; ++i) {
    const glm::vec2 s = hammersley(i, options_.soft_shadow_rays);
    light_points_.push_back(scene.area.point(s.x, s.y));
  }
}

unsigned reference_shader::count_unoccluded(std::span<const ray> rays) const {
  const embree_scene& tracer = scene_->occluders ? *scene_->occluders : scene_->tracer;
  unsigned visible = 0;
  if (options_.packets) {
    std::array<std::uint8_t, 64> occluded{};
    for (std::size_t base = 0; base < rays.size(); base += occluded.size()) {
      const std::size_t n = std::min(occluded.size(), rays.size() - base);
      tracer.occluded(rays.subspan(base, n), std::span<std::uint8_t>(occluded.data(), n));
      for (std::size_t i = 0; i < n; ++i) visible += occluded[i] ? 0u : 1u;
    }
  } else {
    for (const ray& r : rays) visible += tracer.occluded(r) ? 0u : 1u;
  }
  return visible;
}

shading_inputs reference_shader::evaluate_pixel(float x, float y, int width, int height, std::uint64_t& rays) const {
  return evaluate(rays_(x, y, width, height), rays);
}

shading_inputs reference_shader::evaluate(const ray& primary, std::uint64_t& rays) const {
  ++rays;
  return evaluate_hit(primary, scene_->tracer.intersect(primary), rays);
}

shading_inputs reference_shader::evaluate_hit(const ray& primary, const hit& h, std::uint64_t& rays) const {
  shading_inputs in;
  in.view = glm::normalize(primary.direction);
  if (!h.valid()) return in;
  const demo_scene& scene = *scene_;
  const indexed_mesh& m = scene.objects[h.geometry].mesh;
  const glm::uvec3 tri = m.triangles[h.triangle];
  const float u = h.barycentric.x, v = h.barycentric.y, w = 1.0f - u - v;
  const glm::vec3 p0 = m.positions[tri.x], p1 = m.positions[tri.y], p2 = m.positions[tri.z];
  in.geometry = h.geometry;
  in.triangle = h.triangle;
  in.position = w * p0 + u * p1 + v * p2;

  // Geometric normal toward the camera; the shading normal on the same side.
  glm::vec3 ng = glm::normalize(glm::cross(p1 - p0, p2 - p0));
  if (glm::dot(ng, in.view) > 0.0f) ng = -ng;
  glm::vec3 n = ng;
  if (m.has_normals()) {
    n = glm::normalize(w * m.normals[tri.x] + u * m.normals[tri.y] + v * m.normals[tri.z]);
    if (glm::dot(n, ng) < 0.0f) n = -n;
  }
  in.normal = n;
  if (m.has_texcoords()) {
    const std::size_t c = 3 * std::size_t{h.triangle};
    in.uv = w * m.texcoords[c] + u * m.texcoords[c + 1] + v * m.texcoords[c + 2];
  }

  // Secondary rays leave from just above the surface (geometric side facing the camera).
  const glm::vec3 origin = in.position + scene.ray_offset * ng;

  // Hard shadow: one ray toward the sun (none when the surface faces away).
  if (options_.hard_shadow && glm::dot(ng, scene.sun.direction) > 0.0f) {
    const ray sun{origin, 0.0f, scene.sun.direction};
    ++rays;
    if (count_unoccluded(std::span<const ray>(&sun, 1)) == 1) in.light_bits |= sun_light_bit;
  }
  if (light_points_.empty() && hemisphere_.empty()) {  // a primary-only shader: no batch to fill
    in.ao = 1.0f;
    return in;
  }

  // The batch (2 KiB of initialised rays) only for shaders with soft-shadow or AO rays.
  std::array<ray, 64> batch;
  std::size_t count = 0;
  auto flush = [&] {
    const unsigned visible = count_unoccluded(std::span<const ray>(batch.data(), count));
    rays += count;
    count = 0;
    return visible;
  };

  // Soft shadow: rays to the fixed light points the surface and the light face each other at.
  if (!light_points_.empty()) {
    unsigned visible = 0;
    const glm::vec3& light_normal = area_normal_;
    for (const glm::vec3& q : light_points_) {
      const glm::vec3 d = q - origin;  // tfar 1 reaches the light; stop just before it
      if (glm::dot(d, ng) <= 0.0f || glm::dot(d, light_normal) >= 0.0f) continue;
      batch[count++] = ray{origin, 0.0f, d, 0.9999f};
      if (count == batch.size()) visible += flush();
    }
    visible += flush();
    in.soft_shadow = static_cast<float>(visible) / static_cast<float>(light_points_.size());
  }

  // Ambient occlusion: the fixed cosine-weighted directions in the geometric tangent frame.
  if (hemisphere_.empty()) {
    in.ao = 1.0f;
  } else {
    glm::vec3 t, b;
    tangent_frame(ng, t, b);
    unsigned visible = 0;
    for (const glm::vec3& d : hemisphere_) {
      batch[count++] = ray{origin, 0.0f, d.x * t + d.y * b + d.z * ng, scene.ao_radius};
      if (count == batch.size()) visible += flush();
    }
    visible += flush();
    in.ao = static_cast<float>(visible) / static_cast<float>(hemisphere_.size());
  }
  return in;
}

glm::vec3 reference_shader::shade(const shading_inputs& in) const {
  const demo_scene& scene = *scene_;
  if (!in.hit()) {
    const float up = std::sqrt(std::clamp(in.view.z, 0.0f, 1.0f));
    return scene.sky_horizon + (scene.sky_zenith - scene.sky_horizon) * up;
  }
  const material& mat = scene.objects[in.geometry].mat;
  const glm::vec3& n = in.normal;
  glm::vec3 irradiance = scene.ambient * in.ao;
  glm::vec3 highlight{0.0f};
  if (in.light_bits & sun_light_bit) {
    irradiance += scene.sun.radiance * std::max(0.0f, glm::dot(n, scene.sun.direction));
    if (mat.specular != 0.0f) {  // without it the highlight is +0 and the view is not read
      const glm::vec3 half = glm::normalize(scene.sun.direction - in.view);
      highlight += mat.specular * scene.sun.radiance * std::pow(std::max(0.0f, glm::dot(n, half)), 48.0f);
    }
  }
  if (in.soft_shadow > 0.0f) {
    const glm::vec3 d = area_center_ - in.position;
    const float dist2 = glm::dot(d, d);
    const glm::vec3 l = d / std::sqrt(dist2);
    const float cos_surface = std::max(0.0f, glm::dot(n, l));
    const float cos_light = std::max(0.0f, -glm::dot(l, area_normal_));
    irradiance += scene.area.radiance * (area_area_ * cos_surface * cos_light / (pi * dist2) * in.soft_shadow);
  }
  float lod = 0.0f;  // log2 of the footprint in level-0 texels (texture.hpp)
  if (mat.texture == texture_kind::image && options_.pixel_angle > 0.0f)
    lod = std::log2(glm::distance(in.position, rays_.eye) * options_.pixel_angle * mat.texels_per_unit);
  return albedo(mat, in.uv, lod) * irradiance + highlight;
}

result<render_stats> render_reference(const reference_shader& shader, int width, int height, image& out, int threads,
                                      const std::function<void(int, int)>& progress) {
  if (width <= 0 || height <= 0)
    return make_error(errc::empty_input, no_element, "render_reference: image size ", width, "x", height);
  out = image(width, height);
  std::atomic<std::uint64_t> rays{0};
  std::mutex progress_mutex;
  int rows_done = 0;
  const auto start = std::chrono::steady_clock::now();
  openmp_executor{threads}.parallel_for(static_cast<std::size_t>(height), 1, [&](std::size_t begin, std::size_t end) {
    enable_flush_to_zero();
    for (std::size_t row = begin; row < end; ++row) {
      const int y = static_cast<int>(row);
      std::uint64_t row_rays = 0;
      for (int x = 0; x < width; ++x) {
        const shading_inputs in =
            shader.evaluate_pixel(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, width, height, row_rays);
        out.at(x, y) = shader.shade(in);
      }
      rays += row_rays;
      if (progress) {
        const std::lock_guard lock(progress_mutex);
        progress(++rows_done, height);
      }
    }
  });
  render_stats stats;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.rays = rays.load();
  return stats;
}

}  // namespace infolerp::support
