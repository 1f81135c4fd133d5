// Reuse across frames (upsample/frame_reuse.hpp): on the demo scene through Embree with the
// ready source, a fresh frame after invalidate(), a camera standing still and a camera cut
// against the upsampler without reuse in the same run, bit for bit; every executor alike; a
// small move close to the fresh frame; 500 slow frames and 50 standing ending on the fresh frame;
// bad input named. On analytic scenes (a plane, a sphere and its soft shadow under a sun):
// reused terms against the analytic values after a sub-pixel move, disoccluded pixels against
// the from-scratch frame, a moved object, a moved light and a changed material with and without
// invalidate_if against the from-scratch frame (the checks without it show the stale values),
// the age bound, and warm frames allocating nothing.
#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <cstring>
#include <optional>
#include <span>
#include <vector>
#include "infolerp/upsample/frame_reuse.hpp"
#include "infolerp/upsample/ray_cast_source.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "support/allocation_counter.hpp"
#include "support/demo_clusters.hpp"
#include "support/demo_upsample.hpp"
#include "support/small_demo_scene.hpp"
#include "support/thread_pool.hpp"

namespace support = infolerp::support;
using infolerp::probe_mode;
using sample = support::demo_sample;

namespace {

constexpr std::uint32_t W = 96, H = 72;

support::demo_scene& scene() {
  static const support::embree_device device;
  static support::demo_scene s = support::make_small_demo_scene(device);
  return s;
}

const support::scene_clustering& clusters() {
  static const support::scene_clustering c = [] {
    auto seams = support::split_at_texture_seams(scene(), support::cluster_by_normal(scene(), 2));
    REQUIRE(seams);
    return std::move(*seams);
  }();
  return c;
}

support::camera base_camera() {
  static const support::camera c = scene().view;
  return c;
}

support::camera moved(float dx, float dy = 0.0f) {
  support::camera c = base_camera();
  c.eye += glm::vec3(dx, dy, 0.0f);
  return c;
}

infolerp::upsampler<sample> make_upsampler() {
  auto up = infolerp::upsampler<sample>::create(W, H, {.passes = 3, .max_passes = 3, .keep_ibuffer = true});
  REQUIRE(up);
  return std::move(*up);
}

// Calls f(source, view) with the ready source (primary probes unless told) seeing the scene through camera c.
template <probe_mode Mode = probe_mode::primary, class F>
void with_view(const support::camera& c, const F& f) {
  scene().view = c;
  const support::reference_shader shader(scene(), {.ao_rays = 8, .soft_shadow_rays = 4});
  auto src = support::make_demo_ray_cast_source<Mode>(shader, clusters(), int(W), int(H));
  REQUIRE(src);
  f(*src, support::pinhole_frame_of(c, W, H));
  scene().view = base_camera();
}

bool same_frame(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
}

// The frame through camera c without reuse, and the upsampler's evaluation count.
std::vector<glm::vec3> fresh(const support::camera& c, std::size_t* evaluated = nullptr) {
  std::vector<glm::vec3> out(std::size_t{W} * H);
  auto up = make_upsampler();
  with_view(c, [&](const auto& src, const infolerp::pinhole_frame&) { REQUIRE(up.render(src, std::span<glm::vec3>(out))); });
  if (evaluated) *evaluated = up.stats().evaluated();
  return out;
}

template <class E = infolerp::serial_executor>
std::vector<glm::vec3> reuse_frame(infolerp::frame_reuse<sample>& reuse, infolerp::upsampler<sample>& up,
                                   const support::camera& c, E exec = E{}) {
  std::vector<glm::vec3> out(std::size_t{W} * H);
  with_view(c, [&](const auto& src, const infolerp::pinhole_frame& view) {
    REQUIRE(reuse.render(up, src, view, std::span<glm::vec3>(out), exec));
  });
  return out;
}

// Pixels of the image the last render evaluated (the cropped border beyond the edge, which the
// upsampler evaluates every frame, is not among them).
std::size_t evaluated_in_image(const infolerp::frame_reuse<sample>& reuse) {
  std::size_t n = 0;
  for (std::uint8_t m : reuse.marks()) n += m >= std::uint8_t(infolerp::reuse_mark::evaluated) ? 1 : 0;
  return n;
}

double psnr(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  double se = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double d = support::display_luma(a[i]) - support::display_luma(b[i]);
    se += d * d;
  }
  return se == 0.0 ? 200.0 : 10.0 * std::log10(double(a.size()) / se);
}

}  // namespace

