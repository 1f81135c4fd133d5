// Determinism: every component gives bit-identical output across repeated runs
// and for the serial executor and thread_pool_executor with 1, 2 and 8 workers (small grains,
// so that the work really is split). Components without an executor parameter (topology,
// salient clustering, subdivision, Jensen–Shannon) are checked across repeated runs and with
// inputs produced by every executor.
//
// Tagged [threads]: .ci/sanitizers.sh runs these under ThreadSanitizer. Nothing here uses
// OpenMP or Embree (their runtimes are not instrumented and would give false reports).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>
#include <glm/gtc/matrix_transform.hpp>
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/info/jensen_shannon.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/topology.hpp"
#include "infolerp/refine/progressive_driver.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"
#include "infolerp/saliency/cluster_importance.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "reliability/reliability_support.hpp"
#include "support/brute_force_tracer.hpp"
#include "support/procedural.hpp"
#include "support/thread_pool.hpp"

namespace {

using infolerp::indexed_mesh;
using infolerp::support::thread_pool_executor;

// Same bytes (so NaN payloads and signed zeros count too).
template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

indexed_mesh bumpy_sphere(unsigned level) {
  auto m = infolerp::support::make_icosphere(level);
  for (auto& p : m.positions)
    p *= 1.0f + 0.06f * std::sin(9.0f * p.x) * std::sin(7.0f * p.y + 1.0f) * std::cos(5.0f * p.z);
  return m;
}

// Every number of a cluster table, in order.
std::vector<double> flatten(const infolerp::cluster_table& t) {
  std::vector<double> out{t.mesh_saliency};
  for (const auto& c : t.clusters)
    out.insert(out.end(), {c.centroid.x, c.centroid.y, c.centroid.z, c.area, c.mean_normal.x, c.mean_normal.y,
                           c.mean_normal.z, c.peak_normal_deviation, c.radius, c.total_saliency, c.mean_saliency,
                           c.peak_saliency, static_cast<double>(c.faces)});
  return out;
}

// Runs f(executor) with the serial executor, then 1, 2 and 8 workers, twice each; returns the
// outputs so the caller compares them.
template <class F>
auto with_every_executor(F&& f) {
  std::vector<decltype(f(infolerp::serial_executor{}))> outs;
  for (int rep = 0; rep < 2; ++rep) {
    outs.push_back(f(infolerp::serial_executor{}));
    for (unsigned w : {1u, 2u, 8u}) outs.push_back(f(thread_pool_executor{w}));
  }
  return outs;
}

}  // namespace

TEST_CASE("determinism: topology and curvature across repeated runs", "[reliability][determinism][threads]") {
  const indexed_mesh m = bumpy_sphere(3);
  const auto a = infolerp::make_topology(m), b = infolerp::make_topology(m);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  CHECK(same_bits(a->edges, b->edges));
  CHECK(same_bits(a->triangle_edges, b->triangle_edges));
  CHECK(same_bits(a->edge_faces, b->edge_faces));
  CHECK(same_bits(a->neighbours, b->neighbours));
  CHECK(same_bits(*infolerp::mean_curvature(m), *infolerp::mean_curvature(m)));
}

TEST_CASE("determinism: clustering (Algorithm 1, three channels) for 1, 2, 8 workers", "[reliability][determinism][threads]") {
  indexed_mesh m = infolerp::support::make_uv_sphere(16, 10);  // textured: the stretch channel runs
  infolerp::support::append(m, infolerp::support::make_plane(4, 4, 1.5f),
                            glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, -1.3f)));
  const infolerp::support::brute_force_tracer tracer{&m};
  const auto outs = with_every_executor([&](auto exec) {
    auto r = infolerp::cluster_mesh(m, tracer, exec, infolerp::cluster_options{.grain = 2},
                                    infolerp::visibility_channel{.threshold = 0.2, .viewpoints = 12, .samples_per_side = 1,
                                                                 .grain = 4},
                                    infolerp::orientation_channel{.threshold = 0.02, .bins = 64},
                                    infolerp::stretch_channel{.threshold = 0.05, .bins = 0});
    REQUIRE(r.ok());
    return *r;
  });
  CHECK(outs[0].cluster_count > 2);
  for (const auto& o : outs) {
    CHECK(same_bits(o.cluster_of, outs[0].cluster_of));
    CHECK(o.cluster_count == outs[0].cluster_count);
  }
}

TEST_CASE("determinism: saliency for 1, 2, 8 workers", "[reliability][determinism][threads]") {
  const indexed_mesh m = bumpy_sphere(3);
  const auto outs = with_every_executor([&](auto exec) {
    auto r = infolerp::compute_saliency(m, {.epsilon = 0.02, .grain = 1}, exec);
    REQUIRE(r.ok());
    return *r;
  });
  for (const auto& o : outs) {
    CHECK(same_bits(o.saliency, outs[0].saliency));
    CHECK(same_bits(o.curvature, outs[0].curvature));
    for (std::size_t i = 0; i < o.levels.size(); ++i) CHECK(same_bits(o.levels[i], outs[0].levels[i]));
  }
}

