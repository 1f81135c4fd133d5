// Cluster-local 16-bit indices (salient-clustering paper §IV.B–C): every 16-bit index of a part's
// range, read through the part's vertex list, gives back the global vertex frame() wrote for
// that cluster, checked triangle by triangle against the 32-bit output.
#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <random>
#include <vector>
#include <catch2/catch.hpp>
#include "infolerp/lod/cluster_local_indices.hpp"
#include "infolerp/lod/view_dependent_lod.hpp"
#include "infolerp/lod/weighting_map.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"

using namespace infolerp;

namespace {

using triangle = std::array<std::uint32_t, 3>;

// A triangle with its smallest index first, keeping its winding.
triangle rotated(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  if (b < a && b < c) return {b, c, a};
  if (c < a && c < b) return {c, a, b};
  return {a, b, c};
}

// Brute force: each part's indices are local (< its vertex count) and map back through its
// vertex list; the parts of a cluster hold exactly the cluster's triangles of the 32-bit buffer,
// with winding; a cluster of one part keeps their order.
void check_frame(const local_index_table& t, std::span<const std::uint32_t> in, std::span<const index_range> ranges,
                 std::span<const std::uint16_t> out, std::span<const index_range> parts, std::size_t written) {
  std::size_t total = 0;
  for (const index_range& r : ranges) total += r.count;
  REQUIRE(written == total);
  for (std::uint32_t c = 0; c + 1 < t.part_offsets.size(); ++c) {
    std::vector<triangle> want, got;
    for (std::size_t k = ranges[c].first; k < ranges[c].first + ranges[c].count; k += 3)
      want.push_back(rotated(in[k], in[k + 1], in[k + 2]));
    std::vector<std::uint32_t> sequence;
    bool local_ok = true;
    for (std::uint32_t p = t.part_offsets[c]; p < t.part_offsets[c + 1]; ++p) {
      REQUIRE(t.part_cluster[p] == c);
      REQUIRE(t.vertex_count(p) <= max_local_vertices);
      REQUIRE(std::size_t{parts[p].first} + parts[p].count <= written);
      for (std::size_t k = parts[p].first; k < parts[p].first + parts[p].count; k += 3) {
        std::uint32_t g[3];
        for (std::size_t j = 0; j < 3; ++j) {
          local_ok = local_ok && out[k + j] < t.vertex_count(p);
          g[j] = t.vertices[t.vertex_offsets[p] + out[k + j]];
          sequence.push_back(g[j]);
        }
        got.push_back(rotated(g[0], g[1], g[2]));
      }
    }
    INFO("cluster " << c << " of " << t.part_offsets[c + 1] - t.part_offsets[c] << " parts");
    CHECK(local_ok);
    if (t.part_offsets[c + 1] - t.part_offsets[c] == 1)
      CHECK(std::equal(sequence.begin(), sequence.end(), in.begin() + ranges[c].first,
                       in.begin() + ranges[c].first + ranges[c].count));
    std::sort(want.begin(), want.end());
    std::sort(got.begin(), got.end());
    const bool same_triangles = got == want;  // a bool: Catch would print both vectors
    CHECK(same_triangles);
  }
}

// Every part of the table lists each vertex once, ascending, and the holder lists agree.
void check_table(const local_index_table& t, std::size_t vertex_count) {
  REQUIRE(t.holder_offsets.size() == vertex_count + 1);
  std::size_t holders = 0;
  for (std::uint32_t p = 0; p < t.part_count(); ++p) {
    CHECK(t.vertex_count(p) <= max_local_vertices);
    const auto b = t.vertices.begin() + t.vertex_offsets[p], e = t.vertices.begin() + t.vertex_offsets[p + 1];
    CHECK(std::adjacent_find(b, e, [](std::uint32_t x, std::uint32_t y) { return x >= y; }) == e);
    holders += t.vertex_count(p);
  }
  CHECK(holders == t.holder_part.size());
  bool ok = true, first_ok = t.first_holder.size() == vertex_count;
  for (std::uint32_t v = 0; v < vertex_count; ++v) {
    for (std::uint32_t a = t.holder_offsets[v]; a < t.holder_offsets[v + 1]; ++a)
      ok = ok && t.vertices[t.vertex_offsets[t.holder_part[a]] + t.holder_local[a]] == v;
    const bool held = t.holder_offsets[v] < t.holder_offsets[v + 1];
    first_ok = first_ok && (held ? t.first_holder[v].part == t.holder_part[t.holder_offsets[v]] &&
                                       t.first_holder[v].local == t.holder_local[t.holder_offsets[v]]
                                 : t.first_holder[v].part == invalid_id);
  }
  CHECK(ok);
  CHECK(first_ok);
}

struct lod_setup {
  indexed_mesh mesh;
  std::vector<std::uint32_t> cluster;
  std::uint32_t count = 0;
  std::vector<double> weights;  // the weighting map, for hierarchies of other options
  contraction_hierarchy h;      // the default hierarchy (one global order)
  cluster_table table;
};

lod_setup real_mesh(const char* name) {
  lod_setup s;
  auto m = support::load_mesh(support::cgal_mesh(name));
  REQUIRE(m.ok());
  s.mesh = std::move(*m);
  auto sal = compute_saliency(s.mesh);
  REQUIRE(sal.ok());
  auto clusters = salient_clustering(s.mesh, sal->saliency, {.clusters = 10});
  REQUIRE(clusters.ok());
  s.cluster = clusters->cluster, s.count = clusters->count;
  auto wm = weighting_map(s.mesh, sal->saliency, s.cluster, s.count);
  REQUIRE(wm.ok());
  s.weights = std::move(*wm);
  auto h = make_contraction_hierarchy(s.mesh, s.weights, s.cluster, s.count);
  REQUIRE(h.ok());
  s.h = std::move(*h);
  auto table = compute_cluster_attributes(s.mesh, sal->saliency, s.cluster, s.count);
  REQUIRE(table.ok());
  s.table = std::move(*table);
  return s;
}

lod_camera look_at(const glm::dvec3& eye, const glm::dvec3& at) { return {eye, at - eye, {0.0, 1.0, 0.0}, 0.8, 512, 512}; }

// Cameras around and inside a box: one far, one close with part of the mesh behind it, one at
// the centre (inside the mesh and inside the clusters' bounding spheres), then random ones, every
// third of them inside the box. One draw per statement: argument order differs between compilers.
std::vector<lod_camera> cameras_for(const bounding_box& box, std::size_t random_count) {
  const glm::dvec3 c = box.center(), half = 0.5 * (box.hi - box.lo);
  const double d = box.diagonal();
  std::vector<lod_camera> cams = {look_at(c + glm::dvec3(0.3, 0.2, 2.0) * d, c),
                                  look_at(c + glm::dvec3(0.0, 0.1, 0.3) * d, c + glm::dvec3(0.2, 0.0, -1.0) * d),
                                  look_at(c, c + glm::dvec3(1.0, 0.2, 0.1))};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  while (cams.size() < 3 + random_count) {
    glm::dvec3 eye, at;
    for (int a = 0; a < 3; ++a) eye[a] = unit(rng);
    for (int a = 0; a < 3; ++a) at[a] = unit(rng);
    eye = cams.size() % 3 == 0 ? c + eye * half : c + 1.5 * d * eye;
    const lod_camera cam = look_at(eye, c + at * half);
    if (glm::length(glm::cross(glm::normalize(cam.forward), cam.up)) > 1e-2) cams.push_back(cam);
  }
  return cams;
}

// Converts and checks one frame's output.
void check_localized(const local_index_table& t, std::span<const std::uint32_t> in, std::span<const index_range> ranges,
                     std::span<std::uint16_t> out, std::span<index_range> parts) {
  auto n = localize_indices(t, in, ranges, out, parts);
  if (!n.ok()) FAIL(n.error().message());
  check_frame(t, in, ranges, out, parts, *n);
}

// frame() under both selections (screen_error with its global-prefix fallback, paper) for each
// camera at several fractions of the hierarchy's contractions, each converted and checked.
void check_frames(const contraction_hierarchy& h, const cluster_table& table, const local_index_table& t,
                  std::span<const lod_camera> cams) {
  std::vector<std::uint32_t> in(contracted_index_bound(h));
  std::vector<index_range> ranges(h.cluster_count), parts(t.part_count());
  std::vector<std::uint16_t> out(in.size());
  std::size_t per_view = 0, prefix = 0;  // screen_error frames whose stop points differ / are one prefix
  for (lod_selection sel : {lod_selection::screen_error, lod_selection::paper}) {
    auto lod = view_dependent_lod::create(h, table, {.selection = sel, .view = {}});
    if (sel == lod_selection::paper && h.local_contractions == 0) {  // paper needs the cluster-local phase
      CHECK(lod.error().code() == errc::bad_parameter);
      continue;
    }
    REQUIRE(lod.ok());
    for (std::size_t k = 0; k < cams.size(); ++k) {
      const double f = std::array{0.0, 0.3, 0.65, 0.9, 0.95, 0.99, 1.0}[k % 7];
      const auto budget = static_cast<std::uint64_t>((1.0 - f) * static_cast<double>(h.triangle_count()));
      auto st = lod->frame(cams[k], budget, in, ranges);
      if (!st.ok()) FAIL(st.error().message());
      INFO("selection " << static_cast<int>(sel) << ", camera " << k << ", budget " << budget << " of "
                        << h.triangle_count() << " triangles");
      check_localized(t, in, ranges, out, parts);
      const auto stops = lod->stop_points();
      if (sel == lod_selection::screen_error)
        ++(std::adjacent_find(stops.begin(), stops.end(), std::not_equal_to<>()) == stops.end() ? prefix : per_view);
    }
  }
  INFO(per_view << " per-view and " << prefix << " single-prefix screen_error frames");
  CHECK(per_view > 0);
}

// Any dependency-closed stop points, beyond those a selection makes today: random stop points
// closed by neighbour matching, and global prefixes (the fallback of the default selection).
void check_closed_stop_points(const contraction_hierarchy& h, const local_index_table& t, int draws) {
  contraction_workspace w = make_contraction_workspace(h);
  std::vector<std::uint32_t> in(contracted_index_bound(h)), stop(h.cluster_count);
  std::vector<index_range> ranges(h.cluster_count), parts(t.part_count());
  std::vector<std::uint16_t> out(in.size());
  const neighbour_table table = make_neighbour_table(h);
  std::mt19937 rng(5);
  std::uniform_int_distribution<std::uint32_t> at(0, static_cast<std::uint32_t>(h.contraction_count()));
  for (int k = 0; k < draws; ++k) {
    if (k % 2 == 0) {
      for (std::uint32_t& s : stop) s = at(rng);
      match_neighbours(table, stop);
    } else {
      std::fill(stop.begin(), stop.end(), at(rng));
    }
    INFO("draw " << k);
    REQUIRE(contract_indices(h, stop, w, in, ranges).ok());
    check_localized(t, in, ranges, out, parts);
  }
}

}  // namespace