TEST_CASE("frame reuse: the first frame and a frame after invalidate() are fresh frames, bit for bit",
          "[upsample][frame_reuse]") {
  auto reuse = infolerp::frame_reuse<sample>::create(W, H);
  REQUIRE(reuse);
  auto up = make_upsampler();
  std::size_t fresh_evaluated = 0;
  const auto first = reuse_frame(*reuse, up, base_camera());
  CHECK(same_frame(first, fresh(base_camera(), &fresh_evaluated)));
  CHECK(up.stats().evaluated() == fresh_evaluated);
  CHECK(reuse->stats().reused == 0);
  const auto second = reuse_frame(*reuse, up, moved(0.05f));
  CHECK(reuse->stats().reused > 0);
  CHECK_FALSE(same_frame(second, fresh(moved(0.05f))));  // reuse changed something: the check below means something
  reuse->invalidate();
  CHECK_FALSE(reuse->has_history());
  const auto third = reuse_frame(*reuse, up, moved(0.05f));
  CHECK(same_frame(third, fresh(moved(0.05f), &fresh_evaluated)));
  CHECK(up.stats().evaluated() == fresh_evaluated);
  CHECK(reuse->stats().reused == 0);
}

TEST_CASE("frame reuse: a camera standing still reuses every sample and repeats the frame bit for bit",
          "[upsample][frame_reuse]") {
  auto reuse = infolerp::frame_reuse<sample>::create(W, H);
  REQUIRE(reuse);
  auto up = make_upsampler();
  const auto first = reuse_frame(*reuse, up, base_camera());
  const std::size_t first_evaluated = reuse->stats().evaluated;
  CHECK(first_evaluated > 0);
  for (int k = 0; k < 3; ++k) {
    const auto again = reuse_frame(*reuse, up, base_camera());
    CHECK(same_frame(again, first));
    CHECK(evaluated_in_image(*reuse) == 0);
    CHECK(reuse->stats().reused > 0);
  }
}

TEST_CASE("frame reuse: a small move stays close to the fresh frame; a camera cut falls back to a fresh frame",
          "[upsample][frame_reuse]") {
  auto reuse = infolerp::frame_reuse<sample>::create(W, H);
  REQUIRE(reuse);
  auto up = make_upsampler();
  (void)reuse_frame(*reuse, up, base_camera());
  const auto step = reuse_frame(*reuse, up, moved(0.03f, 0.02f));
  const double reused = reuse->stats().reused_fraction();
  CHECK(reused > 0.5 * (reused + reuse->stats().evaluated_fraction()));  // most evaluations served
  const auto ref = fresh(moved(0.03f, 0.02f));
  CHECK(psnr(step, ref) > 35.0);
  // A cut: looking down at the ground in front of the camera, below the previous view's frame.
  support::camera cut = base_camera();
  cut.eye = {0.0f, -7.1f, 1.0f};
  cut.target = {0.0f, -7.2f, 0.0f};
  std::size_t fresh_evaluated = 0;
  const auto after_cut = reuse_frame(*reuse, up, cut);
  CHECK(reuse->stats().reused == 0);
  CHECK(same_frame(after_cut, fresh(cut, &fresh_evaluated)));
  CHECK(up.stats().evaluated() == fresh_evaluated);
}

