// Every option and numeric parameter at its extremes. One table row per option: the entry point
// that reads it, the name its error message must contain, and a runner that sets the option to a
// value, runs the entry point on a small input and checks the output. Each row is run with NaN,
// ±Inf, 0, -1, the smallest and largest values of its type and one past each documented bound.
// Every cell must give a clear status naming the option, or succeed with a well-formed finite
// result; no single allocation may exceed 64 MiB (the inputs are tiny, so anything larger is an
// option sizing memory by its value). CI runs this under ASan + UBSan (float-cast-overflow
// included). New options join the table when they are added.
// After the table: the regressions that the table found, each with the exact input.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <vector>
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/vertex_contraction.hpp"
#include "infolerp/lod/view_dependent_lod.hpp"
#include "infolerp/lod/weighting_map.hpp"
#include "infolerp/refine/progressive_driver.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"
#include "infolerp/saliency/cluster_importance.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"
#include "infolerp/upsample/pass_controller.hpp"
#include "infolerp/upsample/ray_cast_source.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "reliability/reliability_support.hpp"
#include "support/counting_new.hpp"
#include "support/brute_force_tracer.hpp"
#include "support/procedural.hpp"
#include "support/thread_pool.hpp"

using namespace infolerp;

namespace {

constexpr double nan_d = std::numeric_limits<double>::quiet_NaN();
constexpr double inf_d = std::numeric_limits<double>::infinity();
constexpr std::size_t table_allocation_cap = std::size_t{64} << 20;

// What a runner reports: the entry point's status and, on success, whether the output is
// well-formed and finite.
struct outcome {
  status st;
  bool output_ok = true;
};
template <class T>
status status_of(const result<T>& r) {
  return r.ok() ? status{} : r.error();
}
bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool all_finite(std::span<const double> v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

// An option: real (float or double) or a count (an unsigned integer up to `max`).
struct option_row {
  const char* entry;   // the entry point that reads it
  const char* option;  // what its error message must contain
  bool real;
  std::uint64_t max = 0;               // counts: the largest value of the member's type
  std::vector<double> past_bounds{};   // one past each documented bound
  std::function<outcome(double)> run;  // counts get a value in [0, max]
};

std::vector<double> extremes(const option_row& r) {
  std::vector<double> v;
  if (r.real)
    v = {nan_d, inf_d, -inf_d, 0.0, -1.0, std::numeric_limits<double>::lowest(), std::numeric_limits<double>::max(),
         std::numeric_limits<double>::denorm_min(), 1e-30, 1e30};
  else
    v = {0.0, 1.0, static_cast<double>(r.max), static_cast<double>(r.max - 1)};
  v.insert(v.end(), r.past_bounds.begin(), r.past_bounds.end());
  return v;
}
// A double as the member's type, saturated (the table passes the type's own extremes).
float as_float(double x) {
  if (std::isnan(x)) return std::numeric_limits<float>::quiet_NaN();
  if (x > std::numeric_limits<float>::max()) return std::numeric_limits<float>::infinity();
  if (x < std::numeric_limits<float>::lowest()) return -std::numeric_limits<float>::infinity();
  return static_cast<float>(x);
}
template <class T>
T as_count(double x) {
  if (!(x > 0.0)) return 0;
  if (x >= static_cast<double>(std::numeric_limits<T>::max())) return std::numeric_limits<T>::max();
  return static_cast<T>(x);
}

void check_row(const option_row& r) {
  for (double x : extremes(r)) {
    support::heap_largest = 0;
    support::heap_refuse_above = table_allocation_cap;
    const outcome o = r.run(x);
    support::heap_refuse_above = ~std::size_t{0};
    INFO(r.entry << " " << r.option << " = " << x << ": " << to_string(o.st.code()) << " '" << o.st.message() << "'");
    CHECK(support::heap_largest <= table_allocation_cap);
    if (o.st.ok()) {
      CHECK(o.output_ok);
    } else {
      CHECK(o.st.message().find(r.option) != std::string::npos);
    }
  }
}

// ---- inputs -------------------------------------------------------------------------------

const indexed_mesh& sphere() {  // 42 vertices, 80 triangles
  static const indexed_mesh m = support::make_icosphere(1);
  return m;
}
const indexed_mesh& textured_plane() {
  static const indexed_mesh m = support::make_plane(3, 3, 1.0f);
  return m;
}
std::vector<double> bumpy_saliency(const indexed_mesh& m) {
  std::vector<double> s(m.positions.size());
  for (std::size_t v = 0; v < s.size(); ++v) s[v] = 1.0 + 0.5 * std::sin(3.0 * m.positions[v].x);
  return s;
}
std::vector<std::uint32_t> halves(const indexed_mesh& m) {
  std::vector<std::uint32_t> c(m.triangles.size());
  for (std::size_t t = 0; t < c.size(); ++t) c[t] = m.positions[m.triangles[t].x].z > 0.0f ? 1u : 0u;
  return c;
}

// ---- runners per family -------------------------------------------------------------------

template <class... C>
outcome run_cluster(const indexed_mesh& m, const cluster_options& o, const C&... channels) {
  const support::brute_force_tracer tracer{&m};
  auto r = cluster_mesh(m, tracer, serial_executor{}, o, channels...);
  if (!r) return {r.error()};
  bool ok = r->cluster_of.size() == m.triangles.size() && r->cluster_count >= 1;
  for (std::uint32_t id : r->cluster_of) ok = ok && id < r->cluster_count;
  return {{}, ok};
}

outcome run_saliency(const saliency_options& o) {
  auto r = compute_saliency(sphere(), o, support::thread_pool_executor{2});
  if (!r) return {r.error()};
  return {{}, r->saliency.size() == sphere().positions.size() && all_finite(r->saliency)};
}

outcome run_salient_clustering(const salient_clustering_options& o) {
  const std::vector<double> s = bumpy_saliency(sphere());
  auto r = salient_clustering(sphere(), s, o);
  if (!r) return {r.error()};
  bool ok = r->cluster.size() == sphere().triangles.size();
  for (std::uint32_t id : r->cluster) ok = ok && id < r->count;
  return {{}, ok};
}

outcome run_weighting_map(const weighting_map_options& o) {
  const std::vector<double> s = bumpy_saliency(sphere());
  auto r = weighting_map(sphere(), s, halves(sphere()), 2, o, support::thread_pool_executor{2});
  if (!r) return {r.error()};
  bool ok = r->size() == 3 * sphere().triangles.size() && all_finite(*r);
  for (double w : *r) ok = ok && w >= 0.0;
  return {{}, ok};
}

outcome run_hierarchy(const simplification_options& o) {
  const std::vector<double> w(3 * sphere().triangles.size(), 1.0);
  auto h = make_contraction_hierarchy(sphere(), w, halves(sphere()), 2, o);
  if (!h) return {h.error()};
  return {{}, h->contraction_count() < sphere().positions.size()};
}

// A frame of the per-view LOD with lambda_perc, grain, a camera at `eye` looking at the origin and
// a budget of `global` triangles (half the mesh's when `fraction`), compared with the same frame at
// the default grain.
outcome run_lod(double lambda_perc, std::size_t grain, glm::dvec3 eye, double global, bool fraction) {
  const lod_camera camera{.position = eye, .forward = -eye, .width = 64, .height = 64};
  const std::vector<double> s = bumpy_saliency(sphere());
  const std::vector<std::uint32_t> cl = halves(sphere());
  const std::vector<double> w(3 * sphere().triangles.size(), 1.0);
  auto h = make_contraction_hierarchy(sphere(), w, cl, 2);
  auto table = compute_cluster_attributes(sphere(), s, cl, 2);
  REQUIRE(h.ok());
  REQUIRE(table.ok());
  lod_options opt;
  opt.lambda_perc = lambda_perc;
  auto ref = view_dependent_lod::create(*h, *table, opt);
  opt.grain = grain;
  auto lod = view_dependent_lod::create(*h, *table, opt);
  if (!lod) return {lod.error()};
  REQUIRE(ref.ok());
  const std::uint64_t r = fraction ? static_cast<std::uint64_t>(0.5 * static_cast<double>(h->triangle_count()))
                                   : as_count<std::uint64_t>(global);
  std::vector<std::uint32_t> out(contracted_index_bound(*h)), out_ref(out.size());
  std::vector<index_range> ranges(2), ranges_ref(2);
  auto st = lod->frame(camera, r, out, ranges);
  if (!st) return {st.error()};
  auto st_ref = ref->frame(camera, r, out_ref, ranges_ref);
  const bool same = st_ref.ok() && st->indices == st_ref->indices &&
                    std::equal(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(st->indices), out_ref.begin());
  return {{}, same && st->indices % 3 == 0};
}

outcome run_subdivision(const subdivision_options& o) {
  auto s = subdivision_mesh::create(textured_plane(), o);
  if (!s) return {s.error()};
  for (std::uint32_t t = 0; t < 4; ++t)
    if (status st = s->split(t); !st) return {st};
  return {{}, s->leaf_count() > textured_plane().triangles.size()};
}

glm::vec3 shade_by_position(const shading_point& p) { return glm::abs(p.position) * 0.5f; }

pinhole_camera floor_camera(std::uint32_t w = 16, std::uint32_t h = 12) {
  return {.eye = {0.2f, -0.3f, 1.5f}, .target = {0, 0, 0}, .up = {0, 1, 0}, .vertical_fov_degrees = 60.0f, .width = w,
          .height = h};
}

// A whole walkthrough run on a small plane: every shaded colour finite.
outcome run_refiner(const driver_options& o, const pinhole_camera& cam = floor_camera()) {
  auto s = subdivision_mesh::create(textured_plane());
  REQUIRE(s.ok());
  auto r = progressive_refiner::create(*s, o);
  if (!r) return {r.error()};
  const support::brute_force_tracer tracer{&textured_plane()};
  auto rep = r->run(tracer, cam, shade_by_position, support::thread_pool_executor{2});
  if (!rep) return {rep.error()};
  bool ok = true;
  for (std::size_t v = 0; v < r->mesh().vertex_count(); ++v)
    if (r->vertex_shaded(v)) ok = ok && finite(r->vertex_colour(v));
  return {{}, ok};
}

using sample = reliability::table_source::sample_type;

outcome run_upsampler(std::uint32_t w, std::uint32_t h, const upsampler_options& o) {
  auto up = upsampler<sample>::create(w, h, o);
  if (!up) return {up.error()};
  if (std::uint64_t{w} * h > 4096) return {{}, true};  // allocation checked; rendering a large frame is not the point
  const std::uint32_t ids[3] = {0, 1, invalid_id};
  const reliability::table_source src{ids, 4};
  std::vector<glm::vec3> out(std::size_t{w} * h, glm::vec3(-7.0f));
  if (status st = up->render(src, std::span<glm::vec3>(out), support::thread_pool_executor{2}); !st) return {st};
  bool ok = true;
  for (const auto& p : out) ok = ok && finite(p) && p != glm::vec3(-7.0f);
  return {{}, ok};
}

outcome run_controller(const pass_controller_options& o, double seconds = 0.02) {
  auto c = pass_controller::create(o);
  if (!c) return {c.error()};
  for (int f = 0; f < 12; ++f)
    if (status st = c->update(seconds * (1.0 + 0.1 * f)); !st) return {st};
  return {{}, c->passes() >= 1 && c->passes() <= o.max_passes};
}

// The ready ray-cast source over a sphere seen by a pinhole camera, through the upsampler.
struct sphere_camera {
  ray operator()(float x, float y) const {
    const glm::vec3 d(x / 8.0f - 1.0f, y / 8.0f - 1.0f, -2.0f);
    return ray{{0.0f, 0.0f, 3.0f}, 0.0f, glm::normalize(d)};
  }
};
struct plain_material {
  template <class V>
  glm::vec3 operator()(const surface_sample<2, true>& s, const V&) const {
    return s.background() ? glm::vec3(0.1f) : (s.normal * 0.5f + 0.5f) * s.occlusion[0] + glm::vec3(s.texcoord, 0.0f);
  }
};

// Probes = refine renders with probes only where sources differ (smooth() asked).
template <probe_mode Probes = probe_mode::none, class M>
outcome run_ray_cast(const M& m, const ray_cast_options& o) {
  const support::brute_force_tracer tracer{&m};
  const std::vector<std::uint32_t> ids(m.triangles.size(), 0);
  auto geometry = [&m](std::uint32_t) -> const M& { return m; };
  auto src = ray_cast_source<support::brute_force_tracer, sphere_camera, decltype(geometry), plain_material, Probes>::create(
      tracer, sphere_camera{}, geometry, plain_material{}, {std::span<const std::uint32_t>(ids)}, o);
  if (!src) return {src.error()};
  std::vector<glm::vec3> out(16 * 16, glm::vec3(-7.0f));
  const upsampler_options uo{.passes = 3, .max_passes = 3, .min_sources = 1, .probe_every_sample = Probes == probe_mode::none};
  if (status st = upsample(*src, 16, 16, std::span<glm::vec3>(out), Probes == probe_mode::none ? upsampler_options{.passes = 2} : uo);
      !st)
    return {st};
  bool ok = true;
  for (const auto& p : out) ok = ok && finite(p);
  return {{}, ok};
}

indexed_mesh sphere_with_normals() {
  indexed_mesh m = support::make_icosphere(2);
  m.normals = m.positions;
  return m;
}

// ---- the table ----------------------------------------------------------------------------

constexpr std::uint64_t u32_max = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint64_t u64_max = std::numeric_limits<std::uint64_t>::max();
constexpr std::uint64_t size_max = std::numeric_limits<std::size_t>::max();

std::vector<option_row> cluster_rows() {
  const cluster_options co{};
  const orientation_channel ori{};
  const visibility_channel vis{.viewpoints = 8};
  auto with_vis = [](auto set) {
    return [set](double x) {
      visibility_channel v{.viewpoints = 8};
      set(v, x);
      return run_cluster(sphere(), cluster_options{}, v);
    };
  };
  (void)vis;
  return {
      {"cluster_mesh", "threshold", true, 0, {1.0000001, -1e-9},
       [](double x) { return run_cluster(sphere(), cluster_options{}, orientation_channel{.threshold = x}); }},
      {"cluster_mesh", "bins", false, u32_max, {},
       [](double x) { return run_cluster(sphere(), cluster_options{}, orientation_channel{.bins = as_count<std::uint32_t>(x)}); }},
      {"cluster_mesh", "bins", false, u32_max, {},
       [](double x) {
         return run_cluster(sphere(), cluster_options{},
                            orientation_channel{.bins = as_count<std::uint32_t>(x), .exact_rows = true});
       }},
      {"cluster_mesh", "min_cluster_fraction", true, 0, {1.0000001},
       [ori](double x) { return run_cluster(sphere(), cluster_options{.min_cluster_fraction = x}, ori); }},
      {"cluster_mesh", "grain", false, size_max, {},
       [ori](double x) { return run_cluster(sphere(), cluster_options{.grain = as_count<std::size_t>(x)}, ori); }},
      {"cluster_mesh(visibility)", "threshold", true, 0, {1.0000001},
       with_vis([](visibility_channel& v, double x) { v.threshold = x; })},
      {"cluster_mesh(visibility)", "viewpoints", false, u32_max, {double(std::size_t{1} << 28) / 80.0 + 1.0},
       with_vis([](visibility_channel& v, double x) { v.viewpoints = as_count<std::uint32_t>(x); })},
      {"cluster_mesh(visibility)", "samples_per_side", false, u32_max, {16.0},
       with_vis([](visibility_channel& v, double x) { v.samples_per_side = as_count<std::uint32_t>(x); })},
      {"cluster_mesh(visibility)", "radius_scale", true, 0, {0.9999999},
       with_vis([](visibility_channel& v, double x) { v.radius_scale = x; })},
      {"cluster_mesh(visibility)", "grain", false, size_max, {},
       with_vis([](visibility_channel& v, double x) { v.grain = as_count<std::size_t>(x); })},
      {"cluster_mesh(visibility)", "grain", false, size_max, {},
       with_vis([](visibility_channel& v, double x) {
         v.grain = as_count<std::size_t>(x);
         v.coherent = true;
       })},
      {"cluster_mesh(visibility)", "adaptive_probes", false, u32_max, {},
       with_vis([](visibility_channel& v, double x) { v.adaptive_probes = as_count<std::uint32_t>(x); })},
      {"cluster_mesh(visibility)", "image_resolution", false, u32_max, {16385.0},
       with_vis([](visibility_channel& v, double x) {
         v.images = true;
         v.image_resolution = as_count<std::uint32_t>(x);
       })},
      {"cluster_mesh(visibility)", "image_min_pixels", true, 0, {},
       with_vis([](visibility_channel& v, double x) {
         v.images = true;
         v.image_resolution = 32;
         v.image_min_pixels = x;
       })},
      {"cluster_mesh(stretch)", "threshold", true, 0, {1.0000001},
       [co](double x) { return run_cluster(textured_plane(), co, stretch_channel{.threshold = x}); }},
      {"cluster_mesh(stretch)", "bins", false, u32_max, {},
       [co](double x) { return run_cluster(textured_plane(), co, stretch_channel{.bins = as_count<std::uint32_t>(x)}); }},
      {"cluster_mesh(stretch)", "theta", true, 0, {},
       [co](double x) { return run_cluster(textured_plane(), co, stretch_channel{.theta = x}); }},
  };
}

std::vector<option_row> saliency_rows() {
  return {
      {"compute_saliency", "epsilon", true, 0, {}, [](double x) { return run_saliency({.epsilon = x}); }},
      {"compute_saliency", "scale", true, 0, {}, [](double x) { return run_saliency({.scales = {2.0, x}}); }},
      {"compute_saliency", "flat_level_threshold", true, 0, {},
       [](double x) { return run_saliency({.flat_level_threshold = x}); }},
      {"compute_saliency", "grain", false, size_max, {},
       [](double x) { return run_saliency({.grain = as_count<std::size_t>(x)}); }},
      {"compute_saliency", "proxy_cells_per_sigma", true, 0, {},
       [](double x) { return run_saliency({.method = saliency_method::proxy, .proxy_cells_per_sigma = x}); }},
      {"compute_saliency", "exact_below", false, size_max, {},
       [](double x) { return run_saliency({.exact_below = as_count<std::size_t>(x)}); }},
      {"salient_clustering", "clusters", false, u32_max, {43.0},
       [](double x) { return run_salient_clustering({.clusters = as_count<std::uint32_t>(x)}); }},
      {"salient_clustering", "pool_multiplier", true, 0, {0.9999999},
       [](double x) { return run_salient_clustering({.pool_multiplier = x}); }},
      {"salient_clustering", "normal_weight", true, 0, {0.9999999},
       [](double x) { return run_salient_clustering({.normal_weight = x}); }},
      {"salient_clustering", "seed", false, u64_max, {},
       [](double x) { return run_salient_clustering({.seed = as_count<std::uint64_t>(x)}); }},
      {"salient_clustering", "max_iterations", false, u32_max, {},
       [](double x) { return run_salient_clustering({.max_iterations = as_count<std::uint32_t>(x)}); }},
      {"estimate_view_importance", "camera", true, 0, {},
       [](double x) {
         const std::vector<double> s = bumpy_saliency(sphere());
         auto table = compute_cluster_attributes(sphere(), s, halves(sphere()), 2);
         REQUIRE(table.ok());
         auto v = estimate_view_importance(*table, {x, 0.5, 4.0});
         if (!v) return outcome{v.error()};
         return outcome{{}, all_finite(v->area_estimate) && all_finite(v->importance_estimate)};
       }},
      {"distribute_contractions", "lambda_perc", true, 0, {1.0000001},
       [](double x) {
         const std::vector<double> prio{1.0, 2.0};
         const std::vector<std::uint64_t> cap{5, 5};
         auto d = distribute_contractions(prio, cap, 8, x);
         if (!d) return outcome{d.error()};
         return outcome{{}, (*d)[0] + (*d)[1] == 8};
       }},
  };
}

std::vector<option_row> lod_rows() {
  const glm::dvec3 cam(0.3, -2.0, 4.0);
  return {
      {"weighting_map", "epsilon", true, 0, {}, [](double x) { return run_weighting_map({.epsilon = x}); }},
      {"weighting_map", "smoothing_scale", true, 0, {}, [](double x) { return run_weighting_map({.smoothing_scale = x}); }},
      {"weighting_map", "amplify_percentile", true, 0, {100.000001},
       [](double x) { return run_weighting_map({.amplify_percentile = x}); }},
      {"weighting_map", "amplification", true, 0, {0.9999999},
       [](double x) { return run_weighting_map({.amplification = x}); }},
      {"weighting_map", "grain", false, size_max, {},
       [](double x) { return run_weighting_map({.grain = as_count<std::size_t>(x)}); }},
      {"weighting_map", "proxy_cells_per_sigma", true, 0, {},
       [](double x) { return run_weighting_map({.smoothing_method = saliency_method::proxy, .proxy_cells_per_sigma = x}); }},
      {"weighting_map", "exact_below", false, size_max, {},
       [](double x) { return run_weighting_map({.exact_below = as_count<std::size_t>(x)}); }},
      {"make_contraction_hierarchy", "backstop", true, 0, {1.0000001},
       [](double x) { return run_hierarchy({.backstop = x}); }},
      {"make_contraction_hierarchy", "boundary_weight", true, 0, {},
       [](double x) { return run_hierarchy({.boundary_weight = x}); }},
      {"make_contraction_hierarchy", "min_normal_cos", true, 0, {1.0, -1e-9},
       [](double x) { return run_hierarchy({.min_normal_cos = x}); }},
      {"view_dependent_lod", "lambda_perc", true, 0, {1.0000001},
       [cam](double x) { return run_lod(x, 4096, cam, 0.0, true); }},
      {"view_dependent_lod", "grain", false, size_max, {},
       [cam](double x) { return run_lod(0.02, as_count<std::size_t>(x), cam, 0.0, true); }},
      {"view_dependent_lod::frame", "camera", true, 0, {},
       [](double x) { return run_lod(0.02, 4096, glm::dvec3(x, -2.0, 4.0), 0.0, true); }},
      {"view_dependent_lod::frame", "triangles", false, u64_max, {},
       [cam](double x) { return run_lod(0.02, 4096, cam, x, false); }},
  };
}

std::vector<option_row> refine_rows() {
  auto crit = [](auto set) {
    return [set](double x) {
      driver_options o{.max_batches = 6};
      set(o.criteria, x);
      return run_refiner(o);
    };
  };
  auto drv = [](auto set) {
    return [set](double x) {
      driver_options o{.max_batches = 6};
      set(o, x);
      return run_refiner(o);
    };
  };
  auto cam = [](auto set) {
    return [set](double x) {
      pinhole_camera c = floor_camera();
      set(c, x);
      return run_refiner(driver_options{.max_batches = 4}, c);
    };
  };
  return {
      {"subdivision_mesh::create", "bisect_ratio", true, 0, {},
       [](double x) { return run_subdivision({.bisect_ratio = as_float(x)}); }},
      {"subdivision_mesh::create", "propagation_depth", false, u32_max, {},
       [](double x) { return run_subdivision({.propagation_depth = as_count<std::uint32_t>(x)}); }},
      {"progressive_refiner", "s_req", true, 0, {1.0000001, -1e-9},
       crit([](criteria_options& c, double x) { c.s_req = as_float(x); })},
      {"progressive_refiner", "min_pixels", true, 0, {}, crit([](criteria_options& c, double x) { c.min_pixels = as_float(x); })},
      {"progressive_refiner", "always_refine_fraction", true, 0, {},
       crit([](criteria_options& c, double x) { c.always_refine_fraction = as_float(x); })},
      {"progressive_refiner", "batch", false, u32_max, {},
       crit([](criteria_options& c, double x) { c.batch = as_count<std::uint32_t>(x); })},
      {"progressive_refiner", "nld_is_pixel_fraction", true, 0, {},
       crit([](criteria_options& c, double x) {
         c.criterion = refinement_criterion::nld_is;
         c.nld_is_pixel_fraction = as_float(x);
       })},
      {"progressive_refiner", "rnd_point_fraction", true, 0, {1.0000001e6},
       crit([](criteria_options& c, double x) {
         c.criterion = refinement_criterion::rnd;
         c.rnd_point_fraction = as_float(x);
       })},
      {"progressive_refiner", "display_quantum", true, 0, {},
       crit([](criteria_options& c, double x) {
         c.criterion = refinement_criterion::nld_is;
         c.display_quantum = as_float(x);
       })},
      {"progressive_refiner", "random_share", true, 0, {1.0000001},
       crit([](criteria_options& c, double x) { c.random_share = as_float(x); })},
      {"progressive_refiner", "seed", false, u64_max, {},
       crit([](criteria_options& c, double x) {
         c.criterion = refinement_criterion::rnd;
         c.seed = as_count<std::uint64_t>(x);
       })},
      {"progressive_refiner", "max_shading_samples", false, size_max, {},
       drv([](driver_options& o, double x) { o.max_shading_samples = as_count<std::size_t>(x); })},
      {"progressive_refiner", "max_batches", false, size_max, {},
       drv([](driver_options& o, double x) { o.max_batches = std::min<std::size_t>(as_count<std::size_t>(x), 8); })},
      {"progressive_refiner", "max_cached_samples", false, size_max, {},
       drv([](driver_options& o, double x) { o.max_cached_samples = as_count<std::size_t>(x); })},
      {"progressive_refiner", "grain", false, size_max, {},
       drv([](driver_options& o, double x) { o.grain = as_count<std::size_t>(x); })},
      {"progressive_refiner", "background", true, 0, {},
       drv([](driver_options& o, double x) { o.background = glm::vec3(as_float(x)); })},
      {"progressive_refiner::start", "camera", true, 0, {},
       cam([](pinhole_camera& c, double x) { c.eye.x = as_float(x); })},
      {"progressive_refiner::start", "camera", true, 0, {},
       cam([](pinhole_camera& c, double x) { c.up.y = as_float(x); })},
      {"progressive_refiner::start", "camera", true, 0, {180.0},
       cam([](pinhole_camera& c, double x) { c.vertical_fov_degrees = as_float(x); })},
  };
}

std::vector<option_row> upsample_rows() {
  auto rc = [](auto set) {
    return [set](double x) {
      ray_cast_options o{.ao_rays = 4};
      set(o, x);
      return run_ray_cast(sphere(), o);
    };
  };
  return {
      {"upsampler::create", "image size", false, u32_max, {double((1u << 24) + 1)},
       [](double x) { return run_upsampler(as_count<std::uint32_t>(x), 8, {}); }},
      {"upsampler::create", "image size", false, u32_max, {double((1u << 24) + 1)},
       [](double x) { return run_upsampler(as_count<std::uint32_t>(x), as_count<std::uint32_t>(x), {}); }},
      {"upsampler::create", "passes", false, u32_max, {5.0},
       [](double x) { return run_upsampler(12, 10, {.passes = as_count<std::uint32_t>(x)}); }},
      {"upsampler::create", "max_passes", false, u32_max, {17.0},
       [](double x) {
         const std::uint32_t mp = as_count<std::uint32_t>(x);
         return run_upsampler(12, 10, {.passes = std::max(1u, std::min(mp, 4u)), .max_passes = mp});
       }},
      {"upsampler::create", "rows_per_task", false, u32_max, {},
       [](double x) { return run_upsampler(12, 10, {.rows_per_task = as_count<std::uint32_t>(x)}); }},
      {"upsampler::create", "min_sources", false, u32_max, {3.0},
       [](double x) { return run_upsampler(12, 10, {.min_sources = as_count<std::uint32_t>(x)}); }},
      {"pass_controller", "frame-time bounds", true, 0, {},
       [](double x) { return run_controller({.min_frame_seconds = x}); }},
      {"pass_controller", "frame-time bounds", true, 0, {},
       [](double x) { return run_controller({.max_frame_seconds = x}); }},
      {"pass_controller", "max_passes", false, u32_max, {17.0},
       [](double x) { return run_controller({.max_passes = as_count<std::uint32_t>(x)}); }},
      {"pass_controller", "initial_passes", false, u32_max, {5.0},
       [](double x) { return run_controller({.initial_passes = as_count<std::uint32_t>(x)}); }},
      {"pass_controller", "smoothing", true, 0, {1.0000001}, [](double x) { return run_controller({.smoothing = x}); }},
      {"pass_controller", "settle_frames", false, u32_max, {},
       [](double x) { return run_controller({.settle_frames = as_count<std::uint32_t>(x)}); }},
      {"pass_controller", "forget_frames", false, u32_max, {},
       [](double x) { return run_controller({.forget_frames = as_count<std::uint32_t>(x)}); }},
      {"pass_controller::update", "frame", true, 0, {}, [](double x) { return run_controller({}, x); }},
      {"ray_cast_source::create", "ao_rays", false, u32_max, {65537.0},
       rc([](ray_cast_options& o, double x) { o.ao_rays = as_count<unsigned>(x); })},
      {"ray_cast_source::create", "ao_radius", true, 0, {}, rc([](ray_cast_options& o, double x) { o.ao_radius = as_float(x); })},
      {"ray_cast_source::create", "ray_offset", true, 0, {},
       rc([](ray_cast_options& o, double x) { o.ray_offset = as_float(x); })},
      {"ray_cast_source::create", "view_origin", true, 0, {},
       rc([](ray_cast_options& o, double x) {
         o.view_origin = {0.0f, 0.0f, as_float(x)};
         o.view_forward = {0.0f, 0.0f, -1.0f};
       })},
      {"ray_cast_source::create", "view_forward", true, 0, {},
       rc([](ray_cast_options& o, double x) { o.view_forward = {0.0f, as_float(x), -1.0f}; })},
      {"ray_cast_source::create", "tolerance", true, 0, {}, rc([](ray_cast_options& o, double x) { o.tolerance = as_float(x); })},
      {"ray_cast_source::create", "smooth_angle", true, 0, {},
       [](double x) { return run_ray_cast<probe_mode::refine>(sphere(), {.ao_rays = 4, .smooth_angle = as_float(x)}); }},
  };
}

}  // namespace

TEST_CASE("option extremes: cluster family", "[reliability][options]") {
  for (const option_row& r : cluster_rows()) check_row(r);
}
TEST_CASE("option extremes: saliency family", "[reliability][options]") {
  for (const option_row& r : saliency_rows()) check_row(r);
}
TEST_CASE("option extremes: lod family", "[reliability][options]") {
  for (const option_row& r : lod_rows()) check_row(r);
}
TEST_CASE("option extremes: refine family", "[reliability][options]") {
  for (const option_row& r : refine_rows()) check_row(r);
}
TEST_CASE("option extremes: upsample family", "[reliability][options]") {
  for (const option_row& r : upsample_rows()) check_row(r);
}

// ---- regressions --------------------------------------------------------------------------

TEST_CASE("chunking: any grain covers [0, n) once, in order", "[reliability][options]") {
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{1000}, size_max})
    for (std::size_t grain : {std::size_t{0}, std::size_t{1}, std::size_t{3}, size_max / 2, size_max - 1, size_max}) {
      const std::size_t chunks = chunk_count(n, grain);
      INFO("n " << n << " grain " << grain);
      CHECK((n == 0) == (chunks == 0));
      if (chunks == 0 || chunks > 4096) continue;
      std::size_t at = 0;
      for (std::size_t c = 0; c < chunks; ++c) {
        const chunk_bounds b = chunk_at(n, grain, c);
        CHECK(b.begin == at);
        CHECK(b.end > b.begin);
        at = b.end;
      }
      CHECK(at == n);
    }
  std::vector<int> seen(100, 0);
  support::thread_pool_executor{3}.parallel_for(seen.size(), size_max, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) ++seen[i];
  });
  CHECK(std::count(seen.begin(), seen.end(), 1) == 100);
}

