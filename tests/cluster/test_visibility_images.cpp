// The visibility channel's option `images` (cluster/visibility_images.hpp): OR measured by one
// image of primary rays per viewpoint against OR known in closed form, its fallback to sample
// rays, determinism and bad options.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>
#include "infolerp/cluster/visibility_channel.hpp"
#include "support/embree_tracer.hpp"
#include "support/procedural.hpp"
#include "support/thread_pool.hpp"

using namespace infolerp;

namespace {

// Square A = [-1, 1]² at z = 0 facing +z (triangles 0 and 1), and above it at z = 0.5 the
// rectangle B = [-1.2, 0] × [-1.2, 1.2] (triangles 2 and 3), which hides part of A from
// viewpoints above z = 0.5.
indexed_mesh square_under_occluder() {
  indexed_mesh m;
  m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0},
                 {-1.2f, -1.2f, 0.5f}, {0, -1.2f, 0.5f}, {0, 1.2f, 0.5f}, {-1.2f, 1.2f, 0.5f}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
  return m;
}

// The part of a polygon in z = 0 with coordinate `axis` on the `keep_below` side of `bound`.
std::vector<glm::dvec3> clip(const std::vector<glm::dvec3>& poly, int axis, double bound, bool keep_below) {
  std::vector<glm::dvec3> out;
  auto in = [&](const glm::dvec3& p) { return keep_below ? p[axis] <= bound : p[axis] >= bound; };
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3 a = poly[i], b = poly[(i + 1) % poly.size()];
    if (in(a)) out.push_back(a);
    if (in(a) != in(b)) out.push_back(a + (b - a) * ((bound - a[axis]) / (b[axis] - a[axis])));
  }
  return out;
}

// OR of A's triangle t from viewpoint v in closed form: 1 − Ω(t ∩ shadow of B) / Ω(t), the
// shadow of B on z = 0 seen from v being the rectangle (B − c·v) / (1 − c), c = 0.5 / v.z.
double analytic_or(const indexed_mesh& m, std::size_t t, glm::dvec3 v) {
  const triangle_corners tc = corners(m, t);
  const double whole = triangle_solid_angle(v, tc);
  if (v.z <= 0.5) return 1.0;
  const double c = 0.5 / v.z;
  std::vector<glm::dvec3> poly{tc.p0, tc.p1, tc.p2};
  poly = clip(poly, 0, (-1.2 - c * v.x) / (1 - c), false);
  poly = clip(poly, 0, (0.0 - c * v.x) / (1 - c), true);
  poly = clip(poly, 1, (-1.2 - c * v.y) / (1 - c), false);
  poly = clip(poly, 1, (1.2 - c * v.y) / (1 - c), true);
  double hidden = 0.0;
  for (std::size_t i = 1; i + 1 < poly.size(); ++i) hidden += triangle_solid_angle(v, {poly[0], poly[i], poly[i + 1]});
  return 1.0 - hidden / whole;
}

struct traced_scene {
  support::embree_device device{"threads=1"};
  support::embree_scene scene{device};
  explicit traced_scene(const indexed_mesh& m) {
    REQUIRE(scene.add_mesh(m).ok());
    REQUIRE(scene.commit().ok());
  }
};

}  // namespace