TEST_CASE("frame reuse: with refined probes where sources differ, fresh after invalidate() and repeated when standing",
          "[upsample][frame_reuse]") {
  const infolerp::upsampler_options sparse{.passes = 4, .max_passes = 4, .keep_ibuffer = true, .min_sources = 1,
                                           .probe_every_sample = false};
  auto up = infolerp::upsampler<sample>::create(W, H, sparse);
  auto plain = infolerp::upsampler<sample>::create(W, H, sparse);
  auto reuse = infolerp::frame_reuse<sample>::create(W, H);
  REQUIRE((up && plain && reuse));
  std::vector<glm::vec3> out(std::size_t{W} * H), fresh_out(out.size()), first(out.size());
  const auto frame = [&](const support::camera& c) {
    with_view<probe_mode::refine>(c, [&](const auto& src, const infolerp::pinhole_frame& view) {
      REQUIRE(reuse->render(*up, src, view, std::span<glm::vec3>(out)));
      REQUIRE(plain->render(src, std::span<glm::vec3>(fresh_out)));
    });
  };
  frame(base_camera());
  CHECK(same_frame(out, fresh_out));
  first = out;
  frame(base_camera());
  CHECK(same_frame(out, first));
  CHECK(evaluated_in_image(*reuse) == 0);
  frame(moved(0.05f));
  CHECK(reuse->stats().reused > 0);
  CHECK(psnr(out, fresh_out) > 35.0);
  reuse->invalidate();
  frame(moved(0.05f));
  CHECK(same_frame(out, fresh_out));
}

TEST_CASE("frame reuse: every executor gives the same frames", "[upsample][frame_reuse]") {
  const auto path = [](auto exec) {
    auto reuse = infolerp::frame_reuse<sample>::create(W, H);
    REQUIRE(reuse);
    auto up = make_upsampler();
    std::vector<std::vector<glm::vec3>> frames;
    for (int f = 0; f < 4; ++f) frames.push_back(reuse_frame(*reuse, up, moved(0.04f * float(f), 0.01f * float(f)), exec));
    return frames;
  };
  const auto serial = path(infolerp::serial_executor{});
  const auto check = [&](const auto& frames) {
    REQUIRE(frames.size() == serial.size());
    for (std::size_t f = 0; f < frames.size(); ++f) CHECK(same_frame(frames[f], serial[f]));
  };
  check(path(support::thread_pool_executor{2}));
  check(path(support::thread_pool_executor{8}));
#ifdef _OPENMP
  check(path(infolerp::openmp_executor{}));
#endif
}

TEST_CASE("frame reuse: bad input is named", "[upsample][frame_reuse][bad_input]") {
  CHECK(infolerp::frame_reuse<sample>::create(0, H).error().code() == infolerp::errc::empty_input);
  CHECK(infolerp::frame_reuse<sample>::create(W, H, {.depth_tolerance = -1.0f}).error().code() ==
        infolerp::errc::bad_parameter);
  auto reuse = infolerp::frame_reuse<sample>::create(W, H);
  REQUIRE(reuse);
  auto up = make_upsampler();
  std::vector<glm::vec3> out(std::size_t{W} * H);
  with_view(base_camera(), [&](const auto& src, const infolerp::pinhole_frame& view) {
    // A camera whose image is another size.
    infolerp::pinhole_frame other = view;
    other.width = W + 1;
    const infolerp::status s = reuse->render(up, src, other, std::span<glm::vec3>(out));
    CHECK(s.code() == infolerp::errc::bad_size);
    CHECK(s.message().find("97x72") != std::string::npos);
    // An upsampler that does not keep its I-Buffer.
    auto plain = infolerp::upsampler<sample>::create(W, H, {.passes = 3, .max_passes = 3});
    REQUIRE(plain);
    CHECK(reuse->render(*plain, src, view, std::span<glm::vec3>(out)).code() == infolerp::errc::bad_parameter);
    // Ids whose meaning changed without invalidate().
    REQUIRE(reuse->render(up, src, view, std::span<glm::vec3>(out), infolerp::serial_executor{}, 1));
    const infolerp::status ids = reuse->render(up, src, view, std::span<glm::vec3>(out), infolerp::serial_executor{}, 2);
    CHECK(ids.code() == infolerp::errc::bad_parameter);
    CHECK(ids.message().find("1 -> 2") != std::string::npos);
    reuse->invalidate();
    CHECK(reuse->render(up, src, view, std::span<glm::vec3>(out), infolerp::serial_executor{}, 2));
    // A camera frame that is not finite.
    infolerp::pinhole_frame broken = view;
    broken.eye.x = std::nanf("");
    CHECK(reuse->render(up, src, broken, std::span<glm::vec3>(out)).code() == infolerp::errc::bad_parameter);
  });
}

