#pragma once
// The demo scene as an I-Buffer sample source (include/infolerp/upsample/sample_source.hpp),
// shared by the demo's upsampler stage and the time-against-error harness:
//   evaluate(x, y): the reference shader's full evaluation of pixel (x, y) (primary ray, hard
//                   shadow, soft shadow, AO) stored in the default record surface_sample<2>:
//                   position, normal, texcoords, cluster id, sun bit, occlusion {ao, soft},
//                   inv_depth = 1 / view depth (perspective-correct weights; 1 without `perspective`).
//   shade(s, x, y): the reference shader's shade() of that record; the view direction is the
//                   pixel's primary ray and the material is the cluster's object.
// Evaluated pixels reproduce the reference render (up to the renormalised normal's last bit).
//
// Clusterings: the real feature clustering is support::cluster_by_features (demo_clusters.hpp);
// two simple stand-ins for comparison:
//   cluster_by_object   one cluster per scene object (geometry id)
//   cluster_by_normal   per object, face normals binned on a cube map (cells×cells per face),
//                       split further at texcoord halves so that no cluster spans a UV seam.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/refine/pinhole_camera.hpp"
#include "infolerp/upsample/ray_cast_source.hpp"
#include "infolerp/upsample/sample_source.hpp"
#include "support/demo_scene.hpp"
#include "support/image.hpp"
#include "support/reference_shader.hpp"

namespace infolerp::support {

struct scene_clustering {
  std::string name;
  std::vector<std::vector<std::uint32_t>> ids;  // [geometry][triangle] -> global cluster id
  std::vector<std::uint32_t> geometry_of;       // [cluster] -> geometry
  std::size_t count() const { return geometry_of.size(); }
};

inline scene_clustering cluster_by_object(const demo_scene& scene) {
  scene_clustering c{"object", {}, {}};
  for (std::uint32_t g = 0; g < scene.objects.size(); ++g) {
    c.ids.emplace_back(scene.objects[g].mesh.triangle_count(), g);
    c.geometry_of.push_back(g);
  }
  return c;
}

inline scene_clustering cluster_by_normal(const demo_scene& scene, int cells) {
  scene_clustering c{"normal" + std::to_string(cells), {}, {}};
  for (std::uint32_t g = 0; g < scene.objects.size(); ++g) {
    const indexed_mesh& m = scene.objects[g].mesh;
    const auto normals = face_normals(m);
    std::vector<std::uint32_t> local(m.triangle_count());
    std::vector<std::uint32_t> remap(static_cast<std::size_t>(6 * cells * cells * 4), invalid_id);
    for (std::size_t t = 0; t < local.size(); ++t) {
      const glm::vec3 n = normals[t];
      const glm::vec3 a = glm::abs(n);
      const int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
      const float major = std::max(a[axis], 1e-12f);
      const int face = 2 * axis + (n[axis] < 0.0f ? 1 : 0);
      const float u = n[(axis + 1) % 3] / major, v = n[(axis + 2) % 3] / major;  // in [-1, 1]
      auto cell = [&](float w) { return std::clamp(static_cast<int>((w + 1.0f) * 0.5f * static_cast<float>(cells)), 0, cells - 1); };
      int uv_half = 0;
      if (m.has_texcoords()) {
        const glm::vec2 tc = (m.texcoord(t, 0) + m.texcoord(t, 1) + m.texcoord(t, 2)) / 3.0f;
        uv_half = (tc.x - std::floor(tc.x) >= 0.5f ? 1 : 0) + (tc.y - std::floor(tc.y) >= 0.5f ? 2 : 0);
      }
      const std::size_t key = static_cast<std::size_t>(((face * cells + cell(u)) * cells + cell(v)) * 4 + uv_half);
      if (remap[key] == invalid_id) {
        remap[key] = static_cast<std::uint32_t>(c.geometry_of.size());
        c.geometry_of.push_back(g);
      }
      local[t] = remap[key];
    }
    c.ids.push_back(std::move(local));
  }
  return c;
}

using demo_sample = surface_sample<2, true>;  // occlusion = {ambient occlusion, soft-shadow visibility}

struct demo_ibuffer_source {
  using sample_type = demo_sample;
  const reference_shader* shader = nullptr;
  const scene_clustering* clusters = nullptr;
  int width = 0;
  int height = 0;
  bool perspective = true;  // inv_depth = 1 / view depth (perspective-correct weights); false: 1 (screen-linear)

