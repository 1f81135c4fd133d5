// Tests for include/infolerp/upsample/upsampler.hpp and sample_source.hpp with synthetic sample
// sources (no ray tracer): exact reconstruction where the paper's interpolation is exact, the
// R/I/E pattern of Fig. 7, boundaries, any output size, every pixel written, determinism.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <mutex>
#include <new>
#include <string>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec4.hpp>
#include "infolerp/upsample/upsampler.hpp"
#include "support/counting_new.hpp"
#include "support/thread_pool.hpp"

namespace {

using infolerp::sample_kind;
using sample = infolerp::surface_sample<2, true>;

// A convex-region scene: pixels are split by straight lines into regions (cluster boundary,
// shadow boundary, background); inside each region every attribute is linear in (x, y) with
// dyadic coefficients, so float midpoints are exact. Midpoints and centres of samples in one
// convex region lie in that region, hence the upsampler must reproduce the evaluated image
// exactly, and any pixel whose sources straddle a boundary must be evaluated.
struct region_source {
  using sample_type = sample;
  bool cluster_edge = true;     // x + y/2 < 37 → cluster 0, else cluster 1
  bool shadow_edge = true;      // 3x − y < 20 → light 0 visible
  bool background_edge = false; // y > 300 → background
  mutable std::atomic<std::uint32_t> max_x{0}, max_y{0}, calls{0};

  sample evaluate(std::uint32_t xi, std::uint32_t yi) const {
    calls.fetch_add(1, std::memory_order_relaxed);
    std::uint32_t mx = max_x.load();
    while (xi > mx && !max_x.compare_exchange_weak(mx, xi)) {}
    std::uint32_t my = max_y.load();
    while (yi > my && !max_y.compare_exchange_weak(my, yi)) {}
    const float x = static_cast<float>(xi), y = static_cast<float>(yi);
    sample s;
    if (background_edge && yi > 300) return s;  // background: cluster invalid_id
    s.cluster = (cluster_edge && x + 0.5f * y >= 37.0f) ? 1u : 0u;
    s.lights = (shadow_edge && 3.0f * x - y >= 20.0f) ? 0u : 1u;
    const float k = static_cast<float>(s.cluster * 2u + s.lights);  // region-specific coefficients
    s.position = {0.25f * x + k, 0.5f * y - k, 1.0f + 0.125f * x + 0.0625f * y};
    s.normal = {0.0f, 1.0f, 0.03125f * x * (k + 1.0f)};
    s.texcoord = {0.0078125f * x, 0.00390625f * y * (k + 1.0f)};
    s.occlusion = {0.5f + 0.001953125f * x, 0.25f + k * 0.0009765625f * y};
    return s;
  }
  glm::vec4 shade(const sample& s, std::uint32_t, std::uint32_t) const {
    return {s.position.x + s.texcoord.x, s.occlusion[0], static_cast<float>(s.lights), static_cast<float>(s.cluster)};
  }
};

bool same_bits(const sample& a, const sample& b) {
  return a.position == b.position && a.normal == b.normal && a.texcoord == b.texcoord && a.cluster == b.cluster &&
         a.lights == b.lights && a.occlusion == b.occlusion;
}

template <class Src>
std::vector<glm::vec4> poisoned(std::uint32_t w, std::uint32_t h) {
  return std::vector<glm::vec4>(static_cast<std::size_t>(w) * h, glm::vec4(std::numeric_limits<float>::quiet_NaN()));
}

infolerp::upsampler<sample> make(std::uint32_t w, std::uint32_t h, std::uint32_t passes, std::uint32_t max_passes = 5) {
  auto u = infolerp::upsampler<sample>::create(w, h, {.passes = passes, .max_passes = max_passes, .keep_ibuffer = true});
  REQUIRE(u.ok());
  return std::move(*u);
}

struct two_clusters {
  using sample_type = sample;
  sample evaluate(std::uint32_t x, std::uint32_t) const {
    sample s;
    s.cluster = x < 3 ? 0u : 1u;
    s.lights = 1;
    s.texcoord = {static_cast<float>(x), 0.0f};
    return s;
  }
  float shade(const sample& s, std::uint32_t, std::uint32_t) const { return s.texcoord.x; }
};

struct wavy {
  using sample_type = sample;
  sample evaluate(std::uint32_t xi, std::uint32_t yi) const {
    const float x = static_cast<float>(xi), y = static_cast<float>(yi);
    sample s;
    const float r = std::sqrt((x - 130.0f) * (x - 130.0f) + (y - 90.0f) * (y - 90.0f));
    if (r > 120.0f) return s;
    s.cluster = static_cast<std::uint32_t>(std::sin(0.05f * x) * 3.0f + std::cos(0.07f * y) * 3.0f + 6.0f);
    s.lights = (x * 0.3f + std::sin(y * 0.1f) * 9.0f > 40.0f) ? 1u : 3u;
    s.position = {x * 0.1f, std::sin(y * 0.01f), r};
    s.normal = {std::cos(x * 0.013f), 1.0f, std::sin(y * 0.017f)};
    s.texcoord = {x / 300.0f, y / 7.0f};
    s.occlusion = {1.0f / (1.0f + r), std::sqrt(x + y)};
    return s;
  }
  glm::vec4 shade(const sample& s, std::uint32_t, std::uint32_t) const {
    return {s.position.x * s.occlusion[0], s.texcoord.y, s.normal.z, static_cast<float>(s.lights)};
  }
};

using flat = infolerp::surface_sample<2, false>;
struct no_lights {
  using sample_type = flat;
  region_source inner;
  flat evaluate(std::uint32_t x, std::uint32_t y) const {
    const sample s = inner.evaluate(x, y);
    flat f;
    f.position = s.position;
    f.normal = s.normal;
    f.texcoord = s.texcoord;
    f.cluster = s.cluster;
    f.occlusion = s.occlusion;
    return f;
  }
  float shade(const flat& s, std::uint32_t, std::uint32_t) const { return s.position.x; }
};

struct bg_sample {
  float value = 0.0f;
  bool miss = false;
  bool background() const { return miss; }
};
struct careless {
  using sample_type = bg_sample;
  bg_sample evaluate(std::uint32_t x, std::uint32_t y) const {
    return {static_cast<float>(x) * 0.5f + static_cast<float>(y), 2 * x + y > 151};  // half-plane of background
  }
  bool compatible(const bg_sample&, const bg_sample&) const { return true; }
  bg_sample interpolate(const bg_sample& a, const bg_sample& b) const { return {0.5f * (a.value + b.value), a.miss}; }
  bg_sample interpolate(const bg_sample& a, const bg_sample& b, const bg_sample& c, const bg_sample& d) const {
    return {0.25f * ((a.value + b.value) + (c.value + d.value)), a.miss};
  }
  float shade(const bg_sample& s, std::uint32_t, std::uint32_t) const { return s.miss ? -1.0f : s.value; }
};

// Any source with probes: the probe is the full evaluation with the expensive terms poisoned
// (NaN), so a probe that reaches the output without its occlusion completed shows up.
template <class Inner>
struct probing {
  using sample_type = sample;
  Inner inner;
  mutable std::atomic<std::uint32_t> evaluations{0};
  sample evaluate(std::uint32_t x, std::uint32_t y) const {
    evaluations.fetch_add(1, std::memory_order_relaxed);
    return inner.evaluate(x, y);
  }
  sample probe(std::uint32_t x, std::uint32_t y) const {
    sample s = inner.evaluate(x, y);
    s.occlusion = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::quiet_NaN()};
    return s;
  }
  auto shade(const sample& s, std::uint32_t x, std::uint32_t y) const { return inner.shade(s, x, y); }
};

