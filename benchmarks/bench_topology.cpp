// Topology build throughput on a real ~100k-triangle mesh (CGAL's refined_elephant).
// Goal: at least 5 million triangles per second on one core.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <cstring>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/mesh/topology.hpp"
#include "support/mesh_io.hpp"

static void BM_Topology_RefinedElephant(benchmark::State& state) {
  auto m = infolerp::support::load_mesh(infolerp::support::cgal_mesh("refined_elephant"));
  if (!m.ok()) {
    state.SkipWithError(m.error().message().c_str());
    return;
  }
  for (auto _ : state) {
    auto topo = infolerp::make_topology(*m);
    benchmark::DoNotOptimize(topo);
  }
  state.counters["triangles"] = static_cast<double>(m->triangles.size());
  state.counters["triangles_per_second"] = benchmark::Counter(
      static_cast<double>(m->triangles.size()) * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Topology_RefinedElephant)->Unit(benchmark::kMillisecond);

// Reference for the row above, in the same run: copying the mesh's index buffer (a memcpy of
// 12 bytes per triangle), the least any pass over the triangles can cost.
static void BM_Topology_RefinedElephant_Memcpy(benchmark::State& state) {
  auto m = infolerp::support::load_mesh(infolerp::support::cgal_mesh("refined_elephant"));
  if (!m.ok()) {
    state.SkipWithError(m.error().message().c_str());
    return;
  }
  std::vector<glm::uvec3> copy(m->triangles.size());
  for (auto _ : state) {
    std::memcpy(copy.data(), m->triangles.data(), m->triangles.size() * sizeof(glm::uvec3));
    benchmark::DoNotOptimize(copy.data());
    benchmark::ClobberMemory();
  }
  state.counters["triangles_per_second"] = benchmark::Counter(
      static_cast<double>(m->triangles.size()) * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Topology_RefinedElephant_Memcpy)->Unit(benchmark::kMillisecond);
