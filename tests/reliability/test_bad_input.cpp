// The bad-input matrix: classes of bad input against every public entry point that
// takes user data. Each cell says what must happen: a status with a given code whose message
// names the problem (a substring), or success with finite, well-formed output. Nothing may
// crash (CI runs this under ASan + UBSan) and nothing may be half-written: where an entry point
// writes into caller-owned memory or changes an object's state, the test poisons it first and
// compares it after the error.
//
// Set INFOLERP_PRINT_MATRIX=1 to print the matrix (class × entry point, pass/fail).
//
// Not covered here: unchecked kernels whose preconditions are documented next to them
// (js_divergence, js_channel, entropy/mutual_information kernels, corners, face_normals,
// face_areas, mesh_bounds, connected_components); nld() is total (defined for NaN inputs) and
// is checked below.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/info/entropy.hpp"
#include "infolerp/info/jensen_shannon.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/topology.hpp"
#include "infolerp/mesh/validate.hpp"
#include "infolerp/refine/criteria.hpp"
#include "infolerp/refine/nld.hpp"
#include "infolerp/refine/progressive_driver.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"
#include "infolerp/saliency/cluster_importance.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"
#include "infolerp/upsample/pass_controller.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "reliability/reliability_support.hpp"
#include "support/brute_force_tracer.hpp"
#include "support/procedural.hpp"

namespace {

using infolerp::errc;
using infolerp::indexed_mesh;
using infolerp::status;

constexpr double nan_d = std::numeric_limits<double>::quiet_NaN();
constexpr float nan_f = std::numeric_limits<float>::quiet_NaN();
constexpr float inf_f = std::numeric_limits<float>::infinity();

// What a cell expects: code ok = success (the entry point then checks its own output).
struct expect {
  errc code = errc::ok;
  const char* text = "";
};
constexpr expect ok{};

// Outcome of one cell, for the CHECKs and the printed matrix.
struct cell {
  std::string cls, entry;
  bool pass;
};
std::vector<cell>& matrix() {
  static std::vector<cell> cells;
  return cells;
}

// Checks an entry point's status against the expectation; records the cell.
void check_cell(const std::string& cls, const std::string& entry, const status& got, const expect& want,
                bool output_ok = true) {
  INFO("class: " << cls << "; entry point: " << entry << "; got " << infolerp::to_string(got.code()) << " '"
                 << got.message() << "'");
  const bool code_ok = got.code() == want.code;
  const bool text_ok = want.code == errc::ok || got.message().find(want.text) != std::string::npos;
  CHECK(code_ok);
  CHECK(text_ok);
  CHECK(output_ok);
  matrix().push_back({cls, entry, code_ok && text_ok && output_ok});
}
template <class T>
status status_of(const infolerp::result<T>& r) {
  return r.ok() ? status{} : r.error();
}

bool all_finite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

// ---- mesh classes -------------------------------------------------------------------------

// A small closed mesh (42 vertices, 80 triangles) that the bad classes are made from.
indexed_mesh base() { return infolerp::support::make_icosphere(1); }
std::uint32_t add_vertex(indexed_mesh& m, glm::vec3 p) {
  m.positions.push_back(p);
  return static_cast<std::uint32_t>(m.positions.size() - 1);
}

// Mesh entry points, in the order of mesh_class::want.
enum mesh_entry : std::size_t {
  e_validate, e_topology, e_curvature, e_saliency, e_salient_clustering,
  e_cluster_attributes, e_cluster_localized, e_subdivision_build, e_cluster_mesh, mesh_entry_count
};
const char* const mesh_entry_names[mesh_entry_count] = {
    "validate_mesh", "make_topology", "mean_curvature", "compute_saliency",
    "salient_clustering", "compute_cluster_attributes", "cluster_localized_saliency", "subdivision_mesh::create",
    "cluster_mesh(visibility+orientation+stretch)"};

struct mesh_class {
  const char* name;
  indexed_mesh mesh;
  expect want[mesh_entry_count];
};

// Expectations shorthand: the same for every entry point that reads positions (curvature,
// saliency, clustering, attributes, localised saliency), with validate, topology and the
// subdivision build given separately. cluster_mesh accepts degenerate and non-manifold input
// (its rows are defined there), so it expects what reads_positions expects.
mesh_class make_class(const char* name, indexed_mesh m, expect validate, expect topology, expect reads_positions,
                      expect saliency, expect build) {
  return {name, std::move(m),
          {validate, topology, reads_positions, saliency, reads_positions, reads_positions, reads_positions,
           build, reads_positions}};
}

std::vector<mesh_class> mesh_classes() {
  std::vector<mesh_class> out;
  const expect empty{errc::empty_input, "no triangles"}, empty_mesh{errc::empty_input, "empty mesh"};
  out.push_back(make_class("empty mesh", indexed_mesh{}, empty_mesh, ok, empty, empty, empty_mesh));
  {
    indexed_mesh m = base();
    m.triangles.clear();
    out.push_back(make_class("vertices, no triangles", m, empty_mesh, ok, empty, empty, empty_mesh));
  }
  {
    indexed_mesh m = base();
    m.triangles[5].y = static_cast<std::uint32_t>(m.positions.size() + 3);
    const expect e{errc::index_out_of_range, "triangle 5 corner 1"};
    out.push_back(make_class("index out of range", m, e, e, e, e, e));
  }
  {
    indexed_mesh m = base();
    m.triangles[9].z = infolerp::invalid_id;
    const expect e{errc::index_out_of_range, "triangle 9 corner 2"};
    out.push_back(make_class("index 0xffffffff", m, e, e, e, e, e));
  }
  for (const auto& [name, value] : {std::pair{"NaN position", nan_f}, std::pair{"+Inf position", inf_f},
                                    std::pair{"-Inf position", -inf_f}}) {
    indexed_mesh m = base();
    m.positions[7].y = value;
    const expect e{errc::non_finite, "vertex 7"};
    out.push_back(make_class(name, m, e, ok, e, e, e));
  }
  {
    indexed_mesh m = base();
    m.triangles[4].y = m.triangles[4].x;
    out.push_back(make_class("repeated index", m, {errc::degenerate_triangle, "triangle 4: repeated"}, ok, ok, ok,
                             {errc::degenerate_triangle, "triangle 4: repeated"}));
  }
  {
    indexed_mesh m = base();
    const auto a = add_vertex(m, {0, 0, 0}), b = add_vertex(m, {1, 1, 1}), c = add_vertex(m, {2, 2, 2});
    m.triangles.push_back({a, b, c});
    out.push_back(make_class("zero-area triangle", m, {errc::degenerate_triangle, "triangle 80: zero area"}, ok, ok, ok,
                             {errc::degenerate_triangle, "triangle 80: zero area"}));
  }
  {
    indexed_mesh m = base();  // angles ~1e-6 rad at two corners, ~180 degrees at the third
    const auto a = add_vertex(m, {3, 0, 0}), b = add_vertex(m, {4, 0, 0}), c = add_vertex(m, {3.5f, 1e-6f, 0});
    m.triangles.push_back({a, b, c});
    out.push_back(make_class("sliver triangle", m, ok, ok, ok, ok, ok));
  }
  {
    indexed_mesh m = base();  // vertex 0 duplicated, one corner re-pointed: a seam
    const auto d = add_vertex(m, m.positions[0]);
    for (auto& t : m.triangles)
      if (t.x == 0) {
        t.x = d;
        break;
      }
    out.push_back(make_class("duplicate vertex", m, ok, ok, ok, ok, ok));
  }
  {
    indexed_mesh m = base();
    add_vertex(m, {5, 5, 5});
    out.push_back(make_class("isolated vertex", m, ok, ok, ok, ok, ok));
  }
  {
    indexed_mesh m = base();
    add_vertex(m, {nan_f, 0, 0});
    out.push_back(make_class("isolated NaN vertex", m, ok, ok, ok, ok, ok));
  }
  {
    indexed_mesh m = base();
    const auto d = add_vertex(m, {0.1f, 0.2f, 2.0f});
    m.triangles.push_back({m.triangles[0].x, m.triangles[0].y, d});
    out.push_back(make_class("non-manifold edge", m, {errc::non_manifold_edge, "triangle 80"}, ok, ok, ok,
                             {errc::non_manifold_edge, "triangle 80"}));
  }
  {
    indexed_mesh m;  // two triangles sharing only vertex 0
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0.5f}, {0, -1, 0.5f}};
    m.triangles = {{0, 1, 2}, {0, 3, 4}};
    out.push_back(make_class("non-manifold vertex (bowtie)", m, ok, ok, ok, ok, ok));
  }
  {
    indexed_mesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    m.triangles = {{0, 1, 2}};
    out.push_back(make_class("single triangle", m, ok, ok, ok, ok, ok));
  }
  {
    indexed_mesh m;
    m.positions = {{1, 2, 3}, {1, 2, 3}, {1, 2, 3}};
    m.triangles = {{0, 1, 2}};
    out.push_back(make_class("all vertices coincide", m, {errc::degenerate_triangle, "triangle 0: zero area"}, ok, ok,
                             {errc::degenerate_triangle, "zero diagonal"},
                             {errc::degenerate_triangle, "triangle 0: zero area"}));
  }
  {
    indexed_mesh m = base();
    std::swap(m.triangles[3].x, m.triangles[3].y);
    out.push_back(make_class("inconsistent winding", m, ok, ok, ok, ok, ok));
  }
  {
    indexed_mesh m = base();
    infolerp::support::append(m, infolerp::support::make_box({3, 3, 3}, {4, 4, 4}));
    out.push_back(make_class("two components", m, ok, ok, ok, ok, ok));
  }
  return out;
}