TEST_CASE("16-bit local indices map back to frame()'s vertices on bunny00 for any camera and selection", "[lod][real]") {
  const lod_setup s = real_mesh("bunny00");
  const std::vector<lod_camera> cams = cameras_for(mesh_bounds(s.mesh), 11);
  auto local = make_contraction_hierarchy(s.mesh, s.weights, s.cluster, s.count, {.cluster_local_first = true});
  REQUIRE(local.ok());
  for (const contraction_hierarchy* h : std::array<const contraction_hierarchy*, 2>{&s.h, &*local}) {
    INFO((h == &s.h ? "one global order" : "cluster-local phase first"));
    auto whole = make_local_index_table(s.mesh, *h);  // every cluster fits: one part each
    REQUIRE(whole.ok());
    CHECK(whole->part_count() == h->cluster_count);
    check_table(*whole, s.mesh.vertex_count());
    check_frames(*h, s.table, *whole, cams);
    // A small limit splits every cluster into many parts: the counting sort and the part choice.
    auto small = make_local_index_table(s.mesh, *h, 1500);
    REQUIRE(small.ok());
    CHECK(small->part_count() > 3 * h->cluster_count);
    for (std::uint32_t p = 0; p < small->part_count(); ++p) REQUIRE(small->vertex_count(p) <= 1500);
    check_table(*small, s.mesh.vertex_count());
    check_frames(*h, s.table, *small, cams);
    check_closed_stop_points(*h, *small, 8);
  }
}

