// refine/progressive_driver.hpp as a walkthrough agent over the Embree walkthrough scene: views
// that change with the cache kept, asynchronous delivery in any order, the incremental protocol
// replayed into a plain set, restarts, the cache bound, and bad input.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <mutex>
#include <random>
#include <set>
#include <thread>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/refine/progressive_driver.hpp"
#include "support/glm_projection.hpp"
#include "support/thread_pool.hpp"
#include "support/walkthrough_scene.hpp"

using namespace infolerp;  // NOLINT: test file

namespace {

constexpr std::uint32_t W = 64, H = 48, FRAMES = 12;

// Checked once, by the thread that builds it: shaders call scene() from worker threads, and
// Catch2's assertions must not run concurrently.
const support::walkthrough_scene& scene() {
  static const auto s = [] {
    auto built = support::make_walkthrough_scene();
    REQUIRE(built.ok());
    return built;
  }();
  return *s;
}

progressive_refiner make_agent(driver_options o = {}) {
  auto s = subdivision_mesh::create(scene().mesh);
  REQUIRE(s.ok());
  o.criteria.min_pixels = 6.0f;
  auto r = progressive_refiner::create(std::move(*s), o);
  REQUIRE(r.ok());
  return std::move(*r);
}

auto shader() {
  return [](const shading_point& sp) { return scene().shade(sp.position, sp.triangle); };
}

std::vector<glm::vec3> image_of(const progressive_refiner& r) {
  std::vector<glm::vec3> img(std::size_t(W) * H);
  r.reconstruct(img);
  return img;
}

// Takes every outstanding request, shades it and delivers the colours in one call.
void deliver_all(progressive_refiner& r) {
  std::vector<shading_point> req;
  r.take_requests(req);
  std::vector<std::uint32_t> ids;
  std::vector<glm::vec3> colours;
  for (const shading_point& sp : req) ids.push_back(sp.vertex), colours.push_back(shader()(sp));
  REQUIRE(r.deliver(ids, colours).ok());
}

bool same_bits(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
}

// Per frame of the walk: the image after refinement finished, and the samples delivered so far.
struct walk_record {
  std::vector<std::vector<glm::vec3>> images;
  std::vector<std::size_t> samples;
};

// The synchronous walk: set_view, then refine until the criterion stops.
template <class E>
walk_record walk_sync(progressive_refiner& r, E&& exec) {
  walk_record out;
  for (std::uint32_t f = 0; f < FRAMES; ++f) {
    REQUIRE(r.set_view(scene(), support::walkthrough_path(f, FRAMES, W, H), exec).ok());
    r.shade_requests(shader(), exec);
    while (r.refine(shader(), {.batches = 4}, exec) == refine_progress::refined) {
    }
    out.images.push_back(image_of(r));
    out.samples.push_back(r.samples_delivered());
  }
  return out;
}

}  // namespace

TEST_CASE("walkthrough: asynchronous delivery in any order, the delta replay and executors agree") {
  auto sync = make_agent();
  const walk_record reference = walk_sync(sync, serial_executor{});
  REQUIRE(reference.samples.back() > 0);

  auto r = make_agent();
  support::thread_pool_executor pool{3};
  std::mt19937 rng(11);
  std::set<std::uint32_t> replay;  // the visualizer: a plain set fed only by deltas
  display_delta delta;
  std::size_t deltas = 0, from_cache = 0;
  auto apply_delta = [&] {
    r.take_delta(delta);
    ++deltas;
    from_cache += delta.added_from_cache.size();
    for (std::uint32_t t : delta.added_from_cache) CHECK(replay.insert(t).second);
    for (std::uint32_t t : delta.deleted) CHECK(replay.erase(t) == 1);
    for (std::uint32_t t : delta.newly_shaded) CHECK(replay.insert(t).second);
    const auto shown = r.shown_triangles();
    REQUIRE(std::equal(replay.begin(), replay.end(), shown.begin(), shown.end()));
    for (std::uint32_t t : shown) {  // what is shown has every corner shaded
      const glm::uvec3 v = r.mesh().triangle(t).vertices;
      REQUIRE((r.vertex_shaded(v.x) && r.vertex_shaded(v.y) && r.vertex_shaded(v.z)));
    }
  };
  for (std::uint32_t f = 0; f < FRAMES; ++f) {
    REQUIRE(r.set_view(scene(), support::walkthrough_path(f, FRAMES, W, H), pool).ok());
    apply_delta();
    for (;;) {
      // Shade the requests on worker threads, deliver them shuffled, in uneven chunks, each
      // delivery from whichever thread finishes (serialised by a mutex), a delta after each.
      std::vector<shading_point> req;
      r.take_requests(req);
      std::shuffle(req.begin(), req.end(), rng);
      std::mutex m;
      std::vector<std::thread> workers;
      const std::size_t chunks = 1 + req.size() / 17;
      for (std::size_t c = 0; c < chunks; ++c)
        workers.emplace_back([&, c] {
          std::vector<std::uint32_t> ids;
          std::vector<glm::vec3> colours;
          for (std::size_t i = c; i < req.size(); i += chunks) {
            ids.push_back(req[i].vertex);
            colours.push_back(shader()(req[i]));
          }
          const std::lock_guard<std::mutex> lock(m);
          REQUIRE(r.deliver(ids, colours).ok());
          apply_delta();
        });
      for (auto& w : workers) w.join();
      if (r.refine({}, pool) != refine_progress::refined) break;
      apply_delta();
    }
    REQUIRE(r.outstanding_requests() == 0);
    // Everything delivered: the shown set is the visible leaf set.
    const auto shown = r.shown_triangles(), visible = r.visible_leaves();
    CHECK(std::equal(shown.begin(), shown.end(), visible.begin(), visible.end()));
    INFO("frame " << f);
    CHECK(same_bits(image_of(r), reference.images[f]));
    CHECK(r.samples_delivered() == reference.samples[f]);
  }
  CHECK(deltas > 3 * FRAMES);
  CHECK(from_cache > 0);  // the way back re-uses cached triangles

  auto pooled = make_agent();
  const walk_record parallel = walk_sync(pooled, support::thread_pool_executor{4});
  for (std::uint32_t f = 0; f < FRAMES; ++f) CHECK(same_bits(parallel.images[f], reference.images[f]));
  CHECK(parallel.samples == reference.samples);
}

