#pragma once
// A ready I-Buffer sample source (sample_source.hpp) for engines that shade with a ray tracer,
// following the clustering paper's §4 and §4.1: primary ray -> closest hit -> the hit
// triangle's cluster id (a per-triangle array) -> hard-shadow light bits (one ray to each of up
// to 32 point or directional lights) -> ambient-occlusion and soft-shadow ratios (the counts
// the engine chooses) stored in the default record surface_sample<2> (occlusion = {AO, soft}).
// A small material callback turns an (interpolated) record into a colour. An engine with a
// different shading model writes its own source instead.
//
// Generic over the engine's types:
//   Tracer    models infolerp::tracer (core/tracer.hpp)
//   Camera    ray operator()(float x, float y) const: the primary ray through pixel point (x, y)
//             (pixel centres at +0.5), unit direction
//   Geometry  const M& operator()(uint32_t geometry) const: the mesh of a hit's geometry id (M an
//             infolerp::mesh; normals and texcoords used when it has them)
//   Material  Pixel operator()(const surface_sample<2>& s, const V& view) const: the colour of
//             a record; s.normal is unit; view() returns the pixel's unit primary direction
//             (computed only when called: for the sky, for highlights); optionally
//             float view_dependence(const surface_sample<2>& s) const (sample_source.hpp)
// Probes (sample_source.hpp, optional, a compile-time choice): probe_mode::primary probes trace
// the primary ray and the hard-shadow rays; probe_mode::refine probes trace the primary ray only
// and refine_probe adds the hard-shadow rays where the upsampler needs them. agree() compares
// the occlusion terms within options.tolerance (occlusion_within); the default, +infinity,
// always agrees and gives the frame of a source without agree(). smooth() compares normals
// within options.smooth_angle (normals_within), for probes only where sources differ.
// The AO directions are a fixed cosine-weighted Hammersley set rotated into each hit's tangent
// frame, and the soft-shadow points a fixed set the engine gives, so evaluating a pixel twice
// gives the same bits (no Monte Carlo noise for the upsampler to smear).
// Thread-safe for concurrent const calls when the engine's callables are. No allocation after
// construction; an evaluation traces 1 + lights + soft-shadow points + AO rays at most.
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/upsample/sample_source.hpp"

namespace infolerp {

// A hard-shadow light (§4.1). directional: `at` is the unit direction toward the light;
// otherwise `at` is the light's position (shadow rays stop just before it).
struct hard_shadow_light {
  glm::vec3 at{0.0f, 0.0f, 1.0f};
  bool directional = true;
};

struct ray_cast_options {
  unsigned ao_rays = 64;                 // AO directions per evaluation (0: ao = 1; at most 65,536: 768 KiB of directions)
  float ao_radius = 1.5f;                // AO rays look this far
  float ray_offset = 1e-3f;              // secondary rays start this far off the surface
  std::vector<hard_shadow_light> lights{};  // up to 32; light i sets bit i
  std::vector<glm::vec3> soft_points{};  // points on one-sided area lights (soft shadow)
  glm::vec3 soft_normal{0.0f, 0.0f, -1.0f};  // the area light's emitting side
  bool batch_rays = false;               // trace soft-shadow and AO rays through the tracer's batch overload
  glm::vec3 view_origin{0.0f};           // with view_forward != 0: inv_depth = 1 / view depth
  glm::vec3 view_forward{0.0f};          // (perspective-correct weights); 0: screen-linear
  float tolerance = std::numeric_limits<float>::infinity();  // agree(): occlusion terms within this
  // smooth(), for probes only where sources differ (upsampler_options::probe_every_sample off):
  // a sample is also probed where its sources' normals differ by more than this angle (radians;
  // π or more: never), so that curved surfaces are not interpolated over coarse cells.
  float smooth_angle = 5.0f * 3.14159265f / 180.0f;
};

enum class probe_mode : std::uint8_t { none, primary, refine };

namespace detail {
// Van der Corput radical inverse in base 2 (the second Hammersley coordinate).
inline float radical_inverse(std::uint32_t i) {
  i = (i << 16u) | (i >> 16u);
  i = ((i & 0x55555555u) << 1u) | ((i & 0xAAAAAAAAu) >> 1u);
  i = ((i & 0x33333333u) << 2u) | ((i & 0xCCCCCCCCu) >> 2u);
  i = ((i & 0x0F0F0F0Fu) << 4u) | ((i & 0xF0F0F0F0u) >> 4u);
  i = ((i & 0x00FF00FFu) << 8u) | ((i & 0xFF00FF00u) >> 8u);
  return static_cast<float>(i) * 0x1p-32f;
}
// A tangent frame around unit n, continuous except straight down (Duff et al. 2017, sign +1).
inline void tangent_frame(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  if (n.z < -0.9999f) {
    t = {0.0f, -1.0f, 0.0f};
    b = {-1.0f, 0.0f, 0.0f};
    return;
  }
  const float a = 1.0f / (1.0f + n.z);
  const float c = -n.x * n.y * a;
  t = {1.0f - n.x * n.x * a, c, -n.x};
  b = {c, 1.0f - n.y * n.y * a, -n.y};
}
}  // namespace detail

// Point i of an n-point Hammersley set in [0,1)². O(1).
inline glm::vec2 hammersley(unsigned i, unsigned n) {
  return {(static_cast<float>(i) + 0.5f) / static_cast<float>(n), detail::radical_inverse(i)};
}

// n cosine-weighted directions around +Z (Malley's method on Hammersley points). O(n).
inline std::vector<glm::vec3> cosine_hemisphere(unsigned n) {
  constexpr float pi = 3.14159265358979323846f;
  std::vector<glm::vec3> out;
  out.reserve(n);
  for (unsigned i = 0; i < n; ++i) {
    const glm::vec2 s = hammersley(i, n);
    const float r = std::sqrt(s.x), phi = 2.0f * pi * s.y;
    out.push_back({r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - s.x))});
  }
  return out;
}