// Runs mesh entry point e on m; returns its status and whether its output is well-formed.
std::pair<status, bool> run_mesh_entry(mesh_entry e, const indexed_mesh& m) {
  const std::size_t nv = m.positions.size(), nt = m.triangles.size();
  const std::vector<double> saliency(nv, 1.0);
  const std::vector<std::uint32_t> one_cluster(nt, 0);
  switch (e) {
    case e_validate: return {infolerp::validate_mesh(m), true};
    case e_topology: {
      auto r = infolerp::make_topology(m);
      return {status_of(r), !r.ok() || r->triangle_count() == nt};
    }
    case e_curvature: {
      auto r = infolerp::mean_curvature(m);
      return {status_of(r), !r.ok() || (r->size() == nv && all_finite(*r))};
    }
    case e_saliency: {
      auto r = infolerp::compute_saliency(m);
      return {status_of(r), !r.ok() || (r->saliency.size() == nv && all_finite(r->saliency) && all_finite(r->curvature))};
    }
    case e_salient_clustering: {
      auto r = infolerp::salient_clustering(m, saliency, {.clusters = 1});
      bool good = true;
      if (r.ok())
        for (auto c : r->cluster) good = good && c < r->count;
      return {status_of(r), good && (!r.ok() || r->cluster.size() == nt)};
    }
    case e_cluster_attributes: {
      auto r = infolerp::compute_cluster_attributes(m, saliency, one_cluster, 1);
      bool good = true;
      if (r.ok()) {
        const auto& c = r->clusters[0];
        good = std::isfinite(c.area) && std::isfinite(c.radius) && std::isfinite(c.peak_normal_deviation) &&
               std::isfinite(c.centroid.x) && c.faces == nt;
      }
      return {status_of(r), good};
    }
    case e_cluster_localized: {
      auto r = infolerp::cluster_localized_saliency(m, saliency, one_cluster, 1);
      return {status_of(r), !r.ok() || (r->size() == 3 * nt && all_finite(*r))};
    }
    case e_cluster_mesh: {
      const infolerp::support::brute_force_tracer tracer{&m};  // only called once the mesh is validated
      auto r = infolerp::cluster_mesh(m, tracer, infolerp::serial_executor{},
                                      infolerp::visibility_channel{.threshold = 0.3, .viewpoints = 6, .samples_per_side = 1},
                                      infolerp::orientation_channel{.threshold = 0.05},
                                      infolerp::stretch_channel{.threshold = 0.1});
      bool good = true;
      if (r.ok()) {
        good = r->cluster_of.size() == nt && r->channels.size() == 3 && r->channels[2].skipped != nullptr;
        for (auto c : r->cluster_of) good = good && c < r->cluster_count;
      }
      return {status_of(r), good};
    }
    case e_subdivision_build: {
      auto r = infolerp::subdivision_mesh::create(m);
      return {status_of(r), !r.ok() || r->leaf_count() == nt};
    }
    case mesh_entry_count: break;
  }
  return {status{}, false};
}

