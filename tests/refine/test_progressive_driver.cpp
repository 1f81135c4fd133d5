// refine/criteria.hpp and refine/progressive_driver.hpp with a brute-force tracer: stage 1
// figures by hand, the vertex cache (each vertex shaded once), exact interpolation of an affine
// shading, each criterion's termination rule checked from outside, determinism across executors.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include "infolerp/refine/nld_os_queue.hpp"
#include "infolerp/refine/progressive_driver.hpp"
#include "support/brute_force_tracer.hpp"
#include "support/glm_projection.hpp"
#include "support/procedural.hpp"
#include "support/thread_pool.hpp"

using namespace infolerp;  // NOLINT: test file

namespace {

using support::brute_force_tracer;

// A coarse floor (two triangles) under a camera looking straight down.
indexed_mesh floor_mesh() { return support::make_plane(1, 1, 2.0f); }
pinhole_camera top_camera(std::uint32_t w = 64, std::uint32_t h = 64) {
  return {.eye = {0, 0, 1.8f}, .target = {0, 0, 0}, .up = {0, 1, 0}, .vertical_fov_degrees = 60.0f, .width = w, .height = h};
}
// A hard shadow edge along x = 0.23 that misses every vertex of the floor.
glm::vec3 shadowed(glm::vec3 p) { return p.x < 0.23f ? glm::vec3(0.05f) : glm::vec3(0.9f, 0.8f, 0.7f); }

double psnr(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  double se = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const glm::vec3 d = glm::clamp(a[i], 0.0f, 1.0f) - glm::clamp(b[i], 0.0f, 1.0f);
    se += glm::dot(glm::dvec3(d), glm::dvec3(d)) / 3.0;
  }
  const double mse = se / double(a.size());
  return mse <= 0.0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(1.0 / mse);
}

// Per-pixel reference: shade the primary hit point of every pixel.
std::vector<glm::vec3> reference(const indexed_mesh& m, const pinhole_camera& cam, glm::vec3 (*f)(glm::vec3)) {
  brute_force_tracer tr{&m};
  std::vector<glm::vec3> img(std::size_t(cam.width) * cam.height, glm::vec3(0.0f));
  for (std::uint32_t y = 0; y < cam.height; ++y)
    for (std::uint32_t x = 0; x < cam.width; ++x) {
      const ray r = cam.primary_ray(x, y);
      const hit h = tr.intersect(r);
      if (h.valid()) img[std::size_t(y) * cam.width + x] = f(r.origin + h.distance * r.direction);
    }
  return img;
}

progressive_refiner make_refiner(const indexed_mesh& m, driver_options o, subdivision_options so = {}) {
  auto s = subdivision_mesh::create(m, so);
  REQUIRE(s.ok());
  auto r = progressive_refiner::create(std::move(*s), o);
  REQUIRE(r.ok());
  return std::move(*r);
}

// Triangle (a, b, c)'s area in pixels under the camera, from glm's own matrices.
double oracle_area(const pinhole_camera& c, glm::vec3 a, glm::vec3 b, glm::vec3 d) { return support::glm_projected_area(c, a, b, d); }

std::vector<glm::vec3> image_of(const progressive_refiner& r, const pinhole_camera& cam) {
  std::vector<glm::vec3> img(std::size_t(cam.width) * cam.height);
  r.reconstruct(img);
  return img;
}

}  // namespace

TEST_CASE("driver: stage 1 shades each visible original vertex once") {
  const auto m = floor_mesh();
  const auto cam = top_camera();
  auto r = make_refiner(m, {.max_batches = 0});
  std::atomic<int> calls{0};
  auto shade = [&](const shading_point& sp) {
    ++calls;
    return shadowed(sp.position);
  };
  auto rep = r.run(brute_force_tracer{&m}, cam, shade, serial_executor{});
  REQUIRE(rep.ok());
  CHECK(rep->stage1.triangles == 2);
  CHECK(rep->stage1.triangles_total == 2);
  CHECK(rep->stage1.shading_samples == 4);
  CHECK(calls == 4);
  CHECK(rep->batches == 0);
  CHECK(rep->budget_reached);
}

