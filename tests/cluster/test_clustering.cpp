// cluster/region_growing.hpp and cluster/cluster_mesh.hpp: analytic scenes, invariants,
// threshold behaviour, determinism, user channels, bad input, real meshes.
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>
#include <glm/gtc/matrix_transform.hpp>
#include "brute_tracer.hpp"
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "support/embree_tracer.hpp"
#include "support/mesh_io.hpp"
#include "support/counting_channel.hpp"
#include "support/procedural.hpp"
#include "support/thread_pool.hpp"

using namespace infolerp;

namespace {
// Every triangle in exactly one cluster, ids dense and numbered by smallest triangle, every
// cluster connected in the dual graph.
template <class M>
void check_invariants(const M& m, const mesh_clustering& c) {
  REQUIRE(c.cluster_of.size() == mesh_triangle_count(m));
  std::uint32_t next = 0;
  for (std::uint32_t l : c.cluster_of) {
    REQUIRE(l <= next);
    if (l == next) ++next;
  }
  REQUIRE(next == c.cluster_count);
  auto topo = make_topology(m);
  REQUIRE(topo.ok());
  // Components of the dual graph restricted to same-cluster neighbours: one per cluster.
  std::vector<std::uint32_t> comp(c.cluster_of.size(), invalid_id), stack;
  std::uint32_t count = 0;
  for (std::uint32_t s = 0; s < comp.size(); ++s) {
    if (comp[s] != invalid_id) continue;
    comp[s] = count++;
    stack.push_back(s);
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      for (std::uint32_t n : topo->neighbours_of(t))
        if (comp[n] == invalid_id && c.cluster_of[n] == c.cluster_of[t]) {
          comp[n] = comp[s];
          stack.push_back(n);
        }
    }
  }
  REQUIRE(count == c.cluster_count);
}

const serial_executor serial;

// A user-defined channel: per-triangle material ids. Rows are indicators of the material, so
// JS is 0 within a material and 1 across; classes are the materials.
struct material_channel {
  std::vector<int> material;  // per triangle
  double threshold = 0.5;
  struct state {
    std::vector<std::uint32_t> cls;
    std::size_t classes = 0;
    std::size_t element_count() const { return cls.size(); }
    std::size_t class_count() const { return classes; }
    std::uint32_t class_of(std::uint32_t i) const { return cls[i]; }
    double mutual_information(std::uint32_t) const { return 1.0; }
    double divergence(std::uint32_t a, std::uint32_t b) const { return a == b ? 0.0 : 1.0; }
  };
  result<state> init(std::span<const std::uint32_t> tris) const {
    std::map<int, std::uint32_t> ids;
    state s;
    for (std::uint32_t t : tris) ids.emplace(material[t], 0u);
    std::uint32_t k = 0;
    for (auto& [mat, id] : ids) id = k++;
    for (std::uint32_t t : tris) s.cls.push_back(ids[material[t]]);
    s.classes = ids.size();
    return s;
  }
};

// A clustering of a cube: 6 clusters, two triangles together exactly when their normals agree.
void check_cube_faces(const indexed_mesh& cube, const result<mesh_clustering>& r) {
  REQUIRE(r.ok());
  check_invariants(cube, *r);
  REQUIRE(r->cluster_count == 6);
  const auto n = face_normals(cube);
  for (std::size_t a = 0; a < n.size(); ++a)
    for (std::size_t b = 0; b < n.size(); ++b) REQUIRE((r->cluster_of[a] == r->cluster_of[b]) == (n[a] == n[b]));
}

}  // namespace

