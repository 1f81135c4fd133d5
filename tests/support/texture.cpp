#include "support/texture.hpp"

#include <algorithm>
#include <cmath>
#include <glm/common.hpp>
#include "support/image.hpp"

// The reader compiled here, private to this file, like the PNG writer in image.cpp. The
// header is a system header, so its own warnings do not trip -Werror.
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#include <stb/stb_image.h>

namespace infolerp::support {

namespace {

// The next level: every texel the mean of the (up to) 2x2 texels above it.
texture_level halve(const texture_level& a) {
  texture_level b;
  b.width = std::max(1, a.width / 2);
  b.height = std::max(1, a.height / 2);
  b.texels.resize(static_cast<std::size_t>(b.width) * static_cast<std::size_t>(b.height));
  for (int y = 0; y < b.height; ++y)
    for (int x = 0; x < b.width; ++x) {
      const int x0 = std::min(2 * x, a.width - 1), x1 = std::min(2 * x + 1, a.width - 1);
      const int y0 = std::min(2 * y, a.height - 1), y1 = std::min(2 * y + 1, a.height - 1);
      b.texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(b.width) + static_cast<std::size_t>(x)] =
          0.25f * (a.at(x0, y0) + a.at(x1, y0) + a.at(x0, y1) + a.at(x1, y1));
    }
  return b;
}

int wrap(int i, int n) {
  const int m = i % n;
  return m < 0 ? m + n : m;
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
  if (width <= 0 || height <= 0 || texels.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
    return make_error(errc::bad_size, no_element, "texture: ", width, "x", height, " with ", texels.size(), " texels");
  texture t;
  t.levels_.push_back({width, height, std::move(texels)});
  while (t.levels_.back().width > 1 || t.levels_.back().height > 1) t.levels_.push_back(halve(t.levels_.back()));
  return t;
}

glm::vec3 texture::bilinear(glm::vec2 uv, std::size_t k) const {
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
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &n, 3);  // before w and h are read
  return from_stb(data, w, h, path);
}

result<texture> decode_texture(std::span<const unsigned char> bytes, const std::string& name) {
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load_from_memory(bytes.data(), static_cast<int>(bytes.size()), &w, &h, &n, 3);
  return from_stb(data, w, h, name);
}

}  // namespace infolerp::support
