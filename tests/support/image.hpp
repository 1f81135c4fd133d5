#pragma once
// RGB float images for the demo, tests and the time-against-error harness: linear values in,
// sRGB PNG out (through stb_image_write), PSNR on the displayed 8-bit-range values.
#include <cstddef>
#include <string>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"

namespace infolerp::support {

// Row-major linear RGB, (0,0) at the top-left. Values are radiance-like: any float; PNG writing
// and PSNR clamp to [0, 1].
struct image {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> pixels;

  image() = default;
  image(int w, int h, glm::vec3 fill = glm::vec3(0.0f))
      : width(w), height(h), pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill) {}
  glm::vec3& at(int x, int y) { return pixels[index(x, y)]; }
  const glm::vec3& at(int x, int y) const { return pixels[index(x, y)]; }
  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
  }
};

// The sRGB transfer curve (IEC 61966-2-1), per channel, on values clamped to [0, 1].
float linear_to_srgb(float linear);
float srgb_to_linear(float encoded);
// Display encoding used for PNG and PSNR: clamp to [0,1], sRGB curve, round to 8 bits.
unsigned char to_srgb8(float linear);

// Writes an 8-bit sRGB PNG (linear values are encoded with linear_to_srgb). The directory must
// exist. Errors: an empty image, a pixel count that does not match the size, a write failure
// (the message names the path).
status write_png(const image& img, const std::string& path);

// Peak signal-to-noise ratio in dB between two images as displayed (8-bit sRGB, peak 255, mean
// squared error over all pixels and channels). +inf for identical displays.
// Errors: sizes differ, or an empty image. O(pixels), no allocation.
result<double> psnr(const image& a, const image& b);

}  // namespace infolerp::support