TEST_CASE("walkthrough: revisiting a view shades nothing new") {
  auto r = make_agent();
  serial_executor ex;
  const pinhole_camera street = support::walkthrough_camera(support::walkthrough_view::street, W, H);
  const pinhole_camera temple = support::walkthrough_camera(support::walkthrough_view::temple, W, H);
  REQUIRE(r.run(scene(), street, shader(), ex).ok());
  const auto first = image_of(r);
  const std::size_t after_first = r.samples_delivered();
  // The same view again: no request, nothing to refine, the same image.
  REQUIRE(r.set_view(scene(), street, ex).ok());
  CHECK(r.outstanding_requests() == 0);
  CHECK(r.refine(shader(), {}, ex) == refine_progress::finished);
  CHECK(r.samples_delivered() == after_first);
  // Same colours; pixel weights are located afresh from the root (not followed batch by batch),
  // so they may differ in the last float bits.
  const auto again = image_of(r);
  float diff = 0.0f;
  for (std::size_t i = 0; i < again.size(); ++i) diff = std::max(diff, glm::length(again[i] - first[i]));
  CHECK(diff < 1e-5f);
  // Away to the temple and back: the hierarchy the temple refined is shared, so the street's
  // leaves can be finer now; the few corners no view shaded yet are all that is asked for.
  REQUIRE(r.set_view(scene(), temple, ex).ok());
  r.shade_requests(shader(), ex);
  while (r.refine(shader(), {.batches = 8}, ex) == refine_progress::refined) {
  }
  const std::size_t after_temple = r.samples_delivered();
  REQUIRE(r.set_view(scene(), street, ex).ok());
  r.shade_requests(shader(), ex);
  while (r.refine(shader(), {.batches = 8}, ex) == refine_progress::refined) {
  }
  INFO("street " << after_first << ", temple +" << after_temple - after_first << ", street again +"
                 << r.samples_delivered() - after_temple);
  CHECK(r.samples_delivered() - after_temple < after_first / 10);
}

TEST_CASE("walkthrough: only visible triangles are selected, and a view change is honoured at once") {
  auto r = make_agent({.criteria = {.batch = 4}});
  serial_executor ex;
  std::size_t batches = 0;
  for (std::uint32_t f = 0; f < FRAMES; ++f) {
    const pinhole_camera cam = support::walkthrough_path(f, FRAMES, W, H);
    REQUIRE(r.set_view(scene(), cam, ex).ok());
    r.shade_requests(shader(), ex);
    // Two batches per frame at most (an engine calling once per frame), then the view moves on.
    for (int b = 0; b < 2 && r.refine(shader(), {}, ex) == refine_progress::refined; ++b) {
      ++batches;
      const glm::vec3 fwd = glm::normalize(cam.target - cam.eye);
      for (std::uint32_t t : r.last_selection()) {
        const glm::uvec3 v = r.mesh().triangle(t).vertices;
        bool in_front = false;
        for (int c = 0; c < 3; ++c) in_front = in_front || glm::dot(r.mesh().position(v[c]) - cam.eye, fwd) > 0.0f;
        CHECK(in_front);  // never a triangle behind the eye
        CHECK(r.leaf_pixels()[t] == 0);  // split now; it was a visible leaf of this view when selected
        CHECK(!r.mesh().is_leaf(t));
      }
    }
  }
  CHECK(batches > FRAMES);
  // Budgets: a zero time budget or a one-sample budget still runs exactly one batch.
  auto a = make_agent({.criteria = {.batch = 2}});
  REQUIRE(a.start(scene(), support::walkthrough_camera(W, H), shader(), ex).ok());
  CHECK(a.refine(shader(), {.batches = 1000, .seconds = 0.0}, ex) == refine_progress::refined);
  CHECK(a.report().batches == 1);
  CHECK(a.refine(shader(), {.batches = 1000, .samples = 1}, ex) == refine_progress::refined);
  CHECK(a.report().batches == 2);
  // Without a renderer the second batch waits for the first one's deliveries.
  CHECK(a.refine({.batches = 5}, ex) == refine_progress::refined);
  CHECK(a.report().batches == 3);
  CHECK(a.outstanding_requests() > 0);
  CHECK(a.refine({}, ex) == refine_progress::waiting);
}