TEST_CASE("driver: every defaulted executor argument is serial_executor") {
  const auto m = floor_mesh();
  const brute_force_tracer tracer{&m};
  auto shade = [](const shading_point& sp) { return shadowed(sp.position); };
  const driver_options o{.criteria = {.criterion = refinement_criterion::nld_os, .s_req = 0.05f, .batch = 8}};
  auto a = make_refiner(m, o), b = make_refiner(m, o);
  // start() keeps its executor: start(tracer, camera, x) would not say whether x shades or runs.
  REQUIRE(a.start(tracer, top_camera(32, 24), shade, serial_executor{}).ok());
  REQUIRE(b.start(tracer, top_camera(32, 24), shade, serial_executor{}).ok());
  CHECK(a.refine(shade, {.batches = 2}, serial_executor{}) == b.refine(shade, {.batches = 2}));
  CHECK(a.refine_batch(shade, serial_executor{}) == b.refine_batch(shade));
  REQUIRE(a.set_view(tracer, top_camera(24, 32), serial_executor{}).ok());
  REQUIRE(b.set_view(tracer, top_camera(24, 32)).ok());
  CHECK(a.refine({}, serial_executor{}) == b.refine());
  CHECK(a.report().selections > 0);
  CHECK(a.report().selections == b.report().selections);
  CHECK(image_of(a, top_camera(24, 32)) == image_of(b, top_camera(24, 32)));
  auto c = make_refiner(m, o), d = make_refiner(m, o);
  const auto rc = c.run(tracer, top_camera(), shade, serial_executor{});
  const auto rd = d.run(tracer, top_camera(), shade);
  REQUIRE(rc.ok());
  REQUIRE(rd.ok());
  CHECK(rc->batches == rd->batches);
  CHECK(rc->stage2.shading_samples == rd->stage2.shading_samples);
  CHECK(image_of(c, top_camera()) == image_of(d, top_camera()));
}

TEST_CASE("driver: affine shading is reproduced exactly at every refinement level") {
  const auto m = floor_mesh();
  const auto cam = top_camera(48, 40);
  glm::vec3 (*affine)(glm::vec3) = [](glm::vec3 p) { return glm::vec3(0.5f + 0.2f * p.x, 0.3f - 0.1f * p.y, 0.4f); };
  const auto ref = reference(m, cam, affine);
  auto r = make_refiner(m, {.criteria = {.criterion = refinement_criterion::rnd, .batch = 8}, .max_batches = 6});
  auto shade = [&](const shading_point& sp) { return affine(sp.position); };
  REQUIRE(r.start(brute_force_tracer{&m}, cam, shade, serial_executor{}).ok());
  do {
    const auto img = image_of(r, cam);
    for (std::size_t p = 0; p < img.size(); ++p) REQUIRE(glm::distance(img[p], ref[p]) < 1e-5f);
  } while (r.refine_batch(shade, serial_executor{}));
  INFO(r.report().selections << " selections, " << r.mesh().leaf_count() << " leaves");
  CHECK(r.report().batches == 6);
}

TEST_CASE("driver: NLD_OS finds the shadow that misses every vertex, and stops by its rule") {
  const auto m = floor_mesh();
  const auto cam = top_camera();
  const auto ref = reference(m, cam, shadowed);
  auto r = make_refiner(m, {.criteria = {.criterion = refinement_criterion::nld_os, .s_req = 0.05f, .batch = 16}});
  std::vector<int> calls;
  auto shade = [&](const shading_point& sp) {
    if (calls.size() <= sp.vertex) calls.resize(sp.vertex + 1, 0);
    ++calls[sp.vertex];
    return shadowed(sp.position);
  };
  auto rep = r.run(brute_force_tracer{&m}, cam, shade, serial_executor{});
  REQUIRE(rep.ok());
  // Stage 1 misses the shadow entirely (all four corners are lit).
  // Stage 2: large triangles are refined regardless of S until a midpoint falls into the shadow.
  CHECK_FALSE(rep->budget_reached);
  CHECK(rep->stage2.triangles > rep->stage1.triangles);
  CHECK(rep->stage2.triangles_total >= rep->stage2.triangles);
  for (int c : calls) CHECK(c <= 1);  // the cache: no vertex shaded twice
  std::size_t shaded = 0;
  for (int c : calls) shaded += std::size_t(c);
  CHECK(shaded == rep->stage2.shading_samples);
  // Termination rule, checked from outside: no visible leaf qualifies any more (projected area
  // from glm's matrices).
  const auto f = r.frame();
  for (std::uint32_t t : r.visible_leaves()) {
    const double px = f.leaf_pixels[t];
    CHECK(px <= 0.02 * cam.width * cam.height);
    const glm::uvec3 v = r.mesh().triangle(t).vertices;
    if (oracle_area(cam, r.mesh().position(v.x), r.mesh().position(v.y), r.mesh().position(v.z)) >= 6.0) {
      CHECK(nld(f.vertex_luminance[v.x], f.vertex_luminance[v.y], f.vertex_luminance[v.z], f.l_max) <= 0.05f);
    }
  }
  // Every vertex of every visible leaf is shaded.
  for (std::uint32_t t : r.visible_leaves())
    for (int c = 0; c < 3; ++c) CHECK(r.vertex_shaded(r.mesh().triangle(t).vertices[c]));
  // The shadow is found: the error is far below stage 1's.
  auto stage1 = make_refiner(m, {.max_batches = 0});
  REQUIRE(stage1.run(brute_force_tracer{&m}, cam, [](const shading_point& sp) { return shadowed(sp.position); },
                     serial_executor{}).ok());
  const double p1 = psnr(image_of(stage1, cam), ref), p2 = psnr(image_of(r, cam), ref);
  INFO("stage 1 " << p1 << " dB, stage 2 " << p2 << " dB");
  CHECK(p2 > p1 + 10.0);
}

