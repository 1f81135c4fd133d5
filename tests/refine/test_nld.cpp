// refine/nld.hpp: equation (1) checked by hand on small cases, and its defined special cases.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>
#include "infolerp/refine/nld.hpp"

using infolerp::nld;

TEST_CASE("nld: hand-computed small cases") {
  // n = 2: one pair, n² div 4 = 1.  (0 - 1)² / (1 · 1²) -> 1
  CHECK(nld(std::vector<float>{0.0f, 1.0f}, 1.0f) == Approx(1.0f));
  // n = 2, L_max = 2: (0.5 - 1.5)² / (1 · 4) = 0.25 -> 0.5
  CHECK(nld(std::vector<float>{0.5f, 1.5f}, 2.0f) == Approx(0.5f));
  // n = 3: pairs 0.25 + 1 + 0.25 = 1.5, n² div 4 = 2 -> sqrt(0.75)
  CHECK(nld(0.0f, 0.5f, 1.0f, 1.0f) == Approx(std::sqrt(0.75f)));
  // n = 3, one odd out: (0,0,1) pairs 0 + 1 + 1 = 2, / 2 -> 1 (the largest value for n = 3)
  CHECK(nld(0.0f, 0.0f, 1.0f, 1.0f) == Approx(1.0f));
  // n = 4: (0,0,1,1) four unit pairs / 4 -> 1
  CHECK(nld(0.0f, 0.0f, 1.0f, 1.0f, 1.0f) == Approx(1.0f));
  // n = 4: 0.2 0.4 0.6 0.8 -> squares .04+.16+.36+.04+.16+.04 = 0.8, / 4 = 0.2 -> sqrt(0.2)
  CHECK(nld(0.2f, 0.4f, 0.6f, 0.8f, 1.0f) == Approx(std::sqrt(0.2f)));
  // n = 4, one bright corner: 3 pairs of 1 / 4 -> sqrt(0.75)
  CHECK(nld(0.0f, 0.0f, 0.0f, 1.0f, 1.0f) == Approx(std::sqrt(0.75f)));
  // n = 5: (0,0,1,1,1): 6 unit pairs, 25 div 4 = 6 -> 1
  CHECK(nld(std::vector<float>{0, 0, 1, 1, 1}, 1.0f) == Approx(1.0f));
}

TEST_CASE("nld: equal luminances give 0, scaling L and L_max together changes nothing") {
  CHECK(nld(0.7f, 0.7f, 0.7f, 1.0f) == 0.0f);
  CHECK(nld(0.3f, 0.5f, 0.9f, 1.0f) == Approx(nld(3.0f, 5.0f, 9.0f, 10.0f)));
  // Nearly equal values to the last bit: no cancellation, no NaN.
  const float a = 1.0f, b = std::nextafter(1.0f, 2.0f);
  const float s = nld(a, b, a, 1.0f);
  CHECK(s >= 0.0f);
  CHECK(s < 1e-6f);
}

TEST_CASE("nld: defined special cases") {
  CHECK(nld(std::vector<float>{}, 1.0f) == 0.0f);          // n = 0
  CHECK(nld(std::vector<float>{0.4f}, 1.0f) == 0.0f);      // n = 1
  CHECK(nld(0.0f, 0.0f, 0.0f, 0.0f) == 0.0f);              // L_max = 0 (all black)
  CHECK(nld(0.0f, 1.0f, 0.0f, 0.0f) == 0.0f);              // L_max = 0 even if L is not
  CHECK(nld(0.0f, 1.0f, 0.0f, std::numeric_limits<float>::quiet_NaN()) == 0.0f);
  CHECK(nld(0.0f, 1.0f, 0.0f, -1.0f) == 0.0f);
  CHECK(nld(0.0f, std::numeric_limits<float>::infinity(), 0.0f, 1.0f) == 1.0f);  // invalid sample
  CHECK(nld(0.0f, 5.0f, 0.0f, 1.0f) == 1.0f);  // L above L_max: clamped
}

TEST_CASE("nld: matches the pairwise definition and stays in [0, 1] on random inputs") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int trial = 0; trial < 2000; ++trial) {
    const std::size_t n = 2 + static_cast<std::size_t>(trial % 7);
    std::vector<float> L(n);
    float lmax = 0.0f;
    for (auto& l : L) lmax = std::max(lmax, l = u(rng));
    double pairs = 0.0;
    for (std::size_t i = 0; i + 1 < n; ++i)
      for (std::size_t j = i + 1; j < n; ++j) pairs += (double(L[i]) - L[j]) * (double(L[i]) - L[j]);
    const double ref = std::sqrt(pairs / (double((n * n) / 4) * lmax * lmax));
    const float s = nld(L, lmax);
    REQUIRE(s == Approx(ref).margin(1e-6));
    REQUIRE(s >= 0.0f);
    REQUIRE(s <= 1.0f);
  }
}