TEST_CASE("walkthrough: start() after a finished run is a full restart") {
  serial_executor ex;
  const pinhole_camera street = support::walkthrough_camera(support::walkthrough_view::street, W, H);
  const pinhole_camera wall = support::walkthrough_camera(support::walkthrough_view::wall, W, H);
  auto fresh = make_agent();
  auto fresh_rep = fresh.run(scene(), wall, shader(), ex);
  REQUIRE(fresh_rep.ok());
  auto r = make_agent();
  REQUIRE(r.run(scene(), street, shader(), ex).ok());
  auto rep = r.run(scene(), wall, shader(), ex);
  REQUIRE(rep.ok());
  CHECK(rep->batches == fresh_rep->batches);
  CHECK(rep->batches > 0);
  CHECK(rep->stage1.shading_samples == fresh_rep->stage1.shading_samples);
  CHECK(rep->stage2.shading_samples == fresh_rep->stage2.shading_samples);
  CHECK(rep->stage2.triangles_total == fresh_rep->stage2.triangles_total);
  CHECK(r.mesh().triangle_count() == fresh.mesh().triangle_count());
  CHECK(same_bits(image_of(r), image_of(fresh)));
}

TEST_CASE("walkthrough: the cache bound is honoured and changes no image") {
  serial_executor ex;
  auto unbounded = make_agent();
  const walk_record reference = walk_sync(unbounded, ex);
  // A bound a little above what the busiest single view needs.
  std::size_t per_view = 0;
  for (std::uint32_t f = 0; f < FRAMES; ++f) {
    auto one = make_agent();
    REQUIRE(one.run(scene(), support::walkthrough_path(f, FRAMES, W, H), shader(), ex).ok());
    per_view = std::max(per_view, one.cached_samples());
  }
  const std::size_t bound = per_view + per_view / 4;
  REQUIRE(bound < unbounded.cached_samples());  // the bound bites
  auto r = make_agent({.max_cached_samples = bound});
  // Every eviction brings the cache down to its low-water mark (hysteresis), not just to the bound.
  std::size_t before = 0, evictions = 0;
  const auto check_bound = [&] {
    const std::size_t now = r.cached_samples();
    CHECK(now <= bound);
    if (now < before) {  // evicted: down to the mark, or nothing outside the view is left
      ++evictions;
      std::set<std::uint32_t> in_view;
      for (std::uint32_t leaf : r.visible_leaves())
        for (std::uint32_t t = leaf; t != invalid_id; t = r.mesh().triangle(t).parent)
          for (int c = 0; c < 3; ++c)
            if (r.vertex_shaded(r.mesh().triangle(t).vertices[c])) in_view.insert(r.mesh().triangle(t).vertices[c]);
      CHECK((now <= bound - bound / 8 || now == in_view.size()));
    }
    before = now;
  };
  for (std::uint32_t f = 0; f < FRAMES; ++f) {
    REQUIRE(r.set_view(scene(), support::walkthrough_path(f, FRAMES, W, H), ex).ok());
    check_bound();
    r.shade_requests(shader(), ex);
    check_bound();
    refine_progress p;
    while ((p = r.refine(shader(), {}, ex)) == refine_progress::refined) check_bound();
    CHECK(p == refine_progress::finished);  // the bound never stopped refinement here
    INFO("frame " << f);
    CHECK(same_bits(image_of(r), reference.images[f]));
  }
  CHECK(r.samples_delivered() > reference.samples.back());  // evicted samples were shaded again
  CHECK(evictions > 0);
}

