// The demo's own measures and scene set-up (tests/support): the LOD stage's surface distance
// and distances against brute-force minima over every triangle.
#include <catch2/catch.hpp>

#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <vector>
#include <glm/gtc/matrix_transform.hpp>
#include "support/procedural.hpp"
#include "support/surface_distance.hpp"
#include "support/thread_pool.hpp"

using namespace infolerp;

namespace {

double brute_force_distance(const indexed_mesh& m, std::span<const std::uint32_t> idx, const glm::dvec3& p) {
  double best = std::numeric_limits<double>::max();
  for (std::size_t k = 0; k < idx.size(); k += 3) {
    const glm::dvec3 q = support::closest_on_triangle(p, glm::dvec3(m.positions[idx[k]]), glm::dvec3(m.positions[idx[k + 1]]),
                                                      glm::dvec3(m.positions[idx[k + 2]]));
    best = std::min(best, glm::length(q - p));
  }
  return best;
}

// Every other triangle of m: a surface with holes, so some closest points lie on far triangles.
std::vector<std::uint32_t> every_other(const indexed_mesh& m) {
  const auto* first = reinterpret_cast<const std::uint32_t*>(m.triangles.data());
  std::vector<std::uint32_t> half;
  for (std::size_t t = 0; t < m.triangle_count(); t += 2) half.insert(half.end(), first + 3 * t, first + 3 * t + 3);
  return half;
}

}  // namespace

TEST_CASE("surface_distance equals the brute-force closest triangle, near the surface and far from it", "[demo][lod]") {
  // A torus and a separate flat plate (a zero-volume part), one index list.
  indexed_mesh m = support::make_torus(48, 16, 1.0f, 0.3f);
  support::append(m, support::make_plane(8, 8, 3.0f), glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, -2.0f)));
  const auto* first = reinterpret_cast<const std::uint32_t*>(m.triangles.data());
  const std::vector<std::uint32_t> all(first, first + 3 * m.triangle_count());
  const std::vector<std::uint32_t> half = every_other(m);

  std::mt19937 rng(7);
  std::uniform_real_distribution<float> near(-2.5f, 2.5f), far(-40.0f, 40.0f);
  for (const auto* idx : {&all, &half}) {
    const support::surface_distance d(m.positions, *idx);
    std::size_t mismatches = 0;
    for (int i = 0; i < 400; ++i) {
      glm::dvec3 p;
      if (i < 100) {
        p = glm::dvec3(m.positions[static_cast<std::size_t>(i) * 7 % m.vertex_count()]);  // on the surface
      } else if (i < 300) {
        const float x = near(rng), y = near(rng), z = near(rng);
        p = glm::dvec3(x, y, z);
      } else {
        const float x = far(rng), y = far(rng), z = far(rng);
        p = glm::dvec3(x, y, z);
      }
      if (d(p) != brute_force_distance(m, *idx, p)) ++mismatches;
    }
    CHECK(mismatches == 0);
  }
  const support::surface_distance none(m.positions, {});
  CHECK(none(glm::dvec3(0.0)) == std::numeric_limits<double>::max());
}

TEST_CASE("measure's shortcuts give the distances of the definition, for any executor", "[demo][lod]") {
  const indexed_mesh m = support::make_torus(32, 12, 1.0f, 0.3f);
  const auto* first = reinterpret_cast<const std::uint32_t*>(m.triangles.data());
  const std::span<const std::uint32_t> all(first, 3 * m.triangle_count());
  // Half the triangles kept, plus three that are not the mesh's (across the ring and the tube).
  std::vector<std::uint32_t> simplified = every_other(m);
  simplified.insert(simplified.end(), {0, 100, 200, 5, 150, 300, 7, 8, 250});
  std::vector<double> saliency(m.vertex_count());
  for (std::size_t v = 0; v < saliency.size(); ++v) saliency[v] = 0.5 + static_cast<double>(v % 7);

  // The definition, every point searched by brute force.
  double num = 0.0, den = 0.0, hausdorff = 0.0;
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    const double d = brute_force_distance(m, simplified, glm::dvec3(m.positions[v]));
    num += saliency[v] * d, den += saliency[v];
    hausdorff = std::max(hausdorff, d);
  }
  for (std::size_t k = 0; k < simplified.size(); k += 3) {
    const glm::dvec3 a(m.positions[simplified[k]]), b(m.positions[simplified[k + 1]]), c(m.positions[simplified[k + 2]]);
    for (const glm::dvec3& p : {a, b, c, 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a), (a + b + c) / 3.0})
      hausdorff = std::max(hausdorff, brute_force_distance(m, all, p));
  }
  REQUIRE(hausdorff > 0.1);  // the added triangles cut through the torus's hole

  const support::distances serial = support::measure(m, saliency, simplified);
  CHECK(serial.weighted == Approx(num / den).epsilon(1e-12));
  CHECK(serial.hausdorff == Approx(hausdorff).epsilon(1e-12));
  const support::distances pooled = support::measure(m, saliency, simplified, support::thread_pool_executor(3));
  CHECK(pooled.weighted == serial.weighted);
  CHECK(pooled.hausdorff == serial.hausdorff);
  // The mesh itself: every vertex kept, every triangle its own.
  const support::distances same = support::measure(m, saliency, all);
  CHECK(same.weighted == 0.0);
  CHECK(same.hausdorff == 0.0);
}