TEST_CASE("determinism: salient clustering and cluster importance", "[reliability][determinism][threads]") {
  const indexed_mesh m = bumpy_sphere(3);
  const auto sal = with_every_executor([&](auto exec) {
    return infolerp::compute_saliency(m, {.epsilon = 0.02, .grain = 1}, exec)->saliency;
  });
  std::vector<std::uint32_t> first;
  for (const auto& s : sal) {
    auto c = infolerp::salient_clustering(m, s, {.clusters = 12, .seed = 3});
    REQUIRE(c.ok());
    if (first.empty()) first = c->cluster;
    CHECK(same_bits(c->cluster, first));
    auto t1 = infolerp::compute_cluster_attributes(m, s, c->cluster, c->count);
    auto t2 = infolerp::compute_cluster_attributes(m, s, c->cluster, c->count);
    REQUIRE(t1.ok());
    REQUIRE(t2.ok());
    CHECK(same_bits(flatten(*t1), flatten(*t2)));
    CHECK(same_bits(*infolerp::cluster_localized_saliency(m, s, c->cluster, c->count),
                    *infolerp::cluster_localized_saliency(m, s, c->cluster, c->count)));
  }
}

TEST_CASE("determinism: subdivision and the progressive driver for 1, 2, 8 workers", "[reliability][determinism][threads]") {
  const indexed_mesh m = infolerp::support::make_plane(3, 2, 2.0f);
  {  // the subdivision mesh alone, same selections twice
    auto run = [&] {
      auto s = infolerp::subdivision_mesh::create(m);
      REQUIRE(s.ok());
      std::uint32_t t = 0;
      for (int i = 0; i < 40; ++i) {
        REQUIRE(s->split(t).ok());
        t = static_cast<std::uint32_t>((t * 7u + 3u) % s->triangle_count());
      }
      return s->leaf_mesh();
    };
    const auto a = run(), b = run();
    CHECK(same_bits(a.positions, b.positions));
    CHECK(same_bits(a.triangles, b.triangles));
  }
  const infolerp::pinhole_camera cam{.eye = {0.1f, 0.05f, 1.8f}, .target = {0, 0, 0}, .up = {0, 1, 0},
                                     .vertical_fov_degrees = 60.0f, .width = 48, .height = 40};
  auto shade = [](const infolerp::shading_point& sp) {
    return sp.position.x < 0.23f ? glm::vec3(0.05f) : glm::vec3(0.9f, 0.8f, 0.7f + 0.1f * sp.position.y);
  };
  for (auto criterion : {infolerp::refinement_criterion::nld_os, infolerp::refinement_criterion::nld_is,
                         infolerp::refinement_criterion::rnd}) {
    INFO("criterion " << infolerp::to_string(criterion));
    struct outcome {
      std::vector<glm::vec3> image;
      std::vector<std::size_t> figures;
    };
    const auto outs = with_every_executor([&](auto exec) {
      auto r = infolerp::progressive_refiner::create(
          *infolerp::subdivision_mesh::create(m),
          {.criteria = {.criterion = criterion, .s_req = 0.02f, .min_pixels = 2.0f, .batch = 5}, .grain = 16});
      REQUIRE(r.ok());
      auto rep = r->run(infolerp::support::brute_force_tracer{&m}, cam, shade, exec);
      REQUIRE(rep.ok());
      outcome o;
      o.image.resize(std::size_t(cam.width) * cam.height);
      r->reconstruct(o.image);
      o.figures = {rep->stage1.triangles, rep->stage1.shading_samples, rep->stage2.triangles,
                   rep->stage2.triangles_total, rep->stage2.triangles_produced, rep->stage2.shading_samples,
                   rep->batches, rep->selections};
      return o;
    });
    CHECK(outs[0].figures[6] > 0);  // stage 2 ran at least one batch
    for (const auto& o : outs) {
      CHECK(same_bits(o.image, outs[0].image));
      CHECK(o.figures == outs[0].figures);
    }
  }
}

TEST_CASE("determinism: upsampler for 1, 2, 8 workers and every pass count", "[reliability][determinism][threads]") {
  const std::uint32_t ids[5] = {0, 1, 1, infolerp::invalid_id, 2};
  const infolerp::reliability::table_source src{ids, 6};
  using up_t = infolerp::upsampler<infolerp::reliability::table_source::sample_type>;
  for (std::uint32_t passes = 1; passes <= 5; ++passes) {
    INFO("passes " << passes);
    struct outcome {
      std::vector<glm::vec3> image;
      std::vector<infolerp::sample_kind> kinds;
      std::size_t evaluated;
    };
    const auto outs = with_every_executor([&](auto exec) {
      auto up = up_t::create(97, 61, {.passes = passes, .max_passes = 5, .rows_per_task = 1});
      REQUIRE(up.ok());
      outcome o;
      o.image.assign(97 * 61, glm::vec3(-1.0f));
      REQUIRE(up->render(src, std::span<glm::vec3>(o.image), exec).ok());
      o.kinds.assign(up->kinds().begin(), up->kinds().end());
      o.evaluated = up->stats().evaluated();
      return o;
    });
    for (const auto& o : outs) {
      CHECK(same_bits(o.image, outs[0].image));
      CHECK(same_bits(o.kinds, outs[0].kinds));
      CHECK(o.evaluated == outs[0].evaluated);
    }
  }
}

TEST_CASE("determinism: Jensen-Shannon across repeated runs and float/double paths", "[reliability][determinism][threads]") {
  std::vector<double> p(1001), q(1001);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p[i] = 1.0 + std::sin(0.37 * static_cast<double>(i));
    q[i] = 1.0 + std::cos(0.11 * static_cast<double>(i));
  }
  const double a = *infolerp::jensen_shannon(std::span<const double>(p), std::span<const double>(q), 0.3);
  const double b = *infolerp::jensen_shannon(std::span<const double>(p), std::span<const double>(q), 0.3);
  CHECK(std::memcmp(&a, &b, sizeof a) == 0);
}
