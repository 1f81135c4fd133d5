// infolerp_pareto pipeline [--reps N] [--threads N] [--rounds R] [--csv FILE] [--no-plain] [--no-detail]
//
// The salient-clustering pipeline's scale: the default pipeline (compute_saliency, salient_clustering,
// weighting_map, make_contraction_hierarchy, compute_cluster_attributes) on two pairs of meshes:
// bunny00 split 1:4 at edge midpoints once (301,632 triangles) and twice (1,206,528), whose new
// vertices carry no detail (mesh bunny00_split), and the same two with noise along the normals at
// every scale from 3 of their edge lengths up (mesh bunny00_split_detail, pareto.hpp's
// with_noise_detail); the four runs in turn in each of --reps repetitions (default 3; --no-plain,
// --no-detail: leave out a pair). Each run is a child process (fork) that builds its mesh, untimed,
// then runs the pipeline, so that its peak resident memory (getrusage of the child) is the
// pipeline's and not the other size's. Default options everywhere, except salient clustering's
// max_iterations = --rounds (default 8), so that both sizes run the same number of rounds and
// chance does not decide the ratio (its round count is chance, not size: benchmarks/NOTES.md);
// saliency, clustering and weights get an OpenMP executor of --threads (default 2).
// CSV: rep,mesh,triangles,saliency_s,clustering_s,rounds,weights_s,hierarchy_s,table_s,total_s,peak_mib
// stdout adds per mesh and stage the min, median and max of the pairwise ratios 1.2M / 300k.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>
#include "infolerp/core/executor.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/weighting_map.hpp"
#include "infolerp/saliency/cluster_importance.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"
#include "pareto.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"

namespace {

using namespace infolerp;
using clk = std::chrono::steady_clock;

constexpr int stages = 6;  // saliency, clustering, weights, hierarchy, table, total
const char* const stage_names[stages] = {"saliency", "clustering", "weights", "hierarchy", "table", "total"};

struct run_result {
  double seconds[stages] = {};
  double rounds = 0.0;
  double peak_mib = 0.0;
  std::size_t triangles = 0;
  bool ok = false;
};

// In the child: bunny00 split `splits` times (with noise detail if `detail`), then the pipeline,
// timed per stage.
bool pipeline(int splits, bool detail, int threads, std::uint32_t rounds, run_result& r) {
  auto base = support::load_mesh(support::cgal_mesh("bunny00"));
  if (!base.ok()) return false;
  indexed_mesh m = std::move(*base);
  for (int i = 0; i < splits; ++i) m = support::subdivide_midpoint(m);
  if (detail) m = with_noise_detail(m);
  r.triangles = m.triangle_count();
  const openmp_executor exec{threads};
  auto lap = [t = clk::now()]() mutable {
    const auto now = clk::now();
    const double s = std::chrono::duration<double>(now - t).count();
    t = now;
    return s;
  };
  const auto t0 = clk::now();
  lap();
  auto sal = compute_saliency(m, {}, exec);
  if (!sal.ok()) return false;
  r.seconds[0] = lap();
  auto cl = salient_clustering(m, sal->saliency, {.clusters = 10, .max_iterations = rounds}, exec);
  if (!cl.ok()) return false;
  r.seconds[1] = lap();
  r.rounds = cl->iterations;
  auto w = weighting_map(m, sal->saliency, cl->cluster, cl->count, {}, exec);
  if (!w.ok()) return false;
  r.seconds[2] = lap();
  auto h = make_contraction_hierarchy(m, *w, cl->cluster, cl->count);
  if (!h.ok()) return false;
  r.seconds[3] = lap();
  auto table = compute_cluster_attributes(m, sal->saliency, cl->cluster, cl->count);
  if (!table.ok()) return false;
  r.seconds[4] = lap();
  r.seconds[5] = std::chrono::duration<double>(clk::now() - t0).count();
  return true;
}

// Runs the pipeline in a child process; the parent reads its result and peak memory.
run_result run_child(int splits, bool detail, int threads, std::uint32_t rounds) {
  run_result r;
  int fd[2];
  if (pipe(fd) != 0) return r;
  std::fflush(stdout);
  const pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    run_result c;
    c.ok = pipeline(splits, detail, threads, rounds, c);
    const ssize_t n = write(fd[1], &c, sizeof c);
    _exit(n == static_cast<ssize_t>(sizeof c) ? 0 : 1);
  }
  close(fd[1]);
  if (pid < 0) return close(fd[0]), r;
  const ssize_t n = read(fd[0], &r, sizeof r);
  close(fd[0]);
  int status = 0;
  rusage use{};
  wait4(pid, &status, 0, &use);
  if (n != static_cast<ssize_t>(sizeof r)) r.ok = false;
  r.peak_mib = static_cast<double>(use.ru_maxrss) / 1024.0;  // Linux: kilobytes
  return r;
}

}  // namespace

