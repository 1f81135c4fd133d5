// Tests for split_at_uv_seams (cluster/uv_seams.hpp): clusters cut where texcoords jump across
// an edge shared by position, since the I-Buffer interpolates texcoords within a cluster.
// Every case checks the defining properties against a brute-force pass over all triangle
// pairs: no seam edge has one id on both sides, each output cluster lies in one input cluster
// and is edge-connected.
#include <catch2/catch.hpp>

#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <vector>
#include "infolerp/cluster/uv_seams.hpp"
#include "support/procedural.hpp"

namespace {

using infolerp::indexed_mesh;

// A strip of two quads (four triangles) along x. seam: the middle column of vertices is
// duplicated and the right quad's texcoords restart at u = 0, as at a UV sphere's seam.
indexed_mesh strip(bool seam) {
  indexed_mesh m;
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

// A unit cube whose six faces are six charts of a 3×2 atlas. shared: 8 vertices with per-corner
// texcoords; otherwise 4 vertices per face (positions repeat across faces, as exporters write).
indexed_mesh cube_six_charts(bool shared) {
  indexed_mesh box = infolerp::support::make_box(glm::vec3(0.0f), glm::vec3(1.0f));
  indexed_mesh m;
  for (std::size_t f = 0; f < 6; ++f) {
    const glm::vec2 origin{static_cast<float>(f % 3) / 3.0f, static_cast<float>(f / 3) / 2.0f};
    std::map<std::uint32_t, glm::vec2> uv;  // the face's 4 vertices on its chart
    const glm::uvec3 t0 = box.triangles[2 * f], t1 = box.triangles[2 * f + 1];
    const std::uint32_t quad[4] = {t0.x, t0.y, t0.z, t1.z};  // box faces are (a,b,c), (a,c,d)
    const glm::vec2 corner[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int k = 0; k < 4; ++k) uv[quad[k]] = origin + corner[k] * glm::vec2(0.3f, 0.45f);
    for (const glm::uvec3 t : {t0, t1}) {
      glm::uvec3 out = t;
      for (int c = 0; c < 3; ++c) {
        m.texcoords.push_back(uv[t[c]]);
        if (!shared) {
          out[c] = static_cast<std::uint32_t>(m.positions.size());
          m.positions.push_back(box.positions[t[c]]);
        }
      }
      m.triangles.push_back(out);
    }
  }
  if (shared) m.positions = box.positions;
  return m;
}

// A UV sphere with one seam: the meridian u = 0 | 1. The generator's pole corners carry each
// slice's u (a seam at every pole triangle); here they get one texcoord per pole.
indexed_mesh sphere_one_seam(unsigned slices, unsigned stacks) {
  indexed_mesh m = infolerp::support::make_uv_sphere(slices, stacks);
  for (auto& uv : m.texcoords)
    if (uv.y == 0.0f || uv.y == 1.0f) uv.x = 0.5f;
  return m;
}

// Brute force: for every pair of triangles sharing two corner positions, whether texcoords
// agree at both; then the properties of the split.
void check_properties(const indexed_mesh& m, const std::vector<std::uint32_t>& in, const infolerp::seam_clustering& out,
                      std::size_t expected_seam_edges) {
  const std::size_t nt = m.triangle_count();
  REQUIRE(out.cluster_of.size() == nt);
  std::size_t seams = 0;
  std::vector<std::uint32_t> parent(nt);
  std::iota(parent.begin(), parent.end(), 0u);
  const auto find = [&](std::uint32_t t) {
    while (parent[t] != t) t = parent[t] = parent[parent[t]];
    return t;
  };
  for (std::uint32_t a = 0; a < nt; ++a)
    for (std::uint32_t b = a + 1; b < nt; ++b) {
      int shared = 0;
      bool same_uv = true;
      for (unsigned i = 0; i < 3; ++i)
        for (unsigned j = 0; j < 3; ++j)
          if (m.positions[m.triangles[a][static_cast<int>(i)]] == m.positions[m.triangles[b][static_cast<int>(j)]]) {
            ++shared;
            same_uv = same_uv && m.texcoord(a, i) == m.texcoord(b, j);
          }
      if (shared != 2) continue;
      if (!same_uv) {
        ++seams;
        INFO("seam between triangles " << a << " and " << b);
        CHECK(out.cluster_of[a] != out.cluster_of[b]);
      } else if (out.cluster_of[a] == out.cluster_of[b]) {
        parent[find(a)] = find(b);
      }
    }
  CHECK(seams == expected_seam_edges);
  CHECK(out.seam_edges == expected_seam_edges);
  std::map<std::uint32_t, std::set<std::uint32_t>> roots, inputs;
  for (std::uint32_t t = 0; t < nt; ++t) {
    roots[out.cluster_of[t]].insert(find(t));
    inputs[out.cluster_of[t]].insert(in[t]);
  }
  CHECK(roots.size() == out.cluster_count);
  for (const auto& [id, r] : roots) {
    INFO("cluster " << id);
    CHECK(r.size() == 1);              // edge-connected without crossing a seam
    CHECK(inputs.at(id).size() == 1);  // inside one input cluster
  }
}

}  // namespace

TEST_CASE("uv seams: clusters are cut at texture seams and nowhere else", "[cluster][uv_seams]") {
  const auto split = [](const indexed_mesh& m, const std::vector<std::uint32_t>& ids) {
    auto r = infolerp::split_at_uv_seams(m, ids);
    REQUIRE(r);
    check_properties(m, ids, *r, r->seam_edges);
    return *r;
  };
  SECTION("one cluster without a seam stays one id") {
    const auto r = split(strip(false), {7, 7, 7, 7});
    CHECK(r.cluster_count == 1);
    CHECK(r.seam_edges == 0);
  }
  SECTION("one cluster across a seam of duplicated vertices becomes two ids") {
    const auto r = split(strip(true), {7, 7, 7, 7});
    CHECK(r.seam_edges == 1);
    CHECK(r.cluster_of == std::vector<std::uint32_t>{0, 0, 1, 1});
  }
  SECTION("shared vertices with different texcoords are a seam too") {
    auto m = strip(false);
    for (std::size_t c = 6; c < 12; ++c) m.texcoords[c].x += 3.0f;  // right quad: another chart, same vertices
    CHECK(split(m, {7, 7, 7, 7}).cluster_count == 2);
  }
  SECTION("different clusters stay different without a seam") {
    const auto r = split(strip(false), {1, 1, 2, 2});
    CHECK(r.cluster_of == std::vector<std::uint32_t>{0, 0, 1, 1});
  }
  SECTION("a cluster in two pieces becomes two ids without texcoords") {
    auto m = strip(false);
    m.texcoords.clear();
    CHECK(split(m, {1, 2, 1, 2}).cluster_count == 4);
  }
}

TEST_CASE("uv seams: a cube unwrapped into six charts gives six clusters", "[cluster][uv_seams]") {
  for (const bool shared : {true, false}) {
    INFO("shared vertices: " << shared);
    const indexed_mesh m = cube_six_charts(shared);
    const std::vector<std::uint32_t> one(m.triangle_count(), 0);
    auto r = infolerp::split_at_uv_seams(m, one);
    REQUIRE(r);
    check_properties(m, one, *r, 12);  // every cube edge is a seam; the face diagonals are not
    CHECK(r->cluster_count == 6);
    CHECK(r->cuts == 0);
    for (std::size_t f = 0; f < 6; ++f) CHECK(r->cluster_of[2 * f] == r->cluster_of[2 * f + 1]);
  }
}

TEST_CASE("uv seams: a sphere with one seam is cut into two clusters", "[cluster][uv_seams]") {
  // The chart reaches around the sphere, so the seam's two sides are connected the long way:
  // step 2 cuts the piece, and the seam's sides end in different clusters.
  const unsigned slices = 16, stacks = 8;
  const indexed_mesh m = sphere_one_seam(slices, stacks);
  const std::vector<std::uint32_t> one(m.triangle_count(), 0);
  auto r = infolerp::split_at_uv_seams(m, one);
  REQUIRE(r);
  check_properties(m, one, *r, stacks);  // one seam edge per stack along the meridian
  CHECK(r->cluster_count == 2);
  CHECK(r->cuts == 1);
  SECTION("clusters that already stop at the seam are kept") {
    std::vector<std::uint32_t> halves(m.triangle_count());
    for (std::size_t t = 0; t < halves.size(); ++t) halves[t] = m.texcoord(t, 0).x + m.texcoord(t, 1).x + m.texcoord(t, 2).x < 1.5f ? 0u : 1u;
    auto h = infolerp::split_at_uv_seams(m, halves);
    REQUIRE(h);
    check_properties(m, halves, *h, stacks);
    CHECK(h->cluster_count == 2);
    CHECK(h->cuts == 0);
  }
}

TEST_CASE("uv seams: bad input is named", "[cluster][uv_seams]") {
  indexed_mesh m = strip(true);
  CHECK(infolerp::split_at_uv_seams(m, std::vector<std::uint32_t>{0, 0, 0}).error().code() == infolerp::errc::bad_size);
  m.texcoords[5].x = std::numeric_limits<float>::quiet_NaN();
  auto nan = infolerp::split_at_uv_seams(m, std::vector<std::uint32_t>(4, 0));
  REQUIRE(!nan);
  CHECK(nan.error().message().find("triangle 1 corner 2") != std::string::npos);
  m = strip(true);
  m.triangles[3].z = 99;
  auto range = infolerp::split_at_uv_seams(m, std::vector<std::uint32_t>(4, 0));
  REQUIRE(!range);
  CHECK(range.error().code() == infolerp::errc::index_out_of_range);
  CHECK(range.error().element() == 3);
}
