// The Embree adaptor (tests/support/embree_tracer.hpp) against a brute-force double-precision
// Möller–Trumbore reference on CGAL's meshes, and its 16-ray packets against single rays.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/mesh/geometry.hpp"
#include "support/embree_tracer.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"

using infolerp::hit;
using infolerp::indexed_mesh;
using infolerp::ray;
namespace support = infolerp::support;

namespace {

// Uniform float in [0, 1) from the generator's bits (portable, unlike std distributions).
float uniform(std::mt19937& g) { return static_cast<float>(g() >> 8) * 0x1p-24f; }

glm::vec3 random_unit(std::mt19937& g) {
  const float z = 2.0f * uniform(g) - 1.0f, phi = 6.2831853f * uniform(g);
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Half the rays start outside the bounding sphere and aim at a random point of the box, half
// start inside the box in a random direction; every fourth ray gets a finite tfar.
std::vector<ray> random_rays(const indexed_mesh& m, std::size_t count, std::uint32_t seed) {
  std::mt19937 g(seed);
  const auto box = infolerp::mesh_bounds(m);
  const glm::vec3 lo(box.lo), hi(box.hi), c(box.center());
  const float diag = static_cast<float>(box.diagonal());
  auto in_box = [&] { return lo + (hi - lo) * glm::vec3(uniform(g), uniform(g), uniform(g)); };
  std::vector<ray> rays(count);
  for (std::size_t i = 0; i < count; ++i) {
    ray& r = rays[i];
    if (i % 2 == 0) {
      r.origin = c + diag * random_unit(g);
      r.direction = glm::normalize(in_box() - r.origin);
    } else {
      r.origin = in_box();
      r.direction = random_unit(g);
    }
    if (i % 4 == 3) r.tfar = diag * uniform(g);
  }
  return rays;
}

// Closest hit by brute force in double, with what is needed to tell clear cases from ties.
struct reference_hit {
  std::uint32_t triangle = infolerp::invalid_id;
  double t = std::numeric_limits<double>::infinity();
  double margin = -std::numeric_limits<double>::infinity();  // min barycentric of the closest hit
  double second_t = std::numeric_limits<double>::infinity(); // next hit along the ray
  double near_miss = -std::numeric_limits<double>::infinity();  // max min-barycentric of any plane crossing in range
};

struct mt_result {
  double t, u, v;
  bool parallel;
};

mt_result moller_trumbore(const ray& r, const indexed_mesh& m, std::size_t tri) {
  const glm::dvec3 o(r.origin), d(r.direction);
  const glm::uvec3 idx = m.triangles[tri];
  const glm::dvec3 p0(m.positions[idx.x]), p1(m.positions[idx.y]), p2(m.positions[idx.z]);
  const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, pv = glm::cross(d, e2);
  const double det = glm::dot(e1, pv);
  if (det == 0.0) return {0, 0, 0, true};
  const double inv = 1.0 / det;
  const glm::dvec3 tv = o - p0, qv = glm::cross(tv, e1);
  return {glm::dot(e2, qv) * inv, glm::dot(tv, pv) * inv, glm::dot(d, qv) * inv, false};
}

reference_hit brute_force(const ray& r, const indexed_mesh& m) {
  reference_hit best;
  for (std::size_t tri = 0; tri < m.triangles.size(); ++tri) {
    const mt_result x = moller_trumbore(r, m, tri);
    if (x.parallel || !(x.t >= r.tnear && x.t <= r.tfar)) continue;
    const double margin = std::min({x.u, x.v, 1.0 - x.u - x.v});
    best.near_miss = std::max(best.near_miss, margin);
    if (margin < 0.0) continue;
    if (x.t < best.t) {
      best.second_t = best.t;
      best.t = x.t;
      best.triangle = static_cast<std::uint32_t>(tri);
      best.margin = margin;
    } else {
      best.second_t = std::min(best.second_t, x.t);
    }
  }
  return best;
}

support::embree_scene make_scene(const support::embree_device& device, const indexed_mesh& m) {
  support::embree_scene scene{device};
  auto id = scene.add_mesh(m);
  REQUIRE(id.ok());
  REQUIRE(*id == 0u);
  REQUIRE(scene.commit().ok());
  return scene;
}

}  // namespace

TEST_CASE("embree tracer matches brute-force double Moller-Trumbore on CGAL meshes", "[embree]") {
  support::enable_flush_to_zero();
  support::embree_device device;
  for (const char* name : {"bunny00", "armadillo", "fandisk"}) {
    auto loaded = support::load_mesh(support::cgal_mesh(name));
    REQUIRE(loaded.ok());
    const indexed_mesh& m = *loaded;
    const auto scene = make_scene(device, m);
    const double diag = infolerp::mesh_bounds(m).diagonal();
    const auto rays = random_rays(m, 1000, 12345);

    std::size_t clear = 0, ambiguous = 0, hits = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const ray& r = rays[i];
      const reference_hit ref = brute_force(r, m);
      const hit h = scene.intersect(r);
      INFO(name << " ray " << i);
      // Clear cases: the closest hit is well inside its triangle and well ahead of the next
      // one, or no plane crossing comes near any triangle. Ties at edges are judged below.
      const bool clear_hit = ref.triangle != infolerp::invalid_id && ref.margin > 1e-4 &&
                             ref.second_t - ref.t > 1e-4 * diag;
      const bool clear_miss = ref.triangle == infolerp::invalid_id && ref.near_miss < -1e-4;
      if (clear_hit || clear_miss) {
        ++clear;
        REQUIRE(h.valid() == clear_hit);
        if (!clear_hit) continue;
        ++hits;
        CHECK(h.geometry == 0u);
        REQUIRE(h.triangle == ref.triangle);
        CHECK(std::abs(double(h.distance) - ref.t) <= 1e-5 * diag);
        // The barycentrics (Embree convention) reconstruct the hit point.
        const glm::uvec3 idx = m.triangles[h.triangle];
        const double u = h.barycentric.x, v = h.barycentric.y;
        const glm::dvec3 p = (1.0 - u - v) * glm::dvec3(m.positions[idx.x]) + u * glm::dvec3(m.positions[idx.y]) +
                             v * glm::dvec3(m.positions[idx.z]);
        const glm::dvec3 q = glm::dvec3(r.origin) + double(h.distance) * glm::dvec3(r.direction);
        CHECK(glm::length(p - q) <= 1e-5 * diag);
      } else {
        ++ambiguous;
        // Near an edge or a near-coincident second surface: Embree may pick either side, but
        // what it reports must be a real crossing at the reference distance.
        if (h.valid()) {
          const mt_result x = moller_trumbore(r, m, h.triangle);
          REQUIRE_FALSE(x.parallel);
          CHECK(std::min({x.u, x.v, 1.0 - x.u - x.v}) >= -1e-4);
          if (ref.triangle != infolerp::invalid_id) CHECK(std::abs(x.t - ref.t) <= 1e-4 * diag);
        }
      }
    }
    INFO(name << ": " << clear << " clear rays (" << hits << " hits), " << ambiguous << " ambiguous");
    CHECK(ambiguous <= rays.size() / 50);
    CHECK(hits >= rays.size() / 4);  // the rays really exercise the mesh
  }
}

