// Splitting clusters for 16-bit indices (salient-clustering paper §IV.B).
#include <algorithm>
#include <cstdint>
#include <set>
#include <vector>
#include <catch2/catch.hpp>
#include "infolerp/lod/cluster_split.hpp"
#include "support/procedural.hpp"

using namespace infolerp;

namespace {
// Distinct vertices per new cluster, and whether each new cluster lies inside one old cluster.
void check_split(const indexed_mesh& m, const std::vector<std::uint32_t>& old, const split_clusters_result& s,
                 std::uint32_t limit) {
  std::vector<std::set<std::uint32_t>> verts(s.count);
  std::vector<std::uint32_t> parent(s.count, invalid_id);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint32_t c = s.cluster[t];
    REQUIRE(c < s.count);
    for (int j = 0; j < 3; ++j) verts[c].insert(m.triangles[t][j]);
    if (parent[c] == invalid_id) parent[c] = old[t];
    CHECK(parent[c] == old[t]);
    CHECK(c >= s.first_part[old[t]]);
    CHECK(c < s.first_part[old[t] + 1]);
  }
  for (const auto& v : verts) {
    CHECK(!v.empty());
    CHECK(v.size() <= limit);
  }
}
}  // namespace

TEST_CASE("16-bit split keeps every cluster at most 65,536 vertices", "[lod]") {
  const indexed_mesh m = support::make_plane(300, 300, 1.0f);  // 90,601 vertices
  const std::vector<std::uint32_t> one(m.triangle_count(), 0);
  auto s = split_clusters(m, one, 1);
  REQUIRE(s.ok());
  CHECK(s->count == 2);
  check_split(m, one, *s, 65536);
}

TEST_CASE("cluster split with a small limit; clusters within it keep one id; bad input", "[lod]") {
  const indexed_mesh m = support::make_icosphere(3);  // 642 vertices
  std::vector<std::uint32_t> cl(m.triangle_count());
  for (std::size_t t = 0; t < cl.size(); ++t) cl[t] = m.positions[m.triangles[t].x].z > 0.5f ? 1u : 0u;
  auto s = split_clusters(m, cl, 3, 40);  // cluster 2 is empty
  REQUIRE(s.ok());
  check_split(m, cl, *s, 40);
  CHECK(s->first_part[3] == s->first_part[2]);
  CHECK(s->count > 642 / 40);
  auto whole = split_clusters(m, cl, 2, 642);
  REQUIRE(whole.ok());
  CHECK(whole->count == 2);
  CHECK(whole->cluster == cl);
  CHECK(split_clusters(m, cl, 2, 2).error().code() == errc::bad_parameter);
  CHECK(split_clusters(m, cl, 1).error().element() != no_element);
  std::vector<std::uint32_t> short_ids(cl.begin(), cl.end() - 1);
  CHECK(split_clusters(m, short_ids, 2).error().code() == errc::bad_size);
}
