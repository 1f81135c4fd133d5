// The ready sample source (upsample/ray_cast_source.hpp) against the demo's hand-written one
// (tests/support/demo_upsample.hpp, built on the reference shader): on the demo scene through
// Embree, every evaluated record and every shaded pixel has the same bits, and whole upsampled
// frames with and without probes are the same bit for bit. Also: bad options are named, and a
// point light's bit follows its hard shadow.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <glm/gtc/matrix_transform.hpp>
#include <span>
#include <vector>
#include "infolerp/upsample/ray_cast_source.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "support/brute_force_tracer.hpp"
#include "support/demo_clusters.hpp"
#include "support/demo_upsample.hpp"
#include "support/small_demo_scene.hpp"
#include "support/procedural.hpp"

namespace support = infolerp::support;
using infolerp::probe_mode;

namespace {

const support::demo_scene& scene() {
  static const support::embree_device device;
  static const support::demo_scene s = support::make_small_demo_scene(device);
  return s;
}

bool same_bits(const support::demo_sample& a, const support::demo_sample& b) {
  return a.position == b.position && a.normal == b.normal && a.texcoord == b.texcoord && a.cluster == b.cluster &&
         a.lights == b.lights && a.occlusion == b.occlusion && a.inv_depth == b.inv_depth;
}

template <class S>
std::vector<glm::vec3> frame(const S& src, std::uint32_t w, std::uint32_t h, std::uint32_t passes, std::uint32_t min_sources) {
  auto up = infolerp::upsampler<support::demo_sample>::create(w, h, {.passes = passes, .max_passes = passes, .min_sources = min_sources});
  REQUIRE(up);
  std::vector<glm::vec3> out(std::size_t{w} * h);
  REQUIRE(up->render(src, std::span<glm::vec3>(out)));
  return out;
}

bool same_frame(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
}

}  // namespace

TEST_CASE("ray cast source: the demo's records and colours, bit for bit", "[upsample][ray_cast_source]") {
  constexpr int w = 80, h = 60;
  const support::reference_shader shader(scene(), {.ao_rays = 8, .soft_shadow_rays = 4});
  const auto seams = support::split_at_texture_seams(scene(), support::cluster_by_normal(scene(), 2));
  REQUIRE(seams);
  const support::scene_clustering& clusters = *seams;
  const support::demo_ibuffer_source hand{&shader, &clusters, w, h};
  auto ready = support::make_demo_ray_cast_source(shader, clusters, w, h);
  REQUIRE(ready);
  CHECK(ready->max_rays_per_pixel() == shader.max_rays_per_pixel());  // primary + sun + 4 + 8
  std::size_t mismatched_records = 0, mismatched_colours = 0, background = 0, lit = 0;
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x) {
      const auto a = hand.evaluate(x, y), b = ready->evaluate(x, y);
      mismatched_records += same_bits(a, b) ? 0 : 1;
      mismatched_colours += hand.shade(a, x, y) == ready->shade(b, x, y) ? 0 : 1;
      background += a.background() ? 1 : 0;
      lit += a.lights != 0 ? 1 : 0;
    }
  CHECK(mismatched_records == 0);
  CHECK(mismatched_colours == 0);
  CHECK(background > 0);  // the frame shows sky, lit and shadowed surfaces
  CHECK(lit > 0);
  CHECK(lit + background < std::size_t{w} * h);

  SECTION("upsampled frames") {
    CHECK(same_frame(frame(hand, w, h, 3, 2), frame(*ready, w, h, 3, 2)));
    const support::reference_shader primary_sun(scene(), {.ao_rays = 0, .soft_shadow_rays = 0});
    const support::reference_shader primary(scene(), {.ao_rays = 0, .soft_shadow_rays = 0, .hard_shadow = false});
    support::demo_probe_source hand_probe;
    static_cast<support::demo_ibuffer_source&>(hand_probe) = hand;
    hand_probe.primary = &primary_sun;
    auto ready_probe = support::make_demo_ray_cast_source<probe_mode::primary>(shader, clusters, w, h);
    REQUIRE(ready_probe);
    CHECK(same_frame(frame(hand_probe, w, h, 3, 1), frame(*ready_probe, w, h, 3, 1)));
    support::demo_refining_probe_source hand_refine;
    static_cast<support::demo_ibuffer_source&>(hand_refine) = hand;
    hand_refine.primary = &primary;
    hand_refine.probe_lights = false;
    hand_refine.primary_sun = &primary_sun;
    auto ready_refine = support::make_demo_ray_cast_source<probe_mode::refine>(shader, clusters, w, h);
    REQUIRE(ready_refine);
    CHECK(same_frame(frame(hand_refine, w, h, 3, 2), frame(*ready_refine, w, h, 3, 2)));
    // Batched probes (the tracer's packets) give the records of single ones.
    std::size_t batched = 0, differ = 0;
    for (std::uint32_t y = 0; y < h; ++y) {
      std::vector<std::uint32_t> xs;
      for (std::uint32_t x = y % 3; x < w; x += 1 + y % 2) xs.push_back(x);  // strides 1 and 2, as the upsampler's rows
      std::vector<support::demo_sample> a(xs.size()), b(xs.size());
      ready_probe->probe(y, xs, a);
      ready_refine->probe(y, xs, b);
      for (std::size_t k = 0; k < xs.size(); ++k) {
        differ += same_bits(a[k], ready_probe->probe(xs[k], y)) ? 0 : 1;
        differ += same_bits(b[k], ready_refine->probe(xs[k], y)) ? 0 : 1;
      }
      batched += 2 * xs.size();
    }
    CHECK(batched > 3000);
    CHECK(differ == 0);
    // And the upsampled frame is not the per-pixel one (the comparison above is not vacuous).
    CHECK(!same_frame(frame(*ready, w, h, 1, 2), frame(*ready, w, h, 3, 2)));
  }
}