  demo_sample evaluate(std::uint32_t x, std::uint32_t y) const {
    std::uint64_t rays = 0;
    const shading_inputs in = shader->evaluate_pixel(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f,
                                                     width, height, rays);
    return from_inputs(in);
  }
  demo_sample from_inputs(const shading_inputs& in) const {
    demo_sample s;
    if (!in.hit()) return s;
    s.position = in.position;
    s.normal = in.normal;
    s.texcoord = in.uv;
    s.cluster = clusters->ids[in.geometry][in.triangle];
    s.lights = in.light_bits;
    s.occlusion = {in.ao, in.soft_shadow};
    if (perspective) {
      const pinhole_rays& view = shader->camera_rays();
      s.inv_depth = 1.0f / std::max(glm::dot(in.position - view.eye, view.forward), 1e-6f);
    }
    return s;
  }
  // shade() reads the view direction only for the sky and the sun's highlight on specular
  // materials, so the primary ray is rebuilt only for those pixels (the same bits as always rebuilding it). The normal is
  // renormalised: interpolated normals are not unit.
  // A vector whose length is exactly 1 is kept as is: dividing by 1 would give the same bits.
  shading_inputs to_inputs(const demo_sample& s, std::uint32_t x, std::uint32_t y) const {
    shading_inputs in;
    const std::uint32_t g = s.background() ? invalid_id : clusters->geometry_of[s.cluster];
    if (s.background() || ((s.lights & sun_light_bit) != 0 && shader->scene().objects[g].mat.specular != 0.0f)) {
      const glm::vec3 d = shader->primary_ray(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, width, height).direction;
      const float len = std::sqrt(glm::dot(d, d));
      in.view = len == 1.0f ? d : d * (1.0f / len);  // glm::normalize's bits
    }
    if (s.background()) return in;
    in.position = s.position;
    const float len = glm::length(s.normal);
    in.normal = len > 0.0f && len != 1.0f ? s.normal / len : s.normal;
    in.uv = s.texcoord;
    in.geometry = g;
    in.light_bits = s.lights;
    in.ao = s.occlusion[0];
    in.soft_shadow = s.occlusion[1];
    return in;
  }
  glm::vec3 shade(const demo_sample& s, std::uint32_t x, std::uint32_t y) const { return shader->shade(to_inputs(s, x, y)); }
};

// The same with probes (sample_source.hpp): the cheap part of every pixel, its primary hit
// (cluster id, position, normal, texcoords) and, with probe_lights, the sun's hard-shadow ray,
// comes from `primary`: a reference shader without AO and soft-shadow rays
// (shader_options{.ao_rays = 0, .soft_shadow_rays = 0, .hard_shadow = probe_lights}). AO and
// soft shadow (80 of a full evaluation's 82 rays), and without probe_lights the sun bit too, are
// interpolated; then the sources must agree on the sun bit, as in the plain I-Buffer.
// With a probe at every sample the normals are evaluated, unit ones; with probes only where sources
// differ, whole interpolations are not, so shade() renormalises as without probes.
struct demo_probe_source : demo_ibuffer_source {
  const reference_shader* primary = nullptr;
  bool probe_lights = true;

