#pragma once
// The clustering paper's own occlusion measurement (§3.1.1): OR(t, v) = a_v(t) / u_v(t), with
// u_v(t) the unoccluded projected area of t seen from v, computed analytically, and a_v(t) its
// visible projected area, measured per viewpoint by one image of primary rays (the CPU
// counterpart of the paper's rasterisation) traced through the tracer's batch call.
//
// Projected area is solid angle (projection onto the unit sphere around v), so OR does not depend
// on where the camera looks: u_v(t) by Van Oosterom and Strackee's formula, a_v(t) as the sum of
// the solid angles of the pixels whose primary ray first hits t (pixel (x, y) of a pinhole image
// at focal distance 1 subtends dA / (1 + x² + y²)^{3/2}). OR = min(1, a/u).
// The camera at v looks at the mesh's bounding-box centre; its square field of view is the
// tightest that holds every vertex (half-angle at most 80°), so the mesh fills the image.
// Triangles the image cannot measure fall back to the n² sample rays of the ray method (OR = free
// samples / n², as visibility_channel counts them):
//   - a corner outside the field of view or behind the camera,
//   - a projected area under `min_pixels` pixels (the pixel count of a triangle covering p pixels
//     errs by about its perimeter in pixels, so small triangles are noisy).
// Back-facing and degenerate triangles get OR = 0 (as with sample rays).
// The tracer's scene must hold the mesh as geometry 0; hits on other geometry occlude.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/mesh/geometry.hpp"

namespace infolerp {

// Solid angle of triangle (p0, p1, p2) seen from e (Van Oosterom and Strackee, IEEE Trans.
// Biomed. Eng. 30(2), 1983): tan(Ω/2) = |a·(b×c)| / (abc + (a·b)c + (a·c)b + (b·c)a), a, b, c
// the corners relative to e. In [0, 2π]. O(1).
inline double triangle_solid_angle(glm::dvec3 e, const triangle_corners& t) {
  const glm::dvec3 a = t.p0 - e, b = t.p1 - e, c = t.p2 - e;
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const double num = std::abs(glm::dot(a, glm::cross(b, c)));
  const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  return 2.0 * std::atan2(num, den);
}

// A pinhole camera at `eye` looking at `target` with a square field of view, half-width `half` on
// the image plane at distance 1, the tightest holding `points` (at most tan 80°). O(points).
struct viewpoint_camera {
  glm::dvec3 eye, forward, right, up;
  double half = 1.0;
  static constexpr double max_half = 5.6712818196177;  // tan 80°