TEST_CASE("driver: NLD_IS and RND improve the image and respect their limits") {
  const auto m = floor_mesh();
  const auto cam = top_camera();
  const auto ref = reference(m, cam, shadowed);
  auto shade = [](const shading_point& sp) { return shadowed(sp.position); };
  auto base = make_refiner(m, {.max_batches = 0});
  REQUIRE(base.run(brute_force_tracer{&m}, cam, shade, serial_executor{}).ok());
  const double p1 = psnr(image_of(base, cam), ref);

  SECTION("NLD_IS runs until no quadrant qualifies") {
    auto r = make_refiner(m, {.criteria = {.criterion = refinement_criterion::nld_is, .s_req = 0.05f, .batch = 16}});
    auto rep = r.run(brute_force_tracer{&m}, cam, shade, serial_executor{});
    REQUIRE(rep.ok());
    CHECK_FALSE(rep->budget_reached);
    // Stage 1's image is uniform over the floor; the quadrants across the floor's silhouette
    // (floor against background) are what starts NLD_IS refining.
    CHECK(rep->stage2.shading_samples > rep->stage1.shading_samples);
    INFO("NLD_IS " << psnr(image_of(r, cam), ref) << " dB vs stage 1 " << p1);
    CHECK(psnr(image_of(r, cam), ref) > p1);
  }
  SECTION("RND stops after its point budget and is reproducible from its seed") {
    const driver_options o{.criteria = {.criterion = refinement_criterion::rnd, .batch = 8, .rnd_point_fraction = 0.05f, .seed = 3}};
    auto a = make_refiner(m, o), b = make_refiner(m, o);
    auto ra = a.run(brute_force_tracer{&m}, cam, shade, serial_executor{});
    auto rb = b.run(brute_force_tracer{&m}, cam, shade, support::thread_pool_executor{3});
    REQUIRE(ra.ok());
    REQUIRE(rb.ok());
    CHECK(ra->stage2.shading_samples == rb->stage2.shading_samples);
    CHECK(ra->stage2.triangles == rb->stage2.triangles);
    CHECK(image_of(a, cam) == image_of(b, cam));
    CHECK(ra->selections <= std::size_t(0.05 * 64 * 64));
    CHECK(psnr(image_of(a, cam), ref) > p1);
  }
  SECTION("the shading budget stops stage 2 after the batch that reaches it") {
    auto r = make_refiner(m, {.criteria = {.criterion = refinement_criterion::nld_os, .batch = 4}, .max_shading_samples = 40});
    auto rep = r.run(brute_force_tracer{&m}, cam, shade, serial_executor{});
    REQUIRE(rep.ok());
    CHECK(rep->budget_reached);
    CHECK(rep->stage2.shading_samples >= 40);
  }
}

TEST_CASE("driver: identical results for any executor") {
  const auto m = support::make_plane(3, 2, 2.0f);
  const auto cam = top_camera(40, 36);
  auto shade = [](const shading_point& sp) { return shadowed(sp.position); };
  const driver_options o{.criteria = {.criterion = refinement_criterion::nld_os, .s_req = 0.02f, .batch = 5}, .grain = 64};
  auto a = make_refiner(m, o), b = make_refiner(m, o);
  auto ra = a.run(brute_force_tracer{&m}, cam, shade, serial_executor{});
  auto rb = b.run(brute_force_tracer{&m}, cam, shade, support::thread_pool_executor{4});
  REQUIRE(ra.ok());
  REQUIRE(rb.ok());
  CHECK(ra->stage2.shading_samples == rb->stage2.shading_samples);
  CHECK(ra->stage2.triangles_total == rb->stage2.triangles_total);
  CHECK(ra->batches == rb->batches);
  CHECK(image_of(a, cam) == image_of(b, cam));
}