// ---- An analytic scene: the plane z = 0 (cluster 0) and a sphere (cluster 1) under a sun
// whose soft shadow is a smooth function of the distance between the sun ray and the sphere's
// centre (occlusion[0]); the probe is the primary hit without it.
namespace {

using asample = infolerp::surface_sample<1, false>;

struct sphere_scene {
  glm::vec3 centre{0.0f, 0.0f, 1.0f};
  float radius = 0.8f;
  glm::vec3 to_sun = glm::normalize(glm::vec3(0.6f, 0.2f, 1.0f));
  // Visible fraction of the sun at p: 0 deep in the sphere's shadow, 1 outside its penumbra.
  float sun_visible(glm::vec3 p) const {
    const glm::vec3 d = centre - p;
    const float along = glm::dot(d, to_sun);
    if (along <= 0.0f) return 1.0f;
    const float dist = glm::length(d - along * to_sun);
    return std::clamp((dist - 0.7f * radius) / (0.6f * radius), 0.0f, 1.0f);
  }
};

struct analytic_source {
  using sample_type = asample;
  const sphere_scene* sc = nullptr;
  infolerp::pinhole_frame view{};
  bool affine = false;        // the plane's term is affine_term(position) instead of the soft shadow
  float sphere_albedo = 1.0f;  // the sphere's material: its shaded value is this times its term
  float sphere_term = 1.0f;    // the sphere's occlusion term

  static float affine_term(glm::vec3 p) { return 0.5f + 0.11f * p.x - 0.07f * p.y; }

  asample probe(std::uint32_t x, std::uint32_t y) const {
    const infolerp::ray r = view.primary_ray(x, y);
    asample s;
    float best = 1e30f;
    const glm::vec3 oc = r.origin - sc->centre;
    const float b = glm::dot(oc, r.direction), c = glm::dot(oc, oc) - sc->radius * sc->radius, disc = b * b - c;
    if (disc >= 0.0f && -b - std::sqrt(disc) > 0.0f) {
      best = -b - std::sqrt(disc);
      s.cluster = 1;
    }
    if (r.direction.z < 0.0f) {
      const float t = -r.origin.z / r.direction.z;
      if (t < best) {
        best = t;
        s.cluster = 0;
      }
    }
    if (s.background()) return s;
    s.position = r.origin + best * r.direction;
    s.normal = s.cluster == 1 ? glm::normalize(s.position - sc->centre) : glm::vec3(0.0f, 0.0f, 1.0f);
    s.inv_depth = 1.0f / glm::dot(s.position - view.eye, view.forward);
    return s;
  }
  asample evaluate(std::uint32_t x, std::uint32_t y) const {
    asample s = probe(x, y);
    if (!s.background()) s.occlusion[0] = s.cluster == 1 ? sphere_term : affine ? affine_term(s.position) : sc->sun_visible(s.position);
    return s;
  }
  float shade(const asample& s, std::uint32_t, std::uint32_t) const {
    return s.background() ? -1.0f : s.cluster == 1 ? sphere_albedo * s.occlusion[0] : s.occlusion[0];
  }
  float view_dependence(const asample&) const { return 0.0f; }  // diffuse: kept colours serve (with a Pixel type)
};

infolerp::pinhole_frame analytic_view() {
  const infolerp::pinhole_camera cam{.eye = {0.0f, -6.0f, 4.0f}, .target = {0.5f, 0.5f, 0.0f}, .up = {0.0f, 0.0f, 1.0f},
                                     .vertical_fov_degrees = 50.0f, .width = W, .height = H};
  return cam.frame();
}

// Whether a kept sample may change when the sphere moves from a to b: on the sphere, or its
// sun ray passes within the penumbra's reach of either centre (what a user knows of its change).
struct touched_by_move {
  sphere_scene a, b;
  bool operator()(const asample& s) const {
    if (s.background()) return false;
    return s.cluster == 1 || a.sun_visible(s.position) < 1.0f || b.sun_visible(s.position) < 1.0f;
  }
};

}  // namespace