  static viewpoint_camera looking_at(glm::dvec3 eye, glm::dvec3 target, std::span<const glm::dvec3> points) {
    viewpoint_camera c{eye, glm::normalize(target - eye), {}, {}, 0.0};
    const glm::dvec3 helper = std::abs(c.forward.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
    c.right = glm::normalize(glm::cross(c.forward, helper));
    c.up = glm::cross(c.right, c.forward);
    for (const glm::dvec3& q : points) {
      const glm::dvec3 p = c.project(q);
      c.half = p.z > 0.0 ? std::max({c.half, std::abs(p.x), std::abs(p.y)}) : max_half;
      if (c.half >= max_half) break;
    }
    c.half = std::min(c.half, max_half) * (1.0 + 1e-6);
    return c;
  }
  // (x, y) on the image plane and depth along forward (x, y meaningless when depth <= 0).
  glm::dvec3 project(glm::dvec3 p) const {
    const glm::dvec3 q = p - eye;
    const double z = glm::dot(q, forward);
    return {glm::dot(q, right) / z, glm::dot(q, up) / z, z};
  }
};

namespace detail {

// OR(t, v) of every triangle of m toward one viewpoint `eye`, written as round(OR · scale) to
// column[t · stride] (scale <= 255). `points`: m's vertices. `samples`, `offset`: the sample
// pattern of the fallback rays.
// Complexity: R² primary rays + n² occlusion rays per fallback triangle + O(T + V).
// Allocation: T doubles and T bytes, and batches of at most 4096 rays.
template <class M, class T>
void image_occlusion_ratios(const M& m, const T& tracer, glm::dvec3 eye, const bounding_box& box,
                            std::span<const glm::dvec3> points, std::uint32_t resolution,
                            double min_pixels, std::span<const glm::dvec2> samples, double offset, double scale,
                            std::uint8_t* column, std::size_t stride) {
  const std::size_t nt = mesh_triangle_count(m);
  const viewpoint_camera cam = viewpoint_camera::looking_at(eye, box.center(), points);
  // a_v(t): the solid angle of the pixels whose first hit is t, image traced in 16×16 tiles.
  std::vector<double> seen(nt, 0.0);
  const double pixel = 2.0 * cam.half / resolution;
  std::vector<ray> rays;
  std::vector<hit> hits;
  std::vector<double> weights;
  for (std::uint32_t ty = 0; ty < resolution; ty += 16)
    for (std::uint32_t tx = 0; tx < resolution; tx += 16) {
      rays.clear();
      weights.clear();
      for (std::uint32_t j = ty; j < std::min(resolution, ty + 16); ++j)
        for (std::uint32_t i = tx; i < std::min(resolution, tx + 16); ++i) {
          const double x = -cam.half + (i + 0.5) * pixel, y = -cam.half + (j + 0.5) * pixel;
          const glm::dvec3 d = cam.forward + x * cam.right + y * cam.up;
          rays.push_back(ray{glm::vec3(eye), 0.0f, glm::vec3(d)});
          const double r2 = 1.0 + x * x + y * y;
          weights.push_back(pixel * pixel / (r2 * std::sqrt(r2)));
        }
      hits.resize(rays.size());
      trace_intersect(tracer, std::span<const ray>(rays), std::span<hit>(hits));
      for (std::size_t r = 0; r < rays.size(); ++r)
        if (hits[r].valid() && hits[r].geometry == 0 && hits[r].triangle < nt) seen[hits[r].triangle] += weights[r];
    }
  // Per triangle: back-facing 0, measured by the image, or by its sample rays.
  std::vector<std::uint8_t> free_count(nt, 0);
  std::vector<std::uint32_t> fallback, slots;
  rays.clear();
  std::vector<std::uint8_t> occluded;
  auto flush = [&] {
    occluded.resize(rays.size());
    trace_occluded(tracer, std::span<const ray>(rays), std::span<std::uint8_t>(occluded));
    for (std::size_t r = 0; r < rays.size(); ++r) if (!occluded[r]) ++free_count[slots[r]];
    rays.clear();
    slots.clear();
  };
  const double pixels_per_unit = 1.0 / (pixel * pixel);
  for (std::size_t t = 0; t < nt; ++t) {
    const triangle_corners c = corners(m, t);
    const glm::dvec3 n(triangle_normal(c));
    std::uint8_t& out = column[t * stride];
    out = 0;
    if (n == glm::dvec3(0.0) || !(glm::dot(n, eye - c.p0) > 0.0)) continue;  // degenerate or back-facing
    const glm::dvec3 q0 = cam.project(c.p0), q1 = cam.project(c.p1), q2 = cam.project(c.p2);
    auto inside = [&](const glm::dvec3& q) { return q.z > 0.0 && std::abs(q.x) <= cam.half && std::abs(q.y) <= cam.half; };
    const glm::dvec2 e1(q1.x - q0.x, q1.y - q0.y), e2(q2.x - q0.x, q2.y - q0.y);
    const double pixels = 0.5 * std::abs(e1.x * e2.y - e1.y * e2.x) * pixels_per_unit;
    const double u = triangle_solid_angle(eye, c);
    if (inside(q0) && inside(q1) && inside(q2) && pixels >= min_pixels && u > 0.0) {
      out = static_cast<std::uint8_t>(std::lround(std::min(1.0, seen[t] / u) * scale));
      continue;
    }
    fallback.push_back(static_cast<std::uint32_t>(t));
    for (const glm::dvec2& w : samples) {
      const glm::dvec3 x = (1.0 - w.x - w.y) * c.p0 + w.x * c.p1 + w.y * c.p2 + offset * n;
      const glm::dvec3 d = eye - x;
      if (glm::dot(n, d) <= 0.0) continue;  // back-facing sample
      rays.push_back(ray{glm::vec3(x), 0.0f, glm::vec3(d), 1.0f});
      slots.push_back(static_cast<std::uint32_t>(t));
    }
    if (rays.size() >= 4096) flush();
  }
  flush();
  const double per_sample = scale / static_cast<double>(samples.size());
  for (std::uint32_t t : fallback)
    column[std::size_t{t} * stride] = static_cast<std::uint8_t>(std::lround(free_count[t] * per_sample));
}

}  // namespace detail
}  // namespace infolerp