// ---- helpers for stateful entry points ----------------------------------------------------

using sample = infolerp::reliability::table_source::sample_type;

indexed_mesh floor_mesh() { return infolerp::support::make_plane(2, 2, 2.0f); }
infolerp::pinhole_camera top_camera(std::uint32_t w, std::uint32_t h) {
  return {.eye = {0, 0, 1.8f}, .target = {0, 0, 0}, .up = {0, 1, 0}, .vertical_fov_degrees = 60.0f, .width = w,
          .height = h};
}
glm::vec3 grey(const infolerp::shading_point&) { return glm::vec3(0.5f); }

// A tracer that answers every ray with the same hit.
struct fixed_tracer {
  infolerp::hit h;
  infolerp::hit intersect(const infolerp::ray&) const { return h; }
  bool occluded(const infolerp::ray&) const { return h.valid(); }
};

// Starts a fresh refiner with a tracer; checks that a failed start leaves it unchanged.
std::pair<status, bool> start_with(const infolerp::hit& h, std::uint32_t w = 8, std::uint32_t hgt = 8) {
  const indexed_mesh m = floor_mesh();
  auto r = infolerp::progressive_refiner::create(*infolerp::subdivision_mesh::create(m));
  REQUIRE(r.ok());
  const status st = r->start(fixed_tracer{h}, top_camera(w, hgt), grey, infolerp::serial_executor{});
  const bool untouched = st.ok() || (r->pixel_leaves().empty() && r->visible_leaves().empty() &&
                                     r->report().stage1.shading_samples == 0);
  return {st, untouched};
}

}  // namespace

TEST_CASE("bad-input matrix: mesh classes against every mesh entry point", "[reliability][bad_input]") {
  for (const mesh_class& c : mesh_classes())
    for (std::size_t e = 0; e < mesh_entry_count; ++e) {
      const auto [st, output_ok] = run_mesh_entry(static_cast<mesh_entry>(e), c.mesh);
      check_cell(c.name, mesh_entry_names[e], st, c.want[e], output_ok);
    }
}

TEST_CASE("bad-input matrix: raw index buffers (strided view)", "[reliability][bad_input]") {
  const float pos[4 * 4] = {0, 0, 0, 9, 1, 0, 0, 9, 0, 1, 0, 9, 1, 1, 0, 9};  // 4 vertices, stride 16
  const std::uint32_t idx[7] = {0, 1, 2, 1, 3, 2, 0};
  auto view = [&](const float* p, std::size_t nv, std::size_t stride, const std::uint32_t* i, std::size_t ni) {
    return status_of(infolerp::make_strided_mesh_view(p, nv, stride, i, ni));
  };
  check_cell("index count not a multiple of 3", "make_strided_mesh_view", view(pos, 4, 16, idx, 7),
             {errc::bad_index_count, "index count 7 is not a multiple of 3"});
  check_cell("index count not a multiple of 3", "make_strided_mesh_view", view(pos, 4, 16, idx, 5),
             {errc::bad_index_count, "index count 5"});
  check_cell("null buffer, nonzero count", "make_strided_mesh_view", view(nullptr, 4, 16, idx, 6),
             {errc::bad_parameter, "positions is null"});
  check_cell("null buffer, nonzero count", "make_strided_mesh_view", view(pos, 4, 16, nullptr, 6),
             {errc::bad_parameter, "indices is null"});
  check_cell("bad stride", "make_strided_mesh_view", view(pos, 4, 8, idx, 6), {errc::bad_parameter, "stride 8"});
  check_cell("bad stride", "make_strided_mesh_view", view(pos, 4, 14, idx, 6), {errc::bad_parameter, "stride 14"});
  const std::uint32_t bad[6] = {0, 1, 2, 1, 4, 2};
  auto v = infolerp::make_strided_mesh_view(pos, 4, 16, bad, 6);
  REQUIRE(v.ok());
  check_cell("index out of range", "validate_mesh(strided)", infolerp::validate_mesh(*v),
             {errc::index_out_of_range, "triangle 1 corner 1"});
  check_cell("index out of range", "make_topology(strided)", status_of(infolerp::make_topology(*v)),
             {errc::index_out_of_range, "triangle 1"});
  auto good = infolerp::make_strided_mesh_view(pos, 4, 16, idx, 6);
  REQUIRE(good.ok());
  check_cell("single quad (valid)", "validate_mesh(strided)", infolerp::validate_mesh(*good), ok);
  check_cell("isolated NaN vertex", "validate_mesh(check_unused_vertices)",
             [] {
               indexed_mesh m = base();
               add_vertex(m, {nan_f, 0, 0});
               return infolerp::validate_mesh(m, {.check_unused_vertices = true});
             }(),
             {errc::non_finite, "vertex 42"});
}

