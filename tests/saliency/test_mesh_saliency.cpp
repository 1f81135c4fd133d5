// saliency/mesh_saliency.hpp: the fast path against an O(V²) reference, analytic shapes,
// determinism across thread counts, a far stray vertex, bad input.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/topology.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "support/procedural.hpp"
#include "support/thread_pool.hpp"

namespace {

// A plane with Gaussian bumps of the given height at the given (x, y) centres.
infolerp::indexed_mesh bumpy_plane(unsigned n, const std::vector<glm::vec2>& centres, float height, float width) {
  auto m = infolerp::support::make_plane(n, n, 2.0f);
  for (auto& p : m.positions)
    for (const auto& c : centres) {
      const float d2 = (p.x - c.x) * (p.x - c.x) + (p.y - c.y) * (p.y - c.y);
      p.z += height * std::exp(-d2 / (2.0f * width * width));
    }
  return m;
}

// O(V²) reference of the levels S_i and of the normalised saliency, written from the
// definition (std::exp, every vertex pair, 1-ring local maxima).
struct reference {
  std::vector<std::vector<double>> levels;
  std::vector<double> saliency;
};
reference brute_force(const infolerp::indexed_mesh& m, const infolerp::saliency_options& opt) {
  const auto c = *infolerp::mean_curvature(m);
  const double eps = opt.epsilon * infolerp::mesh_bounds(m).diagonal();
  const std::size_t n = m.positions.size();
  auto G = [&](std::size_t v, double sigma) {
    double num = 0.0, den = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      const double d2 = glm::dot(glm::dvec3(m.positions[j]) - glm::dvec3(m.positions[v]),
                                 glm::dvec3(m.positions[j]) - glm::dvec3(m.positions[v]));
      if (d2 > 4.0 * sigma * sigma) continue;
      const double w = std::exp(-d2 / (2.0 * sigma * sigma));
      num += w * c[j];
      den += w;
    }
    return num / den;
  };
  double mean_abs = 0.0;
  for (double x : c) mean_abs += std::abs(x);
  mean_abs /= static_cast<double>(n);
  const auto topo = *infolerp::make_topology(m);
  reference ref;
  ref.saliency.assign(n, 0.0);
  for (double s : opt.scales) {
    std::vector<double> level(n);
    for (std::size_t v = 0; v < n; ++v) level[v] = std::abs(G(v, s * eps) - G(v, 2.0 * s * eps));
    const double mx = *std::max_element(level.begin(), level.end());
    const double scale = 1.0 / std::max(mx, opt.flat_level_threshold * mean_abs);
    const std::size_t global = static_cast<std::size_t>(std::max_element(level.begin(), level.end()) - level.begin());
    std::vector<bool> is_max(n, true);
    for (const auto& e : topo.edges) {  // local maxima: above every 1-ring neighbour by > 1e-12 max
      if (level[e.x] <= level[e.y] + 1e-12 * mx) is_max[e.x] = false;
      if (level[e.y] <= level[e.x] + 1e-12 * mx) is_max[e.y] = false;
    }
    double sum = 0.0;
    int count = 0;
    for (std::size_t v = 0; v < n; ++v)
      if (is_max[v] && v != global) sum += level[v] * scale, ++count;
    const double mbar = count ? sum / count : 0.0;
    const double f = (mx * scale - mbar) * (mx * scale - mbar);
    for (std::size_t v = 0; v < n; ++v) ref.saliency[v] += level[v] * scale * f;
    ref.levels.push_back(level);
  }
  return ref;
}

double max_abs_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

}  // namespace

TEST_CASE("saliency: fast exact path matches the O(V^2) definition to 1e-9") {
  const infolerp::indexed_mesh meshes[] = {
      bumpy_plane(24, {{0.3f, -0.2f}, {-0.5f, 0.4f}}, 0.3f, 0.15f),
      infolerp::support::make_torus(40, 16, 1.0f, 0.35f),
  };
  for (double epsilon : {0.01, 0.03}) {
    infolerp::saliency_options opt{.epsilon = epsilon};
    for (const auto& m : meshes) {
      auto s = infolerp::compute_saliency(m, opt);
      REQUIRE(s.ok());
      const auto ref = brute_force(m, opt);
      for (std::size_t i = 0; i < ref.levels.size(); ++i) {
        const double d = max_abs_diff(s->levels[i], ref.levels[i]);
        INFO("epsilon " << epsilon << " level " << i << " max |fast - reference| " << d);
        CHECK(d <= 1e-9);
      }
      const double ds = max_abs_diff(s->saliency, ref.saliency);
      INFO("epsilon " << epsilon << " saliency max |fast - reference| " << ds);
      CHECK(ds <= 1e-9);
    }
  }
}

TEST_CASE("saliency: a far stray vertex leaves the neighbour grid as fine as the ball asks") {
  auto m = bumpy_plane(24, {{0.3f, -0.2f}}, 0.3f, 0.15f);
  const double diagonal = infolerp::mesh_bounds(m).diagonal();
  m.positions.push_back({1e6f, 0.0f, 0.0f});
  m.triangles.push_back({0u, 1u, static_cast<unsigned>(m.positions.size() - 1)});
  // sigma as on the plane alone: 0.03 of its diagonal.
  const infolerp::saliency_options opt{.epsilon = 0.03 * diagonal / infolerp::mesh_bounds(m).diagonal()};
  auto s = infolerp::compute_saliency(m, opt);
  REQUIRE(s.ok());
  const auto ref = brute_force(m, opt);
  CHECK(max_abs_diff(s->saliency, ref.saliency) <= 1e-9);

  std::vector<double> curvature(m.positions.size(), 0.0);
  const auto used = infolerp::detail::referenced_vertices(m);
  const auto points = infolerp::detail::referenced_points(m, used, curvature);
  const double width = 0.5 * s->epsilon;
  infolerp::serial_executor serial;
  const auto grid = infolerp::detail::make_column_grid(serial, points, width);
  CHECK(grid.h == width);
  CHECK(grid.col_key.size() <= m.positions.size());
}