TEST_CASE("a cube splits into its 6 faces under orientation", "[cluster]") {
  const auto cube = support::make_box({-1, -1, -1}, {1, 1, 1});
  const test::brute_tracer tracer(cube);
  for (std::uint32_t bins : {0u, 64u, 1024u}) {
    check_cube_faces(cube, cluster_mesh(cube, tracer, serial, orientation_channel{.threshold = 0.05, .bins = bins}));
  }
  // A finely tessellated cube too (planar faces of many triangles, one class each).
  indexed_mesh fine;
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {-1.0f, 1.0f}) {
      glm::mat4 t = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, side));
      if (side < 0) t = glm::rotate(t, glm::pi<float>(), glm::vec3(1, 0, 0));
      const glm::mat4 rot = axis == 0 ? glm::mat4(1.0f)
                            : axis == 1 ? glm::rotate(glm::mat4(1.0f), glm::half_pi<float>(), glm::vec3(1, 0, 0))
                                        : glm::rotate(glm::mat4(1.0f), glm::half_pi<float>(), glm::vec3(0, 1, 0));
      support::append(fine, support::make_plane(6, 6, 2.0f), rot * t);
    }
  auto r = cluster_mesh(fine, tracer, serial, orientation_channel{.threshold = 0.05});
  REQUIRE(r.ok());
  check_invariants(fine, *r);
  REQUIRE(r->cluster_count == 6);
  REQUIRE(r->channels[0].all_alike_sets == 0);
}

TEST_CASE("channels that trace nothing run with no_tracer", "[cluster]") {
  // The cube's faces from their normals (the reference), with no tracer in the call.
  const auto cube = support::make_box({-1, -1, -1}, {1, 1, 1});
  check_cube_faces(cube, cluster_mesh(cube, no_tracer{}, serial, orientation_channel{.threshold = 0.05}));
  // Orientation then stretch on a textured mesh: the tracer, never called, changes nothing.
  const auto sphere = support::make_uv_sphere(16, 12);
  const test::brute_tracer tracer(sphere);
  const orientation_channel o{.threshold = 0.02};
  const stretch_channel st{.threshold = 0.1};
  auto with = cluster_mesh(sphere, tracer, serial, o, st);
  auto without = cluster_mesh(sphere, no_tracer{}, serial, cluster_options{}, o, st);
  REQUIRE(with.ok());
  REQUIRE(without.ok());
  REQUIRE(without->channels[1].skipped == nullptr);
  REQUIRE(without->cluster_of == with->cluster_of);
}

TEST_CASE("a planar patch is one cluster with no work done", "[cluster]") {
  const auto plane = support::make_plane(10, 10, 1.0f);
  const test::brute_tracer tracer(plane);
  auto r = cluster_mesh(plane, tracer, serial, orientation_channel{.threshold = 0.01});
  REQUIRE(r.ok());
  REQUIRE(r->cluster_count == 1);
  REQUIRE(r->channels[0].all_alike_sets == 1);
  REQUIRE(r->channels[0].seeds == 0);
}

TEST_CASE("a UV sphere splits by latitude under stretch", "[cluster]") {
  const unsigned slices = 24, stacks = 16;
  auto sphere = support::make_uv_sphere(slices, stacks);
  // Weld the duplicated pole and seam vertices (texcoords stay per corner) so that the caps
  // and the seam are edge-connected.
  std::map<std::tuple<long, long, long>, unsigned> first;
  std::vector<unsigned> remap(sphere.positions.size());
  for (unsigned v = 0; v < sphere.positions.size(); ++v) {
    const glm::vec3 p = sphere.positions[v] * 1e4f;
    remap[v] = first.emplace(std::make_tuple(std::lround(p.x), std::lround(p.y), std::lround(p.z)), v).first->second;
  }
  for (auto& t : sphere.triangles) t = {remap[t.x], remap[t.y], remap[t.z]};
  const test::brute_tracer tracer(sphere);
  // Latitude row of each triangle (from its centroid) and its ring: the triangles of the row
  // with the same stretch (each quad's two triangles differ).
  const auto raw = texture_stretch(sphere);
  REQUIRE(raw.ok());
  std::vector<int> row(sphere.triangles.size());
  std::map<std::pair<int, long>, std::set<std::uint32_t>> rings;
  for (std::size_t t = 0; t < row.size(); ++t) {
    const double z = triangle_centroid(corners(sphere, t)).z;
    row[t] = static_cast<int>(std::acos(std::clamp(z, -1.0, 1.0)) / glm::pi<double>() * stacks);
    rings[{row[t], std::lround(std::log((*raw)[t]) * 1e4)}].insert(static_cast<std::uint32_t>(t));
  }
  REQUIRE(rings.size() <= 2 * stacks);
  for (std::uint32_t bins : {0u, 1024u}) {
    auto r = cluster_mesh(sphere, tracer, serial, cluster_options{.smooth_boundaries = false},
                          stretch_channel{.threshold = 0.02, .bins = bins});
    REQUIRE(r.ok());
    check_invariants(sphere, *r);
    REQUIRE(r->channels[0].skipped == nullptr);
    REQUIRE(r->cluster_count >= 3);
    // Stretch depends on latitude only: every cluster is a union of whole rings.
    for (const auto& [key, tris] : rings) {
      std::set<std::uint32_t> ids;
      for (std::uint32_t t : tris) ids.insert(r->cluster_of[t]);
      INFO("bins " << bins << " row " << key.first << " clusters " << r->cluster_count);
      REQUIRE(ids.size() == 1);
    }
    std::map<int, std::set<std::uint32_t>> clusters_of_row;
    for (std::size_t t = 0; t < row.size(); ++t) clusters_of_row[row[t]].insert(r->cluster_of[t]);
    // The polar caps and the equator are apart.
    const std::uint32_t north = *clusters_of_row[0].begin(), south = *clusters_of_row[int(stacks) - 1].begin(),
                        equator = *clusters_of_row[int(stacks) / 2].begin();
    REQUIRE(north != equator);
    REQUIRE(south != equator);
  }
}

