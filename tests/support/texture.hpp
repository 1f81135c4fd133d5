#pragma once
// Image textures for the demo scene: an RGB image in linear colour with its mip chain (each
// level a 2x2 box filter of the one above, down to 1x1), looked up bilinearly on one level or
// trilinearly between the two levels the sample footprint falls between (Williams 1983).
// Texcoords repeat (wrap) in both directions; v = 0 is the image's bottom row, as in OBJ and
// in assimp's glTF import. Images are read with stb_image (PNG, JPEG, TGA, BMP, ...) from a file
// or from memory (a GLB's embedded images); 8-bit values are sRGB and decoded to linear.
#include <cstddef>
#include <span>
#include <string>
#include <vector>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"

namespace infolerp::support {

struct texture_level {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> texels;  // row-major, row 0 at the top of the image (v = 1)
  glm::vec3 at(int x, int y) const { return texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)]; }
};

class texture {
 public:
  static constexpr std::size_t max_texels = std::size_t{1} << 26;  // 8192 x 8192: level 0 768 MiB

  // The image (linear RGB, width x height texels, row 0 on top) and its mip chain.
  // Errors: a non-positive size, more than max_texels or texels.size() != width * height (bad_size).
  static result<texture> create(int width, int height, std::vector<glm::vec3> texels);

  int width() const { return levels_.front().width; }
  int height() const { return levels_.front().height; }
  std::size_t level_count() const { return levels_.size(); }
  const texture_level& level(std::size_t k) const { return levels_[k]; }

  // Bilinear lookup on mip level k (clamped to the chain), wrapping texcoords. O(1).
  glm::vec3 bilinear(glm::vec2 uv, std::size_t k) const;
  // Trilinear lookup: lod = log2 of the sample footprint in level-0 texels; lod <= 0 is level 0
  // (magnification, bilinear), otherwise a blend of levels floor(lod) and floor(lod) + 1. O(1).
  glm::vec3 trilinear(glm::vec2 uv, float lod) const;

 private:
  std::vector<texture_level> levels_;
};

// Reads an image file. Errors: unreadable or undecodable file (the message names it and gives
// stb_image's reason), an image above max_texels (bad_size, before it is decoded).
result<texture> load_texture(const std::string& path);
// Decodes an image held in memory (a compressed PNG/JPEG/...); name is for the error message.
result<texture> decode_texture(std::span<const unsigned char> bytes, const std::string& name);

}  // namespace infolerp::support