TEST_CASE("16-bit local indices: a cluster of more than 65,536 vertices is split", "[lod]") {
  lod_setup s;
  s.mesh = support::make_plane(300, 300, 1.0f);  // 90,601 vertices
  for (auto& p : s.mesh.positions) p.z = 0.05f * std::sin(9.0f * p.x) * std::cos(7.0f * p.y);
  s.count = 2;  // cluster 1: a strip of a few triangles, so the big one has a neighbour
  s.cluster.resize(s.mesh.triangle_count());
  for (std::size_t t = 0; t < s.cluster.size(); ++t) s.cluster[t] = t < 600 ? 1u : 0u;
  std::vector<double> sal(s.mesh.vertex_count(), 1.0), w(3 * s.mesh.triangle_count(), 1.0);
  auto h = make_contraction_hierarchy(s.mesh, w, s.cluster, s.count);
  REQUIRE(h.ok());
  s.h = std::move(*h);
  auto table = compute_cluster_attributes(s.mesh, sal, s.cluster, s.count);
  REQUIRE(table.ok());
  s.table = std::move(*table);
  auto t = make_local_index_table(s.mesh, s.h);
  REQUIRE(t.ok());
  CHECK(t->part_offsets[1] - t->part_offsets[0] >= 2);
  CHECK(t->part_offsets[2] - t->part_offsets[1] == 1);
  check_table(*t, s.mesh.vertex_count());
  check_frames(s.h, s.table, *t, cameras_for(mesh_bounds(s.mesh), 3));
}