TEST_CASE("an occluded region separates under visibility", "[cluster]") {
  indexed_mesh scene = support::make_plane(10, 10, 2.0f);
  const std::size_t floor_count = scene.triangles.size();
  support::append(scene, support::make_plane(1, 1, 0.8f), glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 0.08f)));
  const test::brute_tracer tracer(scene);
  auto r = cluster_mesh(scene, tracer, serial, visibility_channel{.threshold = 0.3, .viewpoints = 32});
  REQUIRE(r.ok());
  check_invariants(scene, *r);
  std::set<std::uint32_t> under, open;
  for (std::size_t t = 0; t < floor_count; ++t) {
    const auto c = triangle_centroid(corners(scene, t));
    if (std::abs(c.x) < 0.2 && std::abs(c.y) < 0.2) under.insert(r->cluster_of[t]);
    if (std::abs(c.x) > 0.8 || std::abs(c.y) > 0.8) open.insert(r->cluster_of[t]);
  }
  for (std::uint32_t k : under) REQUIRE(open.count(k) == 0);
}

TEST_CASE("Th = 0 gives one cluster per triangle, Th = 1 one cluster", "[cluster]") {
  const auto m = support::make_torus(16, 8, 1.0f, 0.4f);
  const test::brute_tracer tracer(m);
  auto zero = cluster_mesh(m, tracer, serial, orientation_channel{.threshold = 0.0});
  REQUIRE(zero.ok());
  REQUIRE(zero->cluster_count == m.triangles.size());
  auto one = cluster_mesh(m, tracer, serial, orientation_channel{.threshold = 1.0}, stretch_channel{.threshold = 1.0},
                          visibility_channel{.threshold = 1.0, .viewpoints = 4, .samples_per_side = 1});
  REQUIRE(one.ok());
  REQUIRE(one->cluster_count == 1);
  REQUIRE(one->channels[1].skipped != nullptr);  // no texcoords
}

TEST_CASE("tighter thresholds never give fewer clusters", "[cluster]") {
  const auto m = support::make_torus(24, 12, 1.0f, 0.4f);
  const test::brute_tracer tracer(m);
  for (std::uint32_t bins : {0u, 256u}) {
    std::uint32_t previous = std::numeric_limits<std::uint32_t>::max();
    for (double th : {0.001, 0.003, 0.01, 0.03, 0.1, 0.3}) {
      auto r = cluster_mesh(m, tracer, serial, cluster_options{.min_cluster_fraction = 0.0},
                            orientation_channel{.threshold = th, .bins = bins});
      REQUIRE(r.ok());
      check_invariants(m, *r);
      INFO("bins " << bins << " Th " << th << " clusters " << r->cluster_count);
      REQUIRE(r->cluster_count <= previous);
      previous = r->cluster_count;
    }
    REQUIRE(previous < 10);
  }
}

