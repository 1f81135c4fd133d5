// subdivision_mesh::leaf_mesh(source, leaf_source): the tessellated mesh keeps the input's
// texcoords, normals and keyframe positions, and every leaf names its original triangle.
// Checked against analytic values: on a plane whose texcoords, normals and keyframes are
// affine functions of position, every new corner must carry the function of its position.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/refine/subdivision_mesh.hpp"
#include "support/procedural.hpp"

namespace {

// make_plane's texcoords: uv = position.xy / size + 0.5.
glm::vec2 plane_uv(glm::vec3 p, float size) { return glm::vec2(p.x, p.y) / size + 0.5f; }
// Keyframe 1: the plane tilted and moved, an affine map of the rest position.
glm::vec3 keyframe1(glm::vec3 p) { return {2.0f * p.x + 1.0f, p.y - 0.5f * p.x, 0.25f * p.y + 3.0f}; }

}  // namespace

TEST_CASE("leaf_mesh keeps texcoords, normals and keyframes, and names each leaf's source", "[refine][leaf_mesh]") {
  constexpr float size = 4.0f;
  infolerp::indexed_mesh m = infolerp::support::make_plane(3, 2, size);
  m.normals.assign(m.positions.size(), glm::vec3(0.0f, 0.0f, 1.0f));
  m.keyframes.push_back(m.positions);
  m.keyframes.emplace_back();
  for (const auto& p : m.positions) m.keyframes[1].push_back(keyframe1(p));
  auto s = infolerp::subdivision_mesh::create(m);
  REQUIRE(s);
  REQUIRE(s->split(0));
  REQUIRE(s->split(7));
  const std::uint32_t first_child = s->triangle(0).first_child;
  REQUIRE(s->split(first_child));  // a second level
  std::vector<std::uint32_t> source;
  auto leaves = s->leaf_mesh(m, source);
  REQUIRE(leaves);
  const infolerp::indexed_mesh& l = *leaves;
  REQUIRE(l.triangle_count() == s->leaf_count());
  REQUIRE(l.triangle_count() > m.triangle_count());
  REQUIRE(source.size() == l.triangle_count());
  REQUIRE(l.has_texcoords());
  REQUIRE(l.has_normals());
  REQUIRE(l.keyframe_count() == 2);
  for (std::size_t i = 0; i < l.triangle_count(); ++i) {
    INFO("leaf " << i << " from " << source[i]);
    // The leaf lies in its source triangle: its centroid's weights there are all >= 0.
    const glm::uvec3 o = m.triangles[source[i]];
    const glm::vec3 c = (l.positions[l.triangles[i].x] + l.positions[l.triangles[i].y] + l.positions[l.triangles[i].z]) / 3.0f;
    const glm::vec3 a = m.positions[o.x], e1 = m.positions[o.y] - a, e2 = m.positions[o.z] - a;
    const float area = glm::cross(e1, e2).z;
    const float u = glm::cross(c - a, e2).z / area, w = glm::cross(e1, c - a).z / area;
    CHECK(u >= -1e-6f);
    CHECK(w >= -1e-6f);
    CHECK(u + w <= 1.0f + 1e-6f);
    for (unsigned k = 0; k < 3; ++k) {
      const glm::vec3 p = l.positions[l.triangles[i][static_cast<int>(k)]];
      CHECK(glm::length(l.texcoord(i, k) - plane_uv(p, size)) < 1e-6f);
    }
  }
  for (std::size_t v = 0; v < l.vertex_count(); ++v) {
    INFO("vertex " << v);
    CHECK(l.normals[v] == glm::vec3(0.0f, 0.0f, 1.0f));
    CHECK(glm::length(l.keyframes[0][v] - l.positions[v]) < 1e-6f);
    CHECK(glm::length(l.keyframes[1][v] - keyframe1(l.positions[v])) < 1e-5f);
  }
  SECTION("triangle 0's leaves all name it") {
    std::size_t from_zero = 0;
    for (std::size_t i = 0; i < l.triangle_count(); ++i) from_zero += source[i] == 0 ? 1 : 0;
    CHECK(from_zero > 4);  // triangle 0 was split twice: more than its four first children
  }
  SECTION("a different source mesh or a short keyframe is named") {
    infolerp::indexed_mesh other = infolerp::support::make_plane(2, 2, size);
    auto wrong = s->leaf_mesh(other, source);
    REQUIRE(!wrong);
    CHECK(wrong.error().code() == infolerp::errc::bad_size);
    infolerp::indexed_mesh short_frame = m;
    short_frame.keyframes[1].pop_back();
    auto shrt = s->leaf_mesh(short_frame, source);
    REQUIRE(!shrt);
    CHECK(shrt.error().message().find("keyframe 1") != std::string::npos);
  }
}
