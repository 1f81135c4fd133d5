// The visibility channel's exact savings (coherent, cull_hull in cluster/visibility_channel.hpp)
// against plain tracing through Embree, and the support function they rest on
// (mesh/support_function.hpp) against a linear scan.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>
#include <glm/gtc/matrix_transform.hpp>
#include "infolerp/cluster/visibility_channel.hpp"
#include "infolerp/mesh/support_function.hpp"
#include "support/embree_tracer.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"
#include "support/thread_pool.hpp"

using namespace infolerp;

TEST_CASE("point_support equals the maximum of a linear scan, and stops above the limit", "[cluster][visibility]") {
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<glm::dvec3> pts(3000);
  for (auto& p : pts) p = glm::dvec3(g(rng), g(rng), 0.3 * g(rng)) + glm::dvec3(5.0, -2.0, 1.0);
  const point_support hull(pts);
  for (int k = 0; k < 500; ++k) {
    const glm::dvec3 n(g(rng), g(rng), g(rng));
    double scan = -std::numeric_limits<double>::infinity();
    for (const auto& p : pts) scan = std::max(scan, glm::dot(n, p));
    const double start = glm::dot(n, pts[static_cast<std::size_t>(k)]);
    REQUIRE(hull.support_up_to(n, start, std::numeric_limits<double>::infinity()) == scan);
    REQUIRE(hull.support_up_to(n, start, scan) == scan);
    REQUIRE(std::isinf(hull.support_up_to(n, start, std::nextafter(scan, -1e300))));
  }
}

namespace {

// Counts of plain tracing and of every exact option (serial, 2 workers with odd grains, and
// through Embree's coherent ray streams).
void require_exact_savings(const indexed_mesh& m, std::uint32_t viewpoints, std::uint32_t n, bool expect_culled,
                           std::size_t grain = 3) {
  support::embree_device device("threads=1");
  support::embree_scene scene(device), stream(device, {.coherent_streams = true});
  REQUIRE(scene.add_mesh(m).ok());
  REQUIRE(scene.commit().ok());
  REQUIRE(stream.add_mesh(m).ok());
  REQUIRE(stream.commit().ok());
  auto topo = make_topology(m);
  REQUIRE(topo.ok());
  serial_executor serial;
  const visibility_channel plain{.viewpoints = viewpoints, .samples_per_side = n};
  auto base = plain.prepare(m, *topo, scene, serial);
  REQUIRE(base.ok());
  std::size_t free_rays = 0;  // rays the hull proves free (counted with a tracer that sees none)
  for (const bool coherent : {false, true})
    for (const bool cull : {false, true}) {
      visibility_channel c = plain;
      c.coherent = coherent;
      c.cull_hull = cull;
      auto a = c.prepare(m, *topo, scene, serial);
      REQUIRE(a.ok());
      REQUIRE(a->visible == base->visible);
      REQUIRE(c.prepare(m, *topo, stream, serial)->visible == base->visible);  // Embree's coherent streams
      c.grain = grain;
      support::thread_pool_executor pool{2};
      auto b = c.prepare(m, *topo, scene, pool);
      REQUIRE(b.ok());
      REQUIRE(b->visible == base->visible);
    }
  // How many rays cull_hull skips, from the ray builder itself.
  const visibility_setup su = visibility_channel{.viewpoints = viewpoints, .samples_per_side = n}.setup(m);
  const detail::visibility_hull hull = detail::make_visibility_hull(m, su);
  std::vector<std::uint32_t> tris(m.triangles.size()), slots, freed;
  for (std::size_t t = 0; t < tris.size(); ++t) tris[t] = static_cast<std::uint32_t>(t);
  std::vector<ray> rays;
  std::vector<glm::dvec3> scratch;
  detail::make_grouped_visibility_rays(m, su, tris, true, &hull, scratch, rays, slots, freed);
  free_rays = freed.size();
  INFO("rays proven free: " << free_rays << " of " << free_rays + rays.size());
  REQUIRE((free_rays > 0) == expect_culled);
}

}  // namespace

TEST_CASE("visibility exact savings: identical counts on adversarial meshes", "[cluster][visibility]") {
  SECTION("a box inside another box (one mesh): the inner box's faces are never on the hull") {
    indexed_mesh m = support::make_box({-1, -1, -1}, {1, 1, 1});
    support::append(m, support::make_box({-0.3f, -0.3f, -0.3f}, {0.3f, 0.3f, 0.3f}));
    require_exact_savings(m, 40, 2, true);
  }
  SECTION("triangles touching the hull: coplanar with a hull face, and tilted with one corner on it") {
    indexed_mesh m = support::make_box({-1, -1, -1}, {1, 1, 1});
    indexed_mesh extra;
    extra.positions = {{-0.5f, -0.5f, 1.0f}, {0.5f, -0.5f, 1.0f}, {0.0f, 0.5f, 1.0f},    // lying in the top face
                       {-0.2f, 0.0f, 1.0f}, {0.6f, 0.3f, 0.2f}, {-0.4f, 0.7f, 0.3f}};  // corner on the top face
    extra.triangles = {{0, 1, 2}, {3, 4, 5}, {3, 5, 4}};
    support::append(m, extra);
    require_exact_savings(m, 64, 3, true);
  }
  SECTION("open meshes: a plane, and a bowl whose inside faces see each other") {
    require_exact_savings(support::make_plane(5, 5, 2.0f), 32, 2, true);
    indexed_mesh sphere = support::make_uv_sphere(16, 12), bowl;
    bowl.positions = sphere.positions;
    for (const auto& t : sphere.triangles) {
      const float z = (sphere.positions[t.x].z + sphere.positions[t.y].z + sphere.positions[t.z].z) / 3.0f;
      if (z < 0.2f) {
        bowl.triangles.push_back(t);
        bowl.triangles.push_back({t.x, t.z, t.y});  // both sides
      }
    }
    require_exact_savings(bowl, 48, 2, true);
  }
  SECTION("grazing rays: many viewpoints nearly in the planes of a box's faces, far from the origin") {
    indexed_mesh m = support::make_box({99.0f, -1.0f, -1.0f}, {101.0f, 1.0f, 1.0f});
    require_exact_savings(m, 256, 2, false);  // the coordinates are too large for the margin: all traced
    require_exact_savings(support::make_box({-1, -1, -1}, {1, 1, 1}), 256, 2, true);
  }
}

