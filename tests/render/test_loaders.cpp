// The loaders that the demo and examples run on users' files (mesh_io.hpp, texture.hpp): every
// malformed file of tests/data/loaders gets an error naming the file and what is wrong, never a
// crash or an allocation its size does not justify (a header's count is checked before anything
// is allocated for it: the sanitizer build fails on a request of terabytes); OFF's free-form layout; node transforms in
// both loaders; texcoords that are not finite; odd mip sizes that keep every texel.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <vector>
#include "support/mesh_io.hpp"
#include "support/texture.hpp"

using namespace infolerp;

namespace {

std::string data(const std::string& name) { return std::string(INFOLERP_TEST_DATA_DIR) + "/loaders/" + name; }

// The error message of a failed result (empty for a value).
template <class R>
std::string why(const R& r) {
  return r ? std::string() : std::string(r.error().message());
}

}  // namespace

TEST_CASE("loaders: malformed files get an error naming the file and the fault", "[loaders]") {
  struct bad_file {
    std::string name;
    std::string says;  // part of the message
  };
  const bad_file off[] = {{"huge_count.off", "1000000000000 vertices, 1 faces) need more than the file's 48 bytes"},
                          {"long_face.off", "face of 4000000000 vertices is longer than the file"},
                          {"not_a_number.off", "line 4: vertex coordinate is not a number"}};
  for (const auto& [name, says] : off) {
    INFO(name);
    const auto m = support::read_off(data(name));
    REQUIRE_FALSE(m);
    CHECK_THAT(why(m), Catch::Contains(data(name)) && Catch::Contains(says));
  }
  // Through assimp (load_mesh, load_textured_mesh): an OFF file is read by read_off first.
  const bad_file assimp[] = {{"huge_count.off", "1000000000000 vertices, 1 faces) need more than the file's 48 bytes"},
                             {"huge_count.ply", "1000000000000 elements 'vertex' need more than the file's 192 bytes"},
                             {"truncated.ply", "out of range"},
                             {"bad_index.ply", "out of range"},
                             {"bad_index.obj", "vertex index out of range"},
                             {"bad_accessor.gltf", "out of range"},
                             {"truncated.gltf", ""},
                             {"bad_chunk.glb", ""},
                             {"garbage_mtl.obj", "real number"}};
  for (const auto& [name, says] : assimp) {
    INFO(name);
    const auto m = support::load_mesh(data(name));
    REQUIRE_FALSE(m);
    CHECK_THAT(why(m), Catch::Contains(data(name)) && Catch::Contains(says));
    const auto parts = support::load_textured_mesh(data(name));
    REQUIRE_FALSE(parts);
    CHECK(why(parts) == why(m));
  }
}

TEST_CASE("loaders: a file that kills or hangs assimp's reader is an error, not a crash or a hang", "[loaders]") {
  // Found by tests/fuzz/fuzz_load_ply: assimp 5.2's PLY reader dies of a wild read on the first
  // and loops for ever on the second (its header never ends); both run in a child process.
  const auto killed = support::load_mesh(data("kills_assimp.ply"));
  REQUIRE_FALSE(killed);
  CHECK_THAT(why(killed), Catch::Contains(data("kills_assimp.ply")) && Catch::Contains("the file is malformed (the reader died: "));
  const auto hung = support::load_textured_mesh(data("hangs_assimp.ply"));
  REQUIRE_FALSE(hung);
  CHECK_THAT(why(hung), Catch::Contains(data("hangs_assimp.ply")) && Catch::Contains("it did not finish in 2000 ms"));
}

TEST_CASE("loaders: OFF is free-form; a face's colour is not a face", "[loaders]") {
  // Vertices two on a line and one split over lines, then two faces on one line.
  const auto free_form = support::read_off(data("free_form.off"));
  INFO(why(free_form));
  REQUIRE(free_form);
  CHECK(free_form->positions == std::vector<glm::vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}});
  CHECK(free_form->triangles == std::vector<glm::uvec3>{{0, 1, 2}, {1, 3, 2}});
  // Float and integer colours after the indices are ignored.
  const auto coloured = support::read_off(data("face_colours.off"));
  INFO(why(coloured));
  REQUIRE(coloured);
  CHECK(coloured->triangles == std::vector<glm::uvec3>{{0, 1, 2}, {1, 3, 2}});
}