int pareto_pipeline(int argc, char** argv) {
  int reps = 3, threads = 2;
  std::uint32_t rounds = 8;
  std::string csv_path;
  bool plain = true, detailed = true;
  for (int i = 1; i < argc; ++i) {
    const auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (!std::strcmp(argv[i], "--reps")) reps = std::max(1, std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--threads")) threads = std::max(1, std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--rounds")) rounds = static_cast<std::uint32_t>(std::max(1, std::atoi(next().c_str())));
    else if (!std::strcmp(argv[i], "--csv")) csv_path = next();
    else if (!std::strcmp(argv[i], "--no-plain")) plain = false;
    else if (!std::strcmp(argv[i], "--no-detail")) detailed = false;
    else {
      std::fprintf(stderr, "usage: infolerp_pareto pipeline [--reps N] [--threads N] [--rounds R] [--csv FILE]"
                   " [--no-plain] [--no-detail]\n");
      return 2;
    }
  }
  std::FILE* csv = csv_path.empty() ? nullptr : std::fopen(csv_path.c_str(), "w");
  if (!csv_path.empty() && !csv) return std::fprintf(stderr, "cannot write %s\n", csv_path.c_str()), 1;
  const char* header = "rep,mesh,triangles,saliency_s,clustering_s,rounds,weights_s,hierarchy_s,table_s,total_s,peak_mib\n";
  std::printf("%s", header);
  if (csv) std::fprintf(csv, "%s", header);
  std::vector<bool> kinds;  // detail or not
  if (plain) kinds.push_back(false);
  if (detailed) kinds.push_back(true);
  std::vector<std::vector<double>> ratio(kinds.size() * (stages + 1));  // per mesh, per stage, then peak memory
  for (int r = 0; r < reps; ++r)
    for (std::size_t k = 0; k < kinds.size(); ++k) {
      const char* mesh = kinds[k] ? "bunny00_split_detail" : "bunny00_split";
      run_result small, large;
      for (int splits : {1, 2}) {
        run_result& x = splits == 1 ? small : large;
        x = run_child(splits, kinds[k], threads, rounds);
        if (!x.ok) return std::fprintf(stderr, "pipeline failed (%s, %d splits)\n", mesh, splits), 1;
        for (std::FILE* o : {stdout, csv}) {
          if (!o) continue;
          std::fprintf(o, "%d,%s,%zu,%.4f,%.4f,%.0f,%.4f,%.4f,%.4f,%.4f,%.1f\n", r, mesh, x.triangles, x.seconds[0], x.seconds[1],
                       x.rounds, x.seconds[2], x.seconds[3], x.seconds[4], x.seconds[5], x.peak_mib);
          std::fflush(o);
        }
      }
      for (int s = 0; s < stages; ++s) ratio[k * (stages + 1) + static_cast<std::size_t>(s)].push_back(large.seconds[s] / small.seconds[s]);
      ratio[k * (stages + 1) + stages].push_back(large.peak_mib / small.peak_mib);
    }
  for (std::size_t k = 0; k < kinds.size(); ++k)
    for (int s = 0; s <= stages; ++s) {
      std::vector<double> v = ratio[k * (stages + 1) + static_cast<std::size_t>(s)];
      std::sort(v.begin(), v.end());
      std::printf("# %s %s 1.2M / 300k (pairwise): min %.2f median %.2f max %.2f\n", kinds[k] ? "bunny00_split_detail" : "bunny00_split",
                  s < stages ? stage_names[s] : "peak memory", v.front(), v[v.size() / 2], v.back());
    }
  if (csv) std::fclose(csv);
  return 0;
}