TEST_CASE("16-bit local indices: cameras inside a closed mesh and around it", "[lod]") {
  const indexed_mesh m = support::make_icosphere(4);
  std::vector<std::uint32_t> cl(m.triangle_count());
  for (std::size_t t = 0; t < cl.size(); ++t) {  // octants
    const glm::vec3 x = m.positions[m.triangles[t].x];
    cl[t] = (x.x > 0.0f ? 1u : 0u) | (x.y > 0.0f ? 2u : 0u) | (x.z > 0.0f ? 4u : 0u);
  }
  std::vector<double> sal(m.vertex_count()), w(3 * m.triangle_count(), 1.0);
  for (std::size_t v = 0; v < sal.size(); ++v) sal[v] = 1.0 + 0.5 * std::sin(3.0 * m.positions[v].x);
  auto h = make_contraction_hierarchy(m, w, cl, 8);
  REQUIRE(h.ok());
  auto table = compute_cluster_attributes(m, sal, cl, 8);
  REQUIRE(table.ok());
  auto t = make_local_index_table(m, *h, 200);  // several parts per cluster
  REQUIRE(t.ok());
  CHECK(t->part_count() > 2 * 8);
  // cameras_for's third camera sits at the box's centre, the unit sphere's: inside the mesh and
  // inside every cluster's bounding sphere; some of its random cameras are inside the mesh too.
  check_frames(*h, *table, *t, cameras_for(mesh_bounds(m), 12));
}