TEST_CASE("loaders: node transforms are applied by load_mesh and load_textured_mesh alike", "[loaders]") {
  // One triangle instanced by two nodes: translated by +10 x, and by -10 x after scaling by 2.
  const std::vector<glm::vec3> want{{10, 0, 0}, {11, 0, 0}, {10, 1, 0}, {-10, 0, 0}, {-8, 0, 0}, {-10, 2, 0}};
  const auto m = support::load_mesh(data("two_nodes.gltf"));
  INFO(why(m));
  REQUIRE(m);
  CHECK(m->positions == want);
  CHECK(m->triangles == std::vector<glm::uvec3>{{0, 1, 2}, {3, 4, 5}});
  const auto parts = support::load_textured_mesh(data("two_nodes.gltf"));
  REQUIRE(parts);
  REQUIRE(parts->size() == 1);
  CHECK((*parts)[0].mesh.positions == want);
}

TEST_CASE("loaders: texcoords that are not finite are set to (0, 0) and counted", "[loaders]") {
  const auto parts = support::load_textured_mesh(data("nan_texcoords.gltf"));
  INFO(why(parts));
  REQUIRE(parts);
  REQUIRE(parts->size() == 1);
  const auto& part = (*parts)[0];
  REQUIRE(part.mesh.texcoords.size() == 3);
  for (const auto& uv : part.mesh.texcoords) CHECK((std::isfinite(uv.x) && std::isfinite(uv.y)));
  CHECK(part.mesh.texcoords[0] == glm::vec2(0.0f));
  CHECK(part.mesh.texcoords[1] == glm::vec2(0.0f));
  CHECK_THAT(part.note, Catch::Contains("2 texcoords not finite, set to (0, 0)"));
  // The lookup itself is defined for any texcoord: not finite reads as (0, 0).
  auto tex = support::texture::create(2, 2, {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}});
  REQUIRE(tex);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (const glm::vec2 uv : {glm::vec2(nan, 0.5f), glm::vec2(0.5f, inf), glm::vec2(-inf, nan)}) {
    CHECK(tex->bilinear(uv, 0) == tex->bilinear({0, 0}, 0));
    CHECK(tex->trilinear(uv, 0.5f) == tex->trilinear({0, 0}, 0.5f));
  }
}

TEST_CASE("loaders: an OBJ material that no library defines says so", "[loaders]") {
  const auto parts = support::load_textured_mesh(data("undefined_material.obj"));
  INFO(why(parts));
  REQUIRE(parts);
  REQUIRE(parts->size() == 2);
  CHECK((*parts)[0].material == "red");
  CHECK((*parts)[0].note == "no diffuse texture: solid colour");
  CHECK((*parts)[1].material == "ghost");
  CHECK((*parts)[1].note == "material 'ghost' is defined in no material library: solid colour");
}

TEST_CASE("texture: odd sizes keep every texel in the next mip level", "[loaders][texture]") {
  // 5 x 3 texels of value x + 10 y: level 1 is 2 x 1, level 2 1 x 1; every level's mean is
  // level 0's, so the last column and row count.
  std::vector<glm::vec3> t;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) t.push_back(glm::vec3(static_cast<float>(x + 10 * y)));
  auto tex = support::texture::create(5, 3, t);
  REQUIRE(tex);
  REQUIRE(tex->level_count() == 3);
  CHECK(tex->level(1).width == 2);
  CHECK(tex->level(1).height == 1);
  const float mean = 2.0f + 10.0f;  // mean of x over 0..4 plus 10 * mean of y over 0..2
  for (std::size_t k = 0; k < tex->level_count(); ++k) {
    const auto& l = tex->level(k);
    const glm::vec3 sum = std::accumulate(l.texels.begin(), l.texels.end(), glm::vec3(0.0f));
    CHECK(sum.x / static_cast<float>(l.texels.size()) == Approx(mean));
  }
  // Level 1's left texel covers columns 0, 1 and half of 2: (0 + 1 + 0.5 * 2) / 2.5 = 0.8.
  CHECK(tex->level(1).at(0, 0).x == Approx(0.8f + 10.0f));
  CHECK(tex->level(1).at(1, 0).x == Approx(3.2f + 10.0f));
  // A size above the limit is refused before anything is allocated for it.
  const auto huge = support::texture::create(1 << 14, 1 << 14, {});
  REQUIRE_FALSE(huge);
  CHECK_THAT(why(huge), Catch::Contains("16384x16384"));
}