TEST_CASE("view_dependent_lod with a grain of SIZE_MAX gives the default grain's frame", "[reliability][options]") {
  // The workspace's chunk starts wrapped (b += grain) and the chunk loop wrote past the buffer.
  const outcome o = run_lod(0.02, size_max, glm::dvec3(0.3, -2.0, 4.0), 0.0, true);
  CHECK(o.st.ok());
  CHECK(o.output_ok);
}

TEST_CASE("orientation and stretch bins of 2^32 - 1 allocate for the cells in use only", "[reliability][options]") {
  std::vector<glm::vec3> normals;
  for (const auto& p : sphere().positions) normals.push_back(glm::normalize(p));
  support::heap_largest = 0;
  support::heap_refuse_above = table_allocation_cap;
  const orientation_state many = make_orientation_state(normals, 0xffffffffu);
  const std::vector<double> raw{0.5, 1.0, 3.0, inf_d, 2.0};
  const stretch_state cells = make_stretch_state(raw, 0xffffffffu);
  support::heap_refuse_above = ~std::size_t{0};
  CHECK(support::heap_largest < (std::size_t{1} << 16));  // the 42 x 42 stored rows are the largest block
  CHECK(many.kernel().column_count() == normals.size());  // cells this fine separate every normal
  CHECK(cells.kernel().class_count() == 4);               // 3.0 and +inf both normalise to 1 (stretch_channel.hpp)
  // Both numberings (direct table for few possible cells, sort for many) give ascending cell order.
  const std::vector<std::uint32_t> cell{9, 3, 3, 4000, 9, 0}, want{2, 1, 1, 3, 2, 0};
  std::vector<std::uint32_t> by_table, by_sort;
  CHECK(detail::number_occupied_cells(cell, 4001, by_table) == 4);
  CHECK(detail::number_occupied_cells(cell, 0xffffffffu, by_sort) == 4);
  CHECK(by_table == want);
  CHECK(by_sort == want);
}