TEST_CASE("frame reuse: a moved object invalidated by the user never shows stale occlusion", "[upsample][frame_reuse]") {
  const sphere_scene before{};
  sphere_scene after = before;
  after.centre += glm::vec3(-0.9f, 0.6f, 0.0f);
  const infolerp::pinhole_frame view = analytic_view();
  const analytic_source src_before{&before, view}, src_after{&after, view};
  auto up = infolerp::upsampler<asample>::create(W, H, {.passes = 3, .max_passes = 3, .keep_ibuffer = true});
  REQUIRE(up);
  std::vector<float> fresh_before(std::size_t{W} * H), fresh_after(fresh_before.size()), out(fresh_before.size());
  REQUIRE(up->render(src_before, std::span<float>(fresh_before)));
  REQUIRE(up->render(src_after, std::span<float>(fresh_after)));
  std::size_t changed = 0;
  for (std::size_t i = 0; i < out.size(); ++i) changed += std::abs(fresh_before[i] - fresh_after[i]) > 0.05f ? 1 : 0;
  REQUIRE(changed > 100);  // the move changes a visible part of the shadow

  // Worst difference from the fresh frame of the moved scene over the changed pixels.
  const auto stale_error = [&](bool invalidate) {
    auto reuse = infolerp::frame_reuse<asample>::create(W, H);
    REQUIRE(reuse);
    REQUIRE(reuse->render(*up, src_before, view, std::span<float>(out)));
    if (invalidate) reuse->invalidate_if(touched_by_move{before, after});
    REQUIRE(reuse->render(*up, src_after, view, std::span<float>(out)));
    CHECK(reuse->stats().reused > 0);
    float worst = 0.0f;
    for (std::size_t i = 0; i < out.size(); ++i)
      if (std::abs(fresh_before[i] - fresh_after[i]) > 0.05f) worst = std::max(worst, std::abs(out[i] - fresh_after[i]));
    return worst;
  };
  CHECK(stale_error(true) == 0.0f);  // the camera stands still: what is not stale is the fresh frame's own
  CHECK(stale_error(false) > 0.5f);  // without invalidation the old shadow shows
}

TEST_CASE("frame reuse: warm frames along a path allocate nothing", "[upsample][frame_reuse]") {
  const sphere_scene sc{};
  auto up = infolerp::upsampler<asample>::create(W, H, {.passes = 3, .max_passes = 3, .keep_ibuffer = true});
  REQUIRE(up);
  auto reuse = infolerp::frame_reuse<asample>::create(W, H);
  REQUIRE(reuse);
  std::vector<float> out(std::size_t{W} * H);
  infolerp::pinhole_camera cam{.eye = {0.0f, -6.0f, 4.0f}, .target = {0.5f, 0.5f, 0.0f}, .up = {0.0f, 0.0f, 1.0f},
                               .vertical_fov_degrees = 50.0f, .width = W, .height = H};
  REQUIRE(reuse->render(*up, analytic_source{&sc, cam.frame()}, cam.frame(), std::span<float>(out)));
  const std::size_t before = support::heap_allocations.load();
  std::size_t reused = 0;
  for (int f = 1; f <= 4; ++f) {
    cam.eye.x += 0.02f;
    REQUIRE(reuse->render(*up, analytic_source{&sc, cam.frame()}, cam.frame(), std::span<float>(out)));
    reused += reuse->stats().reused;
  }
  CHECK(support::heap_allocations.load() == before);
  CHECK(reused > 0);
  const std::vector<int> probe_counter(4);  // the counter sees this file's allocations
  CHECK(support::heap_allocations.load() > before);
}

