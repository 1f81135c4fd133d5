// libFuzzer target: every option of the clustering family at fuzzed values, extremes included
// (cluster_options, visibility, orientation and stretch channels), on small fuzzed meshes.
// Input: [flags][cluster options][visibility options][orientation options][stretch options]
// [mesh][texcoords...]; values are read with reader::real() and reader::count<T>(). Options that
// only scale the work within their valid range (viewpoints, image resolution) are folded to
// small values so that an input stays cheap; values past their bounds are kept as read.
// Checks: every error names its problem; a result has one valid cluster id per triangle.
#include <vector>
#include "fuzz_common.hpp"
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/mesh/validate.hpp"
#include "support/brute_force_tracer.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::reader r{data, size};
  const std::uint8_t flags = r.u8();
  const infolerp::cluster_options co{.min_cluster_fraction = r.real(), .smooth_boundaries = (flags & 1) != 0,
                                     .grain = r.count<std::size_t>()};
  infolerp::visibility_channel vis{.threshold = r.real(), .viewpoints = r.count<std::uint32_t>(),
                                   .samples_per_side = r.count<std::uint32_t>(), .radius_scale = r.real(),
                                   .denoise = (flags & 2) != 0, .grain = r.count<std::size_t>()};
  vis.coherent = (flags & 4) != 0;
  vis.cull_hull = (flags & 8) != 0;
  vis.adaptive_probes = r.count<std::uint32_t>();
  vis.adaptive_neighbours = (flags & 16) != 0;
  vis.images = (flags & 32) != 0;
  vis.image_resolution = r.count<std::uint32_t>();
  vis.image_min_pixels = r.real();
  if (vis.viewpoints > 12 && vis.viewpoints <= vis.max_viewpoints) vis.viewpoints %= 12;  // valid and costly: fold
  if (vis.image_resolution > 32 && vis.image_resolution <= 16384) vis.image_resolution %= 32;
  const infolerp::orientation_channel ori{.threshold = r.real(), .bins = r.count<std::uint32_t>(),
                                          .exact_rows = (r.u8() & 1) != 0};
  const infolerp::stretch_channel str{.threshold = r.real(), .bins = r.count<std::uint32_t>(),
                                      .exact_rows = (r.u8() & 1) != 0, .theta = r.real()};
  infolerp::indexed_mesh m = fuzz::read_mesh(r, 16, 24);
  if (flags & 64) {
    m.texcoords.resize(3 * m.triangles.size());
    for (auto& uv : m.texcoords) uv = glm::vec2(r.coord(), r.coord());
  }
  const infolerp::support::brute_force_tracer tracer{&m};  // cluster_mesh validates before tracing
  const infolerp::serial_executor serial;
  auto c = (flags & 128) ? infolerp::cluster_mesh(m, tracer, serial, co, ori, str)
                         : infolerp::cluster_mesh(m, tracer, serial, co, vis, ori);
  fuzz::check_error(c.error());
  if (!c.ok()) return 0;
  FUZZ_CHECK(c->cluster_of.size() == m.triangles.size());
  for (std::uint32_t id : c->cluster_of) FUZZ_CHECK(id < c->cluster_count);
  return 0;
}