TEST_CASE("weighting_map: weights that overflow double are refused, never infinite", "[reliability][options]") {
  std::vector<double> huge = bumpy_saliency(sphere());
  for (double& s : huge) s *= 1e300;
  const auto cl = halves(sphere());
  auto a = weighting_map(sphere(), huge, cl, 2);
  if (a) {
    CHECK(all_finite(*a));
  } else {
    CHECK(a.error().code() == errc::bad_parameter);
  }
  auto b = weighting_map(sphere(), bumpy_saliency(sphere()), cl, 2, {.amplify_percentile = 0.0, .amplification = 1e308});
  REQUIRE_FALSE(b.ok());
  CHECK(b.error().code() == errc::bad_parameter);
  CHECK(b.error().message().find("overflows") != std::string::npos);
}

TEST_CASE("ray_cast_source: view vectors, normals, texcoords and barycentrics at their extremes", "[reliability][options]") {
  const float nan_f = std::numeric_limits<float>::quiet_NaN();
  CHECK(run_ray_cast(sphere(), {.view_forward = {nan_f, 0.0f, -1.0f}}).st.code() == errc::bad_parameter);
  CHECK(run_ray_cast(sphere(), {.view_origin = {0.0f, nan_f, 0.0f}}).st.code() == errc::bad_parameter);
  // A view depth that overflows float gave inv_depth 0, and the upsampler's weights 0/0.
  const outcome far_view = run_ray_cast(sphere(), {.ao_rays = 4, .view_origin = {0.0f, 0.0f, -3e38f},
                                                   .view_forward = {0.0f, 0.0f, 2.0f}});
  CHECK(far_view.st.ok());
  CHECK(far_view.output_ok);
  indexed_mesh m = sphere_with_normals();
  CHECK(run_ray_cast(m, {.ao_rays = 4}).output_ok);
  for (auto& n : m.normals) n = glm::vec3(0.0f);  // zero normals: the geometric normal shades
  const outcome zero = run_ray_cast(m, {.ao_rays = 4});
  CHECK(zero.st.ok());
  CHECK(zero.output_ok);
  m.normals[5] = glm::vec3(std::numeric_limits<float>::infinity(), 0.0f, 0.0f);
  const outcome inf_normal = run_ray_cast(m, {.ao_rays = 4});
  CHECK(inf_normal.st.code() == errc::non_finite);
  CHECK(inf_normal.st.message().find("vertex 5") != std::string::npos);
  m.normals[5] = glm::vec3(1e30f, 1e30f, 0.0f);  // finite, but its square overflows float
  const outcome huge_normal = run_ray_cast(m, {.ao_rays = 4});
  CHECK(huge_normal.st.ok());
  CHECK(huge_normal.output_ok);
  indexed_mesh uv = sphere();
  uv.texcoords.assign(3 * uv.triangles.size(), glm::vec2(0.25f));
  CHECK(run_ray_cast(uv, {.ao_rays = 4}).output_ok);
  uv.texcoords[7].y = nan_f;
  const outcome nan_uv = run_ray_cast(uv, {.ao_rays = 4});
  CHECK(nan_uv.st.code() == errc::non_finite);
  CHECK(nan_uv.st.message().find("triangle 2 corner 1") != std::string::npos);
  uv.texcoords.pop_back();
  CHECK(run_ray_cast(uv, {.ao_rays = 4}).st.code() == errc::bad_size);

  // A tracer whose barycentrics are ±1e38: a miss, not a non-finite sample.
  struct wild_tracer {
    hit intersect(const ray&) const { return {0, 3, {1e38f, -1e38f}, 1.0f}; }
    bool occluded(const ray&) const { return false; }
  };
  const wild_tracer wild;
  const indexed_mesh& s = sphere();
  const std::vector<std::uint32_t> ids(s.triangles.size(), 0);
  auto geometry = [&s](std::uint32_t) -> const indexed_mesh& { return s; };
  auto src = ray_cast_source<wild_tracer, sphere_camera, decltype(geometry), plain_material>::create(
      wild, sphere_camera{}, geometry, plain_material{}, {std::span<const std::uint32_t>(ids)}, {.ao_rays = 4});
  REQUIRE(src.ok());
  const auto rec = src->evaluate(3, 4);
  CHECK(rec.background());
  CHECK(finite(src->shade(rec, 3, 4)));
}