// ---- Tests of what reuse can get wrong, each against a frame or value computed without reuse.

TEST_CASE("frame reuse: reused terms over a plane equal the analytic values after a sub-pixel move",
          "[upsample][frame_reuse]") {
  // Looking straight down at the plane z = 0 (no sphere in view) whose term is affine in the
  // world: a perspective-correct bilinear blend of kept terms reproduces it exactly wherever the
  // reprojection lands, while taking the nearest kept sample is off by the term's change over
  // up to half a pixel. The camera moves 0.37 pixel right and 0.21 pixel down (at the plane).
  sphere_scene far_away{};
  far_away.centre = {100.0f, 100.0f, -50.0f};
  infolerp::pinhole_camera cam{.eye = {0.3f, 0.2f, 5.0f}, .target = {0.3f, 0.2f, 0.0f}, .up = {0.0f, 1.0f, 0.0f},
                               .vertical_fov_degrees = 50.0f, .width = W, .height = H};
  const float pixel = 2.0f * 5.0f * std::tan(25.0f * 3.14159265f / 180.0f) / float(H);  // world size of a pixel at the plane
  auto up = infolerp::upsampler<asample>::create(W, H, {.passes = 3, .max_passes = 3, .keep_ibuffer = true});
  auto reuse = infolerp::frame_reuse<asample>::create(W, H, {.refresh_period = 0});
  REQUIRE((up && reuse));
  std::vector<float> out(std::size_t{W} * H);
  REQUIRE(reuse->render(*up, analytic_source{&far_away, cam.frame(), true}, cam.frame(), std::span<float>(out)));
  const glm::vec3 step(0.37f * pixel, -0.21f * pixel, 0.0f);
  cam.eye += step;
  cam.target += step;
  const infolerp::pinhole_frame moved_view = cam.frame();
  const analytic_source moved{&far_away, moved_view, true};
  REQUIRE(reuse->render(*up, moved, moved_view, std::span<float>(out)));
  std::size_t checked = 0;
  float worst = 0.0f;
  for (std::uint32_t y = 0; y < H; ++y)
    for (std::uint32_t x = 0; x < W; ++x) {
      if (reuse->marks()[std::size_t{y} * W + x] != std::uint8_t(infolerp::reuse_mark::reused)) continue;
      const asample p = moved.probe(x, y);
      REQUIRE(p.cluster == 0);
      worst = std::max(worst, std::abs(out[std::size_t{y} * W + x] - analytic_source::affine_term(p.position)));
      ++checked;
    }
  CHECK(checked > 400);  // most of the 25x19 coarse grid of a 3-pass frame (the rest is at the edge)
  // Nearest-sample reuse would be off by up to 0.13 x pixel x (1/2 pixel) = 4e-3; float rounding
  // of positions and weights stays below 2e-5 here.
  CHECK(worst < 2e-5f);
}

