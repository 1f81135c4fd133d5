// tests/support/image.hpp: sRGB curve, PNG round trip through stb, PSNR closed forms.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include "support/image.hpp"

#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STBI_ONLY_PNG
#include <stb/stb_image.h>

namespace support = infolerp::support;

TEST_CASE("sRGB transfer curve", "[image]") {
  CHECK(support::linear_to_srgb(0.0f) == 0.0f);
  CHECK(support::linear_to_srgb(1.0f) == Approx(1.0f));
  CHECK(support::linear_to_srgb(2.0f) == Approx(1.0f));    // clamped
  CHECK(support::linear_to_srgb(-1.0f) == 0.0f);
  CHECK(support::linear_to_srgb(NAN) == 0.0f);
  CHECK(support::linear_to_srgb(0.001f) == Approx(0.01292f));  // linear segment
  CHECK(support::to_srgb8(0.5f) == 188);                       // 0.7354 * 255
  for (float x = 0.0f; x <= 1.0f; x += 0.01f)
    CHECK(support::srgb_to_linear(support::linear_to_srgb(x)) == Approx(x).margin(1e-6));
}

TEST_CASE("PNG round trip through stb", "[image]") {
  support::image img(5, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) img.at(x, y) = {0.2f * static_cast<float>(x), 0.5f * static_cast<float>(y), 0.3f};
  const auto path = (std::filesystem::temp_directory_path() / "infolerp_test_image.png").string();
  REQUIRE(support::write_png(img, path).ok());
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &n, 3);
  REQUIRE(data != nullptr);
  CHECK(w == 5);
  CHECK(h == 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x)
      for (int c = 0; c < 3; ++c) CHECK(data[3 * (y * 5 + x) + c] == support::to_srgb8(img.at(x, y)[c]));
  stbi_image_free(data);
  std::filesystem::remove(path);

  CHECK_FALSE(support::write_png(img, "/nonexistent-dir/x.png").ok());
  CHECK_FALSE(support::write_png(support::image{}, path).ok());
}

TEST_CASE("PSNR closed forms and bad sizes", "[image]") {
  const support::image black(4, 4, glm::vec3(0.0f)), white(4, 4, glm::vec3(1.0f));
  CHECK(std::isinf(*support::psnr(black, black)));
  CHECK(*support::psnr(black, white) == Approx(0.0));  // MSE = 255²
  support::image half = black;
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 2; ++y) half.at(x, y) = glm::vec3(1.0f);
  CHECK(*support::psnr(black, half) == Approx(10.0 * std::log10(2.0)));
  // One 8-bit step in one channel of one pixel of 16: MSE = 1/48.
  support::image step = black;
  step.at(1, 1).g = support::srgb_to_linear(1.0f / 255.0f);
  CHECK(*support::psnr(black, step) == Approx(10.0 * std::log10(255.0 * 255.0 * 48.0)));
  CHECK_FALSE(support::psnr(black, support::image(4, 5)).ok());
  CHECK_FALSE(support::psnr(support::image{}, support::image{}).ok());
}