TEST_CASE("walkthrough: bad input gets a clear status and changes nothing") {
  serial_executor ex;
  auto r = make_agent();
  const pinhole_camera street = support::walkthrough_camera(W, H);
  REQUIRE(r.start(scene(), street, shader(), ex).ok());
  REQUIRE(r.refine({}, ex) == refine_progress::refined);  // leaves requests outstanding
  std::vector<shading_point> req;
  r.take_requests(req, 3);
  REQUIRE(req.size() == 3);
  const auto image = image_of(r);
  const std::size_t outstanding = r.outstanding_requests(), cached = r.cached_samples();
  const std::vector<std::uint32_t> shown(r.shown_triangles().begin(), r.shown_triangles().end());
  auto unchanged = [&] {
    CHECK(same_bits(image_of(r), image));
    CHECK(r.outstanding_requests() == outstanding);
    CHECK(r.cached_samples() == cached);
    CHECK(std::equal(shown.begin(), shown.end(), r.shown_triangles().begin(), r.shown_triangles().end()));
  };
  // Degenerate and NaN cameras.
  pinhole_camera bad = street;
  bad.target = bad.eye;
  CHECK(r.set_view(scene(), bad, ex).code() == errc::bad_parameter);
  bad = street;
  bad.up = glm::normalize(street.target - street.eye);
  CHECK(r.set_view(scene(), bad, ex).code() == errc::bad_parameter);
  bad = street;
  bad.eye.y = std::numeric_limits<float>::quiet_NaN();
  CHECK(r.set_view(scene(), bad, ex).code() == errc::non_finite);
  bad = street;
  bad.vertical_fov_degrees = 180.0f;
  CHECK(r.set_view(scene(), bad, ex).code() == errc::bad_parameter);
  bad = street;
  bad.width = 0;
  CHECK(r.set_view(scene(), bad, ex).code() == errc::empty_input);
  CHECK(r.start(scene(), bad, shader(), ex).code() == errc::empty_input);
  unchanged();
  // Deliveries: unknown vertex, out of range, named twice in one call, a NaN colour.
  std::uint32_t never = 0;
  while (never < r.mesh().vertex_count() && (r.vertex_shaded(never) || std::any_of(req.begin(), req.end(), [&](const shading_point& s) { return s.vertex == never; })))
    ++never;
  std::vector<std::uint32_t> ids = {req[0].vertex, never};
  std::vector<glm::vec3> colours(2, glm::vec3(0.5f));
  const status unknown = r.deliver(ids, colours);
  CHECK(unknown.code() == errc::bad_parameter);
  CHECK(unknown.element() == 1);
  ids = {req[0].vertex, static_cast<std::uint32_t>(r.mesh().vertex_count())};
  CHECK(r.deliver(ids, colours).code() == errc::index_out_of_range);
  ids = {req[1].vertex, req[1].vertex};
  const status dup = r.deliver(ids, colours);
  CHECK(dup.code() == errc::bad_parameter);
  CHECK(dup.element() == 1);
  CHECK(dup.message().find("twice") != std::string::npos);
  ids = {req[0].vertex, req[1].vertex};
  colours[1].y = std::numeric_limits<float>::quiet_NaN();
  CHECK(r.deliver(ids, colours).code() == errc::non_finite);
  CHECK(r.deliver(ids, std::vector<glm::vec3>(1)).code() == errc::bad_size);
  unchanged();
  // Delivered twice.
  ids = {req[2].vertex};
  REQUIRE(r.deliver(ids, std::vector<glm::vec3>{glm::vec3(0.25f)}).ok());
  CHECK(r.outstanding_requests() == outstanding - 1);
  const status twice = r.deliver(ids, std::vector<glm::vec3>{glm::vec3(0.25f)});
  CHECK(twice.code() == errc::bad_parameter);
  CHECK(r.outstanding_requests() == outstanding - 1);
  // A cache bound of zero.
  CHECK(r.set_cache_bound(0).code() == errc::bad_parameter);
  auto s = subdivision_mesh::create(scene().mesh);
  REQUIRE(s.ok());
  CHECK(progressive_refiner::create(std::move(*s), {.max_cached_samples = 0}).error().code() == errc::bad_parameter);
}

TEST_CASE("walkthrough: L_max is the current image's largest luminance; NLD_IS stops at its pixel fraction") {
  serial_executor ex;
  auto r = make_agent();
  const pinhole_camera street = support::walkthrough_camera(support::walkthrough_view::street, W, H);
  for (const pinhole_camera& cam : {street, support::walkthrough_camera(support::walkthrough_view::wall, W, H)}) {
    REQUIRE(r.set_view(scene(), cam, ex).ok());
    r.shade_requests(shader(), ex);
    const auto before = image_of(r);
    float l_max = 0.0f;
    for (const glm::vec3& c : before) l_max = std::max(l_max, luminance(c));
    REQUIRE(r.refine({}, ex) == refine_progress::refined);  // L_max taken from `before`, then the split
    CHECK(r.frame().l_max == l_max);
    r.shade_requests(shader(), ex);
  }
  // NLD_IS: without a fraction it runs to its own end; with 2% of the pixels it stops there.
  const std::size_t pixels = std::size_t(W) * H;
  auto free_run = make_agent({.criteria = {.criterion = refinement_criterion::nld_is, .batch = 4}});
  auto limited = make_agent({.criteria = {.criterion = refinement_criterion::nld_is, .batch = 4, .nld_is_pixel_fraction = 0.02f}});
  auto a = free_run.run(scene(), street, shader(), ex);
  auto b = limited.run(scene(), street, shader(), ex);
  REQUIRE((a.ok() && b.ok()));
  const double cap = 0.02 * double(pixels);
  INFO("free " << a->stage2.shading_samples << ", limited " << b->stage2.shading_samples << ", cap " << cap);
  CHECK(double(a->stage2.shading_samples) > cap + 4 * 12);
  CHECK(double(b->stage2.shading_samples) >= cap);
  CHECK(double(b->stage2.shading_samples) <= cap + 4 * 12);  // one batch of R = 4 may overshoot (<= 12 vertices each)
  CHECK(!b->budget_reached);  // the criterion's own rule ended it
  auto bad = subdivision_mesh::create(scene().mesh);
  REQUIRE(bad.ok());
  CHECK(progressive_refiner::create(std::move(*bad), {.criteria = {.nld_is_pixel_fraction = -1.0f}}).error().code() ==
        errc::bad_parameter);
}