TEST_CASE("16-ray packets agree with single rays bit for bit, tails included", "[embree]") {
  support::enable_flush_to_zero();
  support::embree_device device;
  auto loaded = support::load_mesh(support::cgal_mesh("bunny00"));
  REQUIRE(loaded.ok());
  const auto scene = make_scene(device, *loaded);
  const auto all = random_rays(*loaded, 1000, 777);
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{15}, std::size_t{16}, std::size_t{17},
                        std::size_t{33}, std::size_t{1000}}) {
    const std::span<const ray> rays(all.data(), n);
    std::vector<hit> hits(n);
    std::vector<std::uint8_t> occ(n, 2);
    scene.intersect(rays, hits);
    scene.occluded(rays, occ);
    for (std::size_t i = 0; i < n; ++i) {
      INFO("batch of " << n << ", ray " << i);
      const hit single = scene.intersect(rays[i]);
      REQUIRE(hits[i].geometry == single.geometry);
      REQUIRE(hits[i].triangle == single.triangle);
      REQUIRE(hits[i].barycentric.x == single.barycentric.x);
      REQUIRE(hits[i].barycentric.y == single.barycentric.y);
      REQUIRE(hits[i].distance == single.distance);
      REQUIRE(int(occ[i]) == int(scene.occluded(rays[i])));
    }
  }
}

