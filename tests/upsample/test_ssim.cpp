// Tests for tests/support/ssim.hpp (the harness's SSIM) against hand cases and a brute-force
// 2D-window reference of Wang et al. 2004, Eq. (13).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <vector>
#include "support/ssim.hpp"

namespace {

std::vector<float> pattern(int w, int h, std::uint32_t seed) {
  std::vector<float> v(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  std::uint32_t s = seed;
  for (auto& x : v) {
    s = s * 1664525u + 1013904223u;
    x = static_cast<float>(s >> 8) / 16777216.0f;
  }
  return v;
}

// Direct evaluation: every valid 11x11 window, 2D Gaussian weights, moments in double.
double brute_ssim(const std::vector<float>& a, const std::vector<float>& b, int w, int h) {
  const auto g = infolerp::support::ssim_gaussian();
  const double c1 = 1e-4, c2 = 9e-4;
  double total = 0.0;
  int count = 0;
  for (int y = 0; y + 11 <= h; ++y)
    for (int x = 0; x + 11 <= w; ++x) {
      double ma = 0, mb = 0, saa = 0, sbb = 0, sab = 0;
      for (int j = 0; j < 11; ++j)
        for (int i = 0; i < 11; ++i) {
          const double wt = g[static_cast<std::size_t>(i)] * g[static_cast<std::size_t>(j)];
          const std::size_t k = static_cast<std::size_t>(y + j) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x + i);
          ma += wt * a[k];
          mb += wt * b[k];
        }
      for (int j = 0; j < 11; ++j)
        for (int i = 0; i < 11; ++i) {
          const double wt = g[static_cast<std::size_t>(i)] * g[static_cast<std::size_t>(j)];
          const std::size_t k = static_cast<std::size_t>(y + j) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x + i);
          saa += wt * (a[k] - ma) * (a[k] - ma);
          sbb += wt * (b[k] - mb) * (b[k] - mb);
          sab += wt * (a[k] - ma) * (b[k] - mb);
        }
      total += ((2 * ma * mb + c1) * (2 * sab + c2)) / ((ma * ma + mb * mb + c1) * (saa + sbb + c2));
      ++count;
    }
  return total / count;
}

}  // namespace

TEST_CASE("ssim window is the normalised sigma 1.5 Gaussian", "[ssim]") {
  const auto g = infolerp::support::ssim_gaussian();
  double sum = 0.0;
  for (double v : g) sum += v;
  CHECK(sum == Approx(1.0).epsilon(1e-15));
  CHECK(g[5] / g[6] == Approx(std::exp(1.0 / (2.0 * 2.25))));
  CHECK(g[0] == Approx(g[10]).epsilon(0));
}

TEST_CASE("ssim hand cases", "[ssim]") {
  using infolerp::support::ssim;
  const int w = 40, h = 23;
  const auto a = pattern(w, h, 1);
  SECTION("identical images give exactly 1") { CHECK(*ssim(a, a, w, h) == 1.0); }
  SECTION("two constant images: only the luminance term, (2ab + C1) / (a^2 + b^2 + C1)") {
    const std::vector<float> x(static_cast<std::size_t>(w * h), 0.25f), y(static_cast<std::size_t>(w * h), 0.75f);
    const double expected = (2 * 0.25 * 0.75 + 1e-4) / (0.25 * 0.25 + 0.75 * 0.75 + 1e-4);
    CHECK(*ssim(x, y, w, h) == Approx(expected).epsilon(1e-12));
  }
  SECTION("inverted structure is strongly dissimilar") {
    std::vector<float> inv(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) inv[i] = 1.0f - a[i];
    CHECK(*ssim(a, inv, w, h) < 0.0);
  }
  SECTION("noise lowers ssim monotonically") {
    const auto n = pattern(w, h, 7);
    double last = 1.0;
    for (float amount : {0.01f, 0.05f, 0.2f}) {
      std::vector<float> b(a.size());
      for (std::size_t i = 0; i < a.size(); ++i) b[i] = a[i] + amount * (n[i] - 0.5f);
      const double s = *ssim(a, b, w, h);
      CHECK(s < last);
      last = s;
    }
  }
  SECTION("matches a brute-force 2D window evaluation") {
    const auto b = pattern(w, h, 99);
    std::vector<float> c(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) c[i] = 0.7f * a[i] + 0.3f * b[i];
    CHECK(*ssim(a, c, w, h) == Approx(brute_ssim(a, c, w, h)).epsilon(1e-10));
    CHECK(*ssim(a, b, w, h) == Approx(brute_ssim(a, b, w, h)).epsilon(1e-10));
  }
  SECTION("bad sizes") {
    CHECK(ssim(a, a, 10, 10).error().code() == infolerp::errc::bad_size);
    CHECK(ssim(a, std::span<const float>(a).first(5), w, h).error().code() == infolerp::errc::bad_size);
  }
}
