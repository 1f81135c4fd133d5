#include "support/image.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

// Debian's libstb-dev ships the header and a libstb built from it; compiling the writer here
// keeps the build free of an extra link dependency. The header is a system header, so its own
// warnings do not trip -Werror.
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC  // private to this file: no clash if libstb is linked too
#include <stb/stb_image_write.h>

namespace infolerp::support {

float linear_to_srgb(float linear) {
  const float c = std::clamp(linear, 0.0f, 1.0f);  // NaN compares false: clamp keeps it, caught below
  if (!(c >= 0.0f)) return 0.0f;
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

float srgb_to_linear(float encoded) {
  const float c = std::clamp(encoded, 0.0f, 1.0f);
  if (!(c >= 0.0f)) return 0.0f;
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

unsigned char to_srgb8(float linear) {
  return static_cast<unsigned char>(std::lround(255.0f * linear_to_srgb(linear)));
}

namespace {
status check_image(const image& img, const char* what) {
  if (img.width <= 0 || img.height <= 0)
    return make_error(errc::empty_input, no_element, what, ": image is ", img.width, "x", img.height);
  if (img.pixels.size() != static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height))
    return make_error(errc::bad_size, no_element, what, ": ", img.pixels.size(), " pixels for a ", img.width, "x",
                      img.height, " image");
  return {};
}
}  // namespace

status write_png(const image& img, const std::string& path) {
  if (auto s = check_image(img, "write_png"); !s) return s;
  std::vector<unsigned char> bytes(img.pixels.size() * 3);
  for (std::size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) bytes[3 * i + static_cast<std::size_t>(c)] = to_srgb8(img.pixels[i][c]);
  if (stbi_write_png(path.c_str(), img.width, img.height, 3, bytes.data(), 3 * img.width) == 0)
    return make_error(errc::bad_parameter, no_element, "cannot write PNG '", path, "'");
  return {};
}

result<double> psnr(const image& a, const image& b) {
  if (auto s = check_image(a, "psnr"); !s) return s;
  if (auto s = check_image(b, "psnr"); !s) return s;
  if (a.width != b.width || a.height != b.height)
    return make_error(errc::bad_size, no_element, "psnr: ", a.width, "x", a.height, " vs ", b.width, "x", b.height);
  double sum = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = double(to_srgb8(a.pixels[i][c])) - double(to_srgb8(b.pixels[i][c]));
      sum += d * d;
    }
  const double mse = sum / (3.0 * static_cast<double>(a.pixels.size()));
  if (mse == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

}  // namespace infolerp::support