template <class Tracer, class Camera, class Geometry, class Material, probe_mode Probes = probe_mode::none>
class ray_cast_source {
 public:
  using sample_type = surface_sample<2, true>;

  // clusters[g][t]: the cluster id of triangle t of geometry g; the arrays must cover every
  // triangle a primary ray can hit (unchecked). The tracer must outlive the source.
  // Errors: more than 32 lights, ao_rays above 65,536, a non-finite or negative ao_radius or
  // ray_offset, a NaN or negative smooth_angle, a non-finite view_origin or view_forward
  // (bad_parameter); a NaN or infinite
  // vertex normal or texcoord of geometry g < clusters.size() (non_finite, names the vertex or
  // triangle); texcoords of the library's adaptors present but not 3 per triangle (bad_size).
  // Zero normals are accepted: where the interpolated normal has no direction the geometric
  // normal shades (see surface()). O(V + T) of the geometries for the checks, no allocation.
  [[nodiscard]] static result<ray_cast_source> create(const Tracer& tracer, Camera camera, Geometry geometry,
                                                      Material material,
                                                      std::vector<std::span<const std::uint32_t>> clusters,
                                                      ray_cast_options options) {
    static_assert(check_tracer<Tracer>());
    if (options.lights.size() > 32)
      return make_error(errc::bad_parameter, options.lights.size(), "ray_cast_source: ", options.lights.size(),
                        " hard-shadow lights; at most 32 fit the light bits");
    if (options.ao_rays > 65536)
      return make_error(errc::bad_parameter, no_element, "ray_cast_source: ao_rays ", options.ao_rays, " above 65536");
    if (!(options.ao_radius >= 0.0f) || !std::isfinite(options.ao_radius))
      return make_error(errc::bad_parameter, no_element, "ray_cast_source: ao_radius must be finite and >= 0");
    if (!(options.ray_offset >= 0.0f) || !std::isfinite(options.ray_offset))
      return make_error(errc::bad_parameter, no_element, "ray_cast_source: ray_offset must be finite and >= 0");
    if (!(options.smooth_angle >= 0.0f))
      return make_error(errc::bad_parameter, no_element, "ray_cast_source: smooth_angle must be >= 0 (radians)");
    if (!all_finite(options.view_origin) || !all_finite(options.view_forward))
      return make_error(errc::bad_parameter, no_element, "ray_cast_source: view_origin and view_forward must be finite");
    for (std::uint32_t g = 0; g < clusters.size(); ++g)
      if (status s = check_attributes(geometry(g), g); !s.ok()) return s;
    return ray_cast_source(tracer, std::move(camera), std::move(geometry), std::move(material), std::move(clusters),
                           std::move(options));
  }