TEST_CASE("driver: NLD_OS with a random pass finds a shadow that no vertex shows; plain NLD_OS cannot") {
  // 8×8 cells of 2×2/8 units: every triangle is far below always_refine_fraction of the image, and
  // a small shadow square lies between the vertices, so stage 1 shows no luminance difference.
  const auto m = support::make_plane(8, 8, 2.0f);
  const auto cam = top_camera();
  glm::vec3 (*square)(glm::vec3) = [](glm::vec3 p) {
    return std::abs(p.x - 0.37f) < 0.07f && std::abs(p.y + 0.37f) < 0.07f ? glm::vec3(0.05f) : glm::vec3(0.9f);
  };
  const auto ref = reference(m, cam, square);
  auto shade = [&](const shading_point& sp) { return square(sp.position); };
  const criteria_options plain{.criterion = refinement_criterion::nld_os, .s_req = 0.05f, .batch = 16};
  criteria_options mixed = plain;
  mixed.random_share = 0.25f;
  mixed.rnd_point_fraction = 0.3f;
  auto a = make_refiner(m, {.criteria = plain}), b = make_refiner(m, {.criteria = mixed}), c = make_refiner(m, {.criteria = mixed});
  auto ra = a.run(brute_force_tracer{&m}, cam, shade, serial_executor{});
  auto rb = b.run(brute_force_tracer{&m}, cam, shade, serial_executor{});
  auto rc = c.run(brute_force_tracer{&m}, cam, shade, support::thread_pool_executor{3});
  REQUIRE(ra.ok());
  REQUIRE(rb.ok());
  REQUIRE(rc.ok());
  CHECK(ra->batches == 0);  // plain NLD_OS finds nothing to refine
  CHECK(ra->stage2.shading_samples == ra->stage1.shading_samples);
  CHECK(rb->batches > 0);
  CHECK_FALSE(rb->budget_reached);  // ended by the rule: NLD_OS and the random budget exhausted
  const double pa = psnr(image_of(a, cam), ref), pb = psnr(image_of(b, cam), ref);
  INFO("plain " << pa << " dB, with a random pass " << pb << " dB, " << rb->stage2.shading_samples << " samples");
  CHECK(pb > pa + 3.0);
  // Deterministic for any executor.
  CHECK(rb->stage2.shading_samples == rc->stage2.shading_samples);
  CHECK(image_of(b, cam) == image_of(c, cam));
  // A batch never names a leaf twice, though NLD_OS and the random draws meet the same leaves.
  criteria_options wide = mixed;
  wide.s_req = 0.0f, wide.min_pixels = 0.0f, wide.batch = 64, wide.random_share = 0.5f;
  criterion_state st;
  std::vector<std::uint32_t> picked;
  CHECK(select_for_refinement(b.frame(), wide, st, picked) == 64);
  std::sort(picked.begin(), picked.end());
  CHECK(std::adjacent_find(picked.begin(), picked.end()) == picked.end());
}

TEST_CASE("driver: errors") {
  const auto m = floor_mesh();
  auto s = subdivision_mesh::create(m);
  REQUIRE(s.ok());
  CHECK(progressive_refiner::create(*s, {.criteria = {.s_req = 2.0f}}).error().code() == errc::bad_parameter);
  const auto bounded = progressive_refiner::create(*s, {.max_hierarchy_triangles = 0});
  REQUIRE_FALSE(bounded.ok());
  CHECK(bounded.error().message().find("max_hierarchy_triangles") != std::string::npos);
  auto fine = progressive_refiner::create(*s);
  REQUIRE(fine.ok());
  CHECK(fine->set_hierarchy_bound(0).code() == errc::bad_parameter);
  CHECK(progressive_refiner::create(*s, {.criteria = {.batch = 0}}).error().code() == errc::bad_parameter);
  CHECK(progressive_refiner::create(*s, {.criteria = {.random_share = 1.5f}}).error().code() == errc::bad_parameter);
  CHECK(progressive_refiner::create(*s, {.criteria = {.random_share = std::numeric_limits<float>::quiet_NaN()}})
            .error().code() == errc::bad_parameter);
  auto r = make_refiner(m, {});
  auto shade = [](const shading_point&) { return glm::vec3(1.0f); };
  CHECK(r.start(brute_force_tracer{&m}, top_camera(0, 0), shade, serial_executor{}).code() == errc::empty_input);
  // A tracer whose scene has more triangles than the mesh: the pixel is named.
  struct lying_tracer {
    hit intersect(const ray&) const { return {0, 7, {0.2f, 0.2f}, 1.0f}; }
    bool occluded(const ray&) const { return true; }
  };
  const auto st = r.start(lying_tracer{}, top_camera(4, 4), shade, serial_executor{});
  CHECK(st.code() == errc::index_out_of_range);
  CHECK(st.element() == 0);
}

TEST_CASE("driver: NLD_IS appends a full batch after what the caller's vector already holds") {
  const auto m = floor_mesh();
  const auto cam = top_camera();
  auto shade = [](const shading_point& sp) { return shadowed(sp.position); };
  const criteria_options o{.criterion = refinement_criterion::nld_is, .s_req = 0.05f, .batch = 4};
  auto r = make_refiner(m, {.criteria = o});
  REQUIRE(r.start(brute_force_tracer{&m}, cam, shade, serial_executor{}).ok());
  REQUIRE(r.refine(shade) == refine_progress::refined);  // the luminance image is filled
  std::vector<std::uint32_t> alone;
  select_nld_is(r.frame(), o, alone);
  REQUIRE(!alone.empty());
  std::vector<std::uint32_t> after(6, 12345u);  // more entries than R
  select_nld_is(r.frame(), o, after);
  REQUIRE(after.size() == 6 + alone.size());
  CHECK(std::equal(alone.begin(), alone.end(), after.begin() + 6));
}

