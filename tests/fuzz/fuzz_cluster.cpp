// libFuzzer target: the clustering pipeline (Algorithm 1: visibility, orientation and stretch
// channels, region growing, merging, boundary smoothing) on small fuzzed meshes with fuzzed
// thresholds and channel options, traced with the brute-force tracer.
// Input: [flags][threshold x3][viewpoints][samples][orientation bins][stretch bins]
// [min cluster fraction][mesh][texcoords...]. Checks: dense ids numbered by smallest triangle,
// every cluster edge-connected, identical labels for a second run.
#include <vector>
#include "fuzz_common.hpp"
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/mesh/topology.hpp"
#include "support/brute_force_tracer.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::reader r{data, size};
  const std::uint8_t flags = r.u8();
  const double th_vis = r.unit(), th_ori = r.unit(), th_str = r.unit();
  const infolerp::visibility_channel vis{.threshold = th_vis, .viewpoints = r.u8() % 10u,
                                         .samples_per_side = r.u8() % 4u, .denoise = (flags & 2) != 0, .grain = 3};
  const infolerp::orientation_channel ori{.threshold = th_ori, .bins = r.u8() % 80u};
  const infolerp::stretch_channel str{.threshold = th_str, .bins = r.u8() % 40u, .theta = 2.0 * r.unit()};
  const infolerp::cluster_options opt{.min_cluster_fraction = r.unit() * 0.2, .smooth_boundaries = (flags & 4) != 0,
                                      .grain = 1u + (flags >> 4)};
  infolerp::indexed_mesh m = fuzz::read_mesh(r, 24, 32);
  if (flags & 1) {  // texcoords: the stretch channel runs
    m.texcoords.resize(3 * m.triangles.size());
    for (auto& uv : m.texcoords) uv = glm::vec2(r.coord(), r.coord());
  }
  const infolerp::support::brute_force_tracer tracer{&m};  // cluster_mesh validates before tracing
  auto run = [&] { return infolerp::cluster_mesh(m, tracer, infolerp::serial_executor{}, opt, vis, ori, str); };
  auto c = run();
  fuzz::check_error(c.error());
  if (!c.ok()) return 0;
  const std::size_t nt = m.triangles.size();
  FUZZ_CHECK(c->cluster_of.size() == nt && c->channels.size() == 3);
  FUZZ_CHECK((c->channels[2].skipped != nullptr) == !m.has_texcoords());
  // Dense ids, numbered by smallest triangle.
  std::uint32_t next = 0;
  for (std::uint32_t id : c->cluster_of) {
    FUZZ_CHECK(id < c->cluster_count);
    FUZZ_CHECK(id <= next);
    if (id == next) ++next;
  }
  FUZZ_CHECK(next == c->cluster_count);
  // Every cluster is one edge-connected piece.
  auto topo = infolerp::make_topology(m);
  FUZZ_CHECK(topo.ok());
  std::vector<char> seen(nt, 0), cluster_seen(c->cluster_count, 0);
  std::vector<std::uint32_t> stack;
  for (std::size_t f = 0; f < nt; ++f) {
    if (seen[f]) continue;
    const std::uint32_t id = c->cluster_of[f];
    FUZZ_CHECK(!cluster_seen[id]);  // a second piece of the same cluster
    cluster_seen[id] = 1;
    seen[f] = 1;
    stack.push_back(static_cast<std::uint32_t>(f));
    while (!stack.empty()) {
      const std::uint32_t g = stack.back();
      stack.pop_back();
      for (std::uint32_t h : topo->neighbours_of(g))
        if (!seen[h] && c->cluster_of[h] == id) seen[h] = 1, stack.push_back(h);
    }
  }
  auto again = run();
  FUZZ_CHECK(again.ok() && again->cluster_of == c->cluster_of);
  return 0;
}
