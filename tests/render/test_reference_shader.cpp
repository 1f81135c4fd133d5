// The demo scene and the reference shader: analytic pixels (open ground, a sun shadow, the
// sphere's pole), exact reproducibility (twice, any thread count, packets or single rays), and
// bad inputs.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <glm/geometric.hpp>
#include "infolerp/mesh/geometry.hpp"
#include "support/demo_scene.hpp"
#include "support/mesh_io.hpp"
#include "support/reference_shader.hpp"

using infolerp::ray;
namespace support = infolerp::support;

namespace {

const support::embree_device& device() {
  static const support::embree_device d;
  return d;
}
const support::demo_scene& scene() {
  static const support::demo_scene s = [] {
    auto built = support::make_demo_scene(device());
    REQUIRE(built.ok());
    return std::move(*built);
  }();
  return s;
}

ray straight_down(float x, float y) { return ray{{x, y, 10.0f}, 0.0f, {0.0f, 0.0f, -1.0f}}; }

bool same_bits(const support::image& a, const support::image& b) {
  return a.width == b.width && a.height == b.height &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(glm::vec3)) == 0;
}

}  // namespace

TEST_CASE("open ground: lit, unshadowed, unoccluded, texcoords from the plane", "[shader]") {
  support::enable_flush_to_zero();
  const support::reference_shader shader(scene());
  std::uint64_t rays = 0;
  const auto in = shader.evaluate(straight_down(6.0f, -6.0f), rays);
  REQUIRE(in.hit());
  CHECK(scene().objects[in.geometry].name == "ground");
  CHECK(in.position.x == Approx(6.0f));
  CHECK(in.position.y == Approx(-6.0f));
  CHECK(in.position.z == Approx(0.0f).margin(1e-6));
  CHECK(in.normal.z == Approx(1.0f));
  CHECK(in.uv.x == Approx((6.0f + 8.0f) / 16.0f));  // the 16 x 16 plane maps to [0,1]²
  CHECK(in.uv.y == Approx((-6.0f + 8.0f) / 16.0f));
  CHECK(in.light_bits == support::sun_light_bit);
  CHECK(in.soft_shadow == 1.0f);
  CHECK(in.ao == 1.0f);
  CHECK(rays == 1u + 1u + 16u + 64u);
  CHECK(rays == shader.max_rays_per_pixel());
  // With every light term at its maximum the colour is albedo x (ambient + sun + area light).
  const glm::vec3 c = shader.shade(in);
  CHECK(c.r > 0.0f);
  support::shading_inputs dark = in;
  dark.light_bits = 0;
  dark.soft_shadow = 0.0f;
  dark.ao = 0.0f;
  CHECK(shader.shade(dark) == glm::vec3(0.0f));
  dark.ao = 1.0f;
  const glm::vec3 a = support::albedo(scene().objects[in.geometry].mat, in.uv);
  CHECK(shader.shade(dark) == a * scene().ambient);
}

TEST_CASE("the tall box casts a hard sun shadow and occludes the ground near it", "[shader]") {
  support::enable_flush_to_zero();
  const support::reference_shader shader(scene());
  // Follow the sun direction down from a point inside the tall box to the ground.
  const glm::vec3 inside{0.55f, 2.05f, 1.0f};
  const glm::vec3 d = scene().sun.direction;
  const glm::vec3 ground = inside - (inside.z / d.z) * d;
  std::uint64_t rays = 0;
  const auto in = shader.evaluate(straight_down(ground.x, ground.y), rays);
  REQUIRE(in.hit());
  CHECK(scene().objects[in.geometry].name == "ground");
  CHECK(in.light_bits == 0u);
  CHECK(in.ao < 1.0f);
  CHECK(in.ao > 0.0f);
}

TEST_CASE("the UV sphere's pole is hit with an upward normal and v near 0", "[shader]") {
  support::enable_flush_to_zero();
  const support::reference_shader shader(scene());
  std::uint64_t rays = 0;
  const auto in = shader.evaluate(straight_down(-1.7f, 0.4f), rays);
  REQUIRE(in.hit());
  CHECK(scene().objects[in.geometry].name == "uv sphere");
  CHECK(in.position.z == Approx(2.2f).epsilon(1e-3));
  CHECK(in.normal.z == Approx(1.0f).epsilon(1e-3));
  CHECK(in.uv.y < 1.0f / 32.0f);  // within the first stack
  CHECK(in.ao == 1.0f);           // nothing above the top of the sphere within the AO radius
}