// A source with cheap probes (refine_probe): the probe leaves out the light bits (poisoned, and
// probe_compatible() ignores them); refine_probe() adds them.
template <class Inner>
struct refining : probing<Inner> {
  mutable std::atomic<std::uint32_t> probes{0}, refinements{0};
  sample probe(std::uint32_t x, std::uint32_t y) const {
    probes.fetch_add(1, std::memory_order_relaxed);
    sample s = probing<Inner>::probe(x, y);
    s.lights = 0xDEADu;
    return s;
  }
  bool probe_compatible(const sample& p, const sample& s) const { return p.cluster == s.cluster; }
  sample refine_probe(const sample& p, std::uint32_t x, std::uint32_t y) const {
    refinements.fetch_add(1, std::memory_order_relaxed);
    sample s = probing<Inner>::probe(x, y);
    static std::mutex catch_assertions;  // refine_probe runs on worker threads; Catch2 v2 assertions are not thread-safe
    const std::lock_guard<std::mutex> lock(catch_assertions);
    CHECK(s.cluster == p.cluster);
    return s;
  }
};

// Cluster 0 everywhere but a one-pixel column of cluster 1 at x = 5, between the even columns
// the last pass's sources sit on: the sources agree, the pixel itself does not.
struct thin_line {
  using sample_type = sample;
  sample evaluate(std::uint32_t xi, std::uint32_t yi) const {
    sample s;
    s.cluster = xi == 5 ? 1u : 0u;
    s.lights = 1;
    s.texcoord = {static_cast<float>(xi), static_cast<float>(yi)};
    s.occlusion = {xi == 5 ? 0.0f : 1.0f, 0.5f};
    return s;
  }
  float shade(const sample& s, std::uint32_t, std::uint32_t) const { return s.occlusion[0]; }
};

// Cluster 0 for x < 12, cluster 1 beyond; in shadow (lights 0) at the one-pixel columns x = 5
// and x = 11, between the even columns the last pass's sources sit on.
struct shadow_column {
  using sample_type = sample;
  sample evaluate(std::uint32_t xi, std::uint32_t yi) const {
    sample s;
    s.cluster = xi >= 12 ? 1u : 0u;
    s.lights = (xi == 5 || xi == 11) ? 0u : 1u;
    s.texcoord = {static_cast<float>(xi), static_cast<float>(yi)};
    s.occlusion = {1.0f, 0.5f};
    return s;
  }
  float shade(const sample& s, std::uint32_t, std::uint32_t) const { return static_cast<float>(s.lights); }
};

// Pinhole camera at the origin looking along +z (focal length 64 px), a tilted plane n·p = 4;
// texcoords and AO affine in world space, hence not linear in screen space.
struct plane_view {
  using sample_type = sample;
  bool weights = true;
  sample evaluate(std::uint32_t xi, std::uint32_t yi) const {
    const glm::vec3 d{(static_cast<float>(xi) - 40.0f) / 64.0f, (static_cast<float>(yi) - 30.0f) / 64.0f, 1.0f};
    const glm::vec3 n{0.0f, 0.8f, 0.6f};
    const float t = 4.0f / glm::dot(n, d);
    const glm::vec3 p = t * d;
    sample s;
    s.cluster = 0;
    s.lights = 1;
    s.position = p;
    s.normal = n;
    s.texcoord = {0.25f * p.x + 1.0f, 0.5f * p.y - 0.125f * p.z};
    s.occlusion = {0.5f + 0.01f * p.x, 0.3f + 0.02f * p.z};
    s.inv_depth = weights ? 1.0f / p.z : 1.0f;
    return s;
  }
  float shade(const sample& s, std::uint32_t, std::uint32_t) const { return s.texcoord.x; }
};

bool same_primary(const sample& a, const sample& b) {
  return a.position == b.position && a.normal == b.normal && a.texcoord == b.texcoord && a.cluster == b.cluster &&
         a.lights == b.lights;
}

// The region scene with all its boundaries, or none.
void set_edges(region_source& r, bool edges) {
  r.cluster_edge = edges;
  r.shadow_edge = edges;
  r.background_edge = edges;
}

// Over a w x h I-Buffer of the region scene: samples whose primary part (light bits included)
// differs from an evaluation, and samples whose occlusion was never completed (NaN).
struct primary_errors {
  std::size_t wrong = 0, unset = 0;
};
primary_errors check_primary(std::span<const sample> ib, const region_source& r, std::uint32_t w, std::uint32_t h) {
  primary_errors e;
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x) {
      const sample& s = ib[y * w + x];
      e.wrong += same_primary(s, r.evaluate(x, y)) ? 0 : 1;
      e.unset += std::isnan(s.occlusion[0]) || std::isnan(s.occlusion[1]) ? 1 : 0;
    }
  return e;
}

}  // namespace

TEST_CASE("a single cluster with attributes linear in screen space reconstructs exactly", "[upsample]") {
  region_source src;
  src.cluster_edge = false;
  src.shadow_edge = false;
  const std::uint32_t w = 97, h = 66;
  for (std::uint32_t passes = 1; passes <= 5; ++passes) {
    auto up = make(w, h, passes);
    auto out = poisoned<region_source>(w, h);
    REQUIRE(up.render(src, std::span<glm::vec4>(out)).ok());
    const auto ib = up.ibuffer();
    for (std::uint32_t y = 0; y < h; ++y)
      for (std::uint32_t x = 0; x < w; ++x) REQUIRE(same_bits(ib[y * w + x], src.evaluate(x, y)));
    // One cluster: only the first pass evaluates (the cropped border included).
    const auto& st = up.stats();
    CHECK(st.evaluated() == st.pass[0].evaluated);
    const std::uint32_t step = 1u << (passes - 1);
    CHECK(st.pass[0].width == (w - 1 + step - 1) / step + 1);
    CHECK(st.pass[0].height == (h - 1 + step - 1) / step + 1);
  }
}

