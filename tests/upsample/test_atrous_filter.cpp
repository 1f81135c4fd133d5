// Tests for the harness's denoiser baseline, the edge-avoiding à-trous filter
// (benchmarks/pareto/upsample_denoise.hpp): a constant image stays constant, no value crosses
// an edge between two ids, the result is the same bit for bit for any executor, and noise drops.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>
#include "../../benchmarks/pareto/upsample_denoise.hpp"
#include "support/thread_pool.hpp"

namespace {

using infolerp::bench::atrous_filter;
using infolerp::bench::atrous_guides;

// Guide planes of a w x h image: a tilted plane's depth, normals from a few directions (a
// sphere-ish cap), ids from `id_at`.
struct planes {
  int w, h;
  std::vector<float> nx, ny, nz, depth, a, b;
  std::vector<std::uint32_t> id;
  planes(int width, int height) : w(width), h(height) {
    const auto n = static_cast<std::size_t>(w * h);
    nx.resize(n), ny.resize(n), nz.resize(n), depth.resize(n), a.resize(n), b.resize(n), id.resize(n);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y * w + x);
        const float u = 0.4f * (static_cast<float>(x) / static_cast<float>(w) - 0.5f);
        const float v = 0.4f * (static_cast<float>(y) / static_cast<float>(h) - 0.5f);
        const float len = std::sqrt(u * u + v * v + 1.0f);
        nx[i] = u / len, ny[i] = v / len, nz[i] = 1.0f / len;
        depth[i] = 5.0f + 0.01f * static_cast<float>(x) + 0.02f * static_cast<float>(y);
        id[i] = 0;
      }
  }
  atrous_guides guides() const { return {nx, ny, nz, depth, id}; }
  void noise(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (auto& v : a) v = u(rng);
    for (auto& v : b) v = u(rng) < 0.25f ? 1.0f : 0.0f;
  }
};

// Runs fn's chunks in reverse order: a different schedule from the serial one.
struct reverse_executor {
  template <class F>
  void parallel_for(std::size_t n, std::size_t grain, F&& fn) const {
    grain = grain == 0 ? 1 : grain;
    for (std::size_t c = (n + grain - 1) / grain; c-- > 0;) fn(c * grain, std::min(n, (c + 1) * grain));
  }
};

}  // namespace

TEST_CASE("atrous filter: a constant image stays constant", "[upsample][denoise]") {
  for (int iterations : {1, 4, 5}) {
    planes p(70, 45);
    for (std::size_t i = 0; i < p.id.size(); ++i) p.id[i] = static_cast<std::uint32_t>((i * 7) % 3);  // many edges
    std::fill(p.a.begin(), p.a.end(), 0.37f);
    std::fill(p.b.begin(), p.b.end(), 0.8125f);
    atrous_filter f(p.w, p.h, {.iterations = iterations});
    f.run(p.a, p.b, p.guides(), infolerp::serial_executor{});
    for (std::size_t i = 0; i < p.a.size(); ++i) {
      REQUIRE(std::abs(p.a[i] - 0.37f) <= 1e-6f);
      REQUIRE(std::abs(p.b[i] - 0.8125f) <= 1e-6f);
    }
  }
}

TEST_CASE("atrous filter: an edge between two ids is never crossed", "[upsample][denoise]") {
  // Left of column 29 id 1, right of it id 2, the same normals and depths on both sides: only
  // the id stops the filter there. Changing everything on the right (values, depths, normals)
  // leaves the left's result unchanged bit for bit; with one id the same change does reach it.
  const int split = 29;
  auto run = [&](bool two_ids, bool change_right) {
    planes p(80, 40);
    p.noise(7);
    for (int y = 0; y < p.h; ++y)
      for (int x = 0; x < p.w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y * p.w + x);
        p.id[i] = two_ids && x >= split ? 2u : 1u;
        if (change_right && x >= split) p.a[i] = 1.0f - p.a[i], p.b[i] = 1.0f - p.b[i], p.depth[i] += 1e-4f;
      }
    atrous_filter f(p.w, p.h);
    f.run(p.a, p.b, p.guides(), infolerp::serial_executor{});
    return p;
  };
  const planes base = run(true, false), changed = run(true, true);
  const planes joined = run(false, false), joined_changed = run(false, true);
  bool reached = false;
  for (int y = 0; y < base.h; ++y)
    for (int x = 0; x < split; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * base.w + x);
      REQUIRE(std::memcmp(&base.a[i], &changed.a[i], sizeof(float)) == 0);
      REQUIRE(std::memcmp(&base.b[i], &changed.b[i], sizeof(float)) == 0);
      reached = reached || joined.a[i] != joined_changed.a[i];
    }
  CHECK(reached);  // the test could see a crossing
}

TEST_CASE("atrous filter: the same result for any executor", "[upsample][denoise]") {
  planes p(97, 61);
  p.noise(11);
  for (std::size_t i = 0; i < p.id.size(); ++i) p.id[i] = static_cast<std::uint32_t>((i % 97) * 3 / 97 + (i / 97 > 30 ? 3 : 0));
  auto filtered = [&](const auto& exec) {
    planes q = p;
    atrous_filter f(q.w, q.h);
    f.run(q.a, q.b, q.guides(), exec);
    return q;
  };
  const planes serial = filtered(infolerp::serial_executor{});
  const planes reversed = filtered(reverse_executor{});
  const planes pooled = filtered(infolerp::support::thread_pool_executor{3});
  REQUIRE(std::memcmp(serial.a.data(), reversed.a.data(), serial.a.size() * sizeof(float)) == 0);
  REQUIRE(std::memcmp(serial.b.data(), reversed.b.data(), serial.b.size() * sizeof(float)) == 0);
  REQUIRE(std::memcmp(serial.a.data(), pooled.a.data(), serial.a.size() * sizeof(float)) == 0);
  REQUIRE(std::memcmp(serial.b.data(), pooled.b.data(), serial.b.size() * sizeof(float)) == 0);
}

TEST_CASE("atrous filter: noise on one surface drops", "[upsample][denoise]") {
  // Uniform noise of mean 0.5 on one smooth surface: the filtered image's deviation from 0.5
  // is a fraction of the input's (a wide kernel, nothing stops it).
  planes p(128, 128);
  p.noise(3);
  auto rms = [](const std::vector<float>& v) {
    double s = 0;
    for (float x : v) s += static_cast<double>((x - 0.5f) * (x - 0.5f));
    return std::sqrt(s / static_cast<double>(v.size()));
  };
  const double before = rms(p.a);
  atrous_filter f(p.w, p.h);
  f.run(p.a, p.b, p.guides(), infolerp::serial_executor{});
  CHECK(rms(p.a) < 0.15 * before);
}
