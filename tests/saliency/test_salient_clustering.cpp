// saliency/salient_clustering.hpp: partition invariants, determinism (per seed, per executor),
// distinct seeds and no empty cluster, the flat tie-break (a plane, fandisk), unreached
// components, the PRNG's reference sequence, and eq. (4) by hand.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <vector>
#include <glm/mat4x4.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include "infolerp/mesh/topology.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"
#include "support/thread_pool.hpp"

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
  const auto topo = *infolerp::make_topology(m);
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

namespace {
// A strip of n quads, two triangles each: A_i = (b_i, b_i+1, t_i+1), B_i = (b_i, t_i+1, t_i) with
// b_i = vertex i, t_i = vertex n + 1 + i. Faces in quad order, except that `last` and
// `second_last` (indices into that order) are moved to the end.
infolerp::indexed_mesh strip(unsigned n, std::size_t second_last, std::size_t last) {
  infolerp::indexed_mesh m;
  for (unsigned i = 0; i <= n; ++i) m.positions.push_back({static_cast<float>(i), 0.0f, 0.0f});
  for (unsigned i = 0; i <= n; ++i) m.positions.push_back({static_cast<float>(i), 1.0f, 0.0f});
  std::vector<glm::uvec3> faces;
  for (unsigned i = 0; i < n; ++i) {
    faces.push_back({i, i + 1, n + 2 + i});
    faces.push_back({i, n + 2 + i, n + 1 + i});
  }
  for (std::size_t f = 0; f < faces.size(); ++f)
    if (f != last && f != second_last) m.triangles.push_back(faces[f]);
  m.triangles.push_back(faces[second_last]);
  m.triangles.push_back(faces[last]);
  return m;
}

// Mean distance from each face centroid with all-zero corner saliency to its cluster's seed.
double flat_distance_to_seed(const infolerp::indexed_mesh& m, const std::vector<double>& sal,
                             const infolerp::salient_clusters& c) {
  double sum = 0.0;
  int count = 0;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const glm::uvec3 tri = m.triangles[t];
    if (sal[tri.x] != 0.0 || sal[tri.y] != 0.0 || sal[tri.z] != 0.0) continue;
    const glm::vec3 centre = (m.positions[tri.x] + m.positions[tri.y] + m.positions[tri.z]) / 3.0f;
    sum += glm::length(centre - m.positions[c.seeds[c.cluster[t]]]);
    ++count;
  }
  return count ? sum / count : 0.0;
}
}  // namespace

TEST_CASE("salient clustering: re-seeding gives distinct seeds when thin clusters' last faces share a vertex") {
  // 8 quads; cluster 0 = quads 0-3, cluster 1 = quads 4-7. Every face of a one-quad strip is on
  // the border, so re-seeding takes each cluster's highest-numbered face: A_3 and B_4 (moved to
  // the end), which share the middle vertices b_4 and t_4; b_4 is the most salient of both.
  const unsigned n = 8;
  const auto m = strip(n, 2 * 4 + 1, 2 * 3);
  std::vector<double> sal(m.positions.size());
  for (std::size_t v = 0; v < sal.size(); ++v) sal[v] = 0.1 + 0.01 * static_cast<double>(v);
  sal[4] = 1.0;
  const auto topo = *infolerp::make_topology(m);
  const auto fd = infolerp::detail::make_face_data(m, topo, sal);
  std::vector<std::uint32_t> label(m.triangles.size());
  for (std::size_t i = 0; i < label.size(); ++i) {
    const glm::uvec3 tri = m.triangles[fd.original[i]];
    label[i] = std::min({tri.x, tri.y, tri.z}) % (n + 1) < 4 ? 0u : 1u;  // quad index < 4
  }
  infolerp::detail::clustering_workspace ws;
  const std::vector<std::uint32_t> old_seeds{0, n};
  const auto seeds = infolerp::detail::reseed(m, fd, label, sal, old_seeds, ws);
  REQUIRE(seeds.size() == 2);
  CHECK(seeds[0] == 4);
  CHECK(seeds[1] != seeds[0]);

  // End to end on the same strip: distinct seeds and no empty cluster, for several C and seeds.
  for (std::uint32_t clusters : {2u, 3u, 4u})
    for (std::uint64_t seed : {1u, 2u, 3u, 4u, 5u}) {
      auto r = infolerp::salient_clustering(m, sal, {.clusters = clusters, .pool_multiplier = 2.0, .seed = seed});
      REQUIRE(r.ok());
      INFO("clusters " << clusters << " seed " << seed);
      CHECK(std::set<std::uint32_t>(r->seeds.begin(), r->seeds.end()).size() == clusters);
      std::vector<int> size(r->count, 0);
      for (auto c : r->cluster) ++size[c];
      for (int z : size) CHECK(z > 0);
    }
}