TEST_CASE("R/I/E pattern of Fig. 7: 2x2 start, three passes, two clusters", "[upsample]") {
  // 5x5 image, cluster 0 for x < 3, cluster 1 for x >= 3 (a vertical boundary).
  two_clusters src;
  auto up = make(5, 5, 3);
  std::vector<float> out(25, -1.0f);
  REQUIRE(up.render(src, std::span<float>(out)).ok());
  const auto& st = up.stats();
  REQUIRE(st.passes == 3);
  // Pass 1: 2x2, all evaluated.
  CHECK(st.pass[0].width == 2);
  CHECK(st.pass[0].evaluated == 4);
  // Pass 2: 3x3. Corners R; (2,0),(2,2),(2,4) straddle the boundary → E; (0,2),(4,2) → I.
  CHECK(st.pass[1].width == 3);
  CHECK(st.pass[1].reused == 4);
  CHECK(st.pass[1].interpolated == 2);
  CHECK(st.pass[1].evaluated == 3);
  // Pass 3: 5x5, worked out by hand.
  const char* expected[5] = {"RIRER", "IIIEI", "RIRER", "IIIEI", "RIRER"};
  const auto kinds = up.kinds();
  REQUIRE(kinds.size() == 25);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) {
      const char c = "EIR"[static_cast<int>(kinds[static_cast<std::size_t>(y * 5 + x)])];
      INFO("pixel " << x << "," << y);
      CHECK(c == expected[y][x]);
    }
  CHECK(st.pass[2].reused == 9);
  CHECK(st.pass[2].interpolated == 11);
  CHECK(st.pass[2].evaluated == 5);
  for (int x = 0; x < 5; ++x) CHECK(out[static_cast<std::size_t>(x)] == static_cast<float>(x));
}

TEST_CASE("cluster, shadow and background boundaries are evaluated, not interpolated", "[upsample]") {
  region_source src;
  src.background_edge = true;
  const std::uint32_t w = 320, h = 340;
  for (std::uint32_t passes = 2; passes <= 5; ++passes) {
    auto up = make(w, h, passes);
    auto out = poisoned<region_source>(w, h);
    REQUIRE(up.render(src, std::span<glm::vec4>(out)).ok());
    const auto ib = up.ibuffer();
    // Convex regions: exact everywhere, so no pixel got another region's cluster, light bits or values.
    std::size_t wrong = 0;
    for (std::uint32_t y = 0; y < h; ++y)
      for (std::uint32_t x = 0; x < w; ++x) wrong += same_bits(ib[y * w + x], src.evaluate(x, y)) ? 0 : 1;
    CHECK(wrong == 0);
    CHECK(up.stats().evaluated() > up.stats().pass[0].evaluated);  // the boundaries cost evaluations
  }
  SECTION("without the light-bit test the shadow boundary is interpolated over") {
    // Same scene, light bits compiled out of the record: the shadow edge is invisible to the
    // upsampler, so some pixels near it get interpolated wrong values.
    static_assert(sizeof(flat) < sizeof(sample));
    no_lights nl;
    auto u = infolerp::upsampler<flat>::create(w, h, {.passes = 4, .keep_ibuffer = true});
    REQUIRE(u.ok());
    std::vector<float> out(static_cast<std::size_t>(w) * h);
    REQUIRE(u->render(nl, std::span<float>(out)).ok());
    std::size_t wrong = 0;
    for (std::uint32_t y = 0; y < h; ++y)
      for (std::uint32_t x = 0; x < w; ++x) wrong += out[y * w + x] == nl.evaluate(x, y).position.x ? 0 : 1;
    CHECK(wrong > 0);
  }
}

TEST_CASE("background is never interpolated with geometry, even if compatible() says yes", "[upsample]") {
  careless src;
  static_assert(infolerp::check_sample_source<careless>());
  auto u = infolerp::upsampler<bg_sample>::create(90, 70, {.passes = 3, .keep_ibuffer = true});
  REQUIRE(u.ok());
  std::vector<float> out(90 * 70);
  REQUIRE(u->render(src, std::span<float>(out)).ok());
  const auto ib = u->ibuffer();
  const auto kinds = u->kinds();
  // Both sides of the edge are convex, so a pixel is right unless it was interpolated between
  // background and geometry, which compatible() alone would have allowed.
  std::size_t wrong = 0;
  for (std::uint32_t y = 0; y < 70; ++y)
    for (std::uint32_t x = 0; x < 90; ++x) wrong += ib[y * 90 + x].miss == src.evaluate(x, y).miss ? 0 : 1;
  CHECK(wrong == 0);
  std::size_t evaluated_late = 0;
  for (auto k : kinds) evaluated_late += k == sample_kind::evaluated;
  CHECK(evaluated_late > 0);
}

TEST_CASE("any output size: every pixel written, exact on one cluster, bounded overhang", "[upsample]") {
  region_source src;
  src.cluster_edge = false;
  src.shadow_edge = false;
  const std::uint32_t sizes[][2] = {{1, 1}, {2, 2}, {1024, 768}, {1025, 1025}, {3, 1}, {1, 7}};
  for (const auto& sz : sizes) {
    const std::uint32_t w = sz[0], h = sz[1];
    for (std::uint32_t passes : {1u, 2u, 4u, 5u}) {
      INFO(w << "x" << h << " passes " << passes);
      auto up = make(w, h, passes);
      src.max_x = 0;
      src.max_y = 0;
      auto out = poisoned<region_source>(w, h);
      REQUIRE(up.render(src, std::span<glm::vec4>(out)).ok());
      std::size_t unwritten = 0, wrong = 0;
      for (std::uint32_t y = 0; y < h; ++y)
        for (std::uint32_t x = 0; x < w; ++x) {
          const glm::vec4 p = out[static_cast<std::size_t>(y) * w + x];
          unwritten += std::isnan(p.x) || std::isnan(p.y) || std::isnan(p.z) || std::isnan(p.w);
          wrong += p == src.shade(src.evaluate(x, y), x, y) ? 0 : 1;
        }
      CHECK(unwritten == 0);
      CHECK(wrong == 0);
      const std::uint32_t step = 1u << (passes - 1);
      CHECK(src.max_x.load() < w + step - 1);
      CHECK(src.max_y.load() < h + step - 1);
      // Memory: about 4/3 of the full-resolution buffer with the final I-Buffer kept, 1/3 without.
      const double full = static_cast<double>(w) * h;
      CHECK(static_cast<double>(up.pyramid_samples()) <= 4.0 / 3.0 * full + 4.0 * (w + h) + 4.0 * 5);
      auto lean = infolerp::upsampler<sample>::create(w, h, {.passes = passes, .max_passes = 5});
      REQUIRE(lean.ok());
      CHECK(static_cast<double>(lean->pyramid_samples()) <= 1.0 / 3.0 * full + 4.0 * (w + h) + 4.0 * 5);
      CHECK(lean->ibuffer().empty());
      // Per-pass counts add up to the pass size.
      const auto& st = up.stats();
      for (std::uint32_t p = 0; p < st.passes; ++p)
        CHECK(st.pass[p].reused + st.pass[p].interpolated + st.pass[p].evaluated ==
              static_cast<std::size_t>(st.pass[p].width) * st.pass[p].height);
      CHECK(st.pass[st.passes - 1].width == w);
      CHECK(st.pass[st.passes - 1].height == h);
    }
  }
}