TEST_CASE("bad-input matrix: distributions", "[reliability][bad_input]") {
  const std::vector<double> p{0.25, 0.25, 0.5, 0.0}, zero(4, 0.0), neg{0.5, -0.25, 0.5, 0.25},
      with_nan{0.5, 0.25, nan_d, 0.25}, with_inf{std::numeric_limits<double>::infinity(), 0.0, 0.0, 0.0}, shorter{1.0},
      none;
  auto js = [](const std::vector<double>& a, const std::vector<double>& b, double w = 0.5) {
    auto r = infolerp::jensen_shannon(std::span<const double>(a), std::span<const double>(b), w);
    CHECK((!r.ok() || (*r >= 0.0 && *r <= 1.0)));
    return status_of(r);
  };
  check_cell("all-zero distribution", "jensen_shannon", js(p, zero), {errc::bad_distribution, "q: all 4 bins are zero"});
  check_cell("negative distribution", "jensen_shannon", js(neg, p), {errc::bad_distribution, "p bin 1: negative"});
  check_cell("NaN in distribution", "jensen_shannon", js(p, with_nan), {errc::non_finite, "q bin 2"});
  check_cell("Inf in distribution", "jensen_shannon", js(with_inf, p), {errc::non_finite, "p bin 0"});
  check_cell("empty distribution", "jensen_shannon", js(none, none), {errc::empty_input, "no bins"});
  check_cell("mismatched sizes", "jensen_shannon", js(p, shorter), {errc::bad_distribution, "p has 4 bins but q has 1"});
  check_cell("threshold below 0", "jensen_shannon", js(p, p, -0.25), {errc::bad_parameter, "weight_p"});
  check_cell("threshold above 1", "jensen_shannon", js(p, p, 1.5), {errc::bad_parameter, "weight_p"});
  check_cell("threshold NaN", "jensen_shannon", js(p, p, nan_d), {errc::bad_parameter, "weight_p"});
  {
    const std::vector<float> pf{0.5f, 0.5f}, zf{0.0f, 0.0f};
    check_cell("all-zero distribution", "jensen_shannon(float)",
               status_of(infolerp::jensen_shannon(std::span<const float>(pf), std::span<const float>(zf))),
               {errc::bad_distribution, "all 2 bins are zero"});
  }
  {  // n-ary form
    const std::span<const double> d[2] = {p, neg};
    const std::vector<double> w{0.5, 0.5}, w_neg{0.5, -1.0}, w_zero{0.0, 0.0}, w_one{1.0};
    auto nary = [&](std::span<const std::span<const double>> ds, const std::vector<double>& ws) {
      return status_of(infolerp::jensen_shannon(ds, std::span<const double>(ws)));
    };
    check_cell("negative distribution", "jensen_shannon(n-ary)", nary(d, w), {errc::bad_distribution, "distribution 1 bin 1"});
    check_cell("empty distribution", "jensen_shannon(n-ary)", nary({}, {}), {errc::empty_input, "no distributions"});
    check_cell("mismatched sizes", "jensen_shannon(n-ary)", nary(d, w_one), {errc::bad_size, "1 weights for 2"});
    check_cell("threshold below 0", "jensen_shannon(n-ary)", nary(d, w_neg), {errc::bad_parameter, "weight 1"});
    check_cell("all-zero distribution", "jensen_shannon(n-ary)", nary(d, w_zero), {errc::bad_parameter, "weights sum to 0"});
  }
  check_cell("all-zero distribution", "checked_entropy", status_of(infolerp::checked_entropy(zero)),
             {errc::bad_distribution, "all 4 bins are zero"});
  check_cell("NaN in distribution", "checked_entropy", status_of(infolerp::checked_entropy(with_nan)),
             {errc::non_finite, "bin 2"});
  {
    const std::vector<double> px{0.5, 0.5}, rows{0.5, 0.5, 0.0, 0.0}, rows3{0.5, 0.5, 0.5};
    check_cell("all-zero distribution", "checked_mutual_information",
               status_of(infolerp::checked_mutual_information(px, rows)), {errc::bad_distribution, "row 1"});
    check_cell("mismatched sizes", "checked_mutual_information",
               status_of(infolerp::checked_mutual_information(px, rows3)), {errc::bad_size, "3 row entries for 2"});
    check_cell("negative distribution", "checked_element_mutual_information",
               status_of(infolerp::checked_element_mutual_information(px, neg)), {errc::bad_distribution, "row 0"});
  }
}

