#pragma once
// Structural similarity (SSIM), Wang, Bovik, Sheikh, Simoncelli, "Image quality assessment: from
// error visibility to structural similarity", IEEE TIP 13(4), 2004, Eq. (13) with the paper's
// settings: 11×11 circular-symmetric Gaussian window, σ = 1.5, normalised to unit sum;
// K1 = 0.01, K2 = 0.03, dynamic range L = 1 (values in [0, 1]); the mean SSIM (Eq. 17) over all
// window positions that fit inside the image ("valid" windows, as the authors' ssim_index.m).
// Computed in double with the Gaussian applied separably (rows, then columns).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>
#include "infolerp/core/status.hpp"

namespace infolerp::support {

inline constexpr int ssim_window = 11;

// The normalised 1D Gaussian (σ = 1.5) whose outer product is the 11×11 window.
inline std::array<double, ssim_window> ssim_gaussian() {
  std::array<double, ssim_window> g{};
  double sum = 0.0;
  for (int i = 0; i < ssim_window; ++i) {
    const double d = i - ssim_window / 2;
    g[static_cast<std::size_t>(i)] = std::exp(-d * d / (2.0 * 1.5 * 1.5));
    sum += g[static_cast<std::size_t>(i)];
  }
  for (auto& v : g) v /= sum;
  return g;
}

// Mean SSIM of two single-channel images (row-major width×height, values in [0, 1], e.g. luma).
// 1 for identical images. Errors: sizes differ from width·height, or a side below 11.
// O(width·height·22), allocates five filtered planes.
inline result<double> ssim(std::span<const float> a, std::span<const float> b, int width, int height) {
  if (width < ssim_window || height < ssim_window)
    return make_error(errc::bad_size, no_element, "ssim: image ", width, "x", height, " smaller than the 11x11 window");
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (a.size() != n || b.size() != n)
    return make_error(errc::bad_size, no_element, "ssim: images have ", a.size(), " and ", b.size(), " pixels, ",
                      width, "x", height, " needs ", n);
  const auto g = ssim_gaussian();
  const int ow = width - ssim_window + 1, oh = height - ssim_window + 1;  // valid window positions
  // Horizontal pass over the five moments: a, b, a², b², ab.
  std::array<std::vector<double>, 5> row;
  for (auto& r : row) r.assign(static_cast<std::size_t>(ow) * static_cast<std::size_t>(height), 0.0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < ow; ++x) {
      double m[5] = {0, 0, 0, 0, 0};
      for (int k = 0; k < ssim_window; ++k) {
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x + k);
        const double va = a[i], vb = b[i], w = g[static_cast<std::size_t>(k)];
        m[0] += w * va;
        m[1] += w * vb;
        m[2] += w * va * va;
        m[3] += w * vb * vb;
        m[4] += w * va * vb;
      }
      const std::size_t o = static_cast<std::size_t>(y) * static_cast<std::size_t>(ow) + static_cast<std::size_t>(x);
      for (int c = 0; c < 5; ++c) row[static_cast<std::size_t>(c)][o] = m[c];
    }
  constexpr double c1 = (0.01 * 1.0) * (0.01 * 1.0), c2 = (0.03 * 1.0) * (0.03 * 1.0);
  double total = 0.0;
  for (int y = 0; y < oh; ++y)
    for (int x = 0; x < ow; ++x) {
      double m[5] = {0, 0, 0, 0, 0};
      for (int k = 0; k < ssim_window; ++k) {
        const std::size_t i = static_cast<std::size_t>(y + k) * static_cast<std::size_t>(ow) + static_cast<std::size_t>(x);
        for (int c = 0; c < 5; ++c) m[c] += g[static_cast<std::size_t>(k)] * row[static_cast<std::size_t>(c)][i];
      }
      const double mu_a = m[0], mu_b = m[1];
      const double var_a = m[2] - mu_a * mu_a, var_b = m[3] - mu_b * mu_b, cov = m[4] - mu_a * mu_b;
      total += ((2.0 * mu_a * mu_b + c1) * (2.0 * cov + c2)) / ((mu_a * mu_a + mu_b * mu_b + c1) * (var_a + var_b + c2));
    }
  return total / (static_cast<double>(ow) * static_cast<double>(oh));
}

}  // namespace infolerp::support
