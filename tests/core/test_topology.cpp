// mesh/topology.hpp against brute-force references on procedural and real meshes, and
// mesh/locality_order.hpp.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <set>
#include "infolerp/mesh/locality_order.hpp"
#include "infolerp/mesh/topology.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"

namespace {
// O(T²) reference: triangles sharing two distinct vertices are neighbours.
std::vector<std::set<std::uint32_t>> brute_force_neighbours(const infolerp::indexed_mesh& m) {
  std::vector<std::set<std::uint32_t>> out(m.triangles.size());
  auto edges_of = [](glm::uvec3 t) {
    std::set<std::pair<unsigned, unsigned>> e;
    for (int c = 0; c < 3; ++c)
      if (t[c] != t[(c + 1) % 3]) e.insert(std::minmax(t[c], t[(c + 1) % 3]));
    return e;
  };
  for (std::uint32_t a = 0; a < m.triangles.size(); ++a)
    for (std::uint32_t b = a + 1; b < m.triangles.size(); ++b) {
      const auto ea = edges_of(m.triangles[a]), eb = edges_of(m.triangles[b]);
      if (std::any_of(ea.begin(), ea.end(), [&](const auto& e) { return eb.count(e) != 0; })) {
        out[a].insert(b);
        out[b].insert(a);
      }
    }
  return out;
}
void check_against_brute_force(const infolerp::indexed_mesh& m) {
  auto topo = infolerp::make_topology(m);
  REQUIRE(topo.ok());
  const auto ref = brute_force_neighbours(m);
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto n = topo->neighbours_of(t);
    REQUIRE(std::set<std::uint32_t>(n.begin(), n.end()) == ref[t]);
    REQUIRE(std::is_sorted(n.begin(), n.end()));
  }
}
}  // namespace

TEST_CASE("closed meshes: every edge has two triangles, Euler characteristic holds") {
  const auto sphere = infolerp::support::make_icosphere(3);
  auto topo = infolerp::make_topology(sphere);
  REQUIRE(topo.ok());
  CHECK(topo->edge_count() == 3 * sphere.triangles.size() / 2);
  CHECK(sphere.positions.size() + sphere.triangles.size() - topo->edge_count() == 2);  // V - E + F = 2
  CHECK(infolerp::boundary_edges(*topo).empty());
  for (std::size_t t = 0; t < sphere.triangles.size(); ++t) CHECK(topo->neighbours_of(t).size() == 3);
  const auto torus = infolerp::support::make_torus(24, 12, 1.0f, 0.3f);
  auto tt = infolerp::make_topology(torus);
  REQUIRE(tt.ok());
  CHECK(torus.positions.size() + torus.triangles.size() - tt->edge_count() == 0);  // genus 1
}

TEST_CASE("dual graph matches brute force, including boundaries") {
  check_against_brute_force(infolerp::support::make_icosphere(2));
  check_against_brute_force(infolerp::support::make_plane(7, 5, 1.0f));
  auto plane = infolerp::make_topology(infolerp::support::make_plane(7, 5, 1.0f));
  REQUIRE(plane.ok());
  CHECK(infolerp::boundary_edges(*plane).size() == 2 * (7 + 5));
}

TEST_CASE("non-manifold edges keep every triangle on them adjacent") {
  infolerp::indexed_mesh fan;
  fan.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  fan.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};  // edge (0,1) has three triangles
  auto topo = infolerp::make_topology(fan);
  REQUIRE(topo.ok());
  std::size_t non_manifold = 0;
  for (std::size_t e = 0; e < topo->edge_count(); ++e) non_manifold += topo->is_non_manifold_edge(e);
  CHECK(non_manifold == 1);
  for (std::size_t t = 0; t < 3; ++t) CHECK(topo->neighbours_of(t).size() == 2);
  check_against_brute_force(fan);
}

