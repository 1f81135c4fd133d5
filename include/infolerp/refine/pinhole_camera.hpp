#pragma once
// A pinhole camera for the refinement driver (progressive_driver.hpp) and its criteria: the
// description an engine fills in (pinhole_camera, an aggregate) and its frame computed once
// (pinhole_frame: orthonormal basis, tan of the half field of view, aspect), which makes a
// primary ray in a handful of flops and projects world points back to pixel coordinates, the
// projection NLD_IS's projected-area rule reads (criteria.hpp).
// Value types, no cache, no allocation; a frame is O(1) to make (one tan, two normalisations).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/tracer.hpp"
#include "infolerp/core/unit_vector.hpp"

namespace infolerp {

// A pinhole camera's frame, computed once: pixel (x, y), y down, gets the ray through its
// centre. Make it with pinhole_camera::frame().
struct pinhole_frame {
  glm::vec3 eye{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f}, right{1.0f, 0.0f, 0.0f}, up{0.0f, 1.0f, 0.0f};  // orthonormal
  float tan_half_fov = 0.0f;  // tan(vertical_fov / 2)
  float aspect = 1.0f;        // width / height
  std::uint32_t width = 0, height = 0;

  // The same arithmetic, in the same order, as pinhole_camera's formula evaluated per ray, so a
  // ray has the same bits. O(1).
  [[nodiscard]] ray primary_ray(std::uint32_t x, std::uint32_t y) const {
    const float sx = (2.0f * (float(x) + 0.5f) / float(width) - 1.0f) * tan_half_fov * aspect;
    const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(height)) * tan_half_fov;
    ray out;
    out.origin = eye;
    out.direction = glm::normalize(forward + sx * right + sy * up);
    return out;
  }

  // Point p in continuous pixel coordinates (x right, y down; pixel (i, j)'s centre is
  // (i + 0.5, j + 0.5)) and its depth along the view direction; x and y are meaningful only
  // for depth > 0. In double: the projected area of a tiny triangle far from the origin keeps
  // its digits. O(1).
  [[nodiscard]] glm::dvec3 project(glm::vec3 p) const {
    const glm::dvec3 d = glm::dvec3(p) - glm::dvec3(eye);
    const double depth = glm::dot(d, glm::dvec3(forward));
    const double sx = glm::dot(d, glm::dvec3(right)) / depth, sy = glm::dot(d, glm::dvec3(up)) / depth;
    const double h = double(tan_half_fov);
    return {(sx / (h * double(aspect)) + 1.0) * 0.5 * double(width), (1.0 - sy / h) * 0.5 * double(height), depth};
  }

  // The area, in pixels, of triangle (a, b, c) projected onto the image plane (not clipped to
  // the image: a triangle partly outside counts whole); +infinity when a corner is not in front
  // of the eye (it spans the view), 0 for a degenerate one. O(1).
  [[nodiscard]] double projected_area(glm::vec3 a, glm::vec3 b, glm::vec3 c) const {
    const glm::dvec3 pa = project(a), pb = project(b), pc = project(c);
    if (!(pa.z > 0.0 && pb.z > 0.0 && pc.z > 0.0)) return std::numeric_limits<double>::infinity();
    const double twice = (pb.x - pa.x) * (pc.y - pa.y) - (pb.y - pa.y) * (pc.x - pa.x);
    return 0.5 * std::abs(twice);
  }
};

// A pinhole camera as an engine describes it: pixel (x, y), y down, gets the ray through its
// centre. frame() computes the basis once; primary_ray() here recomputes it per call (for a
// few rays; trace a whole image through frame(), as progressive_refiner does).
struct pinhole_camera {
  glm::vec3 eye{0.0f, 0.0f, 1.0f};     // camera position
  glm::vec3 target{0.0f};              // looked-at point
  glm::vec3 up{0.0f, 1.0f, 0.0f};      // world up (not parallel to target - eye)
  float vertical_fov_degrees = 60.0f;  // full vertical field of view
  std::uint32_t width = 320;           // image width in pixels
  std::uint32_t height = 240;          // image height in pixels

  // The unit view direction; (0,0,0) when eye and target coincide or target - eye overflows.
  [[nodiscard]] static glm::vec3 forward(const glm::vec3& eye, const glm::vec3& target) { return unit_or_zero(target - eye); }

  // The frame: one tan and the basis. O(1).
  [[nodiscard]] pinhole_frame frame() const {
    pinhole_frame fr;
    fr.eye = eye;
    fr.forward = forward(eye, target);
    fr.right = unit_or_zero(glm::cross(fr.forward, up));
    fr.up = glm::cross(fr.right, fr.forward);
    fr.tan_half_fov = std::tan(glm::radians(vertical_fov_degrees) * 0.5f);
    fr.aspect = float(width) / float(height);
    fr.width = width;
    fr.height = height;
    return fr;
  }
  [[nodiscard]] ray primary_ray(std::uint32_t x, std::uint32_t y) const { return frame().primary_ray(x, y); }
};

}  // namespace infolerp