TEST_CASE("progressive_refiner: wild barycentrics and far cameras", "[reliability][options]") {
  struct fixed_tracer {
    hit h;
    hit intersect(const ray&) const { return h; }
    bool occluded(const ray&) const { return h.valid(); }
  };
  auto s = subdivision_mesh::create(textured_plane());
  REQUIRE(s.ok());
  auto r = progressive_refiner::create(*s);
  REQUIRE(r.ok());
  const status wild = r->start(fixed_tracer{{0, 1, {1e38f, -1e38f}, 1.0f}}, floor_camera(8, 8), shade_by_position,
                               serial_executor{});
  CHECK(wild.code() == errc::bad_parameter);
  CHECK(wild.message().find("pixel 0") != std::string::npos);
  // A camera 3e19 units from its target: |target - eye|² overflows float, the direction does not.
  pinhole_camera far = floor_camera(8, 8);
  far.eye = {3e19f, 0.0f, 1e19f};
  const ray pr = far.primary_ray(4, 4);
  CHECK(finite(pr.direction));
  const status st = r->start(support::brute_force_tracer{&textured_plane()}, far, shade_by_position, serial_executor{});
  CHECK(st.ok());
  far.eye = {3e38f, 0.0f, 0.0f};
  far.target = {-3e38f, 0.0f, 0.0f};  // the difference overflows: named
  const status over = r->start(support::brute_force_tracer{&textured_plane()}, far, shade_by_position, serial_executor{});
  CHECK(over.code() == errc::bad_parameter);
  CHECK(over.message().find("too far apart") != std::string::npos);
}