TEST_CASE("rendering allocates nothing once the upsampler exists", "[upsample]") {
  region_source src;
  auto up = make(200, 150, 4);
  std::vector<glm::vec4> out(200 * 150);
  REQUIRE(up.render(src, std::span<glm::vec4>(out)).ok());
  const std::size_t before = infolerp::support::heap_allocations.load();
  for (std::uint32_t passes : {4u, 2u, 5u, 1u}) {
    REQUIRE(up.set_passes(passes).ok());
    REQUIRE(up.render(src, std::span<glm::vec4>(out)).ok());
  }
  CHECK(infolerp::support::heap_allocations.load() == before);
}

TEST_CASE("serial and parallel outputs are bit-identical", "[upsample]") {
  // Curved cluster boundaries and non-dyadic attributes, so rounding would show any difference.
  wavy src;
  const std::uint32_t w = 257, h = 190;
  for (std::uint32_t passes : {1u, 3u, 5u}) {
    auto serial = make(w, h, passes);
    std::vector<glm::vec4> ref(static_cast<std::size_t>(w) * h);
    REQUIRE(serial.render(src, std::span<glm::vec4>(ref)).ok());
    if (passes > 1) CHECK(serial.stats().evaluated() > serial.stats().pass[0].evaluated);
    auto compare = [&](auto&& exec) {
      auto up = make(w, h, passes);
      std::vector<glm::vec4> out(ref.size(), glm::vec4(-7.0f));
      REQUIRE(up.render(src, std::span<glm::vec4>(out), exec).ok());
      CHECK(std::memcmp(out.data(), ref.data(), out.size() * sizeof(glm::vec4)) == 0);
      CHECK(std::equal(up.kinds().begin(), up.kinds().end(), serial.kinds().begin()));
      for (std::uint32_t p = 0; p < passes; ++p) {
        CHECK(up.stats().pass[p].evaluated == serial.stats().pass[p].evaluated);
        CHECK(up.stats().pass[p].interpolated == serial.stats().pass[p].interpolated);
      }
    };
    compare(infolerp::support::thread_pool_executor{1});
    compare(infolerp::support::thread_pool_executor{2});
    compare(infolerp::support::thread_pool_executor{8});
    compare(infolerp::openmp_executor{});
    compare(infolerp::openmp_executor{.threads = 3});
  }
}

TEST_CASE("bad input gives a clear status", "[upsample]") {
  using up_t = infolerp::upsampler<sample>;
  auto zero = up_t::create(0, 0);
  REQUIRE_FALSE(zero.ok());
  CHECK(zero.error().code() == infolerp::errc::empty_input);
  CHECK(zero.error().message().find("0x0") != std::string::npos);
  auto no_passes = up_t::create(16, 16, {.passes = 1, .max_passes = 0});
  REQUIRE_FALSE(no_passes.ok());
  CHECK(no_passes.error().code() == infolerp::errc::bad_parameter);
  CHECK(no_passes.error().message().find("max_passes 0") != std::string::npos);
  auto zero_passes = up_t::create(16, 16, {.passes = 0});
  REQUIRE_FALSE(zero_passes.ok());
  CHECK(zero_passes.error().message().find("passes 0") != std::string::npos);
  auto too_many = up_t::create(16, 16, {.passes = 5, .max_passes = 4});
  REQUIRE_FALSE(too_many.ok());
  CHECK(too_many.error().code() == infolerp::errc::bad_parameter);

  auto up = make(16, 8, 3);
  CHECK(up.set_passes(6).code() == infolerp::errc::bad_parameter);
  CHECK(up.passes() == 3);
  region_source src;
  std::vector<glm::vec4> small(16 * 8 - 1, glm::vec4(5.0f));
  const auto s = up.render(src, std::span<glm::vec4>(small));
  CHECK(s.code() == infolerp::errc::bad_size);
  CHECK(src.calls.load() == 0);
  CHECK(small[0] == glm::vec4(5.0f));
  CHECK(up.resize(0, 3).code() == infolerp::errc::empty_input);
  CHECK(up.width() == 16);

  // The one-shot form validates the same way.
  std::vector<glm::vec4> out(4);
  CHECK(infolerp::upsample(src, 2, 2, std::span<glm::vec4>(out)).ok());
  CHECK(infolerp::upsample(src, 0, 2, std::span<glm::vec4>(out)).code() ==
        infolerp::errc::empty_input);
}

TEST_CASE("with probes, each new sample is tested with its own cluster id", "[upsample]") {
  static_assert(infolerp::probing_sample_source<probing<thin_line>>);
  static_assert(!infolerp::probing_sample_source<thin_line>);
  const std::uint32_t w = 17, h = 9;
  // Without probes the column's sources (x = 4 and 6, cluster 0) agree: it is interpolated over.
  auto plain = make(w, h, 2);
  std::vector<float> out(static_cast<std::size_t>(w) * h);
  thin_line line;
  REQUIRE(plain.render(line, std::span<float>(out)).ok());
  CHECK(plain.ibuffer()[5].cluster == 0u);
  CHECK(out[5] == 1.0f);
  // With probes it is evaluated, row by row.
  probing<thin_line> src;
  auto up = make(w, h, 2);
  REQUIRE(up.render(src, std::span<float>(out)).ok());
  for (std::uint32_t y = 0; y < h; ++y) {
    INFO("row " << y);
    CHECK(up.ibuffer()[y * w + 5].cluster == 1u);
    CHECK(out[y * w + 5] == 0.0f);
    CHECK(up.kinds()[y * w + 5] == sample_kind::evaluated);
  }
}

// Calls check(edges, min_sources, passes) for the region scene without and with its boundaries,
// min_sources 1 and 2, and 2 to 5 passes.
template <class F>
void for_region_settings(F&& check) {
  for (bool edges : {false, true})
    for (std::uint32_t min_sources : {1u, 2u})
      for (std::uint32_t passes = 2; passes <= 5; ++passes) {
        INFO("cluster and shadow edges " << edges << ", passes " << passes << ", min_sources " << min_sources);
        check(edges, min_sources, passes);
      }
}