TEST_CASE("occluded agrees with intersect", "[embree]") {
  support::enable_flush_to_zero();
  support::embree_device device;
  for (const char* name : {"fandisk", "armadillo"}) {
    auto loaded = support::load_mesh(support::cgal_mesh(name));
    REQUIRE(loaded.ok());
    const auto scene = make_scene(device, *loaded);
    std::size_t occluded = 0;
    for (const ray& r : random_rays(*loaded, 4000, 99)) {
      const bool o = scene.occluded(r);
      REQUIRE(o == scene.intersect(r).valid());
      occluded += o ? 1 : 0;
    }
    CHECK(occluded > 1000);
    CHECK(occluded < 4000);
  }
}

TEST_CASE("geometry ids follow the order meshes were added", "[embree]") {
  support::embree_device device;
  support::embree_scene scene{device};
  auto a = scene.add_mesh(support::make_box({-1, -1, -1}, {1, 1, 1}));
  auto b = scene.add_mesh(support::make_icosphere(2, 0.5f));
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  CHECK(*a == 0u);
  CHECK(*b == 1u);
  CHECK(scene.geometry_count() == 2u);
  REQUIRE(scene.commit().ok());
  const hit h = scene.intersect(ray{{0, 0, 10}, 0.0f, {0, 0, -1}});
  CHECK(h.geometry == 0u);  // the box (top at z = 1) is in front of the sphere (top at 0.5)
  CHECK(h.distance == Approx(9.0f));
  const hit inner = scene.intersect(ray{{0, 0, 0}, 0.0f, {0, 0, 1}});
  CHECK(inner.geometry == 1u);
  CHECK(inner.distance == Approx(0.5f).epsilon(0.02));
  CHECK_FALSE(scene.occluded(ray{{0, 0, 10}, 0.0f, {0, 0, 1}}));
  CHECK_FALSE(scene.occluded(ray{{0, 0, 10}, 0.0f, {0, 0, -1}, 8.5f}));  // tfar short of the box
  CHECK(scene.occluded(ray{{0, 0, 10}, 0.0f, {0, 0, -1}, 9.5f}));
}

TEST_CASE("bad inputs to the embree scene are reported, not crashed on", "[embree]") {
  support::embree_device device;
  support::embree_scene scene{device};
  auto empty = scene.add_mesh(indexed_mesh{});
  REQUIRE_FALSE(empty.ok());
  CHECK(empty.error().code() == infolerp::errc::empty_input);

  indexed_mesh bad = support::make_box({0, 0, 0}, {1, 1, 1});
  bad.triangles[5].y = 8;
  auto out_of_range = scene.add_mesh(bad);
  REQUIRE_FALSE(out_of_range.ok());
  CHECK(out_of_range.error().code() == infolerp::errc::index_out_of_range);
  CHECK(out_of_range.error().element() == 5u);
  CHECK(scene.geometry_count() == 0u);

  // A scene left empty commits, and every ray misses.
  REQUIRE(scene.commit().ok());
  CHECK_FALSE(scene.intersect(ray{}).valid());
  CHECK_FALSE(scene.occluded(ray{}));
  std::vector<ray> rays(20);
  std::vector<hit> hits(20);
  std::vector<std::uint8_t> occ(20, 1);
  scene.intersect(rays, hits);
  scene.occluded(rays, occ);
  CHECK(std::none_of(hits.begin(), hits.end(), [](const hit& h) { return h.valid(); }));
  CHECK(std::none_of(occ.begin(), occ.end(), [](std::uint8_t o) { return o != 0; }));

  CHECK_FALSE(scene.add_mesh(support::make_box({0, 0, 0}, {1, 1, 1})).ok());  // after commit
  CHECK_FALSE(scene.commit().ok());                                            // twice

  // Moving keeps the scene usable and empties the source.
  support::embree_scene moved = std::move(scene);
  CHECK(moved.committed());
  CHECK_FALSE(moved.occluded(ray{}));
}