TEST_CASE("driver: options and cameras at their extremes get a status naming them, before any cast or allocation") {
  const auto m = floor_mesh();
  auto s = subdivision_mesh::create(m);
  REQUIRE(s.ok());
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (float bad : {inf, 1e30f, nan, -1.0f, std::nextafter(criteria_options::max_rnd_point_fraction, inf)}) {
    INFO("rnd_point_fraction " << bad);
    const auto r = progressive_refiner::create(*s, {.criteria = {.rnd_point_fraction = bad}});
    REQUIRE(!r.ok());
    CHECK(r.error().code() == errc::bad_parameter);
    CHECK(r.error().message().find("rnd_point_fraction") != std::string::npos);
  }
  CHECK(progressive_refiner::create(*s, {.criteria = {.rnd_point_fraction = criteria_options::max_rnd_point_fraction}}).ok());
  for (float bad : {nan, -1.0f}) {
    CHECK(progressive_refiner::create(*s, {.criteria = {.min_pixels = bad}}).error().code() == errc::bad_parameter);
    CHECK(progressive_refiner::create(*s, {.criteria = {.always_refine_fraction = bad}}).error().code() == errc::bad_parameter);
    CHECK(progressive_refiner::create(*s, {.criteria = {.nld_is_pixel_fraction = bad}}).error().code() == errc::bad_parameter);
  }
  for (float bad : {nan, -1.0f, std::numeric_limits<float>::infinity()}) {
    auto r = progressive_refiner::create(*s, {.criteria = {.display_quantum = bad}});
    REQUIRE(!r.ok());
    CHECK(r.error().code() == errc::bad_parameter);
    CHECK(r.error().message().find("display_quantum") != std::string::npos);
  }
  CHECK(progressive_refiner::create(*s, {.criteria = {.display_quantum = 0.0f}}).ok());
  // A 0xffffffff x 0xffffffff image passes every camera check but no allocation can hold it.
  auto r = make_refiner(m, {});
  auto shade = [](const shading_point&) { return glm::vec3(1.0f); };
  pinhole_camera huge = top_camera(0xffffffffu, 0xffffffffu);
  const status st = r.set_view(brute_force_tracer{&m}, huge);
  CHECK(st.code() == errc::bad_parameter);
  CHECK(st.message().find("pixels") != std::string::npos);
  CHECK(r.start(brute_force_tracer{&m}, huge, shade, serial_executor{}).code() == errc::bad_parameter);
  huge = top_camera(1u << 13, (progressive_refiner::max_view_pixels >> 13) + 1);  // one row past the limit
  CHECK(r.set_view(brute_force_tracer{&m}, huge).code() == errc::bad_parameter);
  CHECK(r.visible_leaves().empty());  // nothing was taken
}

TEST_CASE("criteria: NLD_OS kept between batches selects what the full scan selects, batch after batch") {
  // A view simulated on a subdivided plane: every new leaf gets a pixel count (some none, some
  // above the always-refine fraction) and every new vertex a luminance from five levels (so S
  // ties between different leaves are common); L_max and the batch size change per batch.
  auto mesh = subdivision_mesh::create(support::make_plane(6, 6, 2.0f));
  REQUIRE(mesh.ok());
  std::mt19937 rng(11);
  std::vector<std::uint32_t> pixels;
  std::vector<float> lum;
  nld_os_queue queue;
  const auto cover = [&](std::size_t first_triangle) {
    std::uniform_int_distribution<int> kind(0, 19), px(1, 40), level(0, 4);
    for (std::size_t v = lum.size(); v < mesh->vertex_count(); ++v) lum.push_back(0.25f * float(level(rng)));
    for (std::size_t t = first_triangle; t < mesh->triangle_count(); ++t) {
      const int k = kind(rng);
      pixels.push_back(k == 0 ? 0u : k == 1 ? 200u : static_cast<std::uint32_t>(px(rng)));
      if (pixels.back() > 0 && mesh->is_leaf(t)) queue.add(static_cast<std::uint32_t>(t));
    }
  };
  cover(0);
  const criteria_options o{.s_req = 0.05f, .min_pixels = 6.0f, .always_refine_fraction = 0.02f};
  std::size_t selected = 0, batches = 0;
  for (int batch = 0; batch < 40; ++batch) {
    std::vector<std::uint32_t> visible;
    mesh->leaves(visible);
    visible.erase(std::remove_if(visible.begin(), visible.end(), [&](std::uint32_t t) { return pixels[t] == 0; }), visible.end());
    refinement_frame f;
    f.width = 64;
    f.height = 64;  // 2% of the image: 81.92 pixels
    f.mesh = &*mesh;
    f.leaf_pixels = pixels;
    f.visible = visible;
    f.vertex_luminance = lum;
    f.l_max = std::uniform_real_distribution<float>(0.8f, 1.5f)(rng);
    const std::size_t limit = 1 + std::size_t(batch % 7) * 3;
    std::vector<std::uint32_t> scan, kept;
    select_nld_os(f, o, scan, limit);
    queue.select(f, o, kept, limit);
    INFO("batch " << batch << ", limit " << limit);
    REQUIRE(kept == scan);
    if (scan.empty()) break;
    selected += scan.size(), ++batches;
    const std::size_t before = mesh->triangle_count();
    for (std::uint32_t t : scan) REQUIRE(mesh->split(t).ok());
    cover(before);
  }
  CHECK(batches >= 10);  // the comparison ran over many batches, not one
  CHECK(selected >= 60);
}

