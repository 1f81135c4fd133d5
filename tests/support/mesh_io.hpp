#pragma once
// Loading real meshes (OFF, OBJ, PLY, ... through assimp) for tests, benchmarks and examples,
// on users' files: never a crash. Sizes a header announces are checked against the file's size
// before anything is allocated for them, and assimp (whose 5.2 readers die or loop on some
// malformed PLY and glTF files) runs in a child process (in_child.hpp) that is killed after 2 s
// plus 1 s per MB; its death or hang is an error naming the file.
#include <memory>
#include <string>
#include <string_view>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "support/texture.hpp"

namespace infolerp::support {

// Loads every mesh in the file into one indexed_mesh (triangulated, identical vertices joined,
// node transforms applied as in load_textured_mesh; positions and triangles only).
// Errors: a missing or unreadable file, a file with no triangles; the message names the file.
// Broken files that assimp's importer accepts structurally invalid are rejected
// (aiProcess_ValidateDataStructure) instead of tripping its asserts.
result<indexed_mesh> load_mesh(const std::string& path);
// One material's triangles of a loaded asset: positions (node transforms applied), per-vertex
// normals when the file has them, per-corner texcoords (set 0) when it has them (one that is not
// finite is set to (0, 0) and counted in `note`), the material's diffuse colour and diffuse
// (glTF: base colour) texture. `note` says, when texcoords or the texture are missing, what is
// missing and why (for the demo's report), naming an OBJ material that no `mtllib` defines.
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
// name the bad triangle (assimp silently clamps such indices). The layout is free-form: tokens
// may be split over lines or share one; what follows a face's indices on their line is read as
// more faces when it is exactly whole faces and faces remain, otherwise as the face's colour
// (ignored). Errors: a missing file, a bad header, counts the file's size cannot hold (checked
// before allocating), a truncated or non-numeric vertex or face list, a face with fewer than 3
// vertices; the message names the file and the line. Memory: O(file size).
result<indexed_mesh> read_off(const std::string& path);
// The message of s without the library's "infolerp: " prefix, for messages that add context.
std::string_view bare_message(const status& s);
// s's error (same code and element) with "mesh 'PATH': " before its message.
status in_mesh(const status& s, const std::string& path);

// Path of one of CGAL's meshes unpacked by cmake/install-deps.sh, e.g. cgal_mesh("bunny00").
std::string cgal_mesh(const std::string& name);

}  // namespace infolerp::support