TEST_CASE("frame reuse: pixels disoccluded by a sideways step are never filled from the occluder",
          "[upsample][frame_reuse]") {
  // The sphere over the plane; the camera steps sideways so that plane seen past the sphere's
  // edge was behind it in the previous frame. Such pixels (found analytically: the previous eye's
  // ray to the hit meets the sphere first) must show the plane as the from-scratch frame does.
  const sphere_scene sc{};
  infolerp::pinhole_camera cam{.eye = {0.0f, -6.0f, 2.0f}, .target = {0.0f, 0.0f, 0.8f}, .up = {0.0f, 0.0f, 1.0f},
                               .vertical_fov_degrees = 40.0f, .width = W, .height = H};
  auto up = infolerp::upsampler<asample>::create(W, H, {.passes = 3, .max_passes = 3, .keep_ibuffer = true});
  auto fresh_up = infolerp::upsampler<asample>::create(W, H, {.passes = 3, .max_passes = 3});
  auto reuse = infolerp::frame_reuse<asample>::create(W, H);
  REQUIRE((up && fresh_up && reuse));
  std::vector<float> out(std::size_t{W} * H), fresh_out(out.size());
  const glm::vec3 before_eye = cam.eye;
  // The sphere's term 0: a plane pixel (sun-lit here, term 1) completed from it would show 0.
  REQUIRE(reuse->render(*up, analytic_source{&sc, cam.frame(), false, 1.0f, 0.0f}, cam.frame(), std::span<float>(out)));
  cam.eye.x += 0.25f;
  cam.target.x += 0.25f;
  const analytic_source src{&sc, cam.frame(), false, 1.0f, 0.0f};
  REQUIRE(reuse->render(*up, src, cam.frame(), std::span<float>(out)));
  REQUIRE(fresh_up->render(src, std::span<float>(fresh_out)));
  const auto hidden_before = [&](glm::vec3 p) {  // the segment from the previous eye to p meets the sphere
    const glm::vec3 d = p - before_eye;
    const float len = glm::length(d);
    const glm::vec3 u = d / len, oc = before_eye - sc.centre;
    const float b = glm::dot(oc, u), c = glm::dot(oc, oc) - sc.radius * sc.radius, disc = b * b - c;
    return disc > 0.0f && -b - std::sqrt(disc) > 0.0f && -b - std::sqrt(disc) < len - 1e-3f;
  };
  std::size_t disoccluded = 0;
  float worst = 0.0f;
  for (std::uint32_t y = 0; y < H; ++y)
    for (std::uint32_t x = 0; x < W; ++x) {
      const asample p = src.probe(x, y);
      if (p.background() || p.cluster != 0 || !hidden_before(p.position)) continue;
      ++disoccluded;
      const std::size_t i = std::size_t{y} * W + x;
      worst = std::max(worst, std::abs(out[i] - fresh_out[i]));
    }
  REQUIRE(disoccluded > 20);
  CHECK(worst < 0.05f);
  CHECK(reuse->stats().reused > 0);
}

TEST_CASE("frame reuse: a moved light and a changed material, with and without invalidate_if",
          "[upsample][frame_reuse]") {
  const infolerp::pinhole_frame view = analytic_view();
  auto up = infolerp::upsampler<asample>::create(W, H, {.passes = 3, .max_passes = 3, .keep_ibuffer = true});
  auto fresh_up = infolerp::upsampler<asample>::create(W, H, {.passes = 3, .max_passes = 3});
  REQUIRE((up && fresh_up));
  std::vector<float> out(std::size_t{W} * H), fresh_out(out.size());
  // Worst difference from the from-scratch frame of `after` after a frame of `before` (same
  // camera), with invalidate_if(pred) between them when given.
  const auto worst_after = [&](const analytic_source& before, const analytic_source& after, const auto* pred) {
    auto reuse = infolerp::frame_reuse<asample, float>::create(W, H);
    REQUIRE(reuse);
    REQUIRE(reuse->render(*up, before, view, std::span<float>(out)));
    REQUIRE(reuse->render(*up, before, view, std::span<float>(out)));  // a standing camera: colours kept whole
    if (pred) reuse->invalidate_if(*pred);
    REQUIRE(reuse->render(*up, after, view, std::span<float>(out)));
    REQUIRE(fresh_up->render(after, std::span<float>(fresh_out)));
    float worst = 0.0f;
    for (std::size_t i = 0; i < out.size(); ++i) worst = std::max(worst, std::abs(out[i] - fresh_out[i]));
    return worst;
  };
  SECTION("the sun moves: the shadow changes") {
    const sphere_scene a{};
    sphere_scene b = a;
    b.to_sun = glm::normalize(glm::vec3(-0.5f, 0.4f, 1.0f));
    const analytic_source before{&a, view}, after{&b, view};
    // What the user knows: a kept sample in either shadow (or on the sphere) may change.
    const auto in_either_shadow = [&](const asample& s) {
      return !s.background() && (s.cluster == 1 || a.sun_visible(s.position) < 1.0f || b.sun_visible(s.position) < 1.0f);
    };
    const decltype(in_either_shadow)* none = nullptr;
    CHECK(worst_after(before, after, &in_either_shadow) == 0.0f);  // standing camera: the rest is the fresh frame's own
    CHECK(worst_after(before, after, none) > 0.5f);                // without it the old shadow stays
  }
  SECTION("the sphere's material changes: its kept colour is stale") {
    const sphere_scene a{};
    analytic_source before{&a, view}, after{&a, view};
    after.sphere_albedo = 0.4f;
    const auto on_sphere = [](const asample& s) { return s.cluster == 1; };
    const decltype(on_sphere)* none = nullptr;
    CHECK(worst_after(before, after, &on_sphere) == 0.0f);
    CHECK(worst_after(before, after, none) > 0.5f);  // the kept colour of the old material
  }
}

