// The demo's own measures and scene set-up (tests/support): the LOD stage's surface distance
// and distances against brute-force minima over every triangle; asset groups keeping their
// relative placement, and the up axis.
#include <catch2/catch.hpp>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <unistd.h>
#include <vector>
#include <glm/gtc/matrix_transform.hpp>
#include "infolerp/mesh/geometry.hpp"
#include "support/demo_scene.hpp"
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

namespace {

const support::embree_device& demo_device() {
  static const support::embree_device d;
  return d;
}

// A directory of this process for the files a test writes, removed with the object.
struct scratch_dir {
  std::filesystem::path path;
  explicit scratch_dir(const std::string& name)
      : path(std::filesystem::temp_directory_path() / ("infolerp_demo_support_" + std::to_string(::getpid())) / name) {
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~scratch_dir() { std::filesystem::remove_all(path.parent_path()); }
  scratch_dir(const scratch_dir&) = delete;
  scratch_dir& operator=(const scratch_dir&) = delete;
};

// An axis-aligned box lo..hi written as an OFF file at dir/name; returns its path.
std::string write_box_off(const std::filesystem::path& dir, const std::string& name, glm::vec3 lo, glm::vec3 hi) {
  const indexed_mesh box = support::make_box(lo, hi);
  const std::string path = (dir / name).string();
  std::ofstream out(path);
  out << "OFF\n" << box.vertex_count() << ' ' << box.triangle_count() << " 0\n";
  for (const glm::vec3& p : box.positions) out << p.x << ' ' << p.y << ' ' << p.z << '\n';
  for (const glm::uvec3& t : box.triangles) out << "3 " << t.x << ' ' << t.y << ' ' << t.z << '\n';
  return path;
}

const support::scene_object& object_named(const support::demo_scene& scene, const std::string& name) {
  for (const auto& object : scene.objects)
    if (object.name == name) return object;
  FAIL("no object named " << name);
  return scene.objects.front();
}

glm::dvec3 extent_of(const indexed_mesh& m) {
  const bounding_box b = mesh_bounds(m);
  return b.hi - b.lo;
}

}  // namespace

TEST_CASE("files of one --group keep their relative placement and scale; alone, each is fitted", "[demo][scene]") {
  const scratch_dir dir("group");
  // A body 4 long (along x) and a wheel of side 1 beside it, 3 units further along x.
  const std::string body = write_box_off(dir.path, "body.off", {0, 0, 0}, {4, 1, 2});
  const std::string wheel = write_box_off(dir.path, "wheel.off", {5, 0, 0}, {6, 1, 1});
  const float size = 2.0f;

  auto grouped = support::make_demo_scene(demo_device(), {.mesh_paths = {body, wheel}, .mesh_size = size, .mesh_groups = {"car", "car"}});
  REQUIRE(grouped);
  const glm::dvec3 b = extent_of(object_named(*grouped, body).mesh), w = extent_of(object_named(*grouped, wheel).mesh);
  const double s = size / 6.0;  // the group's largest extent, 6 along x, becomes `size`
  CHECK(b.x == Approx(4.0 * s));
  CHECK(w.x == Approx(1.0 * s));
  const bounding_box bb = mesh_bounds(object_named(*grouped, body).mesh), wb = mesh_bounds(object_named(*grouped, wheel).mesh);
  CHECK(wb.lo.x - bb.lo.x == Approx(5.0 * s));  // the wheel's offset, scaled with the body
  CHECK(wb.lo.z == Approx(bb.lo.z).margin(1e-6));  // both on the ground

  auto alone = support::make_demo_scene(demo_device(), {.mesh_paths = {body, wheel}, .mesh_size = size});
  REQUIRE(alone);
  CHECK(extent_of(object_named(*alone, body).mesh).x == Approx(size));
  CHECK(extent_of(object_named(*alone, wheel).mesh).x == Approx(size));  // each fitted alone
}

TEST_CASE("--up: a Y-up file is turned to the scene's Z-up, a Z-up file stays upright", "[demo][scene]") {
  const scratch_dir dir("up");
  const std::string tower = write_box_off(dir.path, "tower.off", {0, 0, 0}, {1, 4, 2});  // tallest along y
  auto y_up = support::make_demo_scene(demo_device(), {.mesh_paths = {tower}, .mesh_size = 4.0f});
  REQUIRE(y_up);
  const glm::dvec3 e = extent_of(object_named(*y_up, tower).mesh);
  CHECK(e.z == Approx(4.0));  // file y → scene z
  CHECK(e.y == Approx(2.0));  // file z → scene y (depth)
  auto z_up = support::make_demo_scene(demo_device(), {.mesh_paths = {tower}, .mesh_size = 4.0f, .z_up = true});
  REQUIRE(z_up);
  const glm::dvec3 f = extent_of(object_named(*z_up, tower).mesh);
  CHECK(f.y == Approx(4.0));
  CHECK(f.z == Approx(2.0));
  CHECK(mesh_bounds(object_named(*z_up, tower).mesh).lo.z == Approx(0.0).margin(1e-6));  // on the ground
}
