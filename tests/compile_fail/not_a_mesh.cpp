// Must NOT compile: the type lacks triangle_count(). tests/compile_fail/expect_one_error.cmake
// checks that the compiler reports exactly one error, the static_assert naming what is missing,
// however many entry points (each reading the mesh in its body) are called with the type.
#include <cstddef>
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/mesh/topology.hpp"
#include "infolerp/mesh/validate.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"

struct no_triangle_count {
  std::size_t vertex_count() const { return 0; }
  glm::vec3 position(std::size_t) const { return {}; }
  glm::uvec3 triangle(std::size_t) const { return {}; }
};

int main() {
  const no_triangle_count m;
  infolerp::serial_executor exec;
  bool ok = infolerp::make_topology(m).ok() && infolerp::validate_mesh(m).ok();
  ok = ok && infolerp::compute_saliency(m, {}, exec).ok();
  ok = ok && infolerp::cluster_mesh(m, infolerp::no_tracer{}, exec, infolerp::orientation_channel{.threshold = 0.02}).ok();
  return ok ? 0 : 1;
}