TEST_CASE("ray cast source: light bits follow hard shadows of point and directional lights", "[upsample][ray_cast_source]") {
  // Ground z = 0 over [-2, 2]², an occluder square of half-size 0.25 at z = 1, a point light at
  // z = 2 above the centre (its shadow: half-size 0.5 on the ground) and a sun straight up (its
  // shadow lies under the occluder, hidden from the camera). Orthographic camera looking down.
  infolerp::indexed_mesh m = support::make_plane(8, 8, 4.0f);
  support::append(m, support::make_plane(1, 1, 0.5f), glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, 1.0f)));
  const support::brute_force_tracer tracer{&m};
  const auto camera = [](float x, float y) {  // pixel (x, y) of 40×40 looks at about (x/10 - 2, y/10 - 2), off the edges
    return infolerp::ray{{x / 10.0f - 1.987f, y / 10.0f - 1.987f, 5.0f}, 0.0f, {0.0f, 0.0f, -1.0f}};
  };
  const auto geometry = [&](std::uint32_t) -> const infolerp::indexed_mesh& { return m; };
  const auto material = [](const infolerp::surface_sample<2>& s, const auto&) { return s.normal; };
  const std::vector<std::uint32_t> ids(m.triangle_count(), 0);
  infolerp::ray_cast_options o{.ao_rays = 0};
  o.lights = {{.at = {0.0f, 0.0f, 2.0f}, .directional = false}, {.at = {0.0f, 0.0f, 1.0f}, .directional = true}};
  auto src = infolerp::ray_cast_source<support::brute_force_tracer, decltype(camera), decltype(geometry), decltype(material)>::create(
      tracer, camera, geometry, material, {std::span<const std::uint32_t>(ids)}, o);
  REQUIRE(src);
  std::size_t shadowed = 0;
  for (std::uint32_t y = 0; y < 40; ++y)
    for (std::uint32_t x = 0; x < 40; ++x) {
      const auto s = src->evaluate(x, y);
      REQUIRE(!s.background());
      const glm::vec3 p = s.position;
      const bool on_ground = p.z < 0.5f;
      const bool in_point_shadow = on_ground && std::abs(p.x) < 0.5f && std::abs(p.y) < 0.5f;
      INFO("pixel " << x << ", " << y << " at " << p.x << ", " << p.y << ", " << p.z);
      CHECK(s.lights == (in_point_shadow ? 2u : 3u));
      CHECK(s.occlusion[0] == 1.0f);  // no AO rays: unoccluded
      CHECK(s.occlusion[1] == 0.0f);  // no soft-shadow points
      CHECK(src->shade(s, x, y) == glm::vec3(0.0f, 0.0f, 1.0f));
      shadowed += in_point_shadow ? 1 : 0;
    }
  CHECK(shadowed > 0);
}