TEST_CASE("degenerate and bad triangles") {
  infolerp::indexed_mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}, {0, 0, 1}};  // a repeated index: edge (0,0) is left out
  auto topo = infolerp::make_topology(m);
  REQUIRE(topo.ok());
  CHECK(topo->triangle_edges[3 * 1 + 0] == infolerp::invalid_id);
  CHECK(topo->neighbours_of(1).size() == 1);
  // Triangle 1 has edge (0, 1) twice (corners 1 and 2): it is listed once, so the edge is manifold.
  const std::uint32_t e01 = topo->triangle_edges[3 * 1 + 1];
  REQUIRE(e01 == topo->triangle_edges[3 * 1 + 2]);
  const auto faces = topo->faces_of_edge(e01);
  CHECK(std::vector<std::uint32_t>(faces.begin(), faces.end()) == std::vector<std::uint32_t>{0, 1});
  CHECK_FALSE(topo->is_non_manifold_edge(e01));
  m.triangles.push_back({0, 1, 3});
  auto bad = infolerp::make_topology(m);
  REQUIRE_FALSE(bad.ok());
  CHECK(bad.error().code() == infolerp::errc::index_out_of_range);
  CHECK(bad.error().element() == 2);
  CHECK(bad.error().message().find("triangle 2 corner 2: vertex index 3 out of range") != std::string::npos);
  auto empty = infolerp::make_topology(infolerp::indexed_mesh{});
  REQUIRE(empty.ok());
  CHECK(empty->triangle_count() == 0);
}

TEST_CASE("connected components") {
  infolerp::indexed_mesh two = infolerp::support::make_icosphere(1);
  infolerp::support::append(two, infolerp::support::make_box({3, 3, 3}, {4, 4, 4}));
  auto topo = infolerp::make_topology(two);
  REQUIRE(topo.ok());
  const auto comps = infolerp::connected_components(*topo);
  CHECK(comps.count == 2);
  CHECK(comps.label.front() == 0);
  CHECK(comps.label.back() == 1);
}

TEST_CASE("real meshes from CGAL data: edge and face lists agree") {
  for (const char* name : {"fandisk", "bunny00"}) {
    auto m = infolerp::support::load_mesh(infolerp::support::cgal_mesh(name));
    REQUIRE(m.ok());
    auto topo = infolerp::make_topology(*m);
    REQUIRE(topo.ok());
    // Every edge's faces list that triangle's edge back.
    for (std::size_t e = 0; e < topo->edge_count(); ++e)
      for (std::uint32_t f : topo->faces_of_edge(e)) {
        const auto* te = &topo->triangle_edges[3 * f];
        REQUIRE((te[0] == e || te[1] == e || te[2] == e));
      }
    CHECK(topo->edge_count() > m->triangles.size());
  }
  auto missing = infolerp::support::load_mesh("/nonexistent/mesh.off");
  REQUIRE_FALSE(missing.ok());
  CHECK(missing.error().message().find("/nonexistent/mesh.off") != std::string::npos);
}

TEST_CASE("Morton order is a permutation that brings dual-graph neighbours close, and is idempotent") {
  auto m = infolerp::support::make_torus(64, 32, 1.0f, 0.4f);
  std::mt19937 rng(7);
  std::shuffle(m.triangles.begin(), m.triangles.end(), rng);  // a mesh file in no spatial order
  // Mean |index distance| between dual-graph neighbours.
  auto spread = [](const infolerp::indexed_mesh& mesh) {
    auto topo = infolerp::make_topology(mesh);
    REQUIRE(topo.ok());
    double sum = 0.0, pairs = 0.0;
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t)
      for (std::uint32_t n : topo->neighbours_of(t)) {
        sum += std::abs(static_cast<double>(n) - static_cast<double>(t));
        pairs += 1.0;
      }
    return sum / pairs;
  };
  const std::vector<std::uint32_t> order = infolerp::morton_triangle_order(m);
  REQUIRE(order.size() == m.triangles.size());
  std::vector<std::uint32_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::uint32_t> identity(order.size());
  std::iota(identity.begin(), identity.end(), 0u);
  REQUIRE(sorted == identity);
  infolerp::indexed_mesh ordered = m;
  for (std::size_t i = 0; i < order.size(); ++i) ordered.triangles[i] = m.triangles[order[i]];
  const double before = spread(m), after = spread(ordered);
  INFO("mean neighbour index distance " << before << " -> " << after);
  CHECK(after * 10.0 < before);
  CHECK(infolerp::morton_triangle_order(ordered) == identity);
}
