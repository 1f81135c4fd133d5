#pragma once
// A brute-force tracer for tests (O(T) per ray, Möller–Trumbore in double): the reference the
// visibility channel is tested with on small analytic scenes.
#include <cmath>
#include <cstdint>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/core/tracer.hpp"
#include "infolerp/mesh/adaptors.hpp"

namespace infolerp::test {

class brute_tracer {
 public:
  explicit brute_tracer(const indexed_mesh& m) : m_(m) {}
  bool occluded(const ray& r) const { return closest(r, true).valid(); }
  hit intersect(const ray& r) const { return closest(r, false); }

 private:
  hit closest(const ray& r, bool any) const {
    hit best;
    const glm::dvec3 o(r.origin), d(r.direction);
    for (std::uint32_t t = 0; t < m_.triangles.size(); ++t) {
      const glm::dvec3 p0(m_.positions[m_.triangles[t].x]), p1(m_.positions[m_.triangles[t].y]),
          p2(m_.positions[m_.triangles[t].z]);
      const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, pv = glm::cross(d, e2);
      const double det = glm::dot(e1, pv);
      if (std::abs(det) < 1e-300) continue;
      const double inv = 1.0 / det;
      const glm::dvec3 tv = o - p0;
      const double u = glm::dot(tv, pv) * inv;
      if (u < 0.0 || u > 1.0) continue;
      const glm::dvec3 qv = glm::cross(tv, e1);
      const double v = glm::dot(d, qv) * inv;
      if (v < 0.0 || u + v > 1.0) continue;
      const double dist = glm::dot(e2, qv) * inv;
      if (dist < double(r.tnear) || dist > double(r.tfar) || dist >= double(best.distance)) continue;
      best.geometry = 0;
      best.triangle = t;
      best.barycentric = {float(u), float(v)};
      best.distance = float(dist);
      if (any) return best;
    }
    return best;
  }
  const indexed_mesh& m_;
};

}  // namespace infolerp::test
