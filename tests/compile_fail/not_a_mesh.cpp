// Must NOT compile: the type lacks triangle(). ctest checks the compiler names what is missing.
#include <cstddef>
#include "infolerp/mesh/topology.hpp"

struct no_triangles {
  std::size_t vertex_count() const { return 0; }
  std::size_t triangle_count() const { return 0; }
  glm::vec3 position(std::size_t) const { return {}; }
};

int main() { return infolerp::make_topology(no_triangles{}).ok() ? 0 : 1; }