  // §4: full evaluation of pixel (x, y).
  sample_type evaluate(std::uint32_t x, std::uint32_t y) const { return trace(x, y, true, true); }
  // The same from the pixel's probe (refined in probe_mode::refine): its hard-shadow bits are
  // kept, not traced again. The primary ray is traced again for the geometric normal the
  // secondary rays leave from, which the record does not keep (one ray of the evaluation's
  // 1 + lights + soft-shadow points + AO rays).
  sample_type evaluate(const sample_type& probe, std::uint32_t x, std::uint32_t y) const requires(Probes != probe_mode::none) {
    if (probe.background()) return probe;
    sample_type s = trace(x, y, false, true);
    s.lights = probe.lights;
    return s;
  }

  // The record's colour: the material callback with a unit normal. Interpolated normals are
  // renormalised in every probe mode: with probes only where sources differ, whole
  // interpolations reach the material too.
  auto shade(const sample_type& s, std::uint32_t x, std::uint32_t y) const {
    const auto view = [&] { return glm::normalize(camera_(pixel(x), pixel(y)).direction); };
    if (s.background()) return material_(s, view);
    sample_type unit = s;
    const float len = glm::length(s.normal);
    if (len > 0.0f && len != 1.0f) unit.normal = s.normal / len;  // a unit normal: dividing by 1 keeps its bits
    return material_(unit, view);
  }

  sample_type probe(std::uint32_t x, std::uint32_t y) const requires(Probes != probe_mode::none) {
    return trace(x, y, Probes == probe_mode::primary, false);
  }
  // The probes of pixels (xs[k], y), their primary rays traced through the tracer's batch
  // overload when it has one (e.g. Embree's 16-ray packets), 64 at a time on the stack. The same
  // records as probe(x, y) when the batch overload returns the hits of single rays.
  void probe(std::uint32_t y, std::span<const std::uint32_t> xs, std::span<sample_type> out) const
    requires(Probes != probe_mode::none) {
    std::array<ray, 64> rays;
    std::array<hit, 64> hits;
    for (std::size_t base = 0; base < xs.size(); base += rays.size()) {
      const std::size_t n = std::min(rays.size(), xs.size() - base);
      for (std::size_t k = 0; k < n; ++k) rays[k] = camera_(pixel(xs[base + k]), pixel(y));
      trace_intersect(*tracer_, std::span<const ray>(rays.data(), n), std::span<hit>(hits.data(), n));
      for (std::size_t k = 0; k < n; ++k) out[base + k] = terms(rays[k], hits[k], Probes == probe_mode::primary, false);
    }
  }
  bool probe_compatible(const sample_type& p, const sample_type& s) const requires(Probes != probe_mode::none) {
    return Probes == probe_mode::primary ? compatible(p, s) : p.cluster == s.cluster;
  }
  sample_type refine_probe(const sample_type&, std::uint32_t x, std::uint32_t y) const
    requires(Probes == probe_mode::refine) {
    return trace(x, y, true, false);
  }
  // The material's view_dependence(s) when it has one (frame_reuse.hpp: a colour that the view
  // cannot change by a display step is carried across frames); absent otherwise.
  float view_dependence(const sample_type& s) const requires requires(const Material& m) {
    { m.view_dependence(s) } -> std::convertible_to<float>;
  } {
    return material_.view_dependence(s);
  }
  bool agree(const sample_type& a, const sample_type& b) const { return occlusion_within(a, b, options_.tolerance); }
  bool smooth(const sample_type& a, const sample_type& b) const { return normals_within(a, b, smooth_cos_); }

  const ray_cast_options& options() const { return options_; }
  // The most rays one evaluate() traces: 1 + lights + soft-shadow points + AO rays.
  std::size_t max_rays_per_pixel() const { return 1 + options_.lights.size() + options_.soft_points.size() + hemisphere_.size(); }

 private:
  ray_cast_source(const Tracer& tracer, Camera camera, Geometry geometry, Material material,
                  std::vector<std::span<const std::uint32_t>> clusters, ray_cast_options options)
      : tracer_(&tracer), camera_(std::move(camera)), geometry_(std::move(geometry)), material_(std::move(material)),
        clusters_(std::move(clusters)), options_(std::move(options)), hemisphere_(cosine_hemisphere(options_.ao_rays)),
        smooth_cos_(options_.smooth_angle >= 3.14159265f ? -1.0f : std::cos(options_.smooth_angle)) {}

