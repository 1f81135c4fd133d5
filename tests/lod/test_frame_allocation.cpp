// The per-frame entry point allocates nothing after setup (view_dependent_lod.hpp): counted by
// replacing the global operator new in this test executable.
#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>
#include <catch2/catch.hpp>
#include "infolerp/lod/view_dependent_lod.hpp"
#include "support/procedural.hpp"
#include "support/thread_pool.hpp"

namespace {
std::atomic<long> g_allocations{0};
}

// GCC pairs the replaced operator new with std::free below and warns of a mismatch; both are
// this file's own replacements, so the pair is consistent.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

TEST_CASE("a frame allocates nothing after setup", "[lod]") {
  using namespace infolerp;
  const indexed_mesh m = support::make_icosphere(3);
  std::vector<std::uint32_t> cl(m.triangle_count());
  for (std::size_t t = 0; t < cl.size(); ++t) cl[t] = static_cast<std::uint32_t>(t % 5);
  std::vector<double> sal(m.vertex_count(), 1.0), w(3 * m.triangle_count(), 1.0);
  auto h = build_contraction_hierarchy(m, w, cl, 5);
  REQUIRE(h.ok());
  auto table = compute_cluster_attributes(m, sal, cl, 5);
  REQUIRE(table.ok());
  auto lod = view_dependent_lod::create(*h, *table);
  REQUIRE(lod.ok());
  std::vector<std::uint32_t> out(contracted_index_bound(*h));
  std::vector<index_range> ranges(5);
  const long before = g_allocations.load();
  bool ok = true;
  for (std::uint64_t r : {std::uint64_t{10}, std::uint64_t{h->local_contractions}, lod->capacity() - 1}) {
    auto st = lod->frame(glm::dvec3(0.2, 3.0, 1.0), r, out, ranges);
    ok = ok && st.ok();
  }
  const long during = g_allocations.load() - before;
  REQUIRE(ok);
  CHECK(during == 0);
}
