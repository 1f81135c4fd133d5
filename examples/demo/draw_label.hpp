#pragma once
// Text drawn into a demo image, so that a picture says what each of its panels shows.
// The glyphs are stb_easy_font's quads (Debian libstb-dev's system header; the examples may use
// it, include/ may not): each quad is an axis-aligned rectangle in units of one font pixel,
// filled here at an integer scale in white over a darkened box around the text.
//
//   void draw_label(support::image& img, int x, int y, const std::string& text, int scale);
//   int label_scale(int side);   // font pixels per image pixel for a panel of `side` pixels
//
// (x, y) is the top-left corner of the box in image pixels; '\n' starts a new line; printable
// ASCII only (the font's range); whatever falls outside the image is clipped.
// O(box pixels + characters); allocates the quad buffer (270 bytes per character, stb_easy_font's bound).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>
#include <stb/stb_easy_font.h>
#include "support/image.hpp"

namespace infolerp::demo {

namespace detail {
// Fills image pixels [x0, x1) × [y0, y1), clipped, with f(pixel).
template <class F>
void fill_rect(support::image& img, int x0, int y0, int x1, int y1, F f) {
  for (int y = std::max(0, y0); y < std::min(img.height, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(img.width, x1); ++x) img.at(x, y) = f(img.at(x, y));
}
}  // namespace detail

// One font pixel per 160 image pixels of a panel's side (text about 1/20 of the side high), at least 1.
inline int label_scale(int side) { return std::max(1, side / 160); }

inline void draw_label(support::image& img, int x, int y, const std::string& text, int scale) {
  std::vector<char> chars(text.begin(), text.end());
  chars.push_back('\0');
  std::vector<float> quads(270 / sizeof(float) * chars.size());
  const int count = stb_easy_font_print(0.0f, 0.0f, chars.data(), nullptr, quads.data(),
                                        static_cast<int>(quads.size() * sizeof(float)));
  const int pad = 2 * scale;
  detail::fill_rect(img, x, y, x + scale * stb_easy_font_width(chars.data()) + 2 * pad,
                    y + scale * stb_easy_font_height(chars.data()) + 2 * pad, [](glm::vec3 c) { return 0.25f * c; });
  // Each quad: four vertices of (x, y, z as float, colour as 4 bytes); its corners bound the rectangle.
  const float* v = quads.data();
  for (int q = 0; q < count; ++q, v += 16) {
    const float qx0 = std::min(v[0], v[8]), qx1 = std::max(v[0], v[8]);
    const float qy0 = std::min(v[1], v[9]), qy1 = std::max(v[1], v[9]);
    const auto px = [&](float f, int origin) { return origin + pad + scale * static_cast<int>(std::lround(f)); };
    detail::fill_rect(img, px(qx0, x), px(qy0, y), px(qx1, x), px(qy1, y), [](glm::vec3) { return glm::vec3(1.0f); });
  }
}

}  // namespace infolerp::demo
