#pragma once
// Loading real meshes (OFF, OBJ, PLY, ... through assimp) for tests, benchmarks and examples.
#include <string>
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/adaptors.hpp"

namespace infolerp::support {

// Loads every mesh in the file into one indexed_mesh (triangulated, identical vertices joined).
// Errors: a missing or unreadable file, a file with no triangles; the message names the file.
result<indexed_mesh> load_mesh(const std::string& path);
// Path of one of CGAL's meshes unpacked by cmake/install-deps.sh, e.g. cgal_mesh("bunny00").
std::string cgal_mesh(const std::string& name);

}  // namespace infolerp::support