TEST_CASE("with probes: the cheap part is exact everywhere, the expensive part exact on one cluster", "[upsample]") {
  for_region_settings([](bool edges, std::uint32_t min_sources, std::uint32_t passes) {
    probing<region_source> src;
    set_edges(src.inner, edges);
    const std::uint32_t w = 150, h = 333;
    auto u = infolerp::upsampler<sample>::create(w, h, {.passes = passes, .max_passes = 5, .keep_ibuffer = true,
                                                        .min_sources = min_sources});
    REQUIRE(u.ok());
    auto out = poisoned<region_source>(w, h);
    REQUIRE(u->render(src, std::span<glm::vec4>(out)).ok());
    const auto ib = u->ibuffer();
    const primary_errors e = check_primary(ib, src.inner, w, h);
    CHECK(e.wrong == 0);
    CHECK(e.unset == 0);
    std::size_t wrong = 0;
    for (std::uint32_t y = 0; y < h; ++y)
      for (std::uint32_t x = 0; x < w; ++x) wrong += same_bits(ib[y * w + x], src.inner.evaluate(x, y)) ? 0 : 1;
    if (!edges) {
      CHECK(wrong == 0);
      CHECK(u->stats().evaluated() == u->stats().pass[0].evaluated);
    }
    // Fewer evaluations than the plain I-Buffer: a boundary sample is completed from the
    // sources on its own side instead of being evaluated.
    auto plain = make(w, h, passes);
    REQUIRE(plain.render(src.inner, std::span<glm::vec4>(out)).ok());
    if (edges) CHECK(u->stats().evaluated() < plain.stats().evaluated());
    if (!edges) CHECK(u->stats().evaluated() == plain.stats().evaluated());
  });
}

// With probes, for min_sources 1 and 2: serial and 2/8-worker outputs and kinds are
// bit-identical, and a kept upsampler renders again without allocating. `after_serial(serial)`
// adds the caller's checks on the serial frame.
template <class Src, class F>
void check_probe_frames_bit_identical(const Src& src, F&& after_serial, bool probe_every_sample = true) {
  const std::uint32_t w = 257, h = 190;
  for (std::uint32_t min_sources : {1u, 2u}) {
    auto make_probe = [&] {
      auto u = infolerp::upsampler<sample>::create(
          w, h, {.passes = 4, .max_passes = 4, .min_sources = min_sources, .probe_every_sample = probe_every_sample});
      REQUIRE(u.ok());
      return std::move(*u);
    };
    auto serial = make_probe();
    std::vector<glm::vec4> ref(static_cast<std::size_t>(w) * h);
    REQUIRE(serial.render(src, std::span<glm::vec4>(ref)).ok());
    after_serial(serial);
    for (unsigned threads : {2u, 8u}) {
      auto up = make_probe();
      std::vector<glm::vec4> out(ref.size(), glm::vec4(-7.0f));
      REQUIRE(up.render(src, std::span<glm::vec4>(out), infolerp::support::thread_pool_executor{threads}).ok());
      CHECK(std::memcmp(out.data(), ref.data(), out.size() * sizeof(glm::vec4)) == 0);
      CHECK(std::equal(up.kinds().begin(), up.kinds().end(), serial.kinds().begin()));
    }
    const std::size_t before = infolerp::support::heap_allocations.load();
    REQUIRE(serial.render(src, std::span<glm::vec4>(ref)).ok());
    CHECK(infolerp::support::heap_allocations.load() == before);
  }
}

TEST_CASE("with probes, serial and parallel outputs are bit-identical", "[upsample]") {
  probing<wavy> src;
  check_probe_frames_bit_identical(src, [](const auto& serial) {
    CHECK(serial.stats().evaluated() > serial.stats().pass[0].evaluated);
  });
  auto bad = infolerp::upsampler<sample>::create(8, 8, {.min_sources = 3});
  REQUIRE_FALSE(bad.ok());
  CHECK(bad.error().code() == infolerp::errc::bad_parameter);
  CHECK(bad.error().message().find("min_sources 3") != std::string::npos);
}

TEST_CASE("refined probes: refined only where two agreeing sources do not suffice, same result as full probes", "[upsample]") {
  static_assert(infolerp::refining_sample_source<refining<region_source>>);
  static_assert(!infolerp::refining_sample_source<probing<region_source>>);
  for_region_settings([](bool edges, std::uint32_t min_sources, std::uint32_t passes) {
    refining<region_source> src;
    probing<region_source> full;
    for (auto* inner : {&src.inner, &full.inner}) set_edges(*inner, edges);
    const std::uint32_t w = 150, h = 333;
    auto create = [&] {
      auto u = infolerp::upsampler<sample>::create(w, h, {.passes = passes, .max_passes = 5, .keep_ibuffer = true,
                                                          .min_sources = min_sources});
      REQUIRE(u.ok());
      return std::move(*u);
    };
    auto u = create();
    src.probes = 0;
    src.refinements = 0;
    auto out = poisoned<region_source>(w, h);
    REQUIRE(u.render(src, std::span<glm::vec4>(out)).ok());
    const auto ib = u.ibuffer();
    const primary_errors e = check_primary(ib, src.inner, w, h);
    CHECK(e.wrong == 0);
    CHECK(e.unset == 0);
    CHECK(src.probes.load() > 0);
    if (!edges) CHECK(src.refinements.load() == 0);
    if (edges) {
      CHECK(src.refinements.load() > 0);
      CHECK(src.refinements.load() * 10 < src.probes.load());
    }
    // The regions are convex, so two sources that agree on the light bits have the new
    // sample's: the cheap probes give exactly what full probes give.
    auto f = create();
    auto out_full = poisoned<region_source>(w, h);
    REQUIRE(f.render(full, std::span<glm::vec4>(out_full)).ok());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < ib.size(); ++i) differ += same_bits(ib[i], f.ibuffer()[i]) ? 0 : 1;
    CHECK(differ == 0);
    CHECK(u.stats().evaluated() == f.stats().evaluated());
    CHECK(std::memcmp(out.data(), out_full.data(), out.size() * sizeof(glm::vec4)) == 0);
  });
}

