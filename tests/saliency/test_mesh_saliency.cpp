// saliency/mesh_saliency.hpp: the fast path against an O(V²) reference, analytic shapes,
// determinism across thread counts, a far stray vertex, bad input.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <utility>
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

namespace {

// A unit icosphere with Gaussian bumps (height, angular width in radians) along the given
// directions: its salient features are known.
infolerp::indexed_mesh bumpy_sphere(unsigned level, const std::vector<glm::vec3>& dirs, float height, float width) {
  auto m = infolerp::support::make_icosphere(level);
  for (auto& p : m.positions) {
    const glm::vec3 n = glm::normalize(p);
    float r = 1.0f;
    for (const glm::vec3& d : dirs) {
      const float a = std::acos(std::clamp(glm::dot(n, glm::normalize(d)), -1.0f, 1.0f));
      r += height * std::exp(-a * a / (2.0f * width * width));
    }
    p = n * r;
  }
  return m;
}

const std::vector<glm::vec3> bump_dirs = {{1, 0, 0}, {0, 1, 0}, {0, 0, -1}, {-1, -1, 1}, {1, -1, -1}};

infolerp::saliency_options proxy_options(double cells_per_sigma, double epsilon) {
  return {.epsilon = epsilon, .method = infolerp::saliency_method::proxy, .proxy_cells_per_sigma = cells_per_sigma};
}

double relative_l2(const std::vector<double>& a, const std::vector<double>& ref) {
  double d = 0.0, n = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) d += (a[i] - ref[i]) * (a[i] - ref[i]), n += ref[i] * ref[i];
  return std::sqrt(d / n);
}

// Share of ref's 10% most salient vertices that a also ranks in its 10% most salient.
double top10_overlap(const std::vector<double>& a, const std::vector<double>& ref) {
  const std::size_t k = a.size() / 10;
  auto top = [&](const std::vector<double>& s) {
    std::vector<std::size_t> order(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return s[x] != s[y] ? s[x] > s[y] : x < y; });
    std::vector<char> mask(s.size(), 0);
    for (std::size_t i = 0; i < k; ++i) mask[order[i]] = 1;
    return mask;
  };
  const auto ta = top(a), tr = top(ref);
  std::size_t both = 0;
  for (std::size_t i = 0; i < a.size(); ++i) both += ta[i] && tr[i];
  return static_cast<double>(both) / static_cast<double>(k);
}

}  // namespace

TEST_CASE("saliency proxy: the error falls as the cells per sigma grow, down to exact") {
  // epsilon 0.02: the mesh's vertex spacing is about half of ε, so coarse cells group many vertices.
  const auto m = bumpy_sphere(5, bump_dirs, 0.15f, 0.2f);
  const double epsilon = 0.02;
  auto exact = infolerp::compute_saliency(m, {.epsilon = epsilon, .method = infolerp::saliency_method::exact});
  REQUIRE(exact.ok());
  CHECK(exact->method == infolerp::saliency_method::exact);
  double previous = std::numeric_limits<double>::infinity();
  for (double cells : {0.5, 1.0, 2.0, 4.0, 8.0}) {
    auto s = infolerp::compute_saliency(m, proxy_options(cells, epsilon));
    REQUIRE(s.ok());
    CHECK(s->method == infolerp::saliency_method::proxy);
    const double err = relative_l2(s->saliency, exact->saliency);
    INFO("cells per sigma " << cells << ": relative L2 " << err << ", previous " << previous);
    CHECK(err < previous);
    previous = err;
  }
  // Cells smaller than the vertex spacing / sqrt(3) (even for the largest sigma) hold one
  // vertex each: the proxy is the mesh and the result exact's.
  double spacing = std::numeric_limits<double>::infinity();
  for (const auto& t : m.triangles)
    for (int e = 0; e < 3; ++e)
      spacing = std::min(spacing, static_cast<double>(glm::distance(m.positions[t[e]], m.positions[t[(e + 1) % 3]])));
  const double cells = 12.0 * exact->epsilon * 2.0 / spacing;  // largest σ = 12ε, cell edge spacing / 2
  auto fine = infolerp::compute_saliency(m, proxy_options(cells, epsilon));
  REQUIRE(fine.ok());
  const double d = max_abs_diff(fine->saliency, exact->saliency);
  INFO("cells per sigma " << cells << ": max |proxy - exact| " << d);
  CHECK(d <= 1e-9);
}