TEST_CASE("16-bit local indices: bad input gets a clear status", "[lod]") {
  const indexed_mesh m = support::make_icosphere(3);
  std::vector<std::uint32_t> cl(m.triangle_count());
  for (std::size_t t = 0; t < cl.size(); ++t) cl[t] = m.positions[m.triangles[t].x].z > 0.0f ? 1u : 0u;
  std::vector<double> sal(m.vertex_count(), 1.0), w(3 * m.triangle_count(), 1.0);
  auto h = make_contraction_hierarchy(m, w, cl, 2);
  REQUIRE(h.ok());
  CHECK(make_local_index_table(m, *h, 2).error().code() == errc::bad_parameter);
  CHECK(make_local_index_table(m, *h, max_local_vertices + 1).error().code() == errc::bad_parameter);
  const indexed_mesh other = support::make_icosphere(2);
  CHECK(make_local_index_table(other, *h).error().code() == errc::bad_size);
  auto t = make_local_index_table(m, *h, 100);
  REQUIRE(t.ok());
  auto table = compute_cluster_attributes(m, sal, cl, 2);
  REQUIRE(table.ok());
  auto lod = view_dependent_lod::create(*h, *table, {.view = {}, .keep_hidden = true});  // both clusters drawn
  REQUIRE(lod.ok());
  std::vector<std::uint32_t> in(contracted_index_bound(*h));
  std::vector<index_range> ranges(2), parts(t->part_count());
  std::vector<std::uint16_t> out(in.size());
  REQUIRE(lod->frame(look_at({0.0, 0.5, 4.0}, {0.0, 0.0, 0.0}), h->triangle_count() / 2, in, ranges).ok());
  REQUIRE(localize_indices(*t, in, ranges, out, parts).ok());

  std::vector<index_range> one_range(1), few_parts(1);
  CHECK(localize_indices(*t, in, one_range, out, parts).error().code() == errc::bad_size);
  CHECK(localize_indices(*t, in, ranges, out, few_parts).error().code() == errc::bad_size);
  std::vector<std::uint16_t> short_out(ranges[0].count + ranges[1].count - 1);
  CHECK(localize_indices(*t, in, ranges, short_out, parts).error().code() == errc::bad_size);
  std::vector<index_range> ragged = ranges;
  ragged[1].count -= 1;
  auto e = localize_indices(*t, in, ragged, out, parts);
  CHECK(e.error().code() == errc::bad_index_count);
  CHECK(e.error().element() == 1);
  ragged = ranges;
  ragged[1].first = static_cast<std::uint32_t>(in.size());
  CHECK(localize_indices(*t, in, ragged, out, parts).error().code() == errc::bad_index_count);
  // A vertex that no part of cluster 0 holds (the south pole region's vertex in cluster 0's range).
  std::vector<std::uint32_t> foreign = in;
  std::uint32_t stranger = invalid_id;
  for (std::uint32_t v = 0; v < m.vertex_count() && stranger == invalid_id; ++v) {
    bool held = false;
    for (std::uint32_t a = t->holder_offsets[v]; a < t->holder_offsets[v + 1]; ++a)
      held = held || t->part_cluster[t->holder_part[a]] == 0;
    if (!held) stranger = v;
  }
  REQUIRE(stranger != invalid_id);
  REQUIRE(ranges[0].count > 0);
  foreign[ranges[0].first + 4] = stranger;
  e = localize_indices(*t, foreign, ranges, out, parts);
  CHECK(e.error().code() == errc::index_out_of_range);
  CHECK(e.error().element() == ranges[0].first + 3);
  foreign[ranges[0].first + 4] = static_cast<std::uint32_t>(m.vertex_count());
  CHECK(localize_indices(*t, foreign, ranges, out, parts).error().code() == errc::index_out_of_range);
}
