// Must NOT compile: the tracer lacks intersect(). tests/compile_fail/expect_one_error.cmake
// checks that the compiler reports exactly one error, the static_assert naming what is missing,
// although the visibility channel's body traces through the type.
#include <vector>
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/mesh/adaptors.hpp"

struct occlusion_only {
  bool occluded(const infolerp::ray&) const { return false; }
};

int main() {
  const std::vector<glm::vec3> positions{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<glm::uvec3> triangles{{0, 1, 2}};
  const infolerp::mesh_view m{.positions = positions, .triangles = triangles};
  infolerp::serial_executor exec;
  return infolerp::cluster_mesh(m, occlusion_only{}, exec, infolerp::visibility_channel{}).ok() ? 0 : 1;
}