namespace {

// NLD_IS by brute force: every quadrant of the image quadtree down to one pixel in a plain list,
// the next one taken by a linear scan for the largest S (ties: smaller y0, then x0), the
// triangle under its centre selected when S > S_req, its area (oracle_area) reaches min_pixels,
// it is not selected already and its corners' colours (read from the refiner) differ by
// display_quantum · L_max or more in some channel unless it covers more than always_refine_fraction of
// the pixels (counted here). Up to `batch` ids.
std::vector<std::uint32_t> nld_is_brute_force(const refinement_frame& f, const criteria_options& o, const pinhole_camera& cam,
                                              const progressive_refiner& r) {
  struct quad {
    float s;
    std::uint32_t x0, y0, x1, y1;
  };
  const auto L = [&](std::uint32_t x, std::uint32_t y) { return f.pixel_luminance[std::size_t(y) * f.width + x]; };
  std::vector<quad> open;
  const auto split = [&](const quad& q) {
    const std::uint32_t xm = q.x0 + (q.x1 - q.x0 + 1) / 2, ym = q.y0 + (q.y1 - q.y0 + 1) / 2;
    const std::uint32_t xs[3] = {q.x0, xm, q.x1}, ys[3] = {q.y0, ym, q.y1};
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        if (xs[i] < xs[i + 1] && ys[j] < ys[j + 1]) {
          const std::uint32_t a = xs[i], b = xs[i + 1] - 1, c = ys[j], d = ys[j + 1] - 1;
          // S of the four corner pixels (nld.hpp, tested against the pairwise definition there).
          open.push_back({nld(L(a, c), L(b, c), L(a, d), L(b, d), f.l_max), xs[i], ys[j], xs[i + 1], ys[j + 1]});
        }
  };
  split({0.0f, 0, 0, f.width, f.height});
  std::vector<std::uint32_t> out;
  while (!open.empty() && out.size() < o.batch) {
    auto best = open.begin();
    for (auto it = open.begin(); it != open.end(); ++it)
      if (std::tie(best->s, it->y0, it->x0) < std::tie(it->s, best->y0, best->x0)) best = it;
    const quad q = *best;
    open.erase(best);
    const std::uint32_t leaf = f.pixel_leaf[std::size_t((q.y0 + q.y1) / 2) * f.width + (q.x0 + q.x1) / 2];
    if (q.s > o.s_req && leaf != invalid_id && std::find(out.begin(), out.end(), leaf) == out.end()) {
      const glm::uvec3 v = f.mesh->triangle(leaf).vertices;
      const bool big = double(std::count(f.pixel_leaf.begin(), f.pixel_leaf.end(), leaf)) >
                       double(o.always_refine_fraction) * double(f.width) * double(f.height);
      bool differ = false;
      for (int ch = 0; ch < 3; ++ch) {
        const float c[3] = {r.vertex_colour(v.x)[ch], r.vertex_colour(v.y)[ch], r.vertex_colour(v.z)[ch]};
        differ |= *std::max_element(c, c + 3) - *std::min_element(c, c + 3) >= o.display_quantum * f.l_max;
      }
      if (oracle_area(cam, f.mesh->position(v.x), f.mesh->position(v.y), f.mesh->position(v.z)) >= double(o.min_pixels) &&
          (differ || big))
        out.push_back(leaf);
    }
    if (q.x1 - q.x0 > 1 || q.y1 - q.y0 > 1) split(q);
  }
  return out;
}

}  // namespace