namespace {

// The agent keeps its view state incrementally (pixels re-located under split leaves, a heap of
// NLD_OS candidates, a max-tree for L_max, the luminance image updated under dirty leaves, the
// shown cut updated under what changed, RND's random stream). The oracle below recomputes that
// state from scratch, as the straightforward agent that rescanned the whole hierarchy and image
// every batch did: every pixel located from its hit's original triangle, the pixel counts and
// visible set counted, each vertex's luminance from its colour, the shown cut from the
// subdivision state by the paper's display rule (§3: a triangle is displayed once shaded, and
// gives way to its children once they are shaded), the image from that cut, and the criteria's
// selections over the whole frame (RND's from its own copy of the seeded stream).
struct view_oracle {
  std::vector<hit> hits;
  std::vector<std::uint32_t> pixel_leaf, leaf_pixels, visible, display;
  std::vector<float> vertex_luminance;
  std::set<std::uint32_t> shown;

  void trace(const pinhole_camera& cam) {
    std::vector<ray> rays(std::size_t(W) * H);
    for (std::uint32_t y = 0; y < H; ++y)
      for (std::uint32_t x = 0; x < W; ++x) rays[std::size_t(y) * W + x] = cam.primary_ray(x, y);
    hits.assign(rays.size(), hit{});
    trace_intersect(scene(), std::span<const ray>(rays), std::span<hit>(hits));
  }

  // The frame the straightforward agent would hand the criterion now (L_max and the pixel
  // luminances are set by the caller), and the shown cut.
  refinement_frame frame(const progressive_refiner& r) {
    const subdivision_mesh& m = r.mesh();
    pixel_leaf.assign(hits.size(), invalid_id);
    leaf_pixels.assign(m.triangle_count(), 0);
    for (std::size_t p = 0; p < hits.size(); ++p)
      if (hits[p].valid()) ++leaf_pixels[pixel_leaf[p] = m.locate(hits[p].triangle, hits[p].barycentric).leaf];
    visible.clear();
    for (std::uint32_t t = 0; t < m.triangle_count(); ++t)
      if (leaf_pixels[t] > 0) visible.push_back(t);
    vertex_luminance.assign(m.vertex_count(), 0.0f);
    for (std::size_t v = 0; v < m.vertex_count(); ++v)
      if (r.vertex_shaded(v)) vertex_luminance[v] = luminance(r.vertex_colour(v));
    cut(r);
    refinement_frame f = r.frame();
    f.pixel_leaf = pixel_leaf;
    f.leaf_pixels = leaf_pixels;
    f.visible = visible;
    f.vertex_luminance = vertex_luminance;
    f.pixel_luminance = {};
    return f;
  }

