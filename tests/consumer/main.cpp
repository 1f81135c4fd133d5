// A consumer of the installed (or add_subdirectory'd) library: two triangles sharing an edge.
#include <vector>
#include "infolerp/infolerp.hpp"

int main() {
  const std::vector<glm::vec3> positions{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  const std::vector<glm::uvec3> triangles{{0, 1, 2}, {2, 1, 3}};
  const auto topo = infolerp::make_topology(infolerp::mesh_view{positions, triangles});
  return topo.ok() && topo->neighbours_of(0).size() == 1 && topo->edge_count() == 5 ? 0 : 1;
}
