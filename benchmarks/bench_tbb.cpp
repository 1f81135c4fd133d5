// oneTBB as infolerp's job system (examples/tbb_executor.hpp): 1 against 2 threads on the
// clustering of CGAL's fandisk (visibility through Embree, 64 viewpoints, and orientation),
// and the OpenMP executor on as many threads for comparison. Built when oneTBB is found.
//   BM_Clustering_Fandisk_TBB/threads, BM_Clustering_Fandisk_OpenMP/threads
#ifdef INFOLERP_BENCH_TBB
#include <benchmark/benchmark.h>

#include "infolerp/cluster/cluster_mesh.hpp"
#include "support/embree_tracer.hpp"
#include "support/mesh_io.hpp"
#include "tbb_executor.hpp"

namespace {

namespace sup = infolerp::support;

struct fandisk_scene {
  sup::embree_device device;
  infolerp::indexed_mesh mesh;
  sup::embree_scene tracer{device};
  bool ok = false;
  fandisk_scene() {
    auto m = sup::load_mesh(sup::cgal_mesh("fandisk"));
    if (!m) return;
    mesh = std::move(*m);
    ok = tracer.add_mesh(mesh).ok() && tracer.commit().ok();
  }
};

template <class Exec>
void cluster_fandisk(benchmark::State& state, const Exec& exec) {
  static const fandisk_scene scene;
  if (!scene.ok) {
    state.SkipWithError("fandisk not loaded");
    return;
  }
  for (auto _ : state) {
    auto r = infolerp::cluster_mesh(scene.mesh, scene.tracer, exec,
                                    infolerp::visibility_channel{.threshold = 0.48, .viewpoints = 64},
                                    infolerp::orientation_channel{.threshold = 0.05, .bins = 256});
    if (!r) state.SkipWithError(r.error().message().c_str());
    benchmark::DoNotOptimize(r);
  }
}

void BM_Clustering_Fandisk_TBB(benchmark::State& state) {
  cluster_fandisk(state, examples::tbb_executor{static_cast<int>(state.range(0))});
}
BENCHMARK(BM_Clustering_Fandisk_TBB)->Arg(1)->Arg(2)->Repetitions(5)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_Clustering_Fandisk_OpenMP(benchmark::State& state) {
  cluster_fandisk(state, infolerp::openmp_executor{static_cast<int>(state.range(0))});
}
BENCHMARK(BM_Clustering_Fandisk_OpenMP)->Arg(1)->Arg(2)->Repetitions(5)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
#endif
