// examples/embree_tracer.hpp at work: the adaptor's hits are checked against a brute-force
// intersection of every triangle, its batched occlusion against its single rays, and the
// visibility channel clusters a scene through it. Exits non-zero if any check fails.
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>
#include "embree_tracer.hpp"
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/mesh/adaptors.hpp"

namespace {

// A ground quad with a box standing on it (the box shades part of the ground).
void make_scene(std::vector<glm::vec3>& p, std::vector<glm::uvec3>& t) {
  p = {{-4, -4, 0}, {4, -4, 0}, {4, 4, 0}, {-4, 4, 0}};
  t = {{0, 1, 2}, {0, 2, 3}};
  const glm::vec3 lo{-1, -1, 0.01f}, hi{1, 1, 2};
  for (int i = 0; i < 8; ++i) p.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
  const unsigned quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    t.push_back(glm::uvec3(q[0], q[1], q[2]) + 4u);
    t.push_back(glm::uvec3(q[0], q[2], q[3]) + 4u);
  }
}

// Closest hit over every triangle (Möller–Trumbore in double): the reference.
infolerp::hit brute_intersect(const std::vector<glm::vec3>& p, const std::vector<glm::uvec3>& tris, const infolerp::ray& r) {
  infolerp::hit best;
  const glm::dvec3 o(r.origin), d(r.direction);
  for (std::uint32_t i = 0; i < tris.size(); ++i) {
    const glm::dvec3 a(p[tris[i].x]), e1 = glm::dvec3(p[tris[i].y]) - a, e2 = glm::dvec3(p[tris[i].z]) - a;
    const glm::dvec3 q = glm::cross(d, e2);
    const double det = glm::dot(e1, q);
    if (std::abs(det) < 1e-15) continue;
    const glm::dvec3 s = o - a;
    const glm::dvec3 rr = glm::cross(s, e1);
    const double u = glm::dot(s, q) / det, w = glm::dot(d, rr) / det, dist = glm::dot(e2, rr) / det;
    if (u < 0 || w < 0 || u + w > 1 || dist < r.tnear || dist > r.tfar || dist >= best.distance) continue;
    best = {0, i, {static_cast<float>(u), static_cast<float>(w)}, static_cast<float>(dist)};
  }
  return best;
}

}  // namespace

int main() {
  std::vector<glm::vec3> positions;
  std::vector<glm::uvec3> triangles;
  make_scene(positions, triangles);
  const infolerp::mesh_view mesh{.positions = positions, .triangles = triangles};
  RTCDevice device = rtcNewDevice(nullptr);
  int failures = 0;
  {
    auto tracer = example::embree_tracer::create(device, mesh);
    if (!tracer) {
      std::printf("embree_tracer: %s\n", tracer.error().message().c_str());
      return 1;
    }
    // Rays from above the scene towards random ground points: hits on the box's top and sides
    // and on the ground, some rays stopped short (tfar) to exercise occlusion misses too.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-3.5f, 3.5f), len(0.2f, 1.2f);
    std::vector<infolerp::ray> rays;
    for (int i = 0; i < 2000; ++i) {
      const glm::vec3 o{u(rng), u(rng), 5.0f}, target{u(rng), u(rng), 0.0f};
      rays.push_back({o, 0.0f, target - o, i % 4 == 0 ? len(rng) : INFINITY});
    }
    std::vector<std::uint8_t> batch(rays.size());
    tracer->occluded(rays, batch);
    int disagree = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const infolerp::hit h = tracer->intersect(rays[i]), ref = brute_intersect(positions, triangles, rays[i]);
      const bool occ = tracer->occluded(rays[i]);
      if (batch[i] != (occ ? 1 : 0)) ++failures;  // batched and single occlusion must agree exactly
      if (h.valid() != ref.valid() || occ != ref.valid()) {
        ++disagree;  // a ray through an edge may go either way; allowed rarely, below
        continue;
      }
      if (!ref.valid()) continue;
      const bool same_distance = std::abs(h.distance - ref.distance) <= 1e-4f * ref.distance;
      const bool same_point = h.triangle != ref.triangle ||  // across a shared edge: distance only
                              (std::abs(h.barycentric.x - ref.barycentric.x) < 1e-4f &&
                               std::abs(h.barycentric.y - ref.barycentric.y) < 1e-4f);
      if (!same_distance || !same_point) ++failures;
    }
    if (disagree > 2) failures += disagree;
    std::printf("embree_tracer: %zu rays against brute force, %d failed, %d edge disagreements\n", rays.size(),
                failures, disagree);

    // The visibility channel through the adaptor, then orientation: at least the box's 5 seen
    // faces and the ground.
    infolerp::serial_executor exec;
    auto c = infolerp::cluster_mesh(mesh, *tracer, exec, infolerp::visibility_channel{.threshold = 0.3, .viewpoints = 32},
                                    infolerp::orientation_channel{.threshold = 0.05});
    if (!c) {
      std::printf("cluster_mesh: %s\n", c.error().message().c_str());
      ++failures;
    } else {
      std::printf("cluster_mesh through Embree: %u clusters\n", c->cluster_count);
      if (c->cluster_count < 6) ++failures;
    }
  }
  rtcReleaseDevice(device);
  return failures == 0 ? 0 : 1;
}