  demo_sample probe(std::uint32_t x, std::uint32_t y) const {
    std::uint64_t rays = 0;
    return from_inputs(primary->evaluate_pixel(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, width, height, rays));
  }
  // The same for pixels (xs[k], y), the primary rays traced as the tracer's packets, 64 at a time.
  void probe(std::uint32_t y, std::span<const std::uint32_t> xs, std::span<demo_sample> out) const {
    std::array<ray, 64> rays;
    std::array<hit, 64> hits;
    std::uint64_t count = 0;
    for (std::size_t base = 0; base < xs.size(); base += rays.size()) {
      const std::size_t n = std::min(rays.size(), xs.size() - base);
      for (std::size_t k = 0; k < n; ++k)
        rays[k] = primary->primary_ray(static_cast<float>(xs[base + k]) + 0.5f, static_cast<float>(y) + 0.5f, width, height);
      primary->scene().tracer.intersect(std::span<const ray>(rays.data(), n), std::span<hit>(hits.data(), n));
      for (std::size_t k = 0; k < n; ++k) out[base + k] = from_inputs(primary->evaluate_hit(rays[k], hits[k], count));
    }
  }
  bool probe_compatible(const demo_sample& p, const demo_sample& s) const {
    return probe_lights ? compatible(p, s) : p.cluster == s.cluster;
  }
  // With probes only where sources differ: also where normals differ by more than acos(smooth_cos).
  float smooth_cos = -1.0f;
  bool smooth(const demo_sample& a, const demo_sample& b) const { return normals_within(a, b, smooth_cos); }
};

// The same with cheap probes and refinement (refine_probe, sample_source.hpp): probes trace
// the primary ray only (`primary` without the sun, probe_lights = false), so a new sample
// needs two sources of its cluster that agree on the sun bit; only where that fails is the
// probe refined by `primary_sun` (shader_options{.ao_rays = 0, .soft_shadow_rays = 0}) and
// completed from the sources that match it, sun bit included. The refinement re-traces the
// primary ray: the record does not keep the geometric normal the sun ray leaves from.
struct demo_refining_probe_source : demo_probe_source {
  const reference_shader* primary_sun = nullptr;