  static float pixel(std::uint32_t i) { return static_cast<float>(i) + 0.5f; }
  // Normals and texcoords that surface() reads: finite, and texcoords of the adaptors whole.
  template <class M>
  static status check_attributes(const M& m, std::uint32_t g) {
    if constexpr (requires { m.texcoords.size(); })
      if (!m.texcoords.empty() && !mesh_has_texcoords(m))
        return make_error(errc::bad_size, g, "ray_cast_source: geometry ", g, " has ", m.texcoords.size(),
                          " texcoords for ", mesh_triangle_count(m), " triangles (3 per triangle needed)");
    if constexpr (mesh_with_normals<M>)
      if (mesh_has_normals(m))
        for (std::size_t v = 0; v < mesh_vertex_count(m); ++v)
          if (!all_finite(mesh_traits<M>::normal(m, v)))
            return make_error(errc::non_finite, v, "ray_cast_source: geometry ", g, " vertex ", v, " has a non-finite normal");
    if constexpr (textured_mesh<M>)
      if (mesh_has_texcoords(m))
        for (std::size_t t = 0; t < mesh_triangle_count(m); ++t)
          for (unsigned c = 0; c < 3; ++c)
            if (!all_finite(mesh_traits<M>::texcoord(m, t, c)))
              return make_error(errc::non_finite, t, "ray_cast_source: geometry ", g, " triangle ", t, " corner ", c,
                                " has a non-finite texcoord");
    return {};
  }

  // Primary hit, then the terms asked for: hard-shadow bits, then soft shadow and AO.
  sample_type trace(std::uint32_t x, std::uint32_t y, bool hard, bool occlusion) const {
    const ray primary = camera_(pixel(x), pixel(y));
    return terms(primary, tracer_->intersect(primary), hard, occlusion);
  }
  // The same from a primary ray already traced.
  sample_type terms(const ray& primary, const hit& h, bool hard, bool occlusion) const {
    sample_type s;
    if (!h.valid() || !h.barycentric_inside()) return s;  // a hit outside its triangle: a miss
    glm::vec3 ng;
    surface(primary, h, s, ng);
    const glm::vec3 origin = s.position + options_.ray_offset * ng;
    if (hard) s.lights = light_bits(origin, ng);
    if (occlusion) s.occlusion = {ambient_occlusion(origin, ng), soft_shadow(origin, ng)};
    return s;
  }

  // The hit's position, shading normal (facing the camera), texcoords, cluster id and inv_depth;
  // ng: the geometric normal on the camera's side (secondary rays leave on that side). Rules for
  // directions that have none: a triangle whose cross product does not normalise (zero area,
  // overflow) takes the reversed primary direction as ng; an interpolated vertex normal that does
  // not normalise (zero, cancelling, overflowing) leaves ng as the shading normal.
  void surface(const ray& primary, const hit& h, sample_type& s, glm::vec3& ng) const {
    const auto& m = geometry_(h.geometry);
    using M = std::remove_cvref_t<decltype(m)>;
    const glm::uvec3 tri = mesh_triangle(m, h.triangle);
    const float u = h.barycentric.x, v = h.barycentric.y, w = 1.0f - u - v;
    const glm::vec3 p0 = mesh_position(m, tri.x), p1 = mesh_position(m, tri.y), p2 = mesh_position(m, tri.z);
    s.position = w * p0 + u * p1 + v * p2;
    s.cluster = clusters_[h.geometry][h.triangle];
    ng = unit_or(glm::cross(p1 - p0, p2 - p0), -glm::normalize(primary.direction));
    if (glm::dot(ng, primary.direction) > 0.0f) ng = -ng;
    s.normal = ng;
    if constexpr (mesh_with_normals<M>) {
      if (mesh_has_normals(m)) {
        glm::vec3 n = unit_or(w * mesh_traits<M>::normal(m, tri.x) + u * mesh_traits<M>::normal(m, tri.y) +
                                  v * mesh_traits<M>::normal(m, tri.z), ng);
        s.normal = glm::dot(n, ng) < 0.0f ? -n : n;
      }
    }
    if constexpr (textured_mesh<M>) {
      if (mesh_has_texcoords(m))
        s.texcoord = w * mesh_traits<M>::texcoord(m, h.triangle, 0) + u * mesh_traits<M>::texcoord(m, h.triangle, 1) +
                     v * mesh_traits<M>::texcoord(m, h.triangle, 2);
    }
    // Depth clamped to [1e-6, 1/FLT_MIN], NaN (an overflowing difference) counting as far: inv_depth
    // stays a normal positive float, so the upsampler's sums of inv_depth invert to finite weights.
    if (options_.view_forward != glm::vec3(0.0f)) {
      constexpr float far = 1.0f / std::numeric_limits<float>::min();
      const float depth = glm::dot(s.position - options_.view_origin, options_.view_forward);
      s.inv_depth = 1.0f / std::clamp(std::isnan(depth) ? far : depth, 1e-6f, far);
    }
  }