TEST_CASE("background pixels cost one ray and shade to the sky", "[shader]") {
  const support::reference_shader shader(scene());
  std::uint64_t rays = 0;
  const auto in = shader.evaluate(ray{{0.0f, 0.0f, 10.0f}, 0.0f, {0.0f, 0.0f, 1.0f}}, rays);
  CHECK_FALSE(in.hit());
  CHECK(rays == 1u);
  CHECK(shader.shade(in) == scene().sky_zenith);
}

TEST_CASE("reference renders are exactly reproducible: twice, any thread count, packets or single rays",
          "[shader]") {
  const support::reference_shader single(scene());
  const support::reference_shader packets(scene(), {.packets = true});
  support::image a, b, c, d;
  auto sa = support::render_reference(single, 72, 56, a, 2);
  auto sb = support::render_reference(single, 72, 56, b, 2);
  auto sc = support::render_reference(single, 72, 56, c, 1);
  auto sd = support::render_reference(packets, 72, 56, d, 2);
  REQUIRE((sa.ok() && sb.ok() && sc.ok() && sd.ok()));
  CHECK(same_bits(a, b));
  CHECK(same_bits(a, c));
  CHECK(same_bits(a, d));
  CHECK(sa->rays == sb->rays);
  CHECK(sa->rays == sc->rays);
  CHECK(sa->rays == sd->rays);
  CHECK(sa->rays > 72u * 56u);
  CHECK(sa->rays <= 72u * 56u * single.max_rays_per_pixel());
  // The image is not trivially uniform: the scene is there.
  std::size_t sky = 0;
  for (const auto& p : a.pixels) sky += p == scene().sky_zenith ? 1 : 0;
  CHECK(sky < a.pixels.size());
  // A single pixel evaluated on its own matches the same pixel of the render.
  std::uint64_t rays = 0;
  const auto in = single.evaluate_pixel(30.5f, 40.5f, 72, 56, rays);
  CHECK(single.shade(in) == a.at(30, 40));
}

TEST_CASE("shader options: no AO and no area light rays", "[shader]") {
  const support::reference_shader shader(scene(), {.ao_rays = 0, .soft_shadow_rays = 0});
  std::uint64_t rays = 0;
  const auto in = shader.evaluate(straight_down(6.0f, -6.0f), rays);
  CHECK(rays == 2u);
  CHECK(in.ao == 1.0f);
  CHECK(in.soft_shadow == 0.0f);
}

TEST_CASE("bad inputs: empty image, unreadable mesh", "[shader]") {
  const support::reference_shader shader(scene());
  support::image out;
  CHECK_FALSE(support::render_reference(shader, 0, 10, out).ok());
  CHECK_FALSE(support::render_reference(shader, 10, -1, out).ok());
  auto missing = support::make_demo_scene(device(), {.mesh_paths = {"/nonexistent/mesh.off"}});
  REQUIRE_FALSE(missing.ok());
  CHECK(missing.error().message().find("/nonexistent/mesh.off") != std::string::npos);
}

TEST_CASE("a user mesh is fitted onto the ground at the requested size", "[shader]") {
  auto built = support::make_demo_scene(device(), {.mesh_paths = {support::cgal_mesh("fandisk")}, .mesh_size = 1.5f});
  REQUIRE(built.ok());
  REQUIRE(built->objects.size() == 5u);
  const auto& m = built->objects.back().mesh;
  CHECK(built->tracer.geometry_count() == 5u);
  const auto box = infolerp::mesh_bounds(m);
  const glm::dvec3 extent = box.hi - box.lo;
  CHECK(std::max({extent.x, extent.y, extent.z}) == Approx(1.5).epsilon(1e-5));
  CHECK(box.lo.z == Approx(0.0).margin(1e-5));
  CHECK(m.has_normals());
}