TEST_CASE("bad-input matrix: saliency and clustering options and per-vertex data", "[reliability][bad_input]") {
  const indexed_mesh m = base();
  const std::size_t nv = m.positions.size(), nt = m.triangles.size();
  auto sal = [&](infolerp::saliency_options o) { return status_of(infolerp::compute_saliency(m, o)); };
  check_cell("threshold below 0", "compute_saliency", sal({.epsilon = -0.01}), {errc::bad_parameter, "epsilon"});
  check_cell("zero parameter", "compute_saliency", sal({.epsilon = 0.0}), {errc::bad_parameter, "epsilon"});
  check_cell("threshold NaN", "compute_saliency", sal({.epsilon = nan_d}), {errc::bad_parameter, "epsilon"});
  check_cell("Inf parameter", "compute_saliency", sal({.epsilon = std::numeric_limits<double>::infinity()}),
             {errc::bad_parameter, "epsilon"});
  check_cell("empty option list", "compute_saliency", sal({.scales = {}}), {errc::bad_parameter, "at least one scale"});
  check_cell("threshold NaN", "compute_saliency", sal({.scales = {2.0, nan_d}}), {errc::bad_parameter, "scale 1"});
  check_cell("threshold below 0", "compute_saliency", sal({.scales = {-2.0}}), {errc::bad_parameter, "scale 0"});
  // A σ whose square underflows made the Gaussian weights of coincident vertices NaN (fuzzer).
  check_cell("parameter underflows", "compute_saliency", sal({.scales = {1e-160}}), {errc::bad_parameter, "saliency sigma"});
  // A σ near 5e153 passed the σ² check, but the exact kernel's squared ball radius 4σ²
  // overflowed and the averages became NaN (fuzzer).
  const double huge_scale = 5e153 / (0.003 * infolerp::mesh_bounds(m).diagonal());
  check_cell("parameter overflows", "compute_saliency", sal({.scales = {2.0, huge_scale}}),
             {errc::bad_parameter, "saliency sigma"});

  std::vector<double> s(nv, 1.0);
  auto clus = [&](const std::vector<double>& v, infolerp::salient_clustering_options o) {
    return status_of(infolerp::salient_clustering(m, v, o));
  };
  check_cell("zero count", "salient_clustering", clus(s, {.clusters = 0}), {errc::bad_parameter, "clusters 0"});
  check_cell("count above size", "salient_clustering", clus(s, {.clusters = 81}), {errc::bad_parameter, "clusters 81"});
  check_cell("threshold NaN", "salient_clustering", clus(s, {.pool_multiplier = nan_d}), {errc::bad_parameter, "pool_multiplier"});
  check_cell("threshold below 1", "salient_clustering", clus(s, {.normal_weight = 0.5}), {errc::bad_parameter, "normal_weight"});
  check_cell("mismatched sizes", "salient_clustering", clus(std::vector<double>(nv - 1, 1.0), {}),
             {errc::bad_size, "saliency has 41 values for 42 vertices"});
  std::vector<double> bad = s;
  bad[3] = nan_d;
  check_cell("NaN per-vertex value", "salient_clustering", clus(bad, {}), {errc::non_finite, "vertex 3"});
  bad[3] = -1.0;
  check_cell("negative per-vertex value", "salient_clustering", clus(bad, {}), {errc::bad_parameter, "vertex 3"});

  std::vector<std::uint32_t> cluster(nt, 0);
  cluster[2] = 5;
  check_cell("cluster id out of range", "compute_cluster_attributes",
             status_of(infolerp::compute_cluster_attributes(m, s, cluster, 2)), {errc::index_out_of_range, "triangle 2"});
  check_cell("cluster id out of range", "cluster_localized_saliency",
             status_of(infolerp::cluster_localized_saliency(m, s, cluster, 2)), {errc::index_out_of_range, "triangle 2"});
  cluster.pop_back();
  check_cell("mismatched sizes", "compute_cluster_attributes",
             status_of(infolerp::compute_cluster_attributes(m, s, cluster, 6)), {errc::bad_size, "79 ids for 80"});
  check_cell("mismatched sizes", "cluster_localized_saliency",
             status_of(infolerp::cluster_localized_saliency(m, s, cluster, 6)), {errc::bad_size, "79 ids for 80"});
  check_cell("NaN per-vertex value", "cluster_localized_saliency",
             status_of(infolerp::cluster_localized_saliency(m, std::vector<double>(nv, nan_d),
                                                            std::vector<std::uint32_t>(nt, 0), 1)),
             {errc::non_finite, "vertex 0"});

  auto table = infolerp::compute_cluster_attributes(m, s, std::vector<std::uint32_t>(nt, 0), 1);
  REQUIRE(table.ok());
  check_cell("NaN position", "estimate_view_importance",
             status_of(infolerp::estimate_view_importance(*table, {nan_d, 0.0, 0.0})), {errc::bad_parameter, "camera"});
  const std::vector<double> prio{1.0, 2.0}, prio_nan{1.0, nan_d};
  const std::vector<std::uint64_t> cap{5, 5}, cap1{5};
  auto dist = [](const std::vector<double>& p, const std::vector<std::uint64_t>& c, double lp) {
    return status_of(infolerp::distribute_contractions(p, c, 8, lp));
  };
  check_cell("threshold below 0", "distribute_contractions", dist(prio, cap, -0.1), {errc::bad_parameter, "lambda_perc"});
  check_cell("zero parameter", "distribute_contractions", dist(prio, cap, 0.0), {errc::bad_parameter, "lambda_perc"});
  check_cell("threshold above 1", "distribute_contractions", dist(prio, cap, 1.5), {errc::bad_parameter, "lambda_perc"});
  check_cell("threshold NaN", "distribute_contractions", dist(prio, cap, nan_d), {errc::bad_parameter, "lambda_perc"});
  check_cell("NaN per-vertex value", "distribute_contractions", dist(prio_nan, cap, 0.5),
             {errc::bad_parameter, "cluster 1: priority"});
  check_cell("mismatched sizes", "distribute_contractions", dist(prio, cap1, 0.5), {errc::bad_size, "capacity 1"});
}