  // The display rule from the hierarchy and the shaded vertices alone: walking down from a
  // visible leaf's original triangle, a triangle whose corners are all shaded is displayed; the
  // walk goes on to its children when every child in view (a visible leaf in its subtree) is
  // shaded too, and stops at a triangle not shaded. display[leaf] is the last displayed triangle.
  void cut(const progressive_refiner& r) {
    const subdivision_mesh& m = r.mesh();
    std::vector<char> in_view(m.triangle_count(), 0);
    for (std::uint32_t leaf : visible)
      for (std::uint32_t t = leaf; t != invalid_id && !in_view[t]; t = m.triangle(t).parent) in_view[t] = 1;
    const auto ready = [&](std::uint32_t t) {
      const glm::uvec3 v = m.triangle(t).vertices;
      return r.vertex_shaded(v.x) && r.vertex_shaded(v.y) && r.vertex_shaded(v.z);
    };
    display.assign(m.triangle_count(), invalid_id);
    shown.clear();
    std::vector<std::uint32_t> path;
    for (std::uint32_t leaf : visible) {
      path.clear();
      for (std::uint32_t t = leaf; t != invalid_id; t = m.triangle(t).parent) path.push_back(t);
      std::uint32_t d = invalid_id;
      for (auto it = path.rbegin(); it != path.rend() && ready(*it); ++it) {
        d = *it;
        const subdivision_triangle& n = m.triangle(d);
        bool children_ready = true;
        for (std::uint32_t c = n.first_child; c < n.first_child + n.child_count; ++c) children_ready &= !in_view[c] || ready(c);
        if (!children_ready) break;
      }
      display[leaf] = d;
      if (d != invalid_id) shown.insert(d);
    }
  }
};

// The colour of a pixel from scratch: the displayed triangle over its leaf (view_oracle::cut),
// the hit point's weights in it from the positions, the corners' colours interpolated
// (background where nothing is displayed).
glm::vec3 oracle_colour(const progressive_refiner& r, const view_oracle& o, const hit& h) {
  if (!h.valid()) return driver_options{}.background;
  const subdivision_mesh& m = r.mesh();
  const point_location loc = m.locate(h.triangle, h.barycentric);
  const std::uint32_t d = o.display[loc.leaf];
  if (d == invalid_id) return driver_options{}.background;
  const glm::uvec3 lv = m.triangle(loc.leaf).vertices, dv = m.triangle(d).vertices;
  const glm::dvec3 p = double(loc.weights.x) * glm::dvec3(m.position(lv.x)) +
                       double(loc.weights.y) * glm::dvec3(m.position(lv.y)) + double(loc.weights.z) * glm::dvec3(m.position(lv.z));
  const glm::dvec3 a(m.position(dv.x)), b(m.position(dv.y)), c(m.position(dv.z));
  const glm::dvec3 n = glm::cross(b - a, c - a);
  const double u = glm::dot(glm::cross(p - a, c - a), n) / glm::dot(n, n), v = glm::dot(glm::cross(b - a, p - a), n) / glm::dot(n, n);
  return glm::vec3((1.0 - u - v) * glm::dvec3(r.vertex_colour(dv.x)) + u * glm::dvec3(r.vertex_colour(dv.y)) +
                   v * glm::dvec3(r.vertex_colour(dv.z)));
}

// RND replayed (criteria.hpp's rule): splitmix64 (Steele, Lea, Flood 2014) from the seed, pixels
// drawn uniformly by rejection of the 2^64 mod n lowest values, a batch of up to R distinct
// qualifying leaves in draw order within 8·R draws, and no draw past the view's point budget.
struct rnd_oracle {
  std::uint64_t state = 0, drawn = 0;
  bool exhausted = false;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  std::vector<std::uint32_t> select(const progressive_refiner& r, const view_oracle& o, const pinhole_camera& cam,
                                    const criteria_options& co) {
    const std::uint64_t n = std::uint64_t(W) * H, budget = static_cast<std::uint64_t>(double(co.rnd_point_fraction) * double(n));
    std::vector<std::uint32_t> out;
    for (std::uint64_t draws = 0; out.size() < co.batch && draws < 8ull * co.batch; ++draws) {
      if (drawn >= budget) return exhausted = true, out;
      ++drawn;
      std::uint64_t x = next();
      while (x < (0 - n) % n) x = next();
      const std::uint32_t leaf = o.pixel_leaf[x % n];
      if (leaf == invalid_id || !r.mesh().splittable(leaf)) continue;
      const glm::uvec3 v = r.mesh().triangle(leaf).vertices;
      if (support::glm_projected_area(cam, r.mesh().position(v.x), r.mesh().position(v.y), r.mesh().position(v.z)) < double(co.min_pixels))
        continue;
      if (std::find(out.begin(), out.end(), leaf) == out.end()) out.push_back(leaf);
    }
    return out;
  }
};

// Every delta of the 120-frame path as infolerp_pareto walk drives it (a delta after every
// delivery and every batch), replayed into a set, and after every delivery the agent's state
// against the oracle's; each batch against the oracle's selection (NLD_OS by select_nld_os and
// NLD_IS by select_nld_is over the oracle's frame, RND replayed from its seed). The oracle uses
// the same hits and colours, so the comparisons hold on any CPU: pixel leaves, counts, visible
// set, shown set, luminances and selections exactly; colours and L_max within 1e-4 relative (the
// oracle interpolates in double from positions, the agent in float from stored weights). The
// incremental luminance image (NLD_IS) equals, bit for bit, the luminances of the image
// recomputed from the agent's cut before the batch.
void check_walk_against_oracle(refinement_criterion c, bool restart) {
  serial_executor ex;
  const criteria_options co{.criterion = c, .s_req = 0.05f, .always_refine_fraction = 0.02f, .batch = 64};
  auto r = make_agent({.criteria = co});
  view_oracle oracle;
  rnd_oracle rnd{.state = co.seed};
  std::set<std::uint32_t> replayed;
  display_delta delta;
  const auto take = [&] {
    r.take_delta(delta);
    for (std::uint32_t t : delta.deleted) REQUIRE(replayed.erase(t) == 1);
    for (const auto* list : {&delta.added_from_cache, &delta.newly_shaded})
      for (std::uint32_t t : *list) REQUIRE(replayed.insert(t).second);
  };
  std::size_t batches = 0, mismatched_pixels = 0, mismatched_colours = 0, mismatched_selections = 0, mismatched_cuts = 0,
              mismatched_luminance_images = 0, coarser = 0;
  float worst_colour = 0.0f, worst_l_max = 0.0f;
  std::vector<std::uint32_t> expected;
  std::vector<glm::vec3> img(std::size_t(W) * H);
  std::vector<float> pixel_luminance(img.size());
  constexpr std::uint32_t frames = 120;
  for (std::uint32_t f = 0; f < frames; ++f) {
    const pinhole_camera cam = support::walkthrough_path(f, frames, W, H);
    REQUIRE((restart ? r.start(scene(), cam, ex) : r.set_view(scene(), cam, ex)).ok());
    if (restart) replayed.clear(), rnd = {.state = co.seed};  // a restart begins a new display and stream
    rnd.drawn = 0, rnd.exhausted = false;                      // the point budget is per view
    take();
    oracle.trace(cam);
    for (;;) {
      deliver_all(r);
      take();
      // The state after the delivery, from scratch.
      refinement_frame of = oracle.frame(r);
      const std::span<const std::uint32_t> shown = r.shown_triangles();
      REQUIRE(std::equal(shown.begin(), shown.end(), replayed.begin(), replayed.end()));
      mismatched_cuts += !std::equal(shown.begin(), shown.end(), oracle.shown.begin(), oracle.shown.end());
      coarser += oracle.shown.size() > shown.size();
      mismatched_pixels += !std::equal(of.pixel_leaf.begin(), of.pixel_leaf.end(), r.pixel_leaves().begin(), r.pixel_leaves().end());
      const std::span<const std::uint32_t> vis = r.visible_leaves();
      REQUIRE(std::equal(vis.begin(), vis.end(), oracle.visible.begin(), oracle.visible.end()));
      for (std::uint32_t t : oracle.visible) {
        REQUIRE(r.leaf_pixels()[t] == oracle.leaf_pixels[t]);
        const glm::uvec3 v = r.mesh().triangle(t).vertices;
        for (int k = 0; k < 3; ++k)
          if (r.vertex_shaded(v[k])) REQUIRE(r.frame().vertex_luminance[v[k]] == oracle.vertex_luminance[v[k]]);
      }
      // The image against the oracle's colours; L_max against the oracle image's largest luminance.
      r.reconstruct(img);
      float l_max = 0.0f, oracle_l_max = 0.0f;
      for (std::size_t p = 0; p < img.size(); ++p) {
        const glm::vec3 e = oracle_colour(r, oracle, oracle.hits[p]);
        const float diff = glm::length(e - img[p]) / std::max(1.0f, glm::length(e));
        worst_colour = std::max(worst_colour, diff);
        mismatched_colours += !(diff <= 1e-4f);
        pixel_luminance[p] = luminance(img[p]);
        l_max = std::max(l_max, pixel_luminance[p]);
        oracle_l_max = std::max(oracle_l_max, luminance(e));
      }
      // The batch the straightforward agent would select, on the agent's exact L_max and pixel
      // luminances (checked against the oracle's here and after the batch) so ties compare alike.
      of.l_max = l_max;
      expected.clear();
      if (c == refinement_criterion::nld_os) select_nld_os(of, co, expected, co.batch);
      if (c == refinement_criterion::nld_is) of.pixel_luminance = pixel_luminance, select_nld_is(of, co, expected);
      if (c == refinement_criterion::rnd) expected = rnd.select(r, oracle, cam, co);
      const refine_progress step = r.refine({}, ex);
      const refinement_frame af = r.frame();  // L_max and the luminance image as the batch read them
      worst_l_max = std::max(worst_l_max, std::abs(af.l_max - oracle_l_max) / std::max(1.0f, oracle_l_max));
      REQUIRE(std::abs(af.l_max - oracle_l_max) <= 1e-4f * std::max(1.0f, oracle_l_max));
      if (c == refinement_criterion::nld_is)
        mismatched_luminance_images += !std::equal(af.pixel_luminance.begin(), af.pixel_luminance.end(), pixel_luminance.begin(),
                                                   pixel_luminance.end());
      if (step == refine_progress::refined) {
        ++batches;
        const std::span<const std::uint32_t> got = r.last_selection();
        mismatched_selections += !std::equal(got.begin(), got.end(), expected.begin(), expected.end());
      }
      take();
      if (step != refine_progress::refined) break;
    }
    CHECK(expected.empty());  // it finished where the oracle selects nothing
  }
  INFO("batches " << batches << ", worst colour difference " << worst_colour << ", worst L_max difference " << worst_l_max);
  CHECK(batches >= 10);  // refinement ran on the path, not only stage 1
  CHECK(mismatched_pixels == 0);
  CHECK(mismatched_cuts == 0);
  CHECK(coarser == 0);
  CHECK(mismatched_colours == 0);
  CHECK(mismatched_selections == 0);
  CHECK(mismatched_luminance_images == 0);
}

}  // namespace