TEST_CASE("criteria: NLD_IS recursion equals a brute-force walk of every quadrant on a small view") {
  // A 23x17 view (odd sizes: quadrants of unequal halves) of a floor of 3x3 cells with the shadow
  // edge, refined a few NLD_OS batches so leaves of several levels and sizes are under the pixels.
  const auto m = support::make_plane(3, 3, 2.0f);
  const pinhole_camera cam{.eye = {0.3f, -0.9f, 1.6f}, .target = {0, 0, 0}, .up = {0, 1, 0}, .vertical_fov_degrees = 60.0f,
                           .width = 23, .height = 17};
  auto shade = [](const shading_point& sp) { return shadowed(sp.position) * (1.0f + 0.3f * sp.position.y); };
  auto r = make_refiner(m, {.criteria = {.criterion = refinement_criterion::nld_os, .s_req = 0.01f, .min_pixels = 2.0f, .batch = 3}});
  REQUIRE(r.start(brute_force_tracer{&m}, cam, shade, serial_executor{}).ok());
  for (int b = 0; b < 4; ++b) r.refine(shade, refine_budget{.batches = 1});
  r.refine(refine_budget{.batches = 1});  // one more batch, its requests left outstanding
  // An NLD_OS refiner keeps no luminance image (it reads L_max only): the image's, computed here.
  std::vector<glm::vec3> img(23u * 17u);
  r.reconstruct(img);
  std::vector<float> pixel_luminance(img.size());
  std::transform(img.begin(), img.end(), pixel_luminance.begin(), [](glm::vec3 c) { return luminance(c); });
  refinement_frame f = r.frame();
  CHECK(f.pixel_luminance.empty());
  f.pixel_luminance = pixel_luminance;
  REQUIRE(f.pixel_luminance.size() == 23u * 17u);
  REQUIRE(f.projection != nullptr);
  REQUIRE(f.vertex_colour.size() == r.mesh().vertex_count());
  std::size_t nonempty = 0, exhaustive = 0, quantum_mattered = 0;
  for (float s_req : {0.0f, 0.02f, 0.1f, 0.3f})
    for (float min_pixels : {0.0f, 1.0f, 6.0f, 40.0f})
      for (std::uint32_t batch : {1u, 4u, 1000u}) {
        std::vector<std::uint32_t> without_rule;
        for (float quantum : {0.0f, 0.5f / 255.0f, 0.05f})
          for (float large : {0.02f, 0.2f}) {
            const criteria_options o{.criterion = refinement_criterion::nld_is, .s_req = s_req, .min_pixels = min_pixels,
                                     .always_refine_fraction = large, .batch = batch, .display_quantum = quantum};
            std::vector<std::uint32_t> got{7u};  // what the caller's vector held stays
            select_nld_is(f, o, got);
            REQUIRE(got.front() == 7u);
            got.erase(got.begin());
            const std::vector<std::uint32_t> want = nld_is_brute_force(f, o, cam, r);
            INFO("s_req " << s_req << ", min_pixels " << min_pixels << ", batch " << batch << ", display_quantum " << quantum
                          << ", always_refine_fraction " << large);
            CHECK(got == want);
            if (quantum == 0.0f && large == 0.02f) without_rule = want;
            quantum_mattered += want != without_rule;
            nonempty += !want.empty();
            exhaustive += batch == 1000u && want.size() > 4;  // fewer than R: the walk went to pixel size
          }
      }
  CHECK(nonempty >= 120);  // the comparison selected something in most settings
  CHECK(exhaustive >= 12);
  CHECK(quantum_mattered >= 10);  // the display rule and its large-triangle exemption changed selections
}

TEST_CASE("driver: NLD_IS does not split a triangle whose corners show one value unless it is large") {
  // The floor's two triangles are lit alike at every corner; a shadow strip (0.1 < x < 0.4)
  // misses them all. The quadrants across the floor's silhouette have S > S_req, and the
  // triangle under their centres is split only when the display rule is off or the triangle
  // counts as large.
  const auto m = floor_mesh();
  const auto cam = top_camera();
  const auto strip = [](glm::vec3 p) { return p.x > 0.1f && p.x < 0.4f ? glm::vec3(0.05f) : glm::vec3(0.9f, 0.8f, 0.7f); };
  const auto ref = reference(m, cam, strip);
  auto shade = [&](const shading_point& sp) { return strip(sp.position); };
  const auto run = [&](float quantum, float large) {
    auto r = make_refiner(m, {.criteria = {.criterion = refinement_criterion::nld_is, .always_refine_fraction = large,
                                           .batch = 16, .display_quantum = quantum}});
    REQUIRE(r.run(brute_force_tracer{&m}, cam, shade, serial_executor{}).ok());
    return r;
  };
  const auto flat = run(0.5f / 255.0f, 1.0f);  // nothing covers more than the whole image
  CHECK(flat.report().selections == 0);
  const auto off = run(0.0f, 1.0f), exempt = run(0.5f / 255.0f, 0.02f);
  CHECK(off.report().selections > 0);
  CHECK(exempt.report().selections > 0);
  CHECK(psnr(image_of(exempt, cam), ref) > psnr(image_of(flat, cam), ref));
  // Along the exempt run every split triangle below the large size has corners that differ.
  auto r = make_refiner(m, {.criteria = {.criterion = refinement_criterion::nld_is, .always_refine_fraction = 0.02f, .batch = 4}});
  REQUIRE(r.start(brute_force_tracer{&m}, cam, shade, serial_executor{}).ok());
  std::size_t checked = 0;
  for (int b = 0; b < 400; ++b) {
    std::vector<std::uint32_t> covered(r.mesh().triangle_count(), 0);  // pixels per leaf before the batch
    for (std::uint32_t leaf : r.pixel_leaves())
      if (leaf != invalid_id) ++covered[leaf];
    if (!r.refine_batch(shade)) break;
    const float l_max = r.frame().l_max;  // as the batch read it
    REQUIRE(l_max > 0.5f);
    for (std::uint32_t t : r.last_selection()) {
      if (double(covered[t]) > 0.02 * 64.0 * 64.0) continue;
      const glm::uvec3 v = r.mesh().triangle(t).vertices;
      const glm::vec3 lo = glm::min(r.vertex_colour(v.x), glm::min(r.vertex_colour(v.y), r.vertex_colour(v.z)));
      const glm::vec3 hi = glm::max(r.vertex_colour(v.x), glm::max(r.vertex_colour(v.y), r.vertex_colour(v.z)));
      CHECK(std::max(hi.x - lo.x, std::max(hi.y - lo.y, hi.z - lo.z)) >= 0.5f / 255.0f * l_max);
      ++checked;
    }
  }
  CHECK(checked > 0);
}