TEST_CASE("saliency: identical bits for any executor, thread count and grain") {
  const auto m = bumpy_plane(60, {{0.0f, 0.0f}, {0.5f, 0.5f}}, 0.2f, 0.1f);
  infolerp::saliency_options opt{.epsilon = 0.01};
  auto serial = infolerp::compute_saliency(m, opt);
  REQUIRE(serial.ok());
  for (unsigned workers : {2u, 3u, 4u})
    for (std::size_t grain : {std::size_t{1}, std::size_t{3}}) {
      opt.grain = grain;
      auto par = infolerp::compute_saliency(m, opt, infolerp::support::thread_pool_executor{workers});
      REQUIRE(par.ok());
      CHECK(par->saliency == serial->saliency);
    }
}

TEST_CASE("saliency: a sphere is uniformly non-salient, bumps on a plane are salient") {
  const auto sphere = infolerp::support::make_icosphere(4);
  auto s = infolerp::compute_saliency(sphere);
  REQUIRE(s.ok());
  const double sphere_max = *std::max_element(s->saliency.begin(), s->saliency.end());
  INFO("sphere max saliency " << sphere_max);
  CHECK(sphere_max < 1e-3);

  const auto m = bumpy_plane(100, {{0.4f, 0.3f}}, 0.15f, 0.08f);
  auto b = infolerp::compute_saliency(m);
  REQUIRE(b.ok());
  const std::size_t peak =
      static_cast<std::size_t>(std::max_element(b->saliency.begin(), b->saliency.end()) - b->saliency.begin());
  const glm::vec3 p = m.positions[peak];
  INFO("peak at " << p.x << ", " << p.y);
  CHECK(std::hypot(p.x - 0.4f, p.y - 0.3f) < 0.3f);  // on the bump (3.75 widths)
  double near = 0.0, far = 0.0;
  int n_near = 0, n_far = 0;
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    const float d = std::hypot(m.positions[v].x - 0.4f, m.positions[v].y - 0.3f);
    if (d < 0.25f) near += b->saliency[v], ++n_near;
    if (d > 0.6f && std::abs(m.positions[v].x) < 0.9f && std::abs(m.positions[v].y) < 0.9f)
      far += b->saliency[v], ++n_far;
  }
  INFO("mean saliency near the bump " << near / n_near << ", far " << far / n_far);
  CHECK(near / n_near > 100.0 * (far / n_far));
  CHECK(sphere_max < 1e-3 * *std::max_element(b->saliency.begin(), b->saliency.end()));
}

TEST_CASE("saliency: bad input gets a clear status") {
  infolerp::indexed_mesh empty;
  CHECK(infolerp::compute_saliency(empty).error().code() == infolerp::errc::empty_input);
  const auto m = infolerp::support::make_icosphere(1);
  auto bad_eps = infolerp::compute_saliency(m, {.epsilon = -1.0});
  CHECK(bad_eps.error().code() == infolerp::errc::bad_parameter);
  auto bad_scale = infolerp::compute_saliency(m, {.scales = {2.0, std::nan("")}});
  CHECK(bad_scale.error().code() == infolerp::errc::bad_parameter);
  CHECK(bad_scale.error().element() == 1);
  CHECK(bad_scale.error().message().find("scale 1") != std::string::npos);
  auto no_scale = infolerp::compute_saliency(m, {.scales = {}});
  CHECK(no_scale.error().code() == infolerp::errc::bad_parameter);
  // 17 scales as given, though only 2 distinct values (4 distinct sigma).
  const std::vector<double> seventeen = {2.0, 3.0, 2.0, 3.0, 2.0, 3.0, 2.0, 3.0, 2.0, 3.0, 2.0, 3.0, 2.0, 3.0, 2.0, 3.0, 2.0};
  auto too_many = infolerp::compute_saliency(m, {.scales = seventeen});
  REQUIRE(!too_many.ok());
  CHECK(too_many.error().code() == infolerp::errc::bad_parameter);
  CHECK(too_many.error().message().find("17 scales") != std::string::npos);
  CHECK(infolerp::compute_saliency(m, {.scales = std::vector<double>(seventeen.begin(), seventeen.end() - 1)}).ok());
  for (double threshold : {std::nan(""), -1e-3, std::numeric_limits<double>::infinity()}) {
    INFO("flat_level_threshold " << threshold);
    auto bad_threshold = infolerp::compute_saliency(m, {.flat_level_threshold = threshold});
    REQUIRE(!bad_threshold.ok());
    CHECK(bad_threshold.error().code() == infolerp::errc::bad_parameter);
    CHECK(bad_threshold.error().message().find("flat_level_threshold") != std::string::npos);
  }
  CHECK(infolerp::compute_saliency(m, {.flat_level_threshold = 0.0}).ok());
  auto bad_idx = m;
  bad_idx.triangles[5].z = 1000;
  auto r = infolerp::compute_saliency(bad_idx);
  CHECK(r.error().code() == infolerp::errc::index_out_of_range);
  CHECK(r.error().element() == 5);
  infolerp::indexed_mesh point;
  point.positions = {{1, 1, 1}};
  point.triangles = {{0, 0, 0}};
  CHECK(infolerp::compute_saliency(point).error().code() == infolerp::errc::degenerate_triangle);
}