TEST_CASE("walkthrough: on the 120-frame path the agent's state and selections equal a from-scratch recomputation") {
  SECTION("NLD_OS, views kept") { check_walk_against_oracle(refinement_criterion::nld_os, false); }
  SECTION("NLD_OS, restart per frame") { check_walk_against_oracle(refinement_criterion::nld_os, true); }
  SECTION("RND, views kept") { check_walk_against_oracle(refinement_criterion::rnd, false); }
  SECTION("RND, restart per frame") { check_walk_against_oracle(refinement_criterion::rnd, true); }
  SECTION("NLD_IS, views kept") { check_walk_against_oracle(refinement_criterion::nld_is, false); }
}

TEST_CASE("walkthrough: Table 1's Δ_total counts the triangles sent in the current view") {
  serial_executor ex;
  auto r = make_agent();
  display_delta delta;
  std::size_t sent = 0;
  const auto take = [&] {
    r.take_delta(delta);
    sent += delta.added_from_cache.size() + delta.newly_shaded.size();
  };
  for (std::uint32_t f = 0; f < FRAMES; ++f) {
    const pinhole_camera cam = support::walkthrough_path(f, FRAMES, W, H);
    REQUIRE((f == 0 ? r.start(scene(), cam, ex) : r.set_view(scene(), cam, ex)).ok());
    sent = 0;
    take();
    for (;;) {
      deliver_all(r);
      take();
      if (r.refine({}, ex) != refine_progress::refined) break;
      take();
    }
    INFO("frame " << f);
    if (f == 0) CHECK(r.report().stage1.triangles_total == r.report().stage1.triangles);  // all sent at once
    CHECK(r.report().stage2.triangles_total == sent);
  }
  // A revisited view sends only what changed: the last frame is the first one's camera.
  CHECK(r.report().stage2.triangles_total < r.report().stage2.triangles);
}