TEST_CASE("triangle_solid_angle: an octant, and a far triangle as area over distance squared", "[cluster][visibility]") {
  const double octant = triangle_solid_angle({0, 0, 0}, {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  REQUIRE(octant == Approx(std::acos(-1.0) / 2.0).epsilon(1e-12));
  const double far = triangle_solid_angle({0, 0, 1000}, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  REQUIRE(far == Approx(0.5 / (1000.0 * 1000.0)).epsilon(1e-5));
}

TEST_CASE("visibility images: OR of a square partly hidden behind another matches the closed form",
          "[cluster][visibility]") {
  const indexed_mesh m = square_under_occluder();
  traced_scene ts(m);
  auto topo = make_topology(m);
  REQUIRE(topo.ok());
  serial_executor serial;
  const visibility_channel c{.viewpoints = 64, .radius_scale = 3.0, .images = true, .image_resolution = 512,
                             .image_min_pixels = 0.0};
  auto p = c.prepare(m, *topo, ts.scene, serial);
  REQUIRE(p.ok());
  REQUIRE(p->samples == 255);
  const visibility_setup su = c.setup(m);
  std::size_t checked = 0, partial = 0;
  double worst = 0.0;
  for (std::size_t v = 0; v < su.viewpoints.size(); ++v) {
    const glm::dvec3 e = su.viewpoints[v];
    for (std::size_t t = 0; t < 2; ++t) {
      if (e.z <= 0.0) {
        REQUIRE(p->occlusion_ratio(t, v) == 0.0);  // back-facing
        continue;
      }
      if (e.z < 1.5) continue;  // A seen at a grazing angle: few pixels per triangle
      const double want = analytic_or(m, t, e), got = p->occlusion_ratio(t, v);
      INFO("viewpoint " << v << " at (" << e.x << ", " << e.y << ", " << e.z << "), triangle " << t);
      CHECK(got == Approx(want).margin(0.01));
      worst = std::max(worst, std::abs(got - want));
      ++checked;
      partial += want > 0.05 && want < 0.95 ? 1 : 0;
    }
  }
  INFO("largest error " << worst);
  REQUIRE(checked >= 20);
  REQUIRE(partial >= 5);  // the occluder does hide part of A, at many fractions
}

TEST_CASE("visibility images: triangles under image_min_pixels use the sample rays", "[cluster][visibility]") {
  indexed_mesh m = support::make_plane(6, 6, 2.0f);
  support::append(m, support::make_box({-0.3f, -0.3f, 0.05f}, {0.3f, 0.3f, 0.5f}));
  traced_scene ts(m);
  auto topo = make_topology(m);
  REQUIRE(topo.ok());
  serial_executor serial;
  const visibility_channel rays{.viewpoints = 40, .samples_per_side = 3};
  auto base = rays.prepare(m, *topo, ts.scene, serial);
  REQUIRE(base.ok());
  visibility_channel all_small = rays;
  all_small.images = true;
  all_small.image_resolution = 64;
  all_small.image_min_pixels = 1e9;  // every triangle is below it
  auto p = all_small.prepare(m, *topo, ts.scene, serial);
  REQUIRE(p.ok());
  for (std::size_t i = 0; i < base->visible.size(); ++i)
    REQUIRE(p->visible[i] == std::lround(base->visible[i] * 255.0 / 9.0));
  // With no threshold the image measures them instead: different counts.
  all_small.image_min_pixels = 0.0;
  REQUIRE(all_small.prepare(m, *topo, ts.scene, serial)->visible != p->visible);
}

TEST_CASE("visibility images: the same counts for any executor", "[cluster][visibility]") {
  indexed_mesh m = support::make_torus(24, 12, 1.0f, 0.4f);
  support::append(m, support::make_plane(4, 4, 4.0f));
  traced_scene ts(m);
  auto topo = make_topology(m);
  REQUIRE(topo.ok());
  const visibility_channel c{.viewpoints = 20, .images = true, .image_resolution = 96, .image_min_pixels = 2.0};
  serial_executor serial;
  auto a = c.prepare(m, *topo, ts.scene, serial);
  REQUIRE(a.ok());
  support::thread_pool_executor pool{2};
  auto b = c.prepare(m, *topo, ts.scene, pool);
  REQUIRE(b.ok());
  REQUIRE(a->visible == b->visible);
}

TEST_CASE("visibility images: bad options get a status naming them", "[cluster][visibility]") {
  const indexed_mesh m = square_under_occluder();
  traced_scene ts(m);
  auto topo = make_topology(m);
  REQUIRE(topo.ok());
  serial_executor serial;
  auto fails_naming = [&](visibility_channel c, const std::string& what) {
    c.images = true;
    auto p = c.prepare(m, *topo, ts.scene, serial);
    REQUIRE(!p.ok());
    CHECK(p.error().code() == errc::bad_parameter);
    CHECK(p.error().message().find(what) != std::string::npos);
  };
  fails_naming({.image_resolution = 0}, "image_resolution");
  fails_naming({.image_resolution = 20000}, "image_resolution");
  fails_naming({.image_min_pixels = std::numeric_limits<double>::quiet_NaN()}, "image_min_pixels");
  fails_naming({.image_min_pixels = -1.0}, "image_min_pixels");
  fails_naming({.cull_hull = true}, "cull_hull");
  fails_naming({.adaptive_probes = 2}, "adaptive_probes");
}