  demo_sample refine_probe(const demo_sample&, std::uint32_t x, std::uint32_t y) const {
    std::uint64_t rays = 0;
    return from_inputs(primary_sun->evaluate_pixel(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, width, height, rays));
  }
};

// The same, and a new sample is evaluated unless its chosen sources' AO and soft-shadow ratios
// differ pairwise by at most `tolerance` (agree(), sample_source.hpp): adaptive refinement on
// top of the cluster test, between two pass counts' evaluated fractions.
struct demo_tolerant_probe_source : demo_refining_probe_source {
  float tolerance = 0.05f;
  bool agree(const demo_sample& a, const demo_sample& b) const { return occlusion_within(a, b, tolerance); }
};

// The demo scene through the library's ready source (upsample/ray_cast_source.hpp): the same
// rays and the same record as demo_ibuffer_source (its sun is light 0, its area light's points
// the soft-shadow points), the reference shader's shade() as the material callback.
struct demo_camera {
  pinhole_rays rays;
  int width = 0;
  int height = 0;
  ray operator()(float x, float y) const { return rays(x, y, width, height); }
};
struct demo_geometry {
  const demo_scene* scene = nullptr;
  const indexed_mesh& operator()(std::uint32_t g) const { return scene->objects[g].mesh; }
};
struct demo_material {
  const reference_shader* shader = nullptr;
  const scene_clustering* clusters = nullptr;
  template <class View>
  glm::vec3 operator()(const demo_sample& s, const View& view) const {
    shading_inputs in;
    const std::uint32_t g = s.background() ? invalid_id : clusters->geometry_of[s.cluster];
    if (s.background() || ((s.lights & sun_light_bit) != 0 && shader->scene().objects[g].mat.specular != 0.0f)) in.view = view();
    if (s.background()) return shader->shade(in);
    in.position = s.position;
    in.normal = s.normal;
    in.uv = s.texcoord;
    in.geometry = g;
    in.light_bits = s.lights;
    in.ao = s.occlusion[0];
    in.soft_shadow = s.occlusion[1];
    return shader->shade(in);
  }
  // Display steps per radian of view turn (frame_reuse.hpp): the sun's Blinn-Phong highlight
  // (exponent 48) on a specular material where the sun is seen; the sky and everything else do
  // not change with the view (0; image textures at mip level 0, shader_options::pixel_angle 0).
  float view_dependence(const demo_sample& s) const {
    if (s.background()) return std::numeric_limits<float>::infinity();
    const material& mat = shader->scene().objects[clusters->geometry_of[s.cluster]].mat;
    if (mat.specular == 0.0f || (s.lights & sun_light_bit) == 0) return 0.0f;
    const glm::vec3 r = shader->scene().sun.radiance;
    return 255.0f * 48.0f * mat.specular * std::max(r.x, std::max(r.y, r.z));
  }
};
template <probe_mode Probes = probe_mode::none>
using demo_ray_cast_source = ray_cast_source<embree_scene, demo_camera, demo_geometry, demo_material, Probes>;

// shader's options give the counts (AO rays, soft-shadow points, the sun when hard_shadow,
// packets as batch_rays); clusters and shader must outlive the source. `view`: the camera's
// rays (default: the shader's, i.e. the scene's camera when the shader was made; another view
// shades alike except an image texture's mip level, which reads the shader's eye).
template <probe_mode Probes = probe_mode::none>
result<demo_ray_cast_source<Probes>> make_demo_ray_cast_source(const reference_shader& shader, const scene_clustering& clusters,
                                                               int width, int height, bool perspective = true,
                                                               float tolerance = std::numeric_limits<float>::infinity(),
                                                               float smooth_angle = ray_cast_options{}.smooth_angle,
                                                               const pinhole_rays* view = nullptr) {
  const pinhole_rays& rays = view != nullptr ? *view : shader.camera_rays();
  const demo_scene& scene = shader.scene();
  const shader_options& so = shader.options();
  ray_cast_options o{.ao_rays = so.ao_rays, .ao_radius = scene.ao_radius, .ray_offset = scene.ray_offset};
  if (so.hard_shadow) o.lights.push_back({.at = scene.sun.direction, .directional = true});
  for (unsigned i = 0; i < so.soft_shadow_rays; ++i) {
    const glm::vec2 h = hammersley(i, so.soft_shadow_rays);
    o.soft_points.push_back(scene.area.point(h.x, h.y));
  }
  o.soft_normal = scene.area.normal();
  o.batch_rays = so.packets;
  if (perspective) {
    o.view_origin = rays.eye;
    o.view_forward = rays.forward;
  }
  o.tolerance = tolerance;
  o.smooth_angle = smooth_angle;
  std::vector<std::span<const std::uint32_t>> ids(clusters.ids.begin(), clusters.ids.end());
  return demo_ray_cast_source<Probes>::create(scene.tracer, demo_camera{rays, width, height},
                                              demo_geometry{&scene}, demo_material{&shader, &clusters}, std::move(ids),
                                              std::move(o));
}

// The pinhole frame (refine/pinhole_camera.hpp) of camera c for a width x height image: the
// same rays as c.rays(), and the projection frame_reuse.hpp reprojects with.
inline pinhole_frame pinhole_frame_of(const camera& c, std::uint32_t width, std::uint32_t height) {
  const pinhole_rays r = c.rays();
  pinhole_frame f;
  f.eye = r.eye;
  f.forward = r.forward;
  f.right = r.right;
  f.up = r.true_up;
  f.tan_half_fov = r.half_h;
  f.aspect = static_cast<float>(width) / static_cast<float>(height);
  f.width = width;
  f.height = height;
  return f;
}

// Display luma (Rec. 709 weights on 8-bit sRGB values, in [0, 1]): what PSNR and SSIM look at.
inline float display_luma(glm::vec3 linear) {
  return (0.2126f * to_srgb8(linear.x) + 0.7152f * to_srgb8(linear.y) + 0.0722f * to_srgb8(linear.z)) / 255.0f;
}

}  // namespace infolerp::support
