// Tests for support::split_at_texture_seams (tests/support/demo_clusters.hpp): the I-Buffer's ids
// are clusters cut where texcoords jump, since texcoords are interpolated within an id.
#include <catch2/catch.hpp>

#include <cstdint>
#include <vector>
#include "support/demo_clusters.hpp"

namespace {

// A strip of two quads (four triangles) along x. seam: the middle column of vertices is
// duplicated and the right quad's texcoords restart at u = 0, as at a UV sphere's seam.
infolerp::indexed_mesh strip(bool seam) {
  infolerp::indexed_mesh m;
  m.positions = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {2, 0, 0}, {2, 1, 0}};
  std::uint32_t l0 = 2, l1 = 3;  // the middle column as the right quad sees it
  if (seam) {
    m.positions.push_back({1, 0, 0});
    m.positions.push_back({1, 1, 0});
    l0 = 6;
    l1 = 7;
  }
  const float u_mid = seam ? 0.0f : 0.5f;
  m.triangles = {{0, 2, 3}, {0, 3, 1}, {l0, 4, 5}, {l0, 5, l1}};
  m.texcoords = {{0, 0}, {0.5f, 0}, {0.5f, 1}, {0, 0}, {0.5f, 1}, {0, 1},
                 {u_mid, 0}, {1, 0}, {1, 1}, {u_mid, 0}, {1, 1}, {u_mid, 1}};
  return m;
}

}  // namespace

TEST_CASE("clusters are cut at texture seams and nowhere else", "[upsample]") {
  std::vector<std::uint32_t> out;
  SECTION("one cluster without a seam stays one id") {
    CHECK(infolerp::support::split_at_texture_seams(strip(false), {7, 7, 7, 7}, out) == 1);
    CHECK(out == std::vector<std::uint32_t>{0, 0, 0, 0});
  }
  SECTION("one cluster across a seam becomes two ids") {
    CHECK(infolerp::support::split_at_texture_seams(strip(true), {7, 7, 7, 7}, out) == 2);
    CHECK(out == std::vector<std::uint32_t>{0, 0, 1, 1});
  }
  SECTION("shared vertices with different texcoords are a seam too") {
    auto m = strip(false);
    for (std::size_t c = 6; c < 12; ++c) m.texcoords[c].x += 3.0f;  // right quad: another chart, same vertices
    CHECK(infolerp::support::split_at_texture_seams(m, {7, 7, 7, 7}, out) == 2);
  }
  SECTION("different clusters stay different without a seam") {
    CHECK(infolerp::support::split_at_texture_seams(strip(false), {1, 1, 2, 2}, out) == 2);
    CHECK(out[0] == out[1]);
    CHECK(out[2] == out[3]);
    CHECK(out[0] != out[2]);
  }
}
