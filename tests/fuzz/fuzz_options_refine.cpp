// libFuzzer target: every option of the refinement family at fuzzed values, extremes included
// (subdivision_options, criteria_options, driver_options, the pinhole camera), and tracers that
// answer with fuzzed hits, on small fuzzed meshes, through a whole progressive_refiner::run.
// Input: [flags][subdivision options][criteria options][driver options][camera][fuzzed hit]
// [mesh]. The image is at most 16 × 16 pixels and a run at most 8 batches, so an input stays
// cheap. Checks: every error names its problem; every shaded colour is finite.
#include <cmath>
#include <vector>
#include "fuzz_common.hpp"
#include "infolerp/refine/progressive_driver.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"
#include "support/brute_force_tracer.hpp"

namespace {
struct fixed_tracer {  // the same hit for every ray: garbage ids, barycentrics and distances
  infolerp::hit h;
  infolerp::hit intersect(const infolerp::ray&) const { return h; }
  bool occluded(const infolerp::ray&) const { return h.valid(); }
};
glm::vec3 shade(const infolerp::shading_point& p) { return glm::abs(p.position) * 0.25f + p.normal; }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::reader r{data, size};
  const std::uint8_t flags = r.u8();
  const infolerp::subdivision_options so{.bisect_ratio = r.real_f(), .propagation_depth = r.count<std::uint32_t>()};
  infolerp::criteria_options c;
  c.criterion = static_cast<infolerp::refinement_criterion>(r.u8() % 3u);
  c.s_req = r.real_f();
  c.min_pixels = r.real_f();
  c.always_refine_fraction = r.real_f();
  c.batch = r.count<std::uint32_t>();
  // rnd_point_fraction as read when outside [0, 1e6] (refused); valid values folded into [0, 4] so
  // that an input stays cheap.
  c.rnd_point_fraction = r.real_f();
  if (c.rnd_point_fraction >= 0.0f && c.rnd_point_fraction <= 1e6f) c.rnd_point_fraction = std::fmod(c.rnd_point_fraction, 4.0f);
  c.nld_is_pixel_fraction = r.real_f();
  c.random_share = r.real_f();
  c.seed = r.count<std::uint64_t>();
  infolerp::driver_options d{.criteria = c, .max_shading_samples = r.count<std::size_t>(),
                             .max_batches = r.count<std::size_t>() % 9u, .max_cached_samples = r.count<std::size_t>(),
                             .background = glm::vec3(r.real_f()), .grain = r.count<std::size_t>()};
  infolerp::pinhole_camera cam;
  cam.eye = {r.real_f(), r.real_f(), r.real_f() + 2.0f};
  cam.target = {r.real_f(), r.real_f(), r.real_f()};
  cam.up = {r.real_f(), r.real_f(), r.real_f()};
  cam.vertical_fov_degrees = (flags & 1) ? r.real_f() : 60.0f;
  cam.width = r.u8() % 17u;   // image sizes: small, 0 included (the pixel-count bound of set_view
  cam.height = r.u8() % 17u;  // is progressive_driver.hpp's own)
  const fixed_tracer wild{{r.u8() % 2u, r.index(), {r.real_f(), r.real_f()}, r.real_f()}};
  const infolerp::indexed_mesh m = fuzz::read_mesh(r, 16, 24);
  // Read after the mesh, so that inputs written before the option still read every other field
  // as they did; an input that ends here keeps the default.
  if (!r.empty()) d.criteria.display_quantum = r.real_f();

  auto s = infolerp::subdivision_mesh::create(m, so);
  fuzz::check_error(s.error());
  if (!s.ok()) return 0;
  auto refiner = infolerp::progressive_refiner::create(*s, d);
  fuzz::check_error(refiner.error());
  if (!refiner.ok()) return 0;
  const infolerp::support::brute_force_tracer tracer{&m};
  auto rep = (flags & 2) ? refiner->run(wild, cam, shade) : refiner->run(tracer, cam, shade);
  fuzz::check_error(rep.error());
  if (!rep.ok()) return 0;
  for (std::size_t v = 0; v < refiner->mesh().vertex_count(); ++v)
    if (refiner->vertex_shaded(v)) FUZZ_CHECK(fuzz::finite(refiner->vertex_colour(v)));
  return 0;
}