TEST_CASE("visibility viewpoints and upsampler image size are bounded before allocating", "[reliability][options]") {
  support::heap_largest = 0;
  const outcome v = run_cluster(sphere(), cluster_options{}, visibility_channel{.viewpoints = 0xffffffffu});
  CHECK(v.st.code() == errc::bad_parameter);
  CHECK(v.st.message().find("viewpoints") != std::string::npos);
  auto up = upsampler<sample>::create(1u << 24, 1u << 24);
  CHECK(up.error().code() == errc::bad_parameter);
  CHECK(up.error().message().find("1 GiB") != std::string::npos);
  CHECK(support::heap_largest < (std::size_t{1} << 20));
  CHECK(upsampler<sample>::create(3840, 2160).ok());
}

TEST_CASE("a negative weight or saliency is a bad parameter, a NaN one non-finite", "[reliability][options]") {
  std::vector<double> w(3 * sphere().triangles.size(), 1.0);
  w[4] = -2.0;
  const auto neg = make_contraction_hierarchy(sphere(), w, halves(sphere()), 2);
  CHECK(neg.error().code() == errc::bad_parameter);
  CHECK(neg.error().element() == 4);
  w[4] = nan_d;
  CHECK(make_contraction_hierarchy(sphere(), w, halves(sphere()), 2).error().code() == errc::non_finite);
  std::vector<double> s = bumpy_saliency(sphere());
  s[6] = -1.0;
  CHECK(salient_clustering(sphere(), s).error().code() == errc::bad_parameter);
  CHECK(weighting_map(sphere(), s, halves(sphere()), 2).error().code() == errc::bad_parameter);
}

TEST_CASE("subdivision: two triangles on the same three vertices are refused, not split", "[reliability][options]") {
  // A closed two-triangle pillow passes validate_mesh (every edge has two faces), but splitting
  // one gave the shared midpoints' inner edges four faces (an assertion in the refiner's run).
  indexed_mesh pillow;
  pillow.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  pillow.triangles = {{0, 1, 2}, {0, 2, 1}};
  auto s = subdivision_mesh::create(pillow);
  REQUIRE_FALSE(s.ok());
  CHECK(s.error().code() == errc::non_manifold_edge);
  CHECK(s.error().message().find("triangles 0 and 1") != std::string::npos);
}
