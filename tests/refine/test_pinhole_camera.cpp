// refine/pinhole_camera.hpp: the frame computed once gives the rays of the per-ray formula it
// replaced (kept here as the oracle), and projects points back to the pixels they came from.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include "infolerp/refine/pinhole_camera.hpp"

using namespace infolerp;  // NOLINT: test file

namespace {

// The formula pinhole_camera::primary_ray evaluated per ray before the frame existed: basis and
// tan() recomputed for every pixel.
ray oracle_ray(const pinhole_camera& c, std::uint32_t x, std::uint32_t y) {
  const glm::vec3 f = pinhole_camera::forward(c.eye, c.target);
  const glm::vec3 r = unit_or_zero(glm::cross(f, c.up));
  const glm::vec3 u = glm::cross(r, f);
  const float h = std::tan(glm::radians(c.vertical_fov_degrees) * 0.5f);
  const float aspect = float(c.width) / float(c.height);
  const float sx = (2.0f * (float(x) + 0.5f) / float(c.width) - 1.0f) * h * aspect;
  const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(c.height)) * h;
  ray out;
  out.origin = c.eye;
  out.direction = glm::normalize(f + sx * r + sy * u);
  return out;
}

float relative(glm::vec3 a, glm::vec3 b) { return glm::length(a - b) / std::max(glm::length(b), 1e-30f); }

}  // namespace

TEST_CASE("pinhole_camera: the frame's rays equal the per-ray formula within 1e-6 relative") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-50.0f, 50.0f), fov(5.0f, 170.0f);
  std::uniform_int_distribution<std::uint32_t> size(1, 400);
  for (int trial = 0; trial < 200; ++trial) {
    pinhole_camera c{.eye = {pos(rng), pos(rng), pos(rng)}, .target = {pos(rng), pos(rng), pos(rng)},
                     .up = {pos(rng), pos(rng), pos(rng)}, .vertical_fov_degrees = fov(rng), .width = size(rng),
                     .height = size(rng)};
    if (glm::length(glm::cross(pinhole_camera::forward(c.eye, c.target), unit_or_zero(c.up))) < 1e-3f) continue;
    const pinhole_frame fr = c.frame();
    for (std::uint32_t k = 0; k < 50; ++k) {
      const std::uint32_t x = std::uniform_int_distribution<std::uint32_t>(0, c.width - 1)(rng);
      const std::uint32_t y = std::uniform_int_distribution<std::uint32_t>(0, c.height - 1)(rng);
      const ray want = oracle_ray(c, x, y), got = fr.primary_ray(x, y), direct = c.primary_ray(x, y);
      INFO("trial " << trial << " pixel " << x << "," << y);
      CHECK(relative(got.origin, want.origin) <= 1e-6f);
      CHECK(relative(got.direction, want.direction) <= 1e-6f);
      CHECK(relative(direct.direction, want.direction) <= 1e-6f);
    }
  }
}

TEST_CASE("pinhole_camera: a point on a pixel's ray projects to that pixel's centre; projected areas in pixels") {
  const pinhole_camera c{.eye = {0.3f, -0.2f, 4.0f}, .target = {0.1f, 0.2f, 0.0f}, .up = {0, 1, 0},
                         .vertical_fov_degrees = 50.0f, .width = 64, .height = 48};
  const pinhole_frame fr = c.frame();
  for (std::uint32_t y = 0; y < c.height; y += 5)
    for (std::uint32_t x = 0; x < c.width; x += 7) {
      const ray r = fr.primary_ray(x, y);
      const glm::dvec3 p = fr.project(r.origin + 3.0f * r.direction);
      CHECK(p.x == Approx(double(x) + 0.5).margin(1e-3));
      CHECK(p.y == Approx(double(y) + 0.5).margin(1e-3));
      CHECK(p.z > 0.0);
    }
  // Three points on the rays through three pixel centres at any depth span half a 1x1 pixel square...
  const auto on = [&](std::uint32_t x, std::uint32_t y, float t) {
    const ray r = fr.primary_ray(x, y);
    return r.origin + t * r.direction;
  };
  CHECK(fr.projected_area(on(10, 10, 2.0f), on(11, 10, 5.0f), on(10, 11, 3.0f)) == Approx(0.5).margin(1e-3));
  CHECK(fr.projected_area(on(0, 0, 2.0f), on(20, 0, 2.0f), on(0, 10, 2.0f)) == Approx(100.0).epsilon(1e-4));
  // ...a triangle with a corner behind the eye spans the view, a degenerate one covers nothing.
  CHECK(std::isinf(fr.projected_area(on(1, 1, 2.0f), on(2, 2, 2.0f), c.eye - 2.0f * fr.forward)));
  CHECK(fr.projected_area(on(1, 1, 2.0f), on(1, 1, 2.0f), on(1, 1, 2.0f)) == 0.0);
}
