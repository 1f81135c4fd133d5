#pragma once
// Loading real meshes (OFF, OBJ, PLY, ... through assimp) for tests, benchmarks and examples.
#include <string>
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/adaptors.hpp"

namespace infolerp::support {

// Loads every mesh in the file into one indexed_mesh (triangulated, identical vertices joined).
// Errors: a missing or unreadable file, a file with no triangles; the message names the file.
// Broken files that assimp's importer accepts structurally invalid are rejected
// (aiProcess_ValidateDataStructure) instead of tripping its asserts.
result<indexed_mesh> load_mesh(const std::string& path);
// Reads an OFF file as written, without repairing it: polygons are fanned into triangles and
// vertex indices are kept as they are (out-of-range ones included), so that validate_mesh can
// name the bad triangle (assimp silently clamps such indices). Errors: a missing file, a bad
// header, a truncated or non-numeric vertex or face list, a face with fewer than 3 vertices;
// the message names the file and the line.
result<indexed_mesh> read_off(const std::string& path);
// Path of one of CGAL's meshes unpacked by cmake/install-deps.sh, e.g. cgal_mesh("bunny00").
std::string cgal_mesh(const std::string& name);

}  // namespace infolerp::support
