#pragma once
// A pinhole_camera's projection from glm's own view and projection matrices (glm::lookAt,
// glm::perspective, OpenGL clip space, NDC to pixels with y down), in double: the tests'
// reference for pinhole_frame's rays and projected areas, independent of its formulas.
#include <cmath>
#include <limits>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <glm/trigonometric.hpp>
#include "infolerp/refine/pinhole_camera.hpp"

namespace infolerp::support {

// Continuous pixel coordinates (x, y) of point p and its clip-space w (> 0: in front of the eye).
inline glm::dvec3 glm_pixel(const pinhole_camera& c, glm::dvec3 p) {
  const glm::dmat4 vp = glm::perspective(glm::radians(double(c.vertical_fov_degrees)), double(c.width) / double(c.height), 1e-3, 1e3) *
                        glm::lookAt(glm::dvec3(c.eye), glm::dvec3(c.target), glm::dvec3(c.up));
  const glm::dvec4 h = vp * glm::dvec4(p, 1.0);
  return {(h.x / h.w + 1.0) * 0.5 * c.width, (1.0 - h.y / h.w) * 0.5 * c.height, h.w};
}

// Triangle (a, b, d)'s area in pixels; +infinity when a corner is not in front of the eye.
inline double glm_projected_area(const pinhole_camera& c, glm::vec3 a, glm::vec3 b, glm::vec3 d) {
  glm::dvec3 q[3];
  const glm::vec3 p[3] = {a, b, d};
  for (int i = 0; i < 3; ++i)
    if (q[i] = glm_pixel(c, glm::dvec3(p[i])); !(q[i].z > 0.0)) return std::numeric_limits<double>::infinity();
  return 0.5 * std::abs((q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[1].y - q[0].y) * (q[2].x - q[0].x));
}

}  // namespace infolerp::support