  // d normalised, or fallback when d has no direction a float can hold.
  static glm::vec3 unit_or(const glm::vec3& d, const glm::vec3& fallback) {
    const float len2 = glm::dot(d, d);
    return len2 > 0.0f && std::isfinite(len2) ? glm::normalize(d) : fallback;
  }

  // §4.1: bit i set when light i is in front of the surface and unoccluded.
  std::uint32_t light_bits(const glm::vec3& origin, const glm::vec3& ng) const {
    std::uint32_t bits = 0;
    for (std::size_t i = 0; i < options_.lights.size(); ++i) {
      const hard_shadow_light& l = options_.lights[i];
      const ray r = l.directional ? ray{origin, 0.0f, l.at} : ray{origin, 0.0f, l.at - origin, 0.9999f};
      if (glm::dot(ng, r.direction) > 0.0f && !tracer_->occluded(r)) bits |= 1u << i;
    }
    return bits;
  }

  // Unoccluded fraction of `rays` (first `count`), one by one or through the batch overload.
  unsigned count_unoccluded(const std::array<ray, 64>& rays, std::size_t count) const {
    unsigned visible = 0;
    if (options_.batch_rays) {
      std::array<std::uint8_t, 64> occluded{};
      trace_occluded(*tracer_, std::span<const ray>(rays.data(), count), std::span<std::uint8_t>(occluded.data(), count));
      for (std::size_t i = 0; i < count; ++i) visible += occluded[i] ? 0u : 1u;
    } else {
      for (std::size_t i = 0; i < count; ++i) visible += tracer_->occluded(rays[i]) ? 0u : 1u;
    }
    return visible;
  }

  // §4: soft-shadow ratio, the visible fraction of the area light's points (those the surface
  // and the light face each other at); 0 without points.
  float soft_shadow(const glm::vec3& origin, const glm::vec3& ng) const {
    if (options_.soft_points.empty()) return 0.0f;
    std::array<ray, 64> batch;
    std::size_t count = 0;
    unsigned visible = 0;
    for (const glm::vec3& q : options_.soft_points) {
      const glm::vec3 d = q - origin;  // tfar 1 reaches the light; stop just before it
      if (glm::dot(d, ng) <= 0.0f || glm::dot(d, options_.soft_normal) >= 0.0f) continue;
      batch[count++] = ray{origin, 0.0f, d, 0.9999f};
      if (count == batch.size()) visible += count_unoccluded(batch, std::exchange(count, 0));
    }
    visible += count_unoccluded(batch, count);
    return static_cast<float>(visible) / static_cast<float>(options_.soft_points.size());
  }

  // §4: ambient-occlusion ratio over the fixed hemisphere set in the geometric tangent frame;
  // 1 without AO rays.
  float ambient_occlusion(const glm::vec3& origin, const glm::vec3& ng) const {
    if (hemisphere_.empty()) return 1.0f;
    glm::vec3 t, b;
    detail::tangent_frame(ng, t, b);
    std::array<ray, 64> batch;
    std::size_t count = 0;
    unsigned visible = 0;
    for (const glm::vec3& d : hemisphere_) {
      batch[count++] = ray{origin, 0.0f, d.x * t + d.y * b + d.z * ng, options_.ao_radius};
      if (count == batch.size()) visible += count_unoccluded(batch, std::exchange(count, 0));
    }
    visible += count_unoccluded(batch, count);
    return static_cast<float>(visible) / static_cast<float>(hemisphere_.size());
  }

  const Tracer* tracer_;
  Camera camera_;
  Geometry geometry_;
  Material material_;
  std::vector<std::span<const std::uint32_t>> clusters_;
  ray_cast_options options_;
  std::vector<glm::vec3> hemisphere_;
  float smooth_cos_;  // cos(smooth_angle), -1 for π and above
};

}  // namespace infolerp