TEST_CASE("results do not depend on the executor or thread count", "[cluster]") {
  indexed_mesh scene = support::make_torus(20, 10, 1.0f, 0.4f);
  support::append(scene, support::make_icosphere(2, 0.3f));
  const test::brute_tracer tracer(scene);
  auto run = [&](auto&& exec) {
    auto r = cluster_mesh(scene, tracer, exec, visibility_channel{.threshold = 0.2, .viewpoints = 12},
                          orientation_channel{.threshold = 0.01});
    REQUIRE(r.ok());
    return r->cluster_of;
  };
  const auto reference = run(serial);
  for (unsigned workers : {1u, 2u, 8u}) REQUIRE(run(support::thread_pool_executor{workers}) == reference);
}

TEST_CASE("a user channel (material ids) clusters by material", "[cluster]") {
  const auto m = support::make_plane(8, 8, 1.0f);
  material_channel ch;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = triangle_centroid(corners(m, t));
    ch.material.push_back(c.x < 0.0 ? 0 : c.y < 0.0 ? 1 : 2);
  }
  const test::brute_tracer tracer(m);
  auto r = cluster_mesh(m, tracer, serial, ch);
  REQUIRE(r.ok());
  check_invariants(m, *r);
  REQUIRE(r->cluster_count == 3);
  for (std::size_t a = 0; a < m.triangles.size(); ++a)
    for (std::size_t b = 0; b < m.triangles.size(); ++b)
      REQUIRE((r->cluster_of[a] == r->cluster_of[b]) == (ch.material[a] == ch.material[b]));
  // Followed by orientation (a plane: all alike), nothing changes.
  auto r2 = cluster_mesh(m, tracer, serial, ch, orientation_channel{});
  REQUIRE(r2->cluster_of == r->cluster_of);
}

TEST_CASE("small clusters merge below a fraction of the whole mesh, in every channel", "[cluster]") {
  // 800 triangles; the first channel splits the plane into halves of 400, the second finds a
  // patch of 10 triangles in each half. With fraction 0.02 the floor is 16 triangles (of the
  // mesh), not 8 (of a half): the patches merge back, as when the second channel runs alone.
  const auto m = support::make_plane(20, 20, 20.0f);
  material_channel halves, patches;
  std::size_t patch_size = 0;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = triangle_centroid(corners(m, t));
    halves.material.push_back(c.x < 0.0f ? 0 : 1);
    const bool patch = std::fabs(c.x) > 2.0f && std::fabs(c.x) < 7.0f && c.y * c.x > 0.0f && std::fabs(c.y) > 2.0f &&
                       std::fabs(c.y) < 3.0f;
    patches.material.push_back(patch ? (c.x < 0.0f ? 2 : 3) : 0);
    patch_size += patch && c.x > 0.0f;
  }
  REQUIRE(patch_size == 10);
  const test::brute_tracer tracer(m);
  auto merged = cluster_mesh(m, tracer, serial, cluster_options{.min_cluster_fraction = 0.02}, halves, patches);
  REQUIRE(merged.ok());
  check_invariants(m, *merged);
  CHECK(merged->channels[1].merged == 2);
  CHECK(merged->cluster_count == 2);
  auto alone = cluster_mesh(m, tracer, serial, cluster_options{.min_cluster_fraction = 0.02}, patches);
  REQUIRE(alone.ok());
  CHECK(alone->cluster_count == 1);
  // Below a floor of 8 triangles (fraction 0.01 of the mesh) the patches stay in both orders.
  auto kept = cluster_mesh(m, tracer, serial, cluster_options{.min_cluster_fraction = 0.01}, halves, patches);
  REQUIRE(kept.ok());
  check_invariants(m, *kept);
  CHECK(kept->cluster_count == 4);
  CHECK(cluster_mesh(m, tracer, serial, cluster_options{.min_cluster_fraction = 0.01}, patches)->cluster_count == 3);
}

