// Raw ray cost through the Embree adaptor on CGAL's bunny00 (75k triangles), one core: single
// rays against 16-ray packets. The visibility channel and the upsampler compare against these.
// Rays: 4096 incoherent rays, half from outside aimed into the bounding box, half from inside
// the box in random directions (the mix AO and visibility rays see).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/mesh/geometry.hpp"
#include "support/embree_tracer.hpp"
#include "support/mesh_io.hpp"

namespace {

namespace support = infolerp::support;

struct bunny_fixture {
  support::embree_device device{"threads=1"};
  support::embree_scene scene{device};
  std::vector<infolerp::ray> rays;
  bool ok = false;

  bunny_fixture() {
    support::enable_flush_to_zero();
    auto m = support::load_mesh(support::cgal_mesh("bunny00"));
    if (!m || !scene.add_mesh(*m) || !scene.commit()) return;
    const auto box = infolerp::mesh_bounds(*m);
    const glm::vec3 lo(box.lo), hi(box.hi), c(box.center());
    const auto diag = static_cast<float>(box.diagonal());
    std::mt19937 g(42);
    auto uniform = [&] { return static_cast<float>(g() >> 8) * 0x1p-24f; };
    auto unit = [&] {
      const float z = 2.0f * uniform() - 1.0f, phi = 6.2831853f * uniform(), r = std::sqrt(1.0f - z * z);
      return glm::vec3(r * std::cos(phi), r * std::sin(phi), z);
    };
    auto in_box = [&] { return lo + (hi - lo) * glm::vec3(uniform(), uniform(), uniform()); };
    rays.resize(4096);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      if (i % 2 == 0) {
        rays[i].origin = c + diag * unit();
        rays[i].direction = glm::normalize(in_box() - rays[i].origin);
      } else {
        rays[i].origin = in_box();
        rays[i].direction = unit();
      }
    }
    ok = true;
  }
};

const bunny_fixture& fixture() {
  static const bunny_fixture f;
  return f;
}

void set_rate(benchmark::State& state, std::size_t rays_per_iteration) {
  state.counters["rays_per_second"] = benchmark::Counter(
      static_cast<double>(rays_per_iteration) * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

}  // namespace

static void BM_Embree_Occluded_Single(benchmark::State& state) {
  const auto& f = fixture();
  if (!f.ok) return state.SkipWithError("cannot load bunny00");
  support::enable_flush_to_zero();
  for (auto _ : state) {
    unsigned blocked = 0;
    for (const auto& r : f.rays) blocked += f.scene.occluded(r) ? 1u : 0u;
    benchmark::DoNotOptimize(blocked);
  }
  set_rate(state, f.rays.size());
}
BENCHMARK(BM_Embree_Occluded_Single)->Unit(benchmark::kMicrosecond);

static void BM_Embree_Occluded_Packet16(benchmark::State& state) {
  const auto& f = fixture();
  if (!f.ok) return state.SkipWithError("cannot load bunny00");
  support::enable_flush_to_zero();
  std::vector<std::uint8_t> out(f.rays.size());
  for (auto _ : state) {
    f.scene.occluded(f.rays, out);
    benchmark::DoNotOptimize(out.data());
  }
  set_rate(state, f.rays.size());
}
BENCHMARK(BM_Embree_Occluded_Packet16)->Unit(benchmark::kMicrosecond);

static void BM_Embree_Intersect_Single(benchmark::State& state) {
  const auto& f = fixture();
  if (!f.ok) return state.SkipWithError("cannot load bunny00");
  support::enable_flush_to_zero();
  for (auto _ : state) {
    float sum = 0.0f;
    for (const auto& r : f.rays) sum += f.scene.intersect(r).barycentric.x;
    benchmark::DoNotOptimize(sum);
  }
  set_rate(state, f.rays.size());
}
BENCHMARK(BM_Embree_Intersect_Single)->Unit(benchmark::kMicrosecond);

static void BM_Embree_Intersect_Packet16(benchmark::State& state) {
  const auto& f = fixture();
  if (!f.ok) return state.SkipWithError("cannot load bunny00");
  support::enable_flush_to_zero();
  std::vector<infolerp::hit> out(f.rays.size());
  for (auto _ : state) {
    f.scene.intersect(f.rays, out);
    benchmark::DoNotOptimize(out.data());
  }
  set_rate(state, f.rays.size());
}
BENCHMARK(BM_Embree_Intersect_Packet16)->Unit(benchmark::kMicrosecond);