TEST_CASE("bad-input matrix: clustering options and channels", "[reliability][bad_input]") {
  const indexed_mesh m = base();
  const infolerp::support::brute_force_tracer tracer{&m};
  const infolerp::serial_executor serial;
  auto vis = [&](infolerp::visibility_channel c) { return status_of(infolerp::cluster_mesh(m, tracer, serial, c)); };
  auto ori = [&](infolerp::orientation_channel c) { return status_of(infolerp::cluster_mesh(m, tracer, serial, c)); };
  check_cell("zero viewpoints", "cluster_mesh(visibility)", vis({.viewpoints = 0}),
             {errc::bad_parameter, "viewpoints 0 outside 1..2^20"});
  check_cell("count above size", "cluster_mesh(visibility)", vis({.viewpoints = (1u << 20) + 1}),
             {errc::bad_parameter, "viewpoints 1048577 outside 1..2^20"});
  check_cell("zero count", "cluster_mesh(visibility)", vis({.viewpoints = 4, .samples_per_side = 0}),
             {errc::bad_parameter, "samples_per_side 0"});
  check_cell("count above size", "cluster_mesh(visibility)", vis({.viewpoints = 4, .samples_per_side = 16}),
             {errc::bad_parameter, "samples_per_side 16"});
  check_cell("threshold below 1", "cluster_mesh(visibility)", vis({.viewpoints = 4, .radius_scale = 0.5}),
             {errc::bad_parameter, "radius_scale"});
  check_cell("threshold NaN", "cluster_mesh(visibility)", vis({.viewpoints = 4, .radius_scale = nan_d}),
             {errc::bad_parameter, "radius_scale"});
  check_cell("threshold below 0", "cluster_mesh(orientation)", ori({.threshold = -0.1}), {errc::bad_parameter, "channel 0: threshold"});
  check_cell("threshold above 1", "cluster_mesh(orientation)", ori({.threshold = 1.5}), {errc::bad_parameter, "channel 0: threshold"});
  check_cell("threshold NaN", "cluster_mesh(orientation)", ori({.threshold = nan_d}), {errc::bad_parameter, "channel 0: threshold"});
  check_cell("threshold NaN", "cluster_mesh(options)",
             status_of(infolerp::cluster_mesh(m, tracer, serial, infolerp::cluster_options{.min_cluster_fraction = nan_d},
                                              infolerp::orientation_channel{})),
             {errc::bad_parameter, "min_cluster_fraction"});
  check_cell("threshold exactly 0 and 1 (valid)", "cluster_mesh(orientation)", ori({.threshold = 0.0}), ok);
  check_cell("threshold exactly 0 and 1 (valid)", "cluster_mesh(orientation)", ori({.threshold = 1.0}), ok);
  {
    indexed_mesh uv = infolerp::support::make_plane(2, 2, 1.0f);
    const infolerp::support::brute_force_tracer uv_tracer{&uv};
    auto str = [&](infolerp::stretch_channel c) { return status_of(infolerp::cluster_mesh(uv, uv_tracer, serial, c)); };
    check_cell("threshold below 0", "cluster_mesh(stretch)", str({.theta = -1.0}), {errc::bad_parameter, "theta"});
    uv.texcoords[4].y = nan_f;
    check_cell("NaN texcoord", "cluster_mesh(stretch)", str({}), {errc::non_finite, "triangle 1 corner 1"});
  }
  {
    indexed_mesh no_frames = base();  // a keyframed type with zero keyframes
    check_cell("zero keyframes", "cluster_keyframes",
               status_of(infolerp::cluster_keyframes(
                   no_frames, [&](std::size_t) -> const infolerp::support::brute_force_tracer& { return tracer; }, serial,
                   infolerp::cluster_options{}, infolerp::orientation_channel{})),
               {errc::empty_input, "no keyframes"});
    indexed_mesh frames = base();
    frames.keyframes = {frames.positions, frames.positions};
    frames.keyframes[1][3].x = inf_f;
    check_cell("Inf position", "cluster_keyframes",
               status_of(infolerp::cluster_keyframes(
                   frames, [&](std::size_t) -> const infolerp::support::brute_force_tracer& { return tracer; }, serial,
                   infolerp::cluster_options{}, infolerp::orientation_channel{})),
               {errc::non_finite, "vertex 3"});
    indexed_mesh short_frame = base();
    short_frame.keyframes = {short_frame.positions, short_frame.positions, short_frame.positions};
    short_frame.keyframes[2].pop_back();  // keyframe 2 lacks the last vertex's position
    check_cell("short keyframe", "cluster_keyframes",
               status_of(infolerp::cluster_keyframes(
                   short_frame, [&](std::size_t) -> const infolerp::support::brute_force_tracer& { return tracer; },
                   serial, infolerp::cluster_options{}, infolerp::orientation_channel{})),
               {errc::bad_size, "keyframe 2 has"});
    indexed_mesh long_frame = base();
    long_frame.keyframes = {long_frame.positions, long_frame.positions};
    long_frame.keyframes[0].push_back(glm::vec3(0.0f));
    check_cell("long keyframe", "cluster_keyframes",
               status_of(infolerp::cluster_keyframes(
                   long_frame, [&](std::size_t) -> const infolerp::support::brute_force_tracer& { return tracer; },
                   serial, infolerp::cluster_options{}, infolerp::orientation_channel{})),
               {errc::bad_size, "keyframe 0 has"});
  }
}