TEST_CASE("frame reuse: 500 slow frames then 50 standing end on the fresh frame", "[upsample][frame_reuse]") {
  // The ready source on the small demo scene, colours kept: the camera drifts sideways 0.002 a
  // frame for 500 frames, then stands for 50. Every moving frame stays within the quality goal
  // of its from-scratch frame (checked every 50th), and standing, the refreshes reach every
  // sample, so the last frame is the fresh frame bit for bit and is repeated without rendering.
  auto reuse = infolerp::frame_reuse<sample, glm::vec3>::create(W, H);
  REQUIRE(reuse);
  auto up = make_upsampler();
  std::vector<glm::vec3> out(std::size_t{W} * H);
  double worst_moving = 200.0;
  for (int f = 0; f < 550; ++f) {
    const support::camera c = moved(0.002f * float(std::min(f, 499)));
    with_view(c, [&](const auto& src, const infolerp::pinhole_frame& view) {
      REQUIRE(reuse->render(up, src, view, std::span<glm::vec3>(out)));
    });
    if (f < 500 && f % 50 == 49) worst_moving = std::min(worst_moving, psnr(out, fresh(c)));
  }
  CHECK(worst_moving >= 40.0);
  CHECK(reuse->stats().repeated);
  CHECK(same_frame(out, fresh(moved(0.002f * 499.0f))));
}

TEST_CASE("frame reuse: no served term is more than max_age resamplings from an evaluation", "[upsample][frame_reuse]") {
  // max_age 1, no refreshes, a camera moving every frame: frame 1 serves terms resampled once
  // (age 1), and the samples the upsampler interpolates from them carry that age too, so frame
  // 2 can serve almost nothing; frame 3, from frame 2's evaluations, serves again.
  const sphere_scene sc{};
  infolerp::pinhole_camera cam{.eye = {0.0f, -6.0f, 4.0f}, .target = {0.5f, 0.5f, 0.0f}, .up = {0.0f, 0.0f, 1.0f},
                               .vertical_fov_degrees = 50.0f, .width = W, .height = H};
  auto up = infolerp::upsampler<asample>::create(W, H, {.passes = 3, .max_passes = 3, .keep_ibuffer = true});
  auto reuse = infolerp::frame_reuse<asample>::create(W, H, {.refresh_period = 0, .max_age = 1});
  REQUIRE((up && reuse));
  std::vector<float> out(std::size_t{W} * H);
  std::array<std::size_t, 4> reused{};
  for (std::size_t f = 0; f < reused.size(); ++f) {
    REQUIRE(reuse->render(*up, analytic_source{&sc, cam.frame()}, cam.frame(), std::span<float>(out)));
    reused[f] = reuse->stats().reused;
    cam.eye.x += 0.13f;  // a few pixels: the kept samples around a reprojection are mostly interpolated ones
  }
  CHECK(reused[0] == 0);
  CHECK(reused[1] > 300);
  CHECK(reused[2] * 20 < reused[1]);
  CHECK(reused[3] > 300);
}