TEST_CASE("saliency proxy: the 10% most salient vertices of a sphere with bumps are exact's") {
  const auto m = bumpy_sphere(5, bump_dirs, 0.15f, 0.2f);
  for (double epsilon : {0.01, 0.02}) {
    auto exact = infolerp::compute_saliency(m, {.epsilon = epsilon, .method = infolerp::saliency_method::exact});
    auto proxy = infolerp::compute_saliency(m, {.epsilon = epsilon, .method = infolerp::saliency_method::proxy});
    REQUIRE(exact.ok());
    REQUIRE(proxy.ok());
    const double overlap = top10_overlap(proxy->saliency, exact->saliency);
    INFO("epsilon " << epsilon << ": top-10% overlap " << overlap << ", relative L2 "
                    << relative_l2(proxy->saliency, exact->saliency));
    CHECK(overlap >= 0.9);
    // The features are the bumps: most of the proxy's top 10% lies on one (within 3 widths) when
    // the scales are the bumps' (at epsilon 0.02 the largest σ spans 0.8 radians).
    if (epsilon != 0.01) continue;
    const std::size_t k = m.positions.size() / 10;
    std::vector<std::size_t> order(m.positions.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return proxy->saliency[x] > proxy->saliency[y]; });
    std::size_t on_bump = 0;
    for (std::size_t i = 0; i < k; ++i)
      for (const glm::vec3& d : bump_dirs)
        if (std::acos(std::clamp(glm::dot(glm::normalize(m.positions[order[i]]), glm::normalize(d)), -1.0f, 1.0f)) < 0.6f) {
          ++on_bump;
          break;
        }
    INFO("epsilon " << epsilon << ": " << on_bump << " of " << k << " on a bump");
    CHECK(on_bump >= k * 9 / 10);
  }
}

TEST_CASE("saliency proxy: identical bits for any executor and thread count") {
  const auto m = bumpy_sphere(4, bump_dirs, 0.15f, 0.2f);
  for (double cells : {1.0, 2.0, 5.0}) {
    const auto opt = proxy_options(cells, 0.02);
    auto serial = infolerp::compute_saliency(m, opt);
    REQUIRE(serial.ok());
    for (unsigned workers : {2u, 3u, 4u}) {
      auto par = infolerp::compute_saliency(m, opt, infolerp::support::thread_pool_executor{workers});
      REQUIRE(par.ok());
      CHECK(par->saliency == serial->saliency);
      CHECK(par->levels == serial->levels);
    }
  }
}