TEST_CASE("bad input returns a clear status", "[cluster]") {
  auto m = support::make_icosphere(1);
  const test::brute_tracer tracer(m);
  for (double th : {-0.1, 1.5, std::numeric_limits<double>::quiet_NaN()}) {
    auto r = cluster_mesh(m, tracer, serial, orientation_channel{}, orientation_channel{.threshold = th});
    REQUIRE_FALSE(r.ok());
    REQUIRE(r.error().code() == errc::bad_parameter);
    REQUIRE(r.error().element() == 1);
    REQUIRE(r.error().message().find("channel 1") != std::string::npos);
  }
  auto bad_fraction = cluster_mesh(m, tracer, serial, cluster_options{.min_cluster_fraction = 2.0}, orientation_channel{});
  REQUIRE(bad_fraction.error().code() == errc::bad_parameter);
  indexed_mesh nan_mesh = m;
  nan_mesh.positions[5].y = std::numeric_limits<float>::quiet_NaN();
  auto r = cluster_mesh(nan_mesh, tracer, serial, orientation_channel{});
  REQUIRE(r.error().code() == errc::non_finite);
  REQUIRE(r.error().element() == 5);
  REQUIRE(r.error().message().find("vertex 5") != std::string::npos);
  indexed_mesh empty;
  REQUIRE(cluster_mesh(empty, tracer, serial, orientation_channel{}).error().code() == errc::empty_input);
  indexed_mesh bad_index = m;
  bad_index.triangles[3].z = 9999;
  REQUIRE(cluster_mesh(bad_index, tracer, serial, orientation_channel{}).error().code() == errc::index_out_of_range);
  REQUIRE(cluster_mesh(m, tracer, serial, visibility_channel{.viewpoints = 0}).error().code() == errc::bad_parameter);
  auto st = make_orientation_state(face_normals(m), 0);
  REQUIRE(grow_regions(st, element_graph{}, {}, serial).error().code() == errc::bad_size);
}

TEST_CASE("keyframes: clusters of later keyframes refine earlier ones", "[cluster]") {
  // Keyframe 0: a flat plane (one cluster); keyframe 1: the same plane folded along x = 0.
  indexed_mesh m = support::make_plane(8, 8, 2.0f);
  m.keyframes.push_back(m.positions);
  auto folded = m.positions;
  for (auto& p : folded)
    if (p.x > 0.0f) p.z = p.x;
  m.keyframes.push_back(folded);
  const test::brute_tracer tracer(m);
  auto r = cluster_keyframes(m, [&](std::size_t) -> const test::brute_tracer& { return tracer; }, serial,
                             cluster_options{}, orientation_channel{.threshold = 0.05});
  REQUIRE(r.ok());
  check_invariants(m, *r);
  REQUIRE(r->cluster_count == 2);
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = triangle_centroid(corners(m, t));
    REQUIRE(r->cluster_of[t] == (c.x < 0.0 ? r->cluster_of[0] : 1 - r->cluster_of[0]));
  }
}

TEST_CASE("real meshes through Embree: three channels, coverage, connectivity, determinism", "[cluster][real]") {
  support::embree_device device;
  for (const char* name : {"bunny00", "armadillo", "fandisk"}) {
    auto m = support::load_mesh(support::cgal_mesh(name));
    REQUIRE(m.ok());
    support::embree_scene scene(device);
    REQUIRE(scene.add_mesh(*m).ok());
    REQUIRE(scene.commit().ok());
    INFO(name);
    auto run = [&](auto&& exec) {
      return cluster_mesh(*m, scene, exec, visibility_channel{.threshold = 0.48, .viewpoints = 16, .samples_per_side = 1},
                          orientation_channel{.threshold = 0.05, .bins = 256}, stretch_channel{});
    };
    const auto start = std::chrono::steady_clock::now();
    auto r = run(support::thread_pool_executor{2});
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    REQUIRE(r.ok());
    check_invariants(*m, *r);
    REQUIRE(r->channels[0].skipped == nullptr);
    REQUIRE(r->channels[2].skipped != nullptr);  // no texcoords
    // Stage times: every stage of a channel that ran took time, a skipped channel's sets took
    // none, and all of them fit in the call's wall time.
    double staged = 0;
    for (const channel_report& c : r->channels) {
      staged += c.prepare_seconds + c.init_seconds + c.growth_seconds + c.smoothing_seconds;
      const bool ran = c.skipped == nullptr;
      CHECK(c.prepare_seconds > 0);
      CHECK((c.init_seconds > 0) == ran);
      CHECK((c.growth_seconds > 0) == ran);
      CHECK((c.smoothing_seconds > 0) == ran);
    }
    CHECK(staged <= wall);
    REQUIRE(r->channels[0].clusters_after > 1);
    REQUIRE(r->cluster_count >= r->channels[0].clusters_after);
    REQUIRE(r->cluster_count < m->triangles.size() / 4);
    if (std::string(name) == "fandisk") REQUIRE(run(serial)->cluster_of == r->cluster_of);
  }
}