TEST_CASE("refined probes: a shadow between two agreeing sources is interpolated over, one source refines", "[upsample]") {
  // The cheap probe cannot see the shadow at x = 5, and the sources on both sides agree, so
  // the last pass takes their light bits (the documented limit of cheap probes, like the plain
  // I-Buffer's); at x = 11 one side is another cluster, so the probe is refined and the shadow
  // found (and, as the one cluster-0 source is lit, the pixel evaluated).
  refining<shadow_column> src;
  const std::uint32_t w = 17, h = 9;
  auto u = infolerp::upsampler<sample>::create(w, h, {.passes = 2, .max_passes = 2, .keep_ibuffer = true, .min_sources = 1});
  REQUIRE(u.ok());
  std::vector<float> out(static_cast<std::size_t>(w) * h, -1.0f);
  REQUIRE(u->render(src, std::span<float>(out)).ok());
  for (std::uint32_t y = 0; y < h; ++y) {
    INFO("row " << y);
    CHECK(out[y * w + 5] == 1.0f);   // sources x = 4 and 6 agree: interpolated over
    CHECK(out[y * w + 11] == 0.0f);  // source x = 12 is cluster 1: refined, its own shadow
    CHECK(u->kinds()[y * w + 11] == sample_kind::evaluated);
  }
  CHECK(src.refinements.load() >= h);
}

TEST_CASE("refined probes: serial and parallel outputs are bit-identical", "[upsample]") {
  refining<wavy> src;
  check_probe_frames_bit_identical(src, [&](const auto&) { CHECK(src.refinements.load() > 0); });
}

TEST_CASE("probes only where sources differ: none on one cluster, exact primary parts, fewer probes and evaluations", "[upsample]") {
  for_region_settings([](bool edges, std::uint32_t min_sources, std::uint32_t passes) {
    refining<region_source> src;
    set_edges(src.inner, edges);
    const std::uint32_t w = 150, h = 333;
    auto render = [&](bool every, std::vector<glm::vec4>& out) {
      auto u = infolerp::upsampler<sample>::create(
          w, h, {.passes = passes, .max_passes = 5, .keep_ibuffer = true, .min_sources = min_sources,
                 .probe_every_sample = every});
      REQUIRE(u.ok());
      src.probes = 0;
      out = poisoned<region_source>(w, h);
      REQUIRE(u->render(src, std::span<glm::vec4>(out)).ok());
      return std::move(*u);
    };
    std::vector<glm::vec4> out, out_every;
    const auto every = render(true, out_every);
    const std::uint32_t probes_every = src.probes.load();
    const auto u = render(false, out);
    const std::uint32_t probes = src.probes.load();
    // Attributes linear in each convex region: interpolating within one is exact, so every
    // primary part (light bits included) is exact whether it came from a probe or not.
    const primary_errors e = check_primary(u.ibuffer(), src.inner, w, h);
    CHECK(e.wrong == 0);
    CHECK(e.unset == 0);
    auto plain = make(w, h, passes);
    std::vector<glm::vec4> out_plain = poisoned<region_source>(w, h);
    REQUIRE(plain.render(src.inner, std::span<glm::vec4>(out_plain)).ok());
    if (!edges) {  // one cluster: the plain frame, no probe at all
      CHECK(probes == 0);
      CHECK(std::memcmp(out.data(), out_plain.data(), out.size() * sizeof(glm::vec4)) == 0);
    } else {  // a probe per boundary sample, not per pixel; fewer evaluations than without probes
      CHECK(probes > 0);
      CHECK(probes * 10 < probes_every);
      CHECK(u.stats().evaluated() < plain.stats().evaluated());
    }
    CHECK(u.stats().evaluated() <= plain.stats().evaluated());
    CHECK(u.stats().interpolated() >= every.stats().interpolated());
  });
}

TEST_CASE("probes only where sources differ: a feature between agreeing sources is missed, as without probes", "[upsample]") {
  const std::uint32_t w = 17, h = 9;
  probing<thin_line> src;
  auto u = infolerp::upsampler<sample>::create(w, h, {.passes = 2, .max_passes = 2, .keep_ibuffer = true,
                                                      .probe_every_sample = false});
  REQUIRE(u.ok());
  std::vector<float> out(static_cast<std::size_t>(w) * h, -1.0f);
  REQUIRE(u->render(src, std::span<float>(out)).ok());
  for (std::uint32_t y = 0; y < h; ++y) {
    INFO("row " << y);
    CHECK(u->ibuffer()[y * w + 5].cluster == 0u);  // the column's sources (x = 4, 6) agree
    CHECK(out[y * w + 5] == 1.0f);
    CHECK(u->kinds()[y * w + 5] == sample_kind::interpolated);
  }
}

TEST_CASE("probes only where sources differ: serial and parallel outputs are bit-identical", "[upsample]") {
  refining<wavy> src;
  check_probe_frames_bit_identical(
      src, [&](const auto& serial) { CHECK(serial.stats().evaluated() > serial.stats().pass[0].evaluated); }, false);
  CHECK(src.probes.load() > 0);
}

// Refined probes that also probe many pixels of a row in one call, counting the calls; checks
// that each call's pixels are ascending (after the caller's checks, under a lock).
template <class Inner>
struct batching : refining<Inner> {
  using refining<Inner>::probe;
  mutable std::atomic<std::uint32_t> batches{0}, unordered{0};
  void probe(std::uint32_t y, std::span<const std::uint32_t> xs, std::span<sample> out) const {
    batches.fetch_add(1, std::memory_order_relaxed);
    if (!std::is_sorted(xs.begin(), xs.end()) || xs.size() != out.size()) unordered.fetch_add(1, std::memory_order_relaxed);
    for (std::size_t k = 0; k < xs.size(); ++k) out[k] = probe(xs[k], y);
  }
};

TEST_CASE("batched probes: the frames of single probes, per pixel and where sources differ", "[upsample]") {
  static_assert(infolerp::batch_probing_sample_source<batching<wavy>>);
  static_assert(!infolerp::batch_probing_sample_source<refining<wavy>>);
  const std::uint32_t w = 257, h = 190;
  for (bool every : {true, false})
    for (std::uint32_t passes = 2; passes <= 5; ++passes) {
      INFO("probe_every_sample " << every << " passes " << passes);
      auto render = [&](const auto& src, std::vector<glm::vec4>& out) {
        auto u = infolerp::upsampler<sample>::create(
            w, h, {.passes = passes, .max_passes = passes, .min_sources = 1, .probe_every_sample = every});
        REQUIRE(u.ok());
        out.assign(static_cast<std::size_t>(w) * h, glm::vec4(-7.0f));
        REQUIRE(u->render(src, std::span<glm::vec4>(out), infolerp::support::thread_pool_executor{3}).ok());
        return std::vector<sample_kind>(u->kinds().begin(), u->kinds().end());
      };
      refining<wavy> one;
      batching<wavy> many;
      std::vector<glm::vec4> a, b;
      const auto kinds_one = render(one, a);
      const auto kinds_many = render(many, b);
      CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec4)) == 0);
      CHECK(kinds_one == kinds_many);
      CHECK(many.probes.load() == one.probes.load());  // every probe went through a batch
      CHECK(many.batches.load() > 0);
      CHECK(many.batches.load() < many.probes.load());
      CHECK(many.unordered.load() == 0);
      CHECK(many.refinements.load() == one.refinements.load());
    }
}

