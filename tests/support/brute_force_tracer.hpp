#pragma once
// Möller–Trumbore over every triangle of an indexed_mesh: the reference tracer that fast tracers
// must agree with, and a tracer for tests that must not depend on Embree (e.g. under
// ThreadSanitizer, where Embree's uninstrumented threads would be reported).
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include "infolerp/core/tracer.hpp"
#include "infolerp/mesh/adaptors.hpp"

namespace infolerp::support {

struct brute_force_tracer {
  const indexed_mesh* m;
  hit intersect(const ray& r) const {
    hit best;
    for (std::uint32_t t = 0; t < m->triangles.size(); ++t) {
      const glm::vec3 a = m->positions[m->triangles[t].x], b = m->positions[m->triangles[t].y],
                      c = m->positions[m->triangles[t].z];
      const glm::vec3 e1 = b - a, e2 = c - a, pv = glm::cross(r.direction, e2);
      const float det = glm::dot(e1, pv);
      if (std::abs(det) < 1e-12f) continue;
      const glm::vec3 tv = r.origin - a;
      const float u = glm::dot(tv, pv) / det;
      const glm::vec3 qv = glm::cross(tv, e1);
      const float v = glm::dot(r.direction, qv) / det;
      const float d = glm::dot(e2, qv) / det;
      if (u < 0.0f || v < 0.0f || u + v > 1.0f || d < r.tnear || d > r.tfar || d >= best.distance) continue;
      best = {0, t, {u, v}, d};
    }
    return best;
  }
  bool occluded(const ray& r) const { return intersect(r).valid(); }
};

}  // namespace infolerp::support
