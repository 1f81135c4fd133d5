#pragma once
// A generated textured asset, written to disk as OBJ + MTL + PNG, glTF 2.0 (+ .bin + PNG), GLB or
// PLY for tests and benchmarks that load real files (support/mesh_io.hpp):
//   a bumpy sphere made of the six faces of a cube (cells x cells quads each, split in two
//   triangles), each face its own texture chart: chart f is a padded tile of the atlas of
//   material f % materials (tile f / materials of ceil(6 / materials) side by side). Charts
//   meet at UV seams along the cube's edges, where the vertices are duplicated as exporters do.
//   Every material has its own procedural texture (bricks, checker, rings), detailed enough for
//   its mip levels to matter at demo distances.
// Deterministic: the same options give the same bytes.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "support/image.hpp"

namespace infolerp::support {

struct textured_asset_options {
  unsigned cells = 66;         // quads per cube face side: 12 * cells² triangles (66: 52272)
  unsigned materials = 3;      // 1..6
  int texture_size = 512;      // each material's texture is texture_size² texels
};

struct textured_asset {
  indexed_mesh mesh;                     // Y-up, radius about 1; normals per vertex, texcoords per corner
  std::vector<std::uint32_t> material;   // per triangle
  std::vector<std::uint32_t> chart;      // per triangle, 0..5 (the cube face)
  std::vector<image> textures;           // per material, linear RGB; each texel an exact 8-bit sRGB value
  unsigned charts = 6;
  // The chart whose padded tile holds texcoord uv (wrapping), or charts when none (padding).
  std::uint32_t chart_at(glm::vec2 uv, std::uint32_t material_id) const;
  unsigned materials = 0;
  unsigned tiles = 0;                    // tiles side by side per atlas
};

textured_asset make_textured_asset(const textured_asset_options& options = {});

// DIR/NAME.obj, DIR/NAME.mtl and DIR/NAME_K.png (one per material, map_Kd); returns the OBJ's
// path. Triangles are written grouped by material (usemtl), in triangle order within each.
// Errors: the directory or a file cannot be written (the message names it).
result<std::string> write_obj(const textured_asset& asset, const std::filesystem::path& dir, const std::string& name);
// DIR/NAME.gltf, DIR/NAME.bin and the same PNGs; one primitive per material (the same order),
// unindexed corners. Returns the .gltf's path. Errors: as write_obj.
result<std::string> write_gltf(const textured_asset& asset, const std::filesystem::path& dir, const std::string& name);
// DIR/NAME.ply (ASCII; per-vertex texcoords s, t; "comment TextureFile NAME_0.png"): PLY has
// no materials, so the whole mesh takes material 0's texture. Returns its path.
result<std::string> write_ply(const textured_asset& asset, const std::filesystem::path& dir, const std::string& name);
// DIR/NAME.glb: the same document as one binary file, the PNGs embedded. Returns its path.
result<std::string> write_glb(const textured_asset& asset, const std::filesystem::path& dir, const std::string& name);

}  // namespace infolerp::support