TEST_CASE("bad-input matrix: refinement (subdivision, criteria, driver, tracers)", "[reliability][bad_input]") {
  const indexed_mesh m = floor_mesh();
  check_cell("threshold below 0", "subdivision_mesh::create",
             status_of(infolerp::subdivision_mesh::create(m, {.bisect_ratio = -0.5f})),
             {errc::bad_parameter, "bisect_ratio"});
  check_cell("threshold NaN", "subdivision_mesh::create",
             status_of(infolerp::subdivision_mesh::create(m, {.bisect_ratio = nan_f})),
             {errc::bad_parameter, "bisect_ratio"});
  {
    auto s = infolerp::subdivision_mesh::create(m);
    REQUIRE(s.ok());
    check_cell("index out of range", "subdivision_mesh::split(t)", s->split(99u), {errc::index_out_of_range, "triangle 99"});
    // A selection with a bad id in the middle: nothing is split.
    const std::uint32_t sel[3] = {0, 1000, 1};
    const std::size_t before = s->triangle_count();
    const status st = s->split(std::span<const std::uint32_t>(sel));
    check_cell("index out of range", "subdivision_mesh::split(span)", st, {errc::index_out_of_range, "selection 1: triangle 1000"},
               s->triangle_count() == before && s->leaf_count() == m.triangles.size());
  }
  auto crit = [](infolerp::criteria_options o) { return infolerp::validate(o); };
  check_cell("threshold below 0", "validate(criteria_options)", crit({.s_req = -0.1f}), {errc::bad_parameter, "s_req"});
  check_cell("threshold above 1", "validate(criteria_options)", crit({.s_req = 1.5f}), {errc::bad_parameter, "s_req"});
  check_cell("threshold NaN", "validate(criteria_options)", crit({.s_req = nan_f}), {errc::bad_parameter, "s_req"});
  check_cell("threshold NaN", "validate(criteria_options)", crit({.min_pixels = nan_f}), {errc::bad_parameter, "min_pixels"});
  check_cell("zero count", "validate(criteria_options)", crit({.batch = 0}), {errc::bad_parameter, "batch"});
  check_cell("threshold NaN", "validate(criteria_options)", crit({.rnd_point_fraction = nan_f}),
             {errc::bad_parameter, "rnd_point_fraction"});
  check_cell("threshold exactly 0 and 1 (valid)", "validate(criteria_options)", crit({.s_req = 0.0f}), ok);
  check_cell("threshold exactly 0 and 1 (valid)", "validate(criteria_options)", crit({.s_req = 1.0f}), ok);
  {
    auto s = infolerp::subdivision_mesh::create(m);
    check_cell("threshold NaN", "progressive_refiner::create",
               status_of(infolerp::progressive_refiner::create(*s, {.criteria = {.s_req = nan_f}})), {errc::bad_parameter, "s_req"});
    check_cell("zero count", "progressive_refiner::create",
               status_of(infolerp::progressive_refiner::create(*s, {.grain = 0})), {errc::bad_parameter, "grain"});
  }
  // Tracers returning garbage, and empty images: start() fails and leaves the refiner unchanged.
  const infolerp::hit good{0, 1, {0.25f, 0.25f}, 1.0f};
  auto with = [&](auto change) {
    infolerp::hit h = good;
    change(h);
    return h;
  };
  {
    auto [st, untouched] = start_with(good, 0, 0);
    check_cell("image size 0x0", "progressive_refiner::start", st, {errc::empty_input, "0x0"}, untouched);
  }
  {
    auto [st, untouched] = start_with(good, 16, 0);
    check_cell("image size Nx0", "progressive_refiner::start", st, {errc::empty_input, "16x0"}, untouched);
  }
  {
    auto [st, untouched] = start_with(with([](infolerp::hit& h) { h.distance = nan_f; }));
    check_cell("tracer returns NaN distance", "progressive_refiner::start", st, {errc::non_finite, "pixel 0"}, untouched);
  }
  {
    auto [st, untouched] = start_with(with([](infolerp::hit& h) { h.barycentric.y = -inf_f; }));
    check_cell("tracer returns Inf barycentric", "progressive_refiner::start", st, {errc::non_finite, "pixel 0"}, untouched);
  }
  {
    auto [st, untouched] = start_with(with([](infolerp::hit& h) { h.triangle = 8; }));
    check_cell("tracer returns unknown triangle", "progressive_refiner::start", st,
               {errc::index_out_of_range, "pixel 0: hit triangle 8"}, untouched);
  }
  {
    auto [st, untouched] = start_with(infolerp::hit{});  // every ray misses: valid, nothing visible
    check_cell("tracer hits nothing (valid)", "progressive_refiner::start", st, ok, untouched);
  }
  // nld is total: NaN luminances mean "refine", a NaN or zero L_max means "nothing to normalise".
  const float nld_nan = infolerp::nld(0.1f, nan_f, 0.3f, 1.0f), nld_lmax = infolerp::nld(0.1f, 0.2f, 0.3f, nan_f);
  CHECK(nld_nan == 1.0f);
  CHECK(nld_lmax == 0.0f);
  CHECK(infolerp::nld(0.1f, 0.2f, 0.3f, -1.0f) == 0.0f);
  CHECK(infolerp::nld(std::span<const float>{}, 1.0f) == 0.0f);
}

