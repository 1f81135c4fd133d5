// The per-frame entry point and its 16-bit conversion allocate nothing after setup
// (view_dependent_lod.hpp, cluster_local_indices.hpp): counted by replacing the global operator
// new in this test executable.
#include <algorithm>
#include <vector>
#include <catch2/catch.hpp>
#include "infolerp/lod/cluster_local_indices.hpp"
#include "infolerp/lod/view_dependent_lod.hpp"
#include "support/counting_new.hpp"
#include "support/procedural.hpp"
#include "support/thread_pool.hpp"

TEST_CASE("a frame allocates nothing after setup", "[lod]") {
  using namespace infolerp;
  const indexed_mesh m = support::make_icosphere(3);
  std::vector<std::uint32_t> cl(m.triangle_count());
  for (std::size_t t = 0; t < cl.size(); ++t)  // five bands across x, so that the cluster-local phase exists (paper)
    cl[t] = std::min(4u, static_cast<std::uint32_t>(2.5f * (m.positions[m.triangles[t].x].x + 1.0f)));
  std::vector<double> sal(m.vertex_count(), 1.0), w(3 * m.triangle_count(), 1.0);
  auto h = make_contraction_hierarchy(m, w, cl, 5, {.cluster_local_first = true});
  REQUIRE(h.ok());
  auto table = compute_cluster_attributes(m, sal, cl, 5);
  REQUIRE(table.ok());
  auto lod = view_dependent_lod::create(*h, *table);
  auto paper = view_dependent_lod::create(*h, *table, {.selection = lod_selection::paper, .view = {}});
  REQUIRE(lod.ok());
  REQUIRE(paper.ok());
  auto local = make_local_index_table(m, *h, 120);  // several parts per cluster
  REQUIRE(local.ok());
  REQUIRE(local->part_count() > 5);
  std::vector<std::uint32_t> out(contracted_index_bound(*h));
  std::vector<std::uint16_t> out16(out.size());
  std::vector<index_range> ranges(5), parts(local->part_count());
  const lod_camera camera{{0.2, 3.0, 1.0}, {-0.2, -3.0, -1.0}, {0.0, 0.0, 1.0}, 0.8, 640, 480};
  const auto localized_all = [&](const result<lod_frame_stats>& st) {
    auto n = localize_indices(*local, out, ranges, out16, parts);
    return st.ok() && n.ok() && *n == st->indices;
  };
  const std::size_t before = support::heap_allocations.load();
  bool ok = true;
  for (std::uint64_t r : {std::uint64_t{10}, std::uint64_t{h->triangle_count() / 3}, std::uint64_t{h->triangle_count()}}) {
    ok = ok && localized_all(lod->frame(camera, r, out, ranges));
    ok = ok && localized_all(paper->frame(camera, r, out, ranges));
  }
  const std::size_t during = support::heap_allocations.load() - before;
  REQUIRE(ok);
  CHECK(during == 0);
}