TEST_CASE("driver: NLD_IS's display rule does not depend on the shader's scale") {
  // A floor of 4x4 cells with a shadow edge and a gentle slope: at scale 1 the slope moves a
  // small triangle's corners by about half an 8-bit step, so the display rule decides many
  // triangles. Scaling every colour by 0.1 or 10 scales L_max and every corner spread alike: the
  // same triangles are selected in the same batches (an absolute quantum splits other triangles
  // at 10). Steeper slopes put near-ties in S whose order the rounding of the scaled colours
  // flips, so this scene keeps its slopes gentle.
  const auto m = support::make_plane(4, 4, 2.0f);
  const auto cam = top_camera();
  const auto run = [&](float scale, float quantum) {
    auto shade = [scale](const shading_point& sp) {
      return scale * (shadowed(sp.position) * (0.6f + 0.004f * sp.position.y) + glm::vec3(0.002f * sp.position.x));
    };
    auto r = make_refiner(m, {.criteria = {.criterion = refinement_criterion::nld_is, .s_req = 0.0f, .min_pixels = 2.0f,
                                           .batch = 8, .display_quantum = quantum}});
    REQUIRE(r.start(brute_force_tracer{&m}, cam, shade, serial_executor{}).ok());
    std::vector<std::vector<std::uint32_t>> batches;
    while (batches.size() < 300 && r.refine_batch(shade)) batches.emplace_back(r.last_selection().begin(), r.last_selection().end());
    return batches;
  };
  const auto one = run(1.0f, 0.5f / 255.0f);
  REQUIRE(one.size() >= 3);
  CHECK(one != run(1.0f, 0.0f));  // the rule decides selections in this scene
  CHECK(one == run(0.1f, 0.5f / 255.0f));
  CHECK(one == run(10.0f, 0.5f / 255.0f));
}

TEST_CASE("driver: NLD_IS at s_req 0 and min_pixels 1 ends by itself, colours inside what was delivered") {
  // The numerical stress setting: any luminance difference qualifies and a 1-pixel triangle may
  // split. Bounded by projected area, NLD_IS stops near pixel size instead of sending one pixel's
  // triangle down until its float corners nearly coincide; every pixel stays within [0, 1].
  const indexed_mesh m = support::make_plane(2, 2, 2.0f);
  const pinhole_camera cam{.eye = {0, 0, 1.8f}, .target = {0, 0, 0}, .up = {0, 1, 0}, .vertical_fov_degrees = 60.0f,
                           .width = 32, .height = 32};
  auto shade = [](const shading_point& sp) { return glm::vec3(sp.position.x > 0.1f ? 1.0f : 0.0f); };
  for (auto criterion : {refinement_criterion::nld_is, refinement_criterion::nld_os, refinement_criterion::rnd}) {
    INFO(to_string(criterion));
    auto r = make_refiner(m, {.criteria = {.criterion = criterion, .s_req = 0.0f, .min_pixels = 1.0f, .always_refine_fraction = 1.0f},
                              .max_batches = 400});
    REQUIRE(r.start(brute_force_tracer{&m}, cam, shade, serial_executor{}).ok());
    std::size_t batches = 0;
    while (r.refine_batch(shade)) {
      ++batches;
      if (criterion != refinement_criterion::nld_is) continue;
      for (std::uint32_t t : r.last_selection()) {  // what the stress run selected: every one at least a pixel
        const glm::uvec3 v = r.mesh().triangle(t).vertices;
        CHECK(oracle_area(cam, r.mesh().position(v.x), r.mesh().position(v.y), r.mesh().position(v.z)) >= 1.0 - 1e-9);
      }
    }
    CHECK(batches > 0);
    if (criterion == refinement_criterion::nld_is) CHECK_FALSE(r.report().budget_reached);  // ended by its own rule
    std::uint32_t deepest = 0;
    for (std::uint32_t t : r.visible_leaves()) deepest = std::max<std::uint32_t>(deepest, r.mesh().triangle(t).level);
    if (criterion == refinement_criterion::nld_is) CHECK(deepest <= 8);  // a 1-pixel triangle of this view is level 6-7
    std::vector<glm::vec3> img(32 * 32);
    r.reconstruct(img);
    for (const glm::vec3& c : img) {
      CHECK(c.x >= 0.0f);
      CHECK(c.x <= 1.0f);
    }
  }
}