TEST_CASE("saliency proxy: the cell grouping and its merge of sorted runs are the same through any executor, and match a map") {
  // Enough points for many chunks of each parallel step (sort runs, cell starts, cell sums,
  // neighbour lists), in clusters so that cells hold several points.
  infolerp::detail::vertex_points pts;
  std::uint64_t state = 12345;
  auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) * 0x1p-53;
  };
  for (int k = 0; k < 150000; ++k) {
    pts.x.push_back(std::floor(next() * 60.0) + 0.5 * next()), pts.y.push_back(next() * 40.0), pts.z.push_back(next() * 3.0);
    pts.value.push_back(next() - 0.5), pts.id.push_back(static_cast<std::uint32_t>(k));
  }
  for (bool weighted : {false, true}) {
    if (weighted)
      for (int k = 0; k < 150000; ++k) pts.weight.push_back(1.0 + next());
    infolerp::serial_executor serial;
    const auto ref = infolerp::detail::make_proxy_cells(serial, pts, 0.7);
    // Against a map of the cells: the same cells, each with its points' value sum and count.
    std::map<std::array<std::int64_t, 3>, std::pair<double, double>> cells;
    const double lo[3] = {*std::min_element(pts.x.begin(), pts.x.end()), *std::min_element(pts.y.begin(), pts.y.end()),
                          *std::min_element(pts.z.begin(), pts.z.end())};
    for (std::size_t k = 0; k < pts.x.size(); ++k) {
      auto& c = cells[{static_cast<std::int64_t>(std::floor((pts.x[k] - lo[0]) / 0.7)),
                       static_cast<std::int64_t>(std::floor((pts.y[k] - lo[1]) / 0.7)),
                       static_cast<std::int64_t>(std::floor((pts.z[k] - lo[2]) / 0.7))}];
      c.first += pts.value[k], c.second += weighted ? pts.weight[k] : 1.0;
    }
    REQUIRE(ref.points.x.size() == cells.size());
    std::size_t i = 0, off = 0;
    for (const auto& [key, sums] : cells) {  // the map's order is the cells' key order
      off += std::abs(ref.points.value[i] - sums.first) > 1e-9 || std::abs(ref.points.weight[i] - sums.second) > 1e-9 ? 1 : 0;
      ++i;
    }
    CHECK(off == 0);
    // Neighbour lists against the map: per cell, the occupied cells among the 27 around it, in
    // key order (the walk's order).
    std::map<std::array<std::int64_t, 3>, std::uint32_t> index;
    for (const auto& [key, sums] : cells) index.emplace(key, static_cast<std::uint32_t>(index.size()));
    std::size_t wrong_lists = 0;
    for (const auto& [key, at] : index) {
      std::vector<std::uint32_t> want;
      for (std::int64_t dx = -1; dx <= 1; ++dx)
        for (std::int64_t dy = -1; dy <= 1; ++dy)
          for (std::int64_t dz = -1; dz <= 1; ++dz)
            if (auto it = index.find({key[0] + dx, key[1] + dy, key[2] + dz}); it != index.end()) want.push_back(it->second);
      std::sort(want.begin(), want.end());
      const std::vector<std::uint32_t> got(ref.near.begin() + ref.near_start[at], ref.near.begin() + ref.near_start[at + 1]);
      wrong_lists += got == want ? 0 : 1;
    }
    CHECK(wrong_lists == 0);
    for (unsigned workers : {2u, 3u}) {
      infolerp::support::thread_pool_executor pool{workers};
      const auto par = infolerp::detail::make_proxy_cells(pool, pts, 0.7);
      CHECK(par.points.x == ref.points.x);
      CHECK(par.points.y == ref.points.y);
      CHECK(par.points.z == ref.points.z);
      CHECK(par.points.value == ref.points.value);
      CHECK(par.points.weight == ref.points.weight);
      CHECK(par.cell_of == ref.cell_of);
      CHECK(par.order == ref.order);
      CHECK(par.near_start == ref.near_start);
      CHECK(par.near == ref.near);
    }
  }
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(300000);
  for (std::size_t k = 0; k < keyed.size(); ++k) keyed[k] = {static_cast<std::uint64_t>(next() * 1000.0), static_cast<std::uint32_t>(k)};
  auto sorted = keyed;
  std::sort(sorted.begin(), sorted.end());
  // Runs of 7001 sorted, then merged through a pool (the last run shorter).
  for (std::size_t b = 0; b < keyed.size(); b += 7001)
    std::sort(keyed.begin() + static_cast<std::ptrdiff_t>(b),
              keyed.begin() + static_cast<std::ptrdiff_t>(std::min(keyed.size(), b + 7001)));
  infolerp::support::thread_pool_executor pool{3};
  infolerp::detail::merge_sorted_runs(pool, keyed, 7001);
  CHECK(keyed == sorted);
}

TEST_CASE("saliency: the automatic method is exact below exact_below referenced vertices, proxy from there") {
  const auto m = bumpy_sphere(3, bump_dirs, 0.15f, 0.2f);
  const std::size_t nv = m.positions.size();
  auto below = infolerp::compute_saliency(m, {.exact_below = nv + 1});
  auto at = infolerp::compute_saliency(m, {.exact_below = nv});
  REQUIRE(below.ok());
  REQUIRE(at.ok());
  CHECK(below->method == infolerp::saliency_method::exact);
  CHECK(at->method == infolerp::saliency_method::proxy);
  CHECK(infolerp::compute_saliency(m)->method == infolerp::saliency_method::exact);  // default: 200,000
}

TEST_CASE("saliency proxy: bad parameters get a clear status") {
  const auto m = infolerp::support::make_icosphere(2);
  for (double cells : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    INFO("proxy_cells_per_sigma " << cells);
    auto r = infolerp::compute_saliency(m, proxy_options(cells, 0.003));
    REQUIRE(!r.ok());
    CHECK(r.error().code() == infolerp::errc::bad_parameter);
    CHECK(r.error().message().find("proxy_cells_per_sigma") != std::string::npos);
  }
  // Cells so small that the grid would need 2^21 along the diagonal: refused, not wrapped.
  auto tiny = infolerp::compute_saliency(m, proxy_options(1e5, 0.003));
  REQUIRE(!tiny.ok());
  CHECK(tiny.error().code() == infolerp::errc::bad_parameter);
  CHECK(tiny.error().message().find("proxy_cells_per_sigma") != std::string::npos);
  // The same setting is not used, so not refused, by the exact method.
  CHECK(infolerp::compute_saliency(m, {.method = infolerp::saliency_method::exact, .proxy_cells_per_sigma = 1e5}).ok());
  auto bad_method = infolerp::compute_saliency(m, {.method = static_cast<infolerp::saliency_method>(7)});
  REQUIRE(!bad_method.ok());
  CHECK(bad_method.error().code() == infolerp::errc::bad_parameter);
  CHECK(bad_method.error().message().find("method") != std::string::npos);
}