TEST_CASE("salient clustering: flat regions are shared by distance, not flooded by the first cluster") {
  // A plane whose saliency is exactly 0 except at two vertices near opposite corners. Eq. 2
  // costs 0 between two zero-saliency faces, so without the tie-break the cluster that enters
  // the flat part first takes all of it.
  const auto m = infolerp::support::make_plane(24, 24, 2.0f);
  std::vector<double> sal(m.positions.size(), 0.0);
  std::size_t a = 0, b = 0;
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    if (glm::length(m.positions[v] - glm::vec3(-0.6f, -0.6f, 0.0f)) < glm::length(m.positions[a] - glm::vec3(-0.6f, -0.6f, 0.0f))) a = v;
    if (glm::length(m.positions[v] - glm::vec3(0.6f, 0.6f, 0.0f)) < glm::length(m.positions[b] - glm::vec3(0.6f, 0.6f, 0.0f))) b = v;
  }
  sal[a] = 1.0, sal[b] = 0.9;
  // normal_weight 2: on a plane the normal factor of eq. 2 is then 1, not 0.
  infolerp::salient_clustering_options opt{.clusters = 2, .pool_multiplier = 1.0, .normal_weight = 2.0, .max_iterations = 1};
  std::vector<double> share[2];
  double distance[2];
  for (int tie_break = 0; tie_break < 2; ++tie_break) {
    opt.flat_tie_break = tie_break == 1;
    auto r = infolerp::salient_clustering(m, sal, opt);
    REQUIRE(r.ok());
    std::vector<double> size(2, 0.0);
    for (auto c : r->cluster) size[c] += 1.0 / static_cast<double>(m.triangles.size());
    share[tie_break] = size;
    distance[tie_break] = flat_distance_to_seed(m, sal, *r);
  }
  INFO("cluster shares without the tie-break " << share[0][0] << ", " << share[0][1] << "; with it " << share[1][0]
                                              << ", " << share[1][1]);
  INFO("mean distance of flat faces to their seed: without " << distance[0] << ", with " << distance[1]);
  CHECK(std::min(share[0][0], share[0][1]) < 0.05);  // the paper's cost: one cluster floods
  CHECK(std::min(share[1][0], share[1][1]) > 0.4);   // with the tie-break: about half each
  CHECK(distance[1] < 0.8 * distance[0]);
}

TEST_CASE("salient clustering: the flat tie-break on fandisk", "[mesh]") {
  auto m = infolerp::support::load_mesh(infolerp::support::cgal_mesh("fandisk"));
  if (!m.ok()) FAIL(m.error().message());
  auto s = infolerp::compute_saliency(*m);
  REQUIRE(s.ok());
  // One growth from the same drawn seeds, for 8 user seeds: mean distance of the faces with
  // zero saliency to their cluster's seed, averaged over the seeds.
  double distance[2] = {0.0, 0.0};
  for (int tie_break = 0; tie_break < 2; ++tie_break)
    for (std::uint64_t seed = 1; seed <= 8; ++seed) {
      auto r = infolerp::salient_clustering(*m, s->saliency,
                                            {.clusters = 10, .seed = seed, .max_iterations = 1, .flat_tie_break = tie_break == 1});
      REQUIRE(r.ok());
      distance[tie_break] += flat_distance_to_seed(*m, s->saliency, *r) / 8.0;
    }
  INFO("fandisk, mean distance of zero-saliency faces to their seed: without the tie-break " << distance[0]
       << ", with " << distance[1]);
  CHECK(distance[1] < distance[0]);
}

TEST_CASE("salient clustering: the same clusters for every executor and thread count") {
  const auto m = bumpy_sphere();
  auto s = infolerp::compute_saliency(m);
  REQUIRE(s.ok());
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const infolerp::salient_clustering_options opt{.clusters = 10, .seed = seed};
    auto serial = infolerp::salient_clustering(m, s->saliency, opt);
    auto pooled = infolerp::salient_clustering(m, s->saliency, opt, infolerp::support::thread_pool_executor{3});
    REQUIRE(serial.ok());
    REQUIRE(pooled.ok());
    CHECK(pooled->cluster == serial->cluster);
    CHECK(pooled->seeds == serial->seeds);
    CHECK(pooled->iterations == serial->iterations);
  }
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
  CHECK(neg.error().code() == infolerp::errc::bad_parameter);  // finite but negative
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