TEST_CASE("ray cast source: bad options are named", "[upsample][ray_cast_source][bad_input]") {
  infolerp::indexed_mesh m = support::make_plane(1, 1, 1.0f);
  const support::brute_force_tracer tracer{&m};
  const auto camera = [](float, float) { return infolerp::ray{}; };
  const auto geometry = [&](std::uint32_t) -> const infolerp::indexed_mesh& { return m; };
  const auto material = [](const infolerp::surface_sample<2>&, const auto&) { return 0.0f; };
  using source = infolerp::ray_cast_source<support::brute_force_tracer, decltype(camera), decltype(geometry), decltype(material)>;
  infolerp::ray_cast_options o;
  o.lights.resize(33);
  auto many = source::create(tracer, camera, geometry, material, {}, o);
  REQUIRE(!many);
  CHECK(many.error().code() == infolerp::errc::bad_parameter);
  CHECK(many.error().message().find("33 hard-shadow lights") != std::string::npos);
  auto radius = source::create(tracer, camera, geometry, material, {}, {.ao_radius = -1.0f});
  REQUIRE(!radius);
  CHECK(radius.error().message().find("ao_radius") != std::string::npos);
  for (float angle : {-0.1f, std::numeric_limits<float>::quiet_NaN()}) {
    infolerp::ray_cast_options bad;
    bad.smooth_angle = angle;
    auto smooth = source::create(tracer, camera, geometry, material, {}, bad);
    REQUIRE(!smooth);
    CHECK(smooth.error().code() == infolerp::errc::bad_parameter);
    CHECK(smooth.error().message().find("smooth_angle") != std::string::npos);
  }
  infolerp::ray_cast_options never;
  never.smooth_angle = std::numeric_limits<float>::infinity();
  auto ok = source::create(tracer, camera, geometry, material, {}, never);
  REQUIRE(ok);
  infolerp::surface_sample<2> a, b;
  a.normal = {0.0f, 0.0f, 1.0f};
  b.normal = {0.0f, 0.0f, -1.0f};
  CHECK(ok->smooth(a, b));  // smooth_angle infinite: never probes for the normals
  auto five = source::create(tracer, camera, geometry, material, {}, {});
  REQUIRE(five);
  b.normal = {std::sin(0.08f), 0.0f, std::cos(0.08f)};  // 4.6 degrees
  CHECK(five->smooth(a, b));
  b.normal = {std::sin(0.09f), 0.0f, std::cos(0.09f)};  // 5.2 degrees
  CHECK(!five->smooth(a, b));
}

namespace {
// Renders a sphere with vertex normals (one cluster, so whole interpolations cross curved cells)
// through an upsampler and returns the largest | |n| - 1 | among the records the material saw.
template <probe_mode Probes>
float worst_material_normal(bool probe_every_sample) {
  infolerp::indexed_mesh m = support::make_icosphere(2);
  m.normals = m.positions;  // unit: the icosphere's vertices lie on the unit sphere
  const support::brute_force_tracer tracer{&m};
  const auto camera = [](float x, float y) {  // 48×48 pinhole at z = 3 looking down -z
    return infolerp::ray{{0.0f, 0.0f, 3.0f}, 0.0f, glm::normalize(glm::vec3((x - 24.0f) / 56.0f, (y - 24.0f) / 56.0f, -1.0f))};
  };
  const auto geometry = [&](std::uint32_t) -> const infolerp::indexed_mesh& { return m; };
  float worst = 0.0f;
  std::size_t seen = 0;
  const auto material = [&worst, &seen](const infolerp::surface_sample<2>& s, const auto&) {
    if (!s.background()) worst = std::max(worst, std::abs(glm::length(s.normal) - 1.0f)), ++seen;
    return s.normal;
  };
  const std::vector<std::uint32_t> ids(m.triangle_count(), 0);
  auto src = infolerp::ray_cast_source<support::brute_force_tracer, decltype(camera), decltype(geometry), decltype(material),
                                       Probes>::create(tracer, camera, geometry, material, {std::span<const std::uint32_t>(ids)},
                                                       {.ao_rays = 0});
  REQUIRE(src);
  auto up = infolerp::upsampler<infolerp::surface_sample<2>>::create(
      48, 48, {.passes = 4, .max_passes = 4, .min_sources = 2, .probe_every_sample = probe_every_sample});
  REQUIRE(up);
  std::vector<glm::vec3> out(48 * 48);
  REQUIRE(up->render(*src, std::span<glm::vec3>(out)));
  CHECK(seen > 48 * 48 / 4);  // the sphere covers a good part of the frame
  return worst;
}
}  // namespace

TEST_CASE("ray cast source: the material sees unit normals in every probe mode", "[upsample][ray_cast_source]") {
  CHECK(worst_material_normal<probe_mode::none>(true) <= 1e-6f);
  CHECK(worst_material_normal<probe_mode::primary>(true) <= 1e-6f);
  CHECK(worst_material_normal<probe_mode::primary>(false) <= 1e-6f);
  CHECK(worst_material_normal<probe_mode::refine>(true) <= 1e-6f);
  CHECK(worst_material_normal<probe_mode::refine>(false) <= 1e-6f);
}