TEST_CASE("bad-input matrix: upsampler and pass controller", "[reliability][bad_input]") {
  using up_t = infolerp::upsampler<sample>;
  auto create = [](std::uint32_t w, std::uint32_t h, infolerp::upsampler_options o = {}) {
    return status_of(up_t::create(w, h, o));
  };
  check_cell("image size 0x0", "upsampler::create", create(0, 0), {errc::empty_input, "0x0"});
  check_cell("image size Nx0", "upsampler::create", create(5, 0), {errc::empty_input, "5x0"});
  check_cell("image size 0xN", "upsampler::create", create(0, 5), {errc::empty_input, "0x5"});
  check_cell("image size above 2^24", "upsampler::create", create((1u << 24) + 1, 1), {errc::bad_parameter, "above 2^24"});
  check_cell("zero count", "upsampler::create", create(8, 8, {.passes = 0}), {errc::bad_parameter, "passes 0"});
  check_cell("count above size", "upsampler::create", create(8, 8, {.passes = 5, .max_passes = 4}), {errc::bad_parameter, "passes 5"});
  check_cell("count above size", "upsampler::create", create(8, 8, {.max_passes = 17}), {errc::bad_parameter, "max_passes 17"});
  check_cell("zero count", "upsampler::create", create(8, 8, {.max_passes = 0}), {errc::bad_parameter, "max_passes 0"});
  check_cell("zero count", "upsampler::create", create(8, 8, {.rows_per_task = 0}), {errc::bad_parameter, "rows_per_task"});
  check_cell("image size 1x1 (valid)", "upsampler::create", create(1, 1, {.passes = 16, .max_passes = 16}), ok);

  const std::uint32_t ids[3] = {0, 1, infolerp::invalid_id};
  const infolerp::reliability::table_source src{ids, 4};
  auto up = up_t::create(12, 10);
  REQUIRE(up.ok());
  const glm::vec3 poison(-7.0f, 1e9f, 3.0f);
  {  // output of the wrong size: nothing written
    std::vector<glm::vec3> out(12 * 10 - 1, poison);
    const status st = up->render(src, std::span<glm::vec3>(out));
    bool untouched = true;
    for (const auto& p : out) untouched = untouched && p == poison;
    check_cell("output buffer of the wrong size", "upsampler::render", st, {errc::bad_size, "output has 119 pixels"}, untouched);
  }
  {  // resize and set_passes fail without changing the upsampler
    const status st = up->resize(0, 0);
    check_cell("image size 0x0", "upsampler::resize", st, {errc::empty_input, "0x0"},
               up->width() == 12 && up->height() == 10);
    const status sp = up->set_passes(9);
    check_cell("count above size", "upsampler::set_passes", sp, {errc::bad_parameter, "passes 9"}, up->passes() == 4);
  }
  {
    std::vector<glm::vec3> none;
    check_cell("image size 0x0", "upsample(one-shot)",
               infolerp::upsample(src, 0, 0, std::span<glm::vec3>(none)),
               {errc::empty_input, "0x0"});
  }
  {  // fuzzed-looking cluster ids (background, huge ids) are valid data: every pixel written, finite
    std::vector<glm::vec3> out(12 * 10, poison);
    const status st = up->render(src, std::span<glm::vec3>(out));
    bool written = true;
    for (const auto& p : out) written = written && p != poison && std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
    check_cell("background and extreme cluster ids (valid)", "upsampler::render", st, ok, written);
  }

  auto ctl = [](infolerp::pass_controller_options o) { return status_of(infolerp::pass_controller::create(o)); };
  check_cell("threshold NaN", "pass_controller::create", ctl({.min_frame_seconds = nan_d}), {errc::bad_parameter, "frame-time bounds"});
  check_cell("threshold below 0", "pass_controller::create", ctl({.min_frame_seconds = -1.0}), {errc::bad_parameter, "frame-time bounds"});
  check_cell("bounds out of order", "pass_controller::create", ctl({.min_frame_seconds = 0.5, .max_frame_seconds = 0.1}),
             {errc::bad_parameter, "frame-time bounds"});
  check_cell("zero count", "pass_controller::create", ctl({.max_passes = 0}), {errc::bad_parameter, "max_passes 0"});
  check_cell("count above size", "pass_controller::create", ctl({.max_passes = 17}), {errc::bad_parameter, "max_passes 17"});
  check_cell("zero parameter", "pass_controller::create", ctl({.smoothing = 0.0}), {errc::bad_parameter, "smoothing"});
  check_cell("threshold NaN", "pass_controller::create", ctl({.smoothing = nan_d}), {errc::bad_parameter, "smoothing"});
  check_cell("threshold above 1", "pass_controller::create", ctl({.smoothing = 1.5}), {errc::bad_parameter, "smoothing"});
  check_cell("zero count", "pass_controller::create", ctl({.settle_frames = 0}), {errc::bad_parameter, "settle_frames"});
  {
    auto c = infolerp::pass_controller::create({.settle_frames = 1});
    REQUIRE(c.ok());
    const std::uint32_t before = c->passes();
    check_cell("NaN measurement", "pass_controller::update", c->update(nan_d), {errc::non_finite, "not finite"},
               c->passes() == before && std::isnan(c->average_seconds(before)));
    check_cell("negative measurement", "pass_controller::update", c->update(-1.0), {errc::bad_parameter, "negative"},
               c->passes() == before && std::isnan(c->average_seconds(before)));
  }
}

TEST_CASE("bad-input matrix: summary", "[reliability][bad_input]") {
  // Runs after the others in declaration order; prints the matrix on request.
  if (const char* env = std::getenv("INFOLERP_PRINT_MATRIX"); env && *env == '1') {
    std::map<std::string, std::map<std::string, std::string>> table;
    for (const cell& c : matrix()) {
      std::string& v = table[c.cls][c.entry];
      v = v.empty() || v == "pass" ? (c.pass ? "pass" : "FAIL") : v;
    }
    std::size_t pass = 0;
    for (const cell& c : matrix()) pass += c.pass;
    std::printf("bad-input matrix: %zu cells, %zu pass\n", matrix().size(), pass);
    for (const auto& [cls, row] : table) {
      std::printf("%s:", cls.c_str());
      for (const auto& [entry, v] : row) std::printf(" %s=%s", entry.c_str(), v.c_str());
      std::printf("\n");
    }
  }
}
