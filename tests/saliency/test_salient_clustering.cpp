// saliency/salient_clustering.hpp: partition invariants, determinism, unreached components,
// the PRNG's reference sequence, and eq. (4) on a hand-checked case.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>
#include <glm/mat4x4.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include "infolerp/mesh/topology.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"
#include "support/procedural.hpp"

namespace {
infolerp::indexed_mesh bumpy_sphere() {
  auto m = infolerp::support::make_icosphere(4);
  for (auto& p : m.positions) {
    const float f = 1.0f + 0.05f * std::sin(9.0f * p.x) * std::sin(7.0f * p.y + 1.0f) * std::cos(5.0f * p.z);
    p *= f;
  }
  return m;
}

// Number of connected pieces of each cluster in the dual graph.
std::vector<int> pieces_per_cluster(const infolerp::indexed_mesh& m, const std::vector<std::uint32_t>& label,
                                    std::uint32_t count) {
  const auto topo = *infolerp::build_topology(m);
  std::vector<int> pieces(count, 0);
  std::vector<bool> seen(label.size(), false);
  for (std::size_t f = 0; f < label.size(); ++f) {
    if (seen[f]) continue;
    ++pieces[label[f]];
    std::vector<std::uint32_t> stack{static_cast<std::uint32_t>(f)};
    seen[f] = true;
    while (!stack.empty()) {
      const auto g = stack.back();
      stack.pop_back();
      for (auto h : topo.neighbours_of(g))
        if (!seen[h] && label[h] == label[f]) seen[h] = true, stack.push_back(h);
    }
  }
  return pieces;
}
}  // namespace

TEST_CASE("splitmix64 follows the reference sequence") {
  infolerp::splitmix64 rng{0};
  CHECK(rng.next() == 0xe220a8397b1dcdafull);
  CHECK(rng.next() == 0x6e789e6aa1b965f4ull);
  infolerp::splitmix64 r2{42};
  for (int i = 0; i < 1000; ++i) CHECK(r2.uniform(7) < 7);
}

TEST_CASE("salient clustering: every face in exactly one connected cluster, deterministic per seed") {
  const auto m = bumpy_sphere();
  auto s = infolerp::compute_saliency(m);
  REQUIRE(s.ok());
  infolerp::salient_clustering_options opt{.clusters = 10, .seed = 7};
  auto a = infolerp::salient_clustering(m, s->saliency, opt);
  REQUIRE(a.ok());
  CHECK(a->count == 10);
  CHECK(a->cluster.size() == m.triangles.size());
  for (auto c : a->cluster) CHECK(c < a->count);
  const auto pieces = pieces_per_cluster(m, a->cluster, a->count);
  for (std::uint32_t c = 0; c < a->count; ++c) CHECK(pieces[c] == 1);
  CHECK(std::set<std::uint32_t>(a->seeds.begin(), a->seeds.end()).size() == 10);
  CHECK((a->converged || a->iterations == opt.max_iterations));
  INFO("iterations " << a->iterations << " converged " << a->converged << " cycle " << a->cycle);
  CHECK(a->converged);

  auto b = infolerp::salient_clustering(m, s->saliency, opt);
  REQUIRE(b.ok());
  CHECK(b->cluster == a->cluster);
  CHECK(b->seeds == a->seeds);
  opt.seed = 8;
  auto c = infolerp::salient_clustering(m, s->saliency, opt);
  REQUIRE(c.ok());
  for (std::uint32_t k = 0; k < c->count; ++k) CHECK(pieces_per_cluster(m, c->cluster, c->count)[k] == 1);

  // Initial seeds come from the pool of the 5·C most salient vertices.
  std::vector<std::uint32_t> order(m.positions.size());
  for (std::uint32_t v = 0; v < order.size(); ++v) order[v] = v;
  std::sort(order.begin(), order.end(), [&](auto x, auto y) { return s->saliency[x] > s->saliency[y]; });
  opt.max_iterations = 1;
  auto first = infolerp::salient_clustering(m, s->saliency, opt);
  REQUIRE(first.ok());
  const std::set<std::uint32_t> pool(order.begin(), order.begin() + 50);
  for (auto v : first->seeds) CHECK(pool.count(v) == 1);
}

TEST_CASE("salient clustering: unreached components get their own cluster") {
  infolerp::indexed_mesh m = infolerp::support::make_icosphere(2);
  infolerp::support::append(m, infolerp::support::make_icosphere(2),
                            glm::translate(glm::mat4(1.0f), glm::vec3(5.0f, 0.0f, 0.0f)));
  std::vector<double> sal(m.positions.size(), 0.0);
  sal[0] = 1.0;  // the single most salient vertex is on the first sphere
  auto r = infolerp::salient_clustering(m, sal, {.clusters = 1, .pool_multiplier = 1.0});
  REQUIRE(r.ok());
  CHECK(r->count == 2);
  const std::size_t half = m.triangles.size() / 2;
  for (std::size_t f = 0; f < m.triangles.size(); ++f) CHECK(r->cluster[f] == (f < half ? 0u : 1u));
}

TEST_CASE("salient clustering: bad input gets a clear status") {
  const auto m = infolerp::support::make_icosphere(1);
  std::vector<double> sal(m.positions.size(), 0.5);
  CHECK(infolerp::salient_clustering(m, std::span<const double>(sal).first(3)).error().code() == infolerp::errc::bad_size);
  CHECK(infolerp::salient_clustering(m, sal, {.clusters = 0}).error().code() == infolerp::errc::bad_parameter);
  CHECK(infolerp::salient_clustering(m, sal, {.clusters = 100000}).error().code() == infolerp::errc::bad_parameter);
  CHECK(infolerp::salient_clustering(m, sal, {.normal_weight = 0.5}).error().code() == infolerp::errc::bad_parameter);
  sal[4] = -1.0;
  auto neg = infolerp::salient_clustering(m, sal);
  CHECK(neg.error().code() == infolerp::errc::non_finite);
  CHECK(neg.error().element() == 4);
}

TEST_CASE("cluster-localised saliency (eq. 4) by hand") {
  // Two triangles sharing an edge, in different clusters.
  infolerp::indexed_mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  m.triangles = {{0, 1, 2}, {1, 3, 2}};
  const std::vector<double> sal{1.0, 3.0, 2.0, 7.0};
  const std::vector<std::uint32_t> cluster{0, 1};
  const auto res = infolerp::cluster_localized_saliency(m, sal, cluster, 2);
  REQUIRE(res.ok());
  const std::vector<double>& out = *res;
  // Cluster 0: vertices {0,1,2} values {1,3,2}: min 1, max 3, mean 2.
  CHECK(out[0] == Approx(0.0 + 2.0));
  CHECK(out[1] == Approx(1.0 + 2.0));
  CHECK(out[2] == Approx(0.5 + 2.0));
  // Cluster 1: vertices {1,3,2} values {3,7,2}: min 2, max 7, mean 4.
  CHECK(out[3] == Approx(0.2 + 4.0));
  CHECK(out[4] == Approx(1.0 + 4.0));
  CHECK(out[5] == Approx(0.0 + 4.0));
}
