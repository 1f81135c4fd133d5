#include "support/texture.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <glm/common.hpp>
#include "support/image.hpp"

// The reader compiled here, private to this file, like the PNG writer in image.cpp. The
// header is a system header, so its own warnings do not trip -Werror.
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#include <stb/stb_image.h>

namespace infolerp::support {

namespace {

// The source texels under each of the n texels that replace m (n = max(1, m / 2)) and their
// shares of it: texel j of m covers [j n, (j + 1) n) and texel i of n covers [i m, (i + 1) m) in
// units of 1 / (m n), so every source texel counts by its exact overlap, an odd size's last row
// or column included (a 2x2 box for even sizes).
struct tap {
  int j;
  float w;
};
std::vector<std::vector<tap>> box_taps(int m, int n) {
  std::vector<std::vector<tap>> taps(static_cast<std::size_t>(n));
  const auto mm = static_cast<std::size_t>(m), nn = static_cast<std::size_t>(n);
  for (std::size_t i = 0; i < nn; ++i)
    for (std::size_t j = i * mm / nn; j * nn < (i + 1) * mm; ++j) {
      const std::size_t overlap = std::min((i + 1) * mm, (j + 1) * nn) - std::max(i * mm, j * nn);
      taps[i].push_back({static_cast<int>(j), static_cast<float>(overlap) / static_cast<float>(mm)});
    }
  return taps;
}

// The next level: every texel the area-weighted mean of the texels above it.
texture_level halve(const texture_level& a) {
  texture_level b;
  b.width = std::max(1, a.width / 2);
  b.height = std::max(1, a.height / 2);
  b.texels.resize(static_cast<std::size_t>(b.width) * static_cast<std::size_t>(b.height));
  const auto xs = box_taps(a.width, b.width), ys = box_taps(a.height, b.height);
  for (int y = 0; y < b.height; ++y)
    for (int x = 0; x < b.width; ++x) {
      glm::vec3 sum(0.0f);
      for (const tap& ty : ys[static_cast<std::size_t>(y)])
        for (const tap& tx : xs[static_cast<std::size_t>(x)]) sum += ty.w * tx.w * a.at(tx.j, ty.j);
      b.texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(b.width) + static_cast<std::size_t>(x)] = sum;
    }
  return b;
}

int wrap(int i, int n) {
  const int m = i % n;
  return m < 0 ? m + n : m;
}

// An image of w x h texels that texture::create accepts, checked before it is decoded.
status check_size(int w, int h, const std::string& name) {
  if (w > 0 && h > 0 && static_cast<std::size_t>(w) * static_cast<std::size_t>(h) <= texture::max_texels) return {};
  return make_error(errc::bad_size, no_element, "texture '", name, "' is ", w, "x", h, " texels (at most ", texture::max_texels,
                    " texels)");
}

result<texture> from_stb(unsigned char* data, int w, int h, const std::string& name) {
  if (data == nullptr)
    return make_error(errc::bad_parameter, no_element, "cannot read texture '", name, "': ", stbi_failure_reason());
  std::vector<glm::vec3> texels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  for (std::size_t i = 0; i < texels.size(); ++i)
    for (int c = 0; c < 3; ++c) texels[i][c] = srgb_to_linear(static_cast<float>(data[3 * i + static_cast<std::size_t>(c)]) / 255.0f);
  stbi_image_free(data);
  return texture::create(w, h, std::move(texels));
}

}  // namespace

result<texture> texture::create(int width, int height, std::vector<glm::vec3> texels) {
  if (auto s = check_size(width, height, "(in memory)"); !s) return s;
  if (texels.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
    return make_error(errc::bad_size, no_element, "texture: ", width, "x", height, " with ", texels.size(), " texels");
  texture t;
  t.levels_.push_back({width, height, std::move(texels)});
  while (t.levels_.back().width > 1 || t.levels_.back().height > 1) t.levels_.push_back(halve(t.levels_.back()));
  return t;
}

glm::vec3 texture::bilinear(glm::vec2 uv, std::size_t k) const {
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f);
  const texture_level& l = levels_[std::min(k, levels_.size() - 1)];
  // Texel centres at (i + 0.5) / width; v = 0 is the bottom row.
  const float fx = (uv.x - std::floor(uv.x)) * static_cast<float>(l.width) - 0.5f;
  const float fy = (1.0f - (uv.y - std::floor(uv.y))) * static_cast<float>(l.height) - 0.5f;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float ax = fx - x0f, ay = fy - y0f;
  const int x0 = wrap(static_cast<int>(x0f), l.width), x1 = wrap(static_cast<int>(x0f) + 1, l.width);
  const int y0 = wrap(static_cast<int>(y0f), l.height), y1 = wrap(static_cast<int>(y0f) + 1, l.height);
  return glm::mix(glm::mix(l.at(x0, y0), l.at(x1, y0), ax), glm::mix(l.at(x0, y1), l.at(x1, y1), ax), ay);
}

glm::vec3 texture::trilinear(glm::vec2 uv, float lod) const {
  if (!(lod > 0.0f)) return bilinear(uv, 0);  // NaN too
  const float top = static_cast<float>(levels_.size() - 1);
  if (lod >= top) return bilinear(uv, levels_.size() - 1);
  const float k = std::floor(lod);
  const auto ki = static_cast<std::size_t>(k);
  return glm::mix(bilinear(uv, ki), bilinear(uv, ki + 1), lod - k);
}

result<texture> load_texture(const std::string& path) {
  int w = 0, h = 0, n = 0;
  if (stbi_info(path.c_str(), &w, &h, &n) != 0)
    if (auto s = check_size(w, h, path); !s) return s;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &n, 3);  // before w and h are read
  return from_stb(data, w, h, path);
}

result<texture> decode_texture(std::span<const unsigned char> bytes, const std::string& name) {
  if (bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    return make_error(errc::bad_size, no_element, "texture '", name, "' is ", bytes.size(), " bytes (at most 2^31 - 1)");
  int w = 0, h = 0, n = 0;
  const auto size = static_cast<int>(bytes.size());
  if (stbi_info_from_memory(bytes.data(), size, &w, &h, &n) != 0)
    if (auto s = check_size(w, h, name); !s) return s;
  unsigned char* data = stbi_load_from_memory(bytes.data(), size, &w, &h, &n, 3);
  return from_stb(data, w, h, name);
}

}  // namespace infolerp::support