TEST_CASE("normals_within: the angle between normals of any length, both ways", "[upsample]") {
  sample a, b;
  a.normal = {2.0f, 0.0f, 0.0f};
  b.normal = {0.5f, 0.5f, 0.0f};  // 45 degrees, neither unit
  const auto deg = [](float d) { return std::cos(d * 3.14159265f / 180.0f); };
  CHECK(infolerp::normals_within(a, b, deg(46.0f)));
  CHECK(infolerp::normals_within(b, a, deg(46.0f)));
  CHECK(!infolerp::normals_within(a, b, deg(44.0f)));
  CHECK(!infolerp::normals_within(b, a, deg(44.0f)));
  b.normal = {-1.0f, 0.01f, 0.0f};  // nearly opposite
  CHECK(infolerp::normals_within(a, b, deg(179.9f)));
  CHECK(!infolerp::normals_within(a, b, deg(178.0f)));
  CHECK(infolerp::normals_within(a, b, -1.0f));
  b.normal = glm::vec3(0.0f);  // no direction: only -1 accepts it
  CHECK(!infolerp::normals_within(a, b, deg(179.0f)));
  CHECK(infolerp::normals_within(a, b, -1.0f));
  CHECK(infolerp::normals_within(a, a, 1.0f - 1e-6f));
}

// Refined probes with a smooth() that always answers `answer`, counting its calls.
template <class Base>
struct smoothing : Base {
  bool answer = true;
  mutable std::atomic<std::uint32_t> calls{0};
  bool smooth(const sample&, const sample&) const {
    calls.fetch_add(1, std::memory_order_relaxed);
    return answer;
  }
};

TEST_CASE("smooth(): never smooth probes every new sample, always smooth is the sparse frame", "[upsample]") {
  const std::uint32_t w = 257, h = 190;
  const auto render = [&](const auto& src, bool every, std::vector<glm::vec4>& out) {
    auto u = infolerp::upsampler<sample>::create(
        w, h, {.passes = 4, .max_passes = 4, .min_sources = 1, .probe_every_sample = every});
    REQUIRE(u.ok());
    out.assign(static_cast<std::size_t>(w) * h, glm::vec4(-7.0f));
    REQUIRE(u->render(src, std::span<glm::vec4>(out)).ok());
    return std::vector<sample_kind>(u->kinds().begin(), u->kinds().end());
  };
  refining<wavy> plain;
  std::vector<glm::vec4> every, sparse, a, b;
  const auto kinds_every = render(plain, true, every);
  const auto kinds_sparse = render(plain, false, sparse);
  REQUIRE(std::memcmp(every.data(), sparse.data(), every.size() * sizeof(glm::vec4)) != 0);
  smoothing<refining<wavy>> never, always;
  never.answer = false;
  CHECK(render(never, false, a) == kinds_every);
  CHECK(std::memcmp(a.data(), every.data(), a.size() * sizeof(glm::vec4)) == 0);
  CHECK(render(always, false, b) == kinds_sparse);
  CHECK(std::memcmp(b.data(), sparse.data(), b.size() * sizeof(glm::vec4)) == 0);
  CHECK(never.calls.load() > 0);
  CHECK(always.calls.load() > 0);
  smoothing<refining<wavy>> unused;
  unused.answer = false;
  CHECK(render(unused, true, a) == kinds_every);  // with a probe per sample smooth() is not asked
  CHECK(unused.calls.load() == 0);
}

TEST_CASE("inv_depth weights reconstruct attributes affine on a plane seen in perspective", "[upsample]") {
  auto max_error = [](const plane_view& src) {
    auto up = make(81, 61, 4);
    std::vector<float> out(81 * 61);
    REQUIRE(up.render(src, std::span<float>(out)).ok());
    float e = 0.0f;
    for (std::uint32_t y = 0; y < 61; ++y)
      for (std::uint32_t x = 0; x < 81; ++x) {
        const sample& s = up.ibuffer()[y * 81 + x];
        const sample r = src.evaluate(x, y);
        e = std::max({e, glm::length(s.texcoord - r.texcoord), glm::length(s.position - r.position),
                      std::abs(s.occlusion[0] - r.occlusion[0]), std::abs(s.occlusion[1] - r.occlusion[1])});
      }
    return e;
  };
  plane_view perspective, linear;
  linear.weights = false;
  const float e_perspective = max_error(perspective), e_linear = max_error(linear);
  CHECK(e_perspective < 1e-4f);
  CHECK(e_linear > 1e-2f);
}

namespace {
// Base with agree(): the chosen sources' occlusion terms within `tolerance` (occlusion_within).
template <class Base>
struct tolerant : Base {
  float tolerance = std::numeric_limits<float>::infinity();
  bool agree(const sample& a, const sample& b) const { return infolerp::occlusion_within(a, b, tolerance); }
};

// One cluster, lit; AO = 1/2 + (x − y)/64 (dyadic, exact): the last of two passes has sources
// 2 px apart, so an edge's two sources differ by 1/32 in AO and a centre's four corners by
// 1/16 between its diagonal neighbours 10 and 01, while corner 00 differs from each of the
// other three by at most 1/32.
struct ao_ramp {
  using sample_type = sample;
  sample evaluate(std::uint32_t xi, std::uint32_t yi) const {
    sample s;
    s.cluster = 0;
    s.lights = 1;
    s.texcoord = {static_cast<float>(xi), static_cast<float>(yi)};
    s.occlusion = {0.5f + (static_cast<float>(xi) - static_cast<float>(yi)) / 64.0f, 0.25f};
    return s;
  }
  glm::vec4 shade(const sample& s, std::uint32_t, std::uint32_t) const { return glm::vec4(s.occlusion[0]); }
};

// Renders src with the given passes and min_sources, keeping samples and kinds.
template <class Src>
infolerp::upsampler<sample> rendered(const Src& src, std::uint32_t w, std::uint32_t h, std::uint32_t passes,
                                     std::vector<glm::vec4>& out, std::uint32_t min_sources = 2) {
  auto u = infolerp::upsampler<sample>::create(w, h, {.passes = passes, .max_passes = 5, .keep_ibuffer = true,
                                                      .min_sources = min_sources});
  REQUIRE(u.ok());
  out.assign(static_cast<std::size_t>(w) * h, glm::vec4(-3.0f));
  REQUIRE(u->render(src, std::span<glm::vec4>(out)).ok());
  return std::move(*u);
}
}  // namespace

