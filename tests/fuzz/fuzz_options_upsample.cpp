// libFuzzer target: every option of the upsampling family at fuzzed values, extremes included
// (upsampler size and options, pass_controller options and measurements, ray_cast_options with
// fuzzed normals, texcoords and tracer hits), on small fuzzed meshes.
// Input: [flags][width][height][upsampler options][controller options][measurements x8]
// [ray-cast options][fuzzed hit][mesh][normals...][texcoords...]. Sizes within the limits are
// folded to at most 64 × 64 so that an input stays cheap; sizes past them are kept as read.
// Checks: every error names its problem; every frame pixel is written and finite; the
// controller's pass count stays in [1, max_passes].
#include <vector>
#include "fuzz_common.hpp"
#include "infolerp/mesh/validate.hpp"
#include "infolerp/upsample/pass_controller.hpp"
#include "infolerp/upsample/ray_cast_source.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "reliability/reliability_support.hpp"
#include "support/brute_force_tracer.hpp"

namespace {
struct fixed_tracer {  // the same hit for every primary ray; secondary rays are free
  infolerp::hit h;
  infolerp::hit intersect(const infolerp::ray&) const { return h; }
  bool occluded(const infolerp::ray&) const { return false; }
};
struct camera {
  std::uint32_t w, h;
  infolerp::ray operator()(float x, float y) const {
    const glm::vec3 d(2.0f * x / static_cast<float>(w) - 1.0f, 2.0f * y / static_cast<float>(h) - 1.0f, -1.5f);
    return infolerp::ray{{0.0f, 0.0f, 6.0f}, 0.0f, glm::normalize(d)};
  }
};
struct material {
  template <class V>
  glm::vec3 operator()(const infolerp::surface_sample<2, true>& s, const V&) const {
    return s.background() ? glm::vec3(0.1f)
                          : (s.normal * 0.5f + 0.5f) * s.occlusion[0] + glm::vec3(s.texcoord, s.inv_depth);
  }
};
std::uint32_t fold_side(std::uint32_t s) { return s > 64 && s <= (1u << 24) ? 1u + s % 64u : s; }

bool frame_ok(const std::vector<glm::vec3>& out) {
  for (const auto& p : out)
    if (!fuzz::finite(p) || p == glm::vec3(-7.0f)) return false;
  return true;
}

template <class Tracer>
void ray_cast(const Tracer& tracer, const infolerp::indexed_mesh& m, const infolerp::ray_cast_options& o,
              const infolerp::upsampler_options& uo, std::uint32_t w, std::uint32_t h) {
  const std::vector<std::uint32_t> ids(m.triangles.size(), 0);
  auto geometry = [&m](std::uint32_t) -> const infolerp::indexed_mesh& { return m; };
  auto src = infolerp::ray_cast_source<Tracer, camera, decltype(geometry), material>::create(
      tracer, camera{w, h}, geometry, material{}, {std::span<const std::uint32_t>(ids)}, o);
  fuzz::check_error(src.error());
  if (!src.ok()) return;
  std::vector<glm::vec3> out(std::size_t{w} * h, glm::vec3(-7.0f));
  const infolerp::status st = infolerp::upsample(*src, w, h, std::span<glm::vec3>(out), uo);
  fuzz::check_error(st);
  if (st.ok()) FUZZ_CHECK(frame_ok(out));
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::reader r{data, size};
  const std::uint8_t flags = r.u8();
  const std::uint32_t w = fold_side(r.count<std::uint32_t>()), h = fold_side(r.count<std::uint32_t>());
  const infolerp::upsampler_options uo{.passes = r.count<std::uint32_t>(), .max_passes = r.count<std::uint32_t>(),
                                       .rows_per_task = r.count<std::uint32_t>(), .record_kinds = (flags & 1) != 0,
                                       .keep_ibuffer = (flags & 2) != 0, .min_sources = r.count<std::uint32_t>()};
  const infolerp::pass_controller_options po{.min_frame_seconds = r.real(), .max_frame_seconds = r.real(),
                                             .max_passes = r.count<std::uint32_t>(),
                                             .initial_passes = r.count<std::uint32_t>(), .smoothing = r.real(),
                                             .settle_frames = r.count<std::uint32_t>(),
                                             .forget_frames = r.count<std::uint32_t>()};
  double seconds[8];
  for (double& s : seconds) s = r.real();
  infolerp::ray_cast_options ro;
  ro.ao_rays = r.count<unsigned>();
  if (ro.ao_rays > 16 && ro.ao_rays <= 65536) ro.ao_rays %= 16;  // valid and costly: fold
  ro.ao_radius = r.real_f();
  ro.ray_offset = r.real_f();
  if (flags & 4) ro.lights = {{{r.real_f(), r.real_f(), r.real_f()}, true}, {{r.real_f(), r.real_f(), r.real_f()}, false}};
  if (flags & 8) ro.soft_points = {{r.real_f(), r.real_f(), r.real_f()}, {r.real_f(), r.real_f(), r.real_f()}};
  ro.soft_normal = {r.real_f(), r.real_f(), r.real_f()};
  ro.batch_rays = (flags & 16) != 0;
  ro.view_origin = {r.real_f(), r.real_f(), r.real_f()};
  ro.view_forward = {r.real_f(), r.real_f(), r.real_f()};
  ro.tolerance = r.real_f();
  ro.smooth_angle = r.real_f();
  const fixed_tracer wild{{0, r.u8() % 4u, {r.real_f(), r.real_f()}, r.real_f()}};
  infolerp::indexed_mesh m = fuzz::read_mesh(r, 12, 16);
  if (flags & 32) {
    m.normals.resize(m.positions.size());
    for (auto& n : m.normals) n = {r.real_f(), r.real_f(), r.real_f()};
  }
  if (flags & 64) {
    const std::size_t short_by = m.triangles.empty() ? 0 : (r.u8() & 1u);  // sometimes one short
    m.texcoords.resize(3 * m.triangles.size() - short_by);
    for (auto& uv : m.texcoords) uv = {r.real_f(), r.real_f()};
  }

  // The upsampler on the table source.
  const std::uint32_t table_ids[3] = {0, 1, infolerp::invalid_id};
  const infolerp::reliability::table_source table{table_ids, 4};
  auto up = infolerp::upsampler<infolerp::reliability::table_source::sample_type>::create(w, h, uo);
  fuzz::check_error(up.error());
  if (up.ok()) {
    std::vector<glm::vec3> out(std::size_t{w} * h, glm::vec3(-7.0f));
    const infolerp::status st = up->render(table, std::span<glm::vec3>(out));
    FUZZ_CHECK(st.ok());
    FUZZ_CHECK(frame_ok(out));
  }
  // The pass controller under fuzzed frame times.
  auto ctl = infolerp::pass_controller::create(po);
  fuzz::check_error(ctl.error());
  if (ctl.ok())
    for (double s : seconds) {
      fuzz::check_error(ctl->update(s));
      FUZZ_CHECK(ctl->passes() >= 1 && ctl->passes() <= po.max_passes);
    }
  // The ray-cast source: a real tracer on a valid mesh, or a tracer returning the fuzzed hit.
  const std::uint32_t fw = w == 0 || w > 16 ? 8 : w, fh = h == 0 || h > 16 ? 8 : h;
  const infolerp::upsampler_options small{.passes = 2, .max_passes = 2};
  if (!infolerp::validate_mesh(m, {.allow_degenerate = true, .allow_non_manifold = true}).ok()) return 0;
  if (flags & 128) {
    if (wild.h.triangle < m.triangles.size()) ray_cast(wild, m, ro, small, fw, fh);
  } else {
    ray_cast(infolerp::support::brute_force_tracer{&m}, m, ro, small, fw, fh);
  }
  return 0;
}
