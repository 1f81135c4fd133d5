// refine/pinhole_camera.hpp: rays checked against what they must satisfy, not against a copy of
// their formula: the ray through pixel (x, y) starts at the eye and projects, through glm's own
// view and projection matrices, to (x + 1/2, y + 1/2); the rays through the outermost pixel
// centres span the field of view less one pixel; and the frame projects points back to the
// pixels they came from.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include "infolerp/refine/pinhole_camera.hpp"
#include "support/glm_projection.hpp"

using namespace infolerp;  // NOLINT: test file

namespace {

double angle(glm::vec3 a, glm::vec3 b) {
  const glm::dvec3 x = glm::normalize(glm::dvec3(a)), y = glm::normalize(glm::dvec3(b));
  return std::atan2(glm::length(glm::cross(x, y)), glm::dot(x, y));
}

}  // namespace

TEST_CASE("pinhole_camera: the ray through pixel (x, y) projects to (x + 1/2, y + 1/2) under glm's matrices") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-50.0f, 50.0f), fov(5.0f, 170.0f);
  std::uniform_int_distribution<std::uint32_t> size(1, 400);
  int cameras = 0;
  for (int trial = 0; trial < 200; ++trial) {
    pinhole_camera c{.eye = {pos(rng), pos(rng), pos(rng)}, .target = {pos(rng), pos(rng), pos(rng)},
                     .up = {pos(rng), pos(rng), pos(rng)}, .vertical_fov_degrees = fov(rng), .width = size(rng),
                     .height = size(rng)};
    const glm::dvec3 f = glm::normalize(glm::dvec3(c.target) - glm::dvec3(c.eye));
    if (glm::length(glm::cross(f, glm::normalize(glm::dvec3(c.up)))) < 1e-3) continue;
    ++cameras;
    const pinhole_frame fr = c.frame();
    // One pixel's width in the units of the projection's image plane (distance 1): the margin
    // below is a thousandth of it, scaled by how far off axis float directions lose digits.
    const double tan_half = std::tan(glm::radians(double(c.vertical_fov_degrees)) * 0.5);
    const double margin = 1e-3 * std::max(1.0, tan_half * tan_half * double(std::max(c.width, c.height)) / 50.0);
    for (std::uint32_t k = 0; k < 50; ++k) {
      const std::uint32_t x = std::uniform_int_distribution<std::uint32_t>(0, c.width - 1)(rng);
      const std::uint32_t y = std::uniform_int_distribution<std::uint32_t>(0, c.height - 1)(rng);
      const ray got = fr.primary_ray(x, y), direct = c.primary_ray(x, y);
      INFO("trial " << trial << " pixel " << x << "," << y);
      CHECK(got.origin == c.eye);
      CHECK(glm::length(got.direction) == Approx(1.0f).margin(1e-6));
      CHECK(glm::dot(glm::dvec3(got.direction), f) > 0.0);  // in front of the eye
      const glm::dvec3 p = support::glm_pixel(c, glm::dvec3(c.eye) + glm::dvec3(got.direction));
      CHECK(p.x == Approx(double(x) + 0.5).margin(margin));
      CHECK(p.y == Approx(double(y) + 0.5).margin(margin));
      CHECK(direct.origin == got.origin);
      CHECK(direct.direction == got.direction);
    }
  }
  CHECK(cameras >= 150);
}

TEST_CASE("pinhole_camera: the rays through the outermost pixel centres span the field of view less one pixel") {
  // An image plane at distance 1 spans ±tan(fov/2) vertically and ±aspect·tan(fov/2)
  // horizontally; the outermost centres lie half a pixel inside, so the angle between the top
  // and bottom rows' rays (through the middle column) is 2·atan(tan(fov/2)·(1 − 1/H)), and
  // likewise across the middle row. The middle pixel of an odd-sized image looks at the target;
  // the first column is to the left (up × forward side) and the first row is up.
  for (float fov : {10.0f, 60.0f, 90.0f, 150.0f})
    for (auto [w, h] : {std::pair{101u, 51u}, std::pair{31u, 77u}}) {
      const pinhole_camera c{.eye = {1.0f, 2.0f, 3.0f}, .target = {-2.0f, 0.5f, 1.0f}, .up = {0.1f, 0.2f, 1.0f},
                             .vertical_fov_degrees = fov, .width = w, .height = h};
      INFO("fov " << fov << ", " << w << "x" << h);
      const double t = std::tan(glm::radians(double(fov)) * 0.5), aspect = double(w) / double(h);
      const glm::vec3 top = c.primary_ray(w / 2, 0).direction, bottom = c.primary_ray(w / 2, h - 1).direction;
      const glm::vec3 left = c.primary_ray(0, h / 2).direction, right = c.primary_ray(w - 1, h / 2).direction;
      CHECK(angle(top, bottom) == Approx(2.0 * std::atan(t * (1.0 - 1.0 / h))).margin(1e-5));
      CHECK(angle(left, right) == Approx(2.0 * std::atan(aspect * t * (1.0 - 1.0 / w))).margin(1e-5));
      const glm::vec3 f = c.target - c.eye;
      CHECK(angle(c.primary_ray(w / 2, h / 2).direction, f) == Approx(0.0).margin(1e-6));
      CHECK(glm::dot(top, c.up) > glm::dot(bottom, c.up));
      CHECK(glm::dot(left, glm::cross(c.up, f)) > glm::dot(right, glm::cross(c.up, f)));
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