TEST_CASE("walkthrough: memory_bytes covers the hierarchy, the cache and the view, and grows with refinement") {
  auto r = make_agent();
  REQUIRE(r.set_view(scene(), support::walkthrough_path(0, FRAMES, W, H)).ok());
  r.shade_requests(shader(), serial_executor{});
  // A floor from the sizes alone: two copies of the hierarchy's triangles and positions (the
  // mesh and the one start() returns to), 12 bytes of colour and 1 of state per vertex, 4 bytes
  // of leaf and 12 of weights per pixel.
  const auto floor = [&] {
    const subdivision_mesh& m = r.mesh();
    return 2 * (m.original_triangle_count() * sizeof(subdivision_triangle)) + m.triangle_count() * sizeof(subdivision_triangle) +
           m.vertex_count() * (sizeof(glm::vec3) + sizeof(glm::vec3) + 1) + std::size_t(W) * H * 16;
  };
  const std::size_t before = r.memory_bytes();
  CHECK(before >= floor());
  while (r.refine(shader(), {.batches = 4}) == refine_progress::refined) {
  }
  REQUIRE(r.mesh().triangle_count() > 4 * scene().mesh.triangles.size());
  CHECK(r.memory_bytes() >= floor());
  CHECK(r.memory_bytes() > before);
}

TEST_CASE("walkthrough: pruning never drops a leaf in view or a cached sample, along a walk out and back") {
  // A street of 4 blocks walked to the far end and back, with a cache bound (evicted parts
  // become prunable) and a hierarchy bound far below what the walk builds. At every view a copy
  // of the agent that does not prune takes the same view: what the view shows (the image after
  // its requests are delivered, bit for bit), what it requests and what stays cached must agree,
  // so nothing pruned was in view, shown, cached or requested. (Refinement after that may differ:
  // a split's closure reaches out-of-view neighbours, finer in the copy than in the pruned agent.)
  auto built = support::make_long_street_scene(4);
  REQUIRE(built.ok());
  const support::walkthrough_scene& sc = *built;
  auto s = subdivision_mesh::create(sc.mesh);
  REQUIRE(s.ok());
  auto made = progressive_refiner::create(
      std::move(*s), {.criteria = {.min_pixels = 6.0f}, .max_cached_samples = 1000, .max_hierarchy_triangles = 3000});
  REQUIRE(made.ok());
  progressive_refiner b = std::move(*made);
  auto shade = [&](const shading_point& sp) { return sc.shade(sp.position, sp.triangle); };
  const auto requested = [&](progressive_refiner& r) {
    std::vector<shading_point> req;
    r.take_requests(req);
    std::vector<std::uint32_t> ids;
    std::vector<glm::vec3> colours;
    std::vector<std::array<float, 3>> where;
    for (const shading_point& sp : req)
      ids.push_back(sp.vertex), colours.push_back(shade(sp)), where.push_back({sp.position.x, sp.position.y, sp.position.z});
    REQUIRE(r.deliver(ids, colours).ok());
    std::sort(where.begin(), where.end());
    return where;
  };
  const auto cache = [](const progressive_refiner& r) {  // every cached sample: where, and its colour
    std::vector<std::array<float, 6>> out;
    for (std::size_t v = 0; v < r.mesh().vertex_count(); ++v)
      if (r.vertex_shaded(v)) {
        const glm::vec3 p = r.mesh().position(v), c = r.vertex_colour(v);
        out.push_back({p.x, p.y, p.z, c.x, c.y, c.z});
      }
    std::sort(out.begin(), out.end());
    return out;
  };
  constexpr std::uint32_t path = 16;
  std::size_t pruned_views = 0, largest = 0;
  for (std::uint32_t step = 0; step <= 2 * path; ++step) {
    const std::uint32_t f = step <= path ? step : 2 * path - step;  // out, then back the same way
    const pinhole_camera cam = support::long_street_path(f, path + 1, 4, W, H);
    progressive_refiner c = b;  // the same agent, not pruning
    REQUIRE(c.set_hierarchy_bound(std::numeric_limits<std::size_t>::max()).ok());
    REQUIRE(b.set_view(sc, cam).ok());
    REQUIRE(c.set_view(sc, cam).ok());
    INFO("step " << step);
    CHECK(requested(b) == requested(c));
    CHECK(same_bits(image_of(b), image_of(c)));
    CHECK(b.cached_samples() == c.cached_samples());
    CHECK(cache(b) == cache(c));
    CHECK(b.visible_leaves().size() == c.visible_leaves().size());
    pruned_views += b.mesh().live_triangle_count() < c.mesh().live_triangle_count();
    largest = std::max(largest, b.mesh().live_triangle_count());
    while (b.refine(shade, {.batches = 4}) == refine_progress::refined) {
    }
    display_delta delta;  // the visualizer takes the changes, as an engine does every frame
    b.take_delta(delta);
  }
  CHECK(pruned_views >= 3);  // the bound was reached and pruning ran
  CHECK(largest < 3 * 3000);  // a view change brings the hierarchy back toward the bound
}
