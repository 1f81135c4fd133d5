#pragma once
// Loading real meshes (OFF, OBJ, PLY, ... through assimp) for tests, benchmarks and examples.
#include <memory>
#include <string>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "support/texture.hpp"

namespace infolerp::support {

// Loads every mesh in the file into one indexed_mesh (triangulated, identical vertices joined).
// Errors: a missing or unreadable file, a file with no triangles; the message names the file.
// Broken files that assimp's importer accepts structurally invalid are rejected
// (aiProcess_ValidateDataStructure) instead of tripping its asserts.
result<indexed_mesh> load_mesh(const std::string& path);
// One material's triangles of a loaded asset: positions (node transforms applied), per-vertex
// normals when the file has them, per-corner texcoords (set 0) when it has them, the
// material's diffuse colour and diffuse (glTF: base colour) texture. `note` says, when
// texcoords or the texture are missing, what is missing and why (for the demo's report).
struct textured_part {
  std::string material;                    // the material's name, or "material K"
  indexed_mesh mesh;
  glm::vec3 diffuse{0.8f};                 // linear RGB factor (multiplies the texture)
  std::shared_ptr<const texture> image;    // null: no diffuse texture
  std::string note;
};

// Loads an asset (OBJ + MTL, glTF 2.0 / GLB, PLY, OFF, ... through assimp) as one part per
// material that has triangles, in material order. Texture paths are relative to the asset's
// directory; "*K" names the K-th image embedded in the file. A texture that cannot be read is
// an error (the message names it); an absent one is not (note says so).
// Errors: those of load_mesh, an unreadable texture.
result<std::vector<textured_part>> load_textured_mesh(const std::string& path);

// Reads an OFF file as written, without repairing it: polygons are fanned into triangles and
// vertex indices are kept as they are (out-of-range ones included), so that validate_mesh can
// name the bad triangle (assimp silently clamps such indices). Errors: a missing file, a bad
// header, a truncated or non-numeric vertex or face list, a face with fewer than 3 vertices;
// the message names the file and the line.
result<indexed_mesh> read_off(const std::string& path);
// Path of one of CGAL's meshes unpacked by cmake/install-deps.sh, e.g. cgal_mesh("bunny00").
std::string cgal_mesh(const std::string& name);

}  // namespace infolerp::support