TEST_CASE("occlusion_within: every term within the tolerance, both ways", "[upsample]") {
  sample a, b;
  a.occlusion = {0.5f, 0.25f};
  b.occlusion = {0.75f, 0.25f};
  CHECK(infolerp::occlusion_within(a, b, 0.25f));
  CHECK(infolerp::occlusion_within(b, a, 0.25f));
  CHECK_FALSE(infolerp::occlusion_within(a, b, 0.125f));
  CHECK_FALSE(infolerp::occlusion_within(b, a, 0.125f));
  b.occlusion = {0.5f, 0.0f};
  CHECK_FALSE(infolerp::occlusion_within(a, b, 0.125f));  // the second term
  CHECK(infolerp::occlusion_within(a, b, std::numeric_limits<float>::infinity()));
  b.occlusion[1] = std::numeric_limits<float>::quiet_NaN();  // unset terms never agree
  CHECK_FALSE(infolerp::occlusion_within(a, b, std::numeric_limits<float>::infinity()));
}

TEST_CASE("agree() off (infinite tolerance) gives today's frames bit for bit, plain and with probes", "[upsample]") {
  const std::uint32_t w = 257, h = 190;
  auto same = [&](const auto& without, const auto& with, std::uint32_t passes, std::uint32_t min_sources) {
    INFO("passes " << passes << " min_sources " << min_sources);
    std::vector<glm::vec4> a, b;
    const auto ua = rendered(without, w, h, passes, a, min_sources);
    const auto ub = rendered(with, w, h, passes, b, min_sources);
    CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec4)) == 0);
    CHECK(std::equal(ua.kinds().begin(), ua.kinds().end(), ub.kinds().begin()));
    CHECK(ua.stats().evaluated() == ub.stats().evaluated());
    if (passes > 1) CHECK(ua.stats().evaluated() > ua.stats().pass[0].evaluated);  // boundaries were evaluated
  };
  for (std::uint32_t passes = 1; passes <= 5; ++passes) {
    same(wavy{}, tolerant<wavy>{}, passes, 2);
    for (std::uint32_t min_sources : {1u, 2u}) {
      same(probing<wavy>{}, tolerant<probing<wavy>>{}, passes, min_sources);
      same(refining<wavy>{}, tolerant<refining<wavy>>{}, passes, min_sources);
    }
  }
}

TEST_CASE("agree(): sources of one cluster that differ by more than the tolerance are evaluated", "[upsample]") {
  const std::uint32_t w = 17, h = 9;
  // 1/32 < 0.05 < 1/16: edges agree, centres do not (their corners 10 and 01 differ by 1/16,
  // although 00 is within 1/32 of every other corner: the test must not stop at 00).
  auto check_kinds = [&](const auto& src, float tolerance, bool centres_evaluated) {
    INFO("tolerance " << tolerance);
    std::vector<glm::vec4> out;
    for (std::uint32_t min_sources : {1u, 2u}) {
      const auto u = rendered(src, w, h, 2, out, min_sources);
      std::size_t wrong = 0, wrong_value = 0;
      for (std::uint32_t y = 0; y < h; ++y)
        for (std::uint32_t x = 0; x < w; ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * w + x;
          const bool centre = (x & 1u) && (y & 1u), coarse = !(x & 1u) && !(y & 1u);
          const sample_kind want = coarse ? sample_kind::reused
                                   : centre && centres_evaluated ? sample_kind::evaluated
                                                                 : sample_kind::interpolated;
          wrong += u.kinds()[i] == want ? 0 : 1;
          // AO is linear: interpolated or evaluated, every value is exact.
          wrong_value += u.ibuffer()[i].occlusion[0] == ao_ramp{}.evaluate(x, y).occlusion[0] ? 0 : 1;
        }
      CHECK(wrong == 0);
      CHECK(wrong_value == 0);
      CHECK(u.stats().pass[1].evaluated == (centres_evaluated ? (w / 2) * (h / 2) : 0u));
    }
  };
  for (float tolerance : {0.05f, 0.07f}) {
    const bool centres = tolerance < 0.0625f;
    tolerant<ao_ramp> plain;
    plain.tolerance = tolerance;
    check_kinds(plain, tolerance, centres);
    tolerant<probing<ao_ramp>> probe;  // the probe's own occlusion is NaN: agree() never sees it
    probe.tolerance = tolerance;
    check_kinds(probe, tolerance, centres);
    tolerant<refining<ao_ramp>> refine;
    refine.tolerance = tolerance;
    check_kinds(refine, tolerance, centres);
    CHECK(refine.refinements.load() == 0u);  // sources that disagree evaluate; the probe is not refined first
  }
  // Below 1/32 the edges are evaluated too: only the first pass's samples are reused.
  tolerant<probing<ao_ramp>> strict;
  strict.tolerance = 0.01f;
  std::vector<glm::vec4> out;
  const auto u = rendered(strict, w, h, 2, out, 1);
  CHECK(u.stats().pass[1].interpolated == 0u);
  CHECK(u.stats().pass[1].reused == static_cast<std::size_t>((w + 1) / 2) * ((h + 1) / 2));
}

TEST_CASE("agree(): serial and parallel outputs are bit-identical", "[upsample]") {
  std::vector<glm::vec4> out;
  // Evaluations of the same source without agree(), for the serial frame's min_sources.
  const auto untouched = [&](const auto& src, const auto& serial) {
    return rendered(src, 257, 190, 4, out, serial.options().min_sources).stats().evaluated();
  };
  tolerant<probing<wavy>> probe;
  probe.tolerance = 0.2f;
  check_probe_frames_bit_identical(probe, [&](const auto& serial) {
    CHECK(serial.stats().evaluated() > untouched(probing<wavy>{}, serial));  // the tolerance evaluated some samples
    CHECK(serial.stats().interpolated() > serial.stats().evaluated());
  });
  tolerant<refining<wavy>> refine;
  refine.tolerance = 0.2f;
  check_probe_frames_bit_identical(refine, [&](const auto& serial) {
    CHECK(serial.stats().evaluated() > untouched(refining<wavy>{}, serial));
  });
  // Plain path.
  tolerant<wavy> plain;
  plain.tolerance = 0.2f;
  std::vector<glm::vec4> ref, par(static_cast<std::size_t>(257) * 190);
  const auto serial = rendered(plain, 257, 190, 4, ref);
  CHECK(serial.stats().evaluated() > rendered(wavy{}, 257, 190, 4, out).stats().evaluated());
  auto up = make(257, 190, 4);
  REQUIRE(up.render(plain, std::span<glm::vec4>(par), infolerp::support::thread_pool_executor{3}).ok());
  CHECK(std::memcmp(par.data(), ref.data(), ref.size() * sizeof(glm::vec4)) == 0);
  CHECK(std::equal(up.kinds().begin(), up.kinds().end(), serial.kinds().begin()));
}
