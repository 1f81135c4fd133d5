// The per-frame entry point allocates nothing after setup (view_dependent_lod.hpp): counted by
// replacing the global operator new in this test executable.
#include <vector>
#include <catch2/catch.hpp>
#include "infolerp/lod/cluster_local_indices.hpp"
#include "infolerp/lod/view_dependent_lod.hpp"
#include "support/allocation_counter.hpp"
#include "support/procedural.hpp"
#include "support/thread_pool.hpp"

TEST_CASE("a frame allocates nothing after setup", "[lod]") {
  using namespace infolerp;
  const indexed_mesh m = support::make_icosphere(3);
  std::vector<std::uint32_t> cl(m.triangle_count());
  for (std::size_t t = 0; t < cl.size(); ++t) cl[t] = static_cast<std::uint32_t>(t % 5);
  std::vector<double> sal(m.vertex_count(), 1.0), w(3 * m.triangle_count(), 1.0);
  auto h = make_contraction_hierarchy(m, w, cl, 5, {.cluster_local_first = true});
  REQUIRE(h.ok());
  auto table = compute_cluster_attributes(m, sal, cl, 5);
  REQUIRE(table.ok());
  auto lod = view_dependent_lod::create(*h, *table);
  auto paper = view_dependent_lod::create(*h, *table, {.selection = lod_selection::paper, .view = {}});
  REQUIRE(lod.ok());
  REQUIRE(paper.ok());
  std::vector<std::uint32_t> out(contracted_index_bound(*h));
  std::vector<index_range> ranges(5);
  const lod_camera camera{{0.2, 3.0, 1.0}, {-0.2, -3.0, -1.0}, {0.0, 0.0, 1.0}, 0.8, 640, 480};
  const std::size_t before = support::heap_allocations.load();
  bool ok = true;
  for (std::uint64_t r : {std::uint64_t{10}, std::uint64_t{h->local_contractions}, lod->capacity() - 1}) {
    ok = ok && lod->frame(camera, r, out, ranges).ok();
    ok = ok && paper->frame(camera, r, out, ranges).ok();
  }
  const std::size_t during = support::heap_allocations.load() - before;
  REQUIRE(ok);
  CHECK(during == 0);
}

TEST_CASE("16-bit local indices allocate nothing per frame", "[lod]") {
  using namespace infolerp;
  const indexed_mesh m = support::make_icosphere(3);
  std::vector<std::uint32_t> cl(m.triangle_count());
  for (std::size_t t = 0; t < cl.size(); ++t) cl[t] = static_cast<std::uint32_t>(t % 3);
  std::vector<double> sal(m.vertex_count(), 1.0), w(3 * m.triangle_count(), 1.0);
  auto h = make_contraction_hierarchy(m, w, cl, 3);
  REQUIRE(h.ok());
  auto table = compute_cluster_attributes(m, sal, cl, 3);
  REQUIRE(table.ok());
  auto lod = view_dependent_lod::create(*h, *table);
  REQUIRE(lod.ok());
  auto local = make_local_index_table(m, *h, 120);  // several parts per cluster
  REQUIRE(local.ok());
  REQUIRE(local->part_count() > 3);
  std::vector<std::uint32_t> out(contracted_index_bound(*h));
  std::vector<std::uint16_t> out16(out.size());
  std::vector<index_range> ranges(3), parts(local->part_count());
  const lod_camera camera{{0.2, 3.0, 1.0}, {-0.2, -3.0, -1.0}, {0.0, 0.0, 1.0}, 0.8, 640, 480};
  REQUIRE(lod->frame(camera, lod->capacity() / 2, out, ranges).ok());
  const std::size_t before = support::heap_allocations.load();
  auto n = localize_indices(*local, out, ranges, out16, parts);
  const std::size_t during = support::heap_allocations.load() - before;
  REQUIRE(n.ok());
  CHECK(*n == ranges[0].count + ranges[1].count + ranges[2].count);
  CHECK(during == 0);
}
