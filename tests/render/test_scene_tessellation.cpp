// The demo scene tessellated for its view (clustering paper §4.1, demo_scene_options::tessellate):
// no triangle covers more than the asked share of the image afterwards (up to subdivision's
// level cap), texcoords stay per corner and normals per vertex, and a share outside [0, 1] is
// refused by name.
#include <catch2/catch.hpp>

#include <limits>
#include <string>
#include <glm/gtc/matrix_transform.hpp>
#include "infolerp/refine/subdivision_mesh.hpp"
#include "support/demo_scene.hpp"

using namespace infolerp;

TEST_CASE("demo scene tessellated for its view: no triangle above the share, attributes carried", "[scene][tessellate]") {
  const support::embree_device device;
  const auto plain = support::make_demo_scene(device);
  REQUIRE(plain);
  const float share = 0.002f;
  support::demo_scene_options options;
  options.tessellate = share;
  const auto tessellated = support::make_demo_scene(device, options);
  REQUIRE(tessellated);
  REQUIRE(tessellated->objects.size() == plain->objects.size());
  const support::camera& c = tessellated->view;
  const screen_fraction_test test{.view_projection = glm::perspective(glm::radians(c.vertical_fov_degrees), 1.0f, 0.05f, 1000.0f) *
                                                     glm::lookAt(c.eye, c.target, c.up),
                                  .max_fraction = share};
  std::size_t above_before = 0, above_after = 0, added = 0;
  for (std::size_t k = 0; k < plain->objects.size(); ++k) {
    const indexed_mesh& a = plain->objects[k].mesh;
    const indexed_mesh& b = tessellated->objects[k].mesh;
    for (const auto& t : a.triangles) above_before += test(a.positions[t.x], a.positions[t.y], a.positions[t.z]) ? 1u : 0u;
    for (const auto& t : b.triangles) above_after += test(b.positions[t.x], b.positions[t.y], b.positions[t.z]) ? 1u : 0u;
    added += b.triangle_count() - a.triangle_count();
    CHECK(b.has_texcoords() == a.has_texcoords());
    CHECK(b.has_normals() == a.has_normals());
  }
  CHECK(above_before > 0);  // the test means something: the plain scene has such triangles
  CHECK(above_after == 0);
  CHECK(added > 0);
  for (const float bad : {-0.1f, 1.5f, std::numeric_limits<float>::quiet_NaN()}) {
    options.tessellate = bad;
    const auto refused = support::make_demo_scene(device, options);
    REQUIRE_FALSE(refused);
    CHECK_THAT(std::string(refused.error().message()), Catch::Contains("tessellate = ") && Catch::Contains("a share of the image in [0, 1]"));
  }
}