TEST_CASE("estimates change no result: Algorithm 1 with and without estimate()", "[cluster][real][estimate]") {
  support::embree_device device;
  auto m = support::load_mesh(support::cgal_mesh("fandisk"));
  REQUIRE(m.ok());
  support::embree_scene scene(device);
  REQUIRE(scene.add_mesh(*m).ok());
  REQUIRE(scene.commit().ok());
  auto topo = make_topology(*m);
  REQUIRE(topo.ok());
  auto vis = visibility_channel{.viewpoints = 32, .samples_per_side = 1}.prepare(*m, *topo, scene, serial);
  REQUIRE(vis.ok());
  {  // the estimate is what the clustering uses
    std::vector<std::uint32_t> all(m->triangles.size());
    std::iota(all.begin(), all.end(), 0u);
    auto st = vis->init(all);
    REQUIRE(st.ok());
    double worst = 0.0;
    for (std::uint32_t a = 0; a < all.size(); a += 37)
      for (std::uint32_t b = 0; b < all.size(); b += 101) worst = std::max(worst, std::abs(st->estimate(a, b) - st->divergence(a, b)));
    REQUIRE(worst <= st->estimate_error());
    REQUIRE(st->estimate_error() < 1e-4);
  }
  // Thresholds across the range (for visibility, orientation with stored binned rows).
  for (const auto& [tv, to] : {std::pair{0.1, 0.01}, {0.3, 0.02}, {0.48, 0.05}, {0.7, 0.2}}) {
    INFO("visibility Th " << tv << ", orientation Th " << to);
    prepared_visibility_channel pv = *vis;
    pv.threshold = tv;
    auto po = orientation_channel{.threshold = to, .bins = 256}.prepare(*m, *topo, scene, serial);
    REQUIRE(po.ok());
    std::size_t evaluated_with[2] = {}, evaluated_without[2] = {};
    auto with = cluster_mesh(*m, scene, serial, support::counting_channel<prepared_visibility_channel, true>{&pv, tv, &evaluated_with[0]},
                             support::counting_channel<prepared_orientation_channel, true>{&*po, to, &evaluated_with[1]});
    auto without = cluster_mesh(*m, scene, serial, support::counting_channel<prepared_visibility_channel, false>{&pv, tv, &evaluated_without[0]},
                                support::counting_channel<prepared_orientation_channel, false>{&*po, to, &evaluated_without[1]});
    REQUIRE(with.ok());
    REQUIRE(without.ok());
    REQUIRE(cluster_mesh(*m, scene, serial, pv, *po)->cluster_of == with->cluster_of);  // the wrapper changes nothing
    INFO("divergences with / without the estimate: visibility " << evaluated_with[0] << " / " << evaluated_without[0]
         << ", orientation " << evaluated_with[1] << " / " << evaluated_without[1]);
    CHECK(evaluated_with[0] * 10 < evaluated_without[0]);
    CHECK(evaluated_with[1] * 2 < evaluated_without[1]);
    REQUIRE(with->cluster_count > 2);
    REQUIRE(with->cluster_of == without->cluster_of);
    for (std::size_t c = 0; c < 2; ++c) {
      REQUIRE(with->channels[c].seeds == without->channels[c].seeds);
      REQUIRE(with->channels[c].sequential_seeds == without->channels[c].sequential_seeds);
      REQUIRE(with->channels[c].merged == without->channels[c].merged);
      REQUIRE(with->channels[c].smoothed_triangles == without->channels[c].smoothed_triangles);
    }
  }
}

