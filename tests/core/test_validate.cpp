// mesh/validate.hpp: each error class with its element index, options, and a garbage fuzz loop.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include "infolerp/mesh/validate.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"

namespace {
using infolerp::errc;
infolerp::indexed_mesh quad() {  // two triangles sharing edge (0, 2)
  infolerp::indexed_mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}
}  // namespace

TEST_CASE("valid meshes pass") {
  CHECK(infolerp::validate_mesh(quad()).ok());
  CHECK(infolerp::validate_mesh(infolerp::support::make_icosphere(3)).ok());
  CHECK(infolerp::validate_mesh(infolerp::support::make_torus(16, 8, 1.0f, 0.3f)).ok());
  CHECK(infolerp::validate_mesh(infolerp::support::make_box({0, 0, 0}, {1, 2, 3})).ok());
  auto elephant = infolerp::support::load_mesh(infolerp::support::cgal_mesh("refined_elephant"));
  REQUIRE(elephant.ok());
  CHECK(infolerp::validate_mesh(*elephant).ok());
}

TEST_CASE("each error class names its element") {
  SECTION("empty") {
    infolerp::indexed_mesh m;
    CHECK(infolerp::validate_mesh(m).code() == errc::empty_input);
    m.positions = {{0, 0, 0}};
    CHECK(infolerp::validate_mesh(m).code() == errc::empty_input);
  }
  SECTION("index out of range") {
    auto m = quad();
    m.triangles[1] = {0, 2, 4};
    const auto s = infolerp::validate_mesh(m);
    CHECK(s.code() == errc::index_out_of_range);
    CHECK(s.element() == 1);
    CHECK(s.message().find("triangle 1 corner 2") != std::string::npos);
    m.triangles[0] = {0xffffffffu, 1, 2};
    CHECK(infolerp::validate_mesh(m).element() == 0);
  }
  SECTION("non-finite positions: used vertices, or all with check_unused_vertices") {
    auto m = quad();
    m.positions[3].y = std::numeric_limits<float>::quiet_NaN();
    auto s = infolerp::validate_mesh(m);
    CHECK(s.code() == errc::non_finite);
    CHECK(s.element() == 3);
    CHECK(s.message().find("vertex 3") != std::string::npos);
    m = quad();
    m.positions.push_back({std::numeric_limits<float>::infinity(), 0, 0});  // vertex 4, unused
    CHECK(infolerp::validate_mesh(m).ok());
    s = infolerp::validate_mesh(m, {.check_unused_vertices = true});
    CHECK(s.code() == errc::non_finite);
    CHECK(s.element() == 4);
  }
  SECTION("degenerate triangles: repeated index, zero area; allowed by option") {
    auto m = quad();
    m.triangles.push_back({1, 2, 1});
    auto s = infolerp::validate_mesh(m);
    CHECK(s.code() == errc::degenerate_triangle);
    CHECK(s.element() == 2);
    CHECK(infolerp::validate_mesh(m, {.allow_degenerate = true}).ok());
    m = quad();
    m.positions.push_back({2, 2, 0});  // 4: collinear with 0 and 2
    m.triangles.push_back({0, 2, 4});
    s = infolerp::validate_mesh(m);
    CHECK(s.code() == errc::degenerate_triangle);
    CHECK(s.element() == 2);
    CHECK(s.message().find("zero area") != std::string::npos);
    // Tiny but not zero is not degenerate.
    m = quad();
    for (auto& p : m.positions) p *= 1e-30f;
    CHECK(infolerp::validate_mesh(m).ok());
  }
  SECTION("non-manifold edges; allowed by option") {
    auto m = quad();
    m.positions.push_back({0.5f, 0.5f, 1.0f});
    m.triangles.push_back({2, 0, 4});  // third triangle on edge (0, 2)
    m.triangles.push_back({1, 3, 4});
    auto s = infolerp::validate_mesh(m);
    CHECK(s.code() == errc::non_manifold_edge);
    CHECK(s.element() == 2);
    CHECK(s.message().find("edge (0, 2) is shared by 3 triangles (0, 1, 2)") != std::string::npos);
    CHECK(infolerp::validate_mesh(m, {.allow_non_manifold = true}).ok());
  }
  SECTION("checks run in the documented order") {
    auto m = quad();
    m.triangles.push_back({1, 1, 2});                                  // degenerate
    m.positions[0].x = std::numeric_limits<float>::quiet_NaN();        // non-finite
    CHECK(infolerp::validate_mesh(m).code() == errc::non_finite);
    m.triangles.push_back({0, 1, 9});                                  // out of range
    CHECK(infolerp::validate_mesh(m).code() == errc::index_out_of_range);
  }
}

TEST_CASE("strided views of raw engine buffers validate too") {
  const float xyzw[] = {0, 0, 0, 9, 1, 0, 0, 9, 1, 1, 0, 9};  // stride 16 bytes
  const std::uint32_t good[] = {0, 1, 2}, bad[] = {0, 1, 3};
  auto view = infolerp::make_strided_mesh_view(xyzw, 3, 16, good, 3);
  REQUIRE(view.ok());
  CHECK(infolerp::validate_mesh(*view).ok());
  auto broken = infolerp::make_strided_mesh_view(xyzw, 3, 16, bad, 3);
  REQUIRE(broken.ok());
  CHECK(infolerp::validate_mesh(*broken).code() == errc::index_out_of_range);
}

TEST_CASE("garbage never crashes validation") {
  std::mt19937 rng(1234);
  int failures[16] = {};
  for (int trial = 0; trial < 3000; ++trial) {
    infolerp::indexed_mesh m;
    const std::size_t nv = rng() % 12, nt = rng() % 12;
    for (std::size_t v = 0; v < nv; ++v) {
      glm::vec3 p;
      if (rng() % 4 == 0) {
        const std::uint32_t bits[3] = {static_cast<std::uint32_t>(rng()), static_cast<std::uint32_t>(rng()),
                                       static_cast<std::uint32_t>(rng())};
        std::memcpy(&p, bits, sizeof p);  // any bit pattern: NaN, Inf, subnormal, huge
      } else {
        p = glm::vec3(static_cast<float>(rng() % 5), static_cast<float>(rng() % 5), static_cast<float>(rng() % 3));
      }
      m.positions.push_back(p);
    }
    for (std::size_t t = 0; t < nt; ++t) {
      const std::uint32_t range = rng() % 8 == 0 ? 0xffffffffu : static_cast<std::uint32_t>(nv + 1);
      m.triangles.push_back({rng() % range, rng() % range, rng() % range});
    }
    const auto s = infolerp::validate_mesh(m, {.check_unused_vertices = rng() % 2 == 0});
    ++failures[static_cast<int>(s.code())];
    if (!s.ok()) {
      CHECK(s.message().rfind("infolerp: validate_mesh: ", 0) == 0);
      if (s.code() == errc::index_out_of_range || s.code() == errc::degenerate_triangle || s.code() == errc::non_manifold_edge)
        CHECK(s.element() < nt);
      if (s.code() == errc::non_finite) CHECK(s.element() < nv);
    }
  }
  // The generator reaches every outcome.
  for (errc c : {errc::ok, errc::empty_input, errc::index_out_of_range, errc::non_finite, errc::degenerate_triangle,
                 errc::non_manifold_edge})
    CHECK(failures[static_cast<int>(c)] > 0);
}
