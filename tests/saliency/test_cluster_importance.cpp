// saliency/cluster_importance.hpp on hand-checked cases (eqs. 5-9).
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <vector>
#include "infolerp/mesh/adaptors.hpp"
#include "infolerp/saliency/cluster_importance.hpp"

namespace {
constexpr double pi = 3.14159265358979323846;
// Cluster 0: triangle in z = 0 facing +z. Cluster 1: triangle in x = 5 facing +x.
infolerp::indexed_mesh two_triangles() {
  infolerp::indexed_mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 0, 0}, {5, 2, 0}, {5, 0, 2}};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  return m;
}
}  // namespace

TEST_CASE("cluster attributes and per-view estimates by hand") {
  const auto m = two_triangles();
  const std::vector<double> sal{0.3, 0.6, 0.9, 0.1, 0.1, 0.4};
  const std::vector<std::uint32_t> cluster{0, 1};
  auto table = infolerp::compute_cluster_attributes(m, sal, cluster, 2);
  REQUIRE(table.ok());
  const auto& c0 = table->clusters[0];
  CHECK(c0.area == Approx(0.5));
  CHECK(c0.centroid.x == Approx(1.0 / 3));
  CHECK(c0.centroid.y == Approx(1.0 / 3));
  CHECK(c0.mean_normal.z == Approx(1.0));
  CHECK(c0.peak_normal_deviation == Approx(0.0).margin(1e-12));
  CHECK(c0.radius == Approx(std::sqrt(5.0) / 3));
  CHECK(c0.total_saliency == Approx(0.6));
  CHECK(c0.peak_saliency == Approx(0.6));
  CHECK(table->clusters[1].total_saliency == Approx(0.2));
  CHECK(table->clusters[1].mean_normal.x == Approx(1.0));
  CHECK(table->mesh_saliency == Approx(0.8));

  // Camera straight above cluster 0: v_cam is opposite the normal, λ_angle = π.
  auto view = infolerp::estimate_view_importance(*table, {1.0 / 3, 1.0 / 3, 10.0});
  REQUIRE(view.ok());
  CHECK(view->area_estimate[0] == Approx(pi / (10.0 - std::sqrt(5.0) / 3) * 0.5));
  CHECK(view->importance_estimate[0] == Approx(0.6 * 0.6 * 0.6 / 0.8));
  CHECK(view->importance_estimate[1] == Approx(0.2 * 0.2 * 0.2 / 0.8));
  // Cluster 1 seen from above: v_cam ⟂ its normal, λ_angle = π/2.
  const glm::dvec3 cam{1.0 / 3, 1.0 / 3, 10.0};
  const auto& c1 = table->clusters[1];
  CHECK(view->area_estimate[1] ==
        Approx(std::acos(glm::dot(glm::normalize(c1.centroid - cam), c1.mean_normal)) /
               (glm::length(c1.centroid - cam) - c1.radius) * 2.0));

  // Camera inside cluster 0's bounding sphere: its λ_dist falls back to the first positive one
  // (cluster 1's), since no earlier cluster had one.
  const glm::dvec3 inside{0.3, 0.3, 0.1};
  auto near = infolerp::estimate_view_importance(*table, inside);
  REQUIRE(near.ok());
  const double d1 = glm::length(c1.centroid - inside) - c1.radius;
  const double angle0 = std::acos(glm::dot(glm::normalize(c0.centroid - inside), c0.mean_normal));
  CHECK(near->area_estimate[0] == Approx(angle0 / d1 * 0.5));
  CHECK(std::isfinite(near->area_estimate[0]));
}

TEST_CASE("per-view estimates stay finite for huge but finite saliency") {
  const auto m = two_triangles();
  for (const double big : {1e120, 1e200, 1e307, std::numeric_limits<double>::max()}) {
    INFO("saliency up to " << big);
    const std::vector<double> sal{big, big, big, 0.5 * big, 0.25 * big, 1.0};
    auto table = infolerp::compute_cluster_attributes(m, sal, std::vector<std::uint32_t>{0, 1}, 2);
    REQUIRE(table.ok());
    auto view = infolerp::estimate_view_importance(*table, {1.0 / 3, 1.0 / 3, 10.0});
    REQUIRE(view.ok());
    for (std::size_t k = 0; k < 2; ++k) {
      CHECK(std::isfinite(view->importance_estimate[k]));
      // Positive while the mesh's total saliency is finite (at DBL_MAX the sums overflow and a
      // cluster's share of them is 0 or all).
      if (big <= 1e307) CHECK(view->importance_estimate[k] > 0.0);
    }
    // The more salient cluster stays at least as important (both may reach the cap).
    CHECK(view->importance_estimate[0] >= view->importance_estimate[1]);
  }
}

TEST_CASE("budget distribution (eq. 9) by hand") {
  // Order by priority: cluster 1, 2, 0. Step ceil(0.02 * 100) = 2; cluster 1 fills at 5.
  const std::vector<double> priority{3.0, 1.0, 2.0};
  const std::vector<std::uint64_t> capacity{100, 5, 100};
  auto r = infolerp::distribute_contractions(priority, capacity, 100);
  REQUIRE(r.ok());
  CHECK(*r == std::vector<std::uint64_t>{47, 5, 48});
  // A target beyond all capacity fills every cluster.
  auto full = infolerp::distribute_contractions(priority, capacity, 1000);
  REQUIRE(full.ok());
  CHECK(*full == std::vector<std::uint64_t>{100, 5, 100});
  // The largest target: λ_perc · 2^64 cannot be cast to an integer; every cluster still fills.
  auto most = infolerp::distribute_contractions(priority, capacity, UINT64_MAX);
  REQUIRE(most.ok());
  CHECK(*most == std::vector<std::uint64_t>{100, 5, 100});
  // A small target: the step rounds up to 1, the two least important clusters take one each.
  auto small = infolerp::distribute_contractions(priority, capacity, 2);
  CHECK(*small == std::vector<std::uint64_t>{0, 1, 1});
  // λ_perc = 0.5: the least important cluster takes half, the next one the rest.
  auto half = infolerp::distribute_contractions(priority, capacity, 10, 0.5);
  CHECK(*half == std::vector<std::uint64_t>{0, 5, 5});
  CHECK(infolerp::distribute_contractions(priority, capacity, 10, 0.0).error().code() == infolerp::errc::bad_parameter);
  CHECK(infolerp::distribute_contractions(priority, std::vector<std::uint64_t>{1}, 10).error().code() ==
        infolerp::errc::bad_size);
}

TEST_CASE("cluster attributes: bad input gets a clear status") {
  const auto m = two_triangles();
  const std::vector<double> sal(6, 0.5);
  const std::vector<std::uint32_t> bad{0, 7};
  auto r = infolerp::compute_cluster_attributes(m, sal, bad, 2);
  CHECK(r.error().code() == infolerp::errc::index_out_of_range);
  CHECK(r.error().element() == 1);
  CHECK(infolerp::compute_cluster_attributes(m, sal, std::vector<std::uint32_t>{0}, 2).error().code() ==
        infolerp::errc::bad_size);
}