TEST_CASE("boundary smoothing straightens a jagged boundary and never touches a third cluster", "[cluster][smoothing]") {
  const auto m = support::make_plane(12, 12, 2.0f);
  const std::size_t n = m.triangles.size();
  std::vector<std::uint32_t> all(n), scratch(n, invalid_id);
  std::iota(all.begin(), all.end(), 0u);
  auto topo = make_topology(m);
  REQUIRE(topo.ok());
  const element_graph g = subset_graph(*topo, all, scratch);
  // A 1-D feature (the centroid's x) as a stretch-like channel: JS grows with |Δx|.
  std::vector<double> x(n);
  std::vector<glm::dvec3> c(n);
  for (std::size_t t = 0; t < n; ++t) x[t] = (c[t] = triangle_centroid(corners(m, t))).x;
  const auto s = make_stretch_state(x, 0);
  // A: x < 0 plus teeth into x < 0.45 on every other row; C: a corner; B: the rest.
  region_growing_result r;
  r.cluster_of.resize(n);
  for (std::size_t t = 0; t < n; ++t) {
    const bool tooth = static_cast<int>((c[t].y + 1.0) * 6.0) % 2 == 0 && c[t].x < 0.45;
    r.cluster_of[t] = (c[t].x > 0.65 && c[t].y > 0.65) ? 2u : (c[t].x < 0.0 || tooth) ? 0u : 1u;
  }
  auto nearest = [&](double px, double py) {
    std::uint32_t best = 0;
    for (std::uint32_t t = 0; t < n; ++t)
      if (std::hypot(c[t].x - px, c[t].y - py) < std::hypot(c[best].x - px, c[best].y - py)) best = t;
    return best;
  };
  r.seeds = {nearest(-0.9, 0.0), nearest(0.3, -0.5), nearest(0.9, 0.9)};
  const auto before = r.cluster_of;
  auto boundary_length = [&](const std::vector<std::uint32_t>& l) {
    std::size_t e = 0;
    for (std::uint32_t t = 0; t < n; ++t)
      for (std::uint32_t u : g.neighbours_of(t)) e += (l[t] == 0 && l[u] == 1) ? 1 : 0;
    return e;
  };
  const std::uint32_t moved = smooth_boundaries(s, g, m, all, 0.5, r);
  REQUIRE(moved > 0);
  REQUIRE(boundary_length(r.cluster_of) < boundary_length(before));
  for (std::size_t t = 0; t < n; ++t) REQUIRE((before[t] == 2) == (r.cluster_of[t] == 2));
  mesh_clustering mc{r.cluster_of, 3, {}};
  check_invariants(m, mc);
}

TEST_CASE("boundary smoothing's key sort orders like std::sort at every size and key shape", "[cluster][smoothing]") {
  std::mt19937_64 rng(5);
  std::vector<std::uint64_t> scratch;
  for (std::size_t n : {0u, 1u, 2u, 255u, 256u, 257u, 1000u, 4097u}) {
    for (int shape = 0; shape < 4; ++shape) {
      std::vector<std::uint64_t> keys(n);
      for (auto& k : keys) {
        const std::uint64_t r = rng();
        k = shape == 0 ? r                                                     // every byte varies
            : shape == 1 ? ((r & 0xffff) << 32) | (r >> 20 & 0xffff)           // edge keys of a small mesh
            : shape == 2 ? 0x0102030405060708ull                               // all equal
                         : (r & 1) << 63 | 0x00ff00ff00000000ull | (r >> 8 & 0xff);  // top bit and one low byte
      }
      auto expected = keys;
      std::sort(expected.begin(), expected.end());
      infolerp::detail::sort_keys(keys, scratch);
      INFO("n " << n << ", shape " << shape);
      CHECK(keys == expected);
    }
  }
}