TEST_CASE("visibility exact savings: identical counts on real meshes", "[cluster][visibility][real]") {
  auto m = support::load_mesh(support::cgal_mesh("fandisk"));  // a CAD part: large flat hull faces
  REQUIRE(m.ok());
  require_exact_savings(*m, 16, 2, true, 61);
}

TEST_CASE("visibility adaptive sampling: the probe rule, its bound, and determinism", "[cluster][visibility]") {
  // A box over a floor: shadows cross floor triangles between samples, so probes can be wrong.
  indexed_mesh m = support::make_plane(8, 8, 2.0f);
  support::append(m, support::make_box({-0.3f, -0.3f, 0.05f}, {0.3f, 0.3f, 0.5f}));
  support::embree_device device("threads=1");
  support::embree_scene scene(device);
  REQUIRE(scene.add_mesh(m).ok());
  REQUIRE(scene.commit().ok());
  auto topo = make_topology(m);
  REQUIRE(topo.ok());
  serial_executor serial;
  const std::uint32_t n = 3, ns = n * n;
  const visibility_channel plain{.viewpoints = 48, .samples_per_side = n};
  auto base = plain.prepare(m, *topo, scene, serial);
  REQUIRE(base.ok());
  SECTION("P >= n² traces every sample: the plain counts") {
    for (std::uint32_t probes : {ns, ns + 5}) {
      visibility_channel c = plain;
      c.adaptive_probes = probes;
      REQUIRE(c.prepare(m, *topo, scene, serial)->visible == base->visible);
    }
  }
  SECTION("each entry is exact, or its probes agreed and it is off by at most n² − P") {
    const visibility_setup su = plain.setup(m);
    for (std::uint32_t probes : {1u, 2u, 4u}) {
      visibility_channel c = plain;
      c.adaptive_probes = probes;
      c.coherent = probes == 2;
      c.cull_hull = probes == 4;
      auto a = c.prepare(m, *topo, scene, serial);
      REQUIRE(a.ok());
      std::size_t wrong = 0;
      for (std::size_t t = 0; t < m.triangles.size(); ++t)
        for (std::size_t v = 0; v < plain.viewpoints; ++v) {
          const int got = a->visible[t * plain.viewpoints + v], want = base->visible[t * plain.viewpoints + v];
          if (got == want) continue;
          ++wrong;
          REQUIRE(std::abs(got - want) <= static_cast<int>(ns - probes));
          // Agreed probes: the count is all front-facing samples or none, traced one by one here.
          const triangle_corners tc = corners(m, t);
          const glm::dvec3 nrm(triangle_normal(tc));
          int front = 0, free_probes = 0;
          for (std::size_t s = 0; s < ns; ++s) {
            const glm::dvec2 w = su.samples[s];
            const glm::dvec3 x = (1.0 - w.x - w.y) * tc.p0 + w.x * tc.p1 + w.y * tc.p2 + su.offset * nrm;
            const glm::dvec3 d = su.viewpoints[v] - x;
            if (glm::dot(nrm, d) <= 0.0) continue;
            ++front;
            bool probe = false;
            for (std::size_t j = 0; j < probes; ++j) probe = probe || j * ns / probes == s;
            if (probe) free_probes += scene.occluded(ray{glm::vec3(x), 0.0f, glm::vec3(d), 1.0f}) ? 0 : 1;
          }
          REQUIRE((got == front || got == 0));
          REQUIRE(free_probes == (got == 0 ? 0 : static_cast<int>(probes)));
        }
      INFO("P = " << probes << ": " << wrong << " entries differ");
      REQUIRE(wrong > 0);  // the scene does exercise the approximation
      c.grain = 5;
      support::thread_pool_executor pool{2};
      REQUIRE(c.prepare(m, *topo, scene, pool)->visible == a->visible);
      // The neighbour rule: each entry exact or the probe rule's, fewer entries wrong.
      c.adaptive_neighbours = true;
      auto b = c.prepare(m, *topo, scene, serial);
      REQUIRE(b.ok());
      std::size_t wrong_neighbours = 0, repaired = 0;
      for (std::size_t i = 0; i < b->visible.size(); ++i) {
        REQUIRE((b->visible[i] == base->visible[i] || b->visible[i] == a->visible[i]));
        wrong_neighbours += b->visible[i] != base->visible[i] ? 1 : 0;
        repaired += b->visible[i] == base->visible[i] && a->visible[i] != base->visible[i] ? 1 : 0;
      }
      INFO("with neighbours: " << wrong_neighbours << " entries differ, " << repaired << " repaired");
      REQUIRE(wrong_neighbours < wrong);
      REQUIRE(repaired > 0);
      REQUIRE(c.prepare(m, *topo, scene, pool)->visible == b->visible);
    }
  }
}
