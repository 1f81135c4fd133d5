// infolerp_pareto visibility --csv FILE [--reps R] [--meshes a,b,...] [--options o,o:setting,...]
//
// Time against error of the visibility channel's options (cluster/visibility_channel.hpp) on
// CGAL's meshes (default refined_elephant and armadillo), one core (serial executor, Embree
// device with one thread), every configuration timed R times (default 3) interleaved in one run.
//
// CSV: mesh,option,setting,seconds,rays,mean_js,max_js,ari,ari_self
//   seconds    median of the R prepare() times (the whole channel: rays and counting)
//   rays       rays handed to the tracer in one prepare()
//   mean_js, max_js   JS (bits, equal weights) between each triangle's raw p(V|t) row and the
//              reference's row (1 where exactly one of the two is unseen)
//   ari        adjusted Rand index of the visibility clusters (Algorithm 1 with this channel
//              alone, Th = 0.48) against the reference's clusters
//   ari_self   the reference's clusters at Th x 1.01 against those at Th (same on every row)
// Rows: option=default (n = 2, 64 viewpoints), option=reference (n = 4), then one row per option
// and setting (--options keeps only the listed options, or option:setting pairs, beside those two); options whose name starts with "exact" must give the default's counts bit for
// bit (checked here: the run fails otherwise).
// Rows with setting "stream" trace through an Embree scene with coherent_streams
// (rtcOccluded1M, flagged coherent) instead of 16-ray packets.
// Beside the CSV: FILE.png (seconds against mean_js, gnuplot) and FILE.gp (its script), with a
// trailing .csv of FILE replaced.
// Also printed: min and median seconds per row (wall, and the process's CPU time), the peak RSS of the process, and per mesh the
// peak memory (VmHWM) of a forked child that loads the mesh, builds the Embree scenes and runs
// one prepare() of the default, of the largest image and of the neighbour rule, against the
// child's VmHWM before prepare() and the T·N bytes of counts.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/info/jensen_shannon.hpp"
#include "pareto.hpp"
#include "support/adjusted_rand_index.hpp"
#include "support/embree_tracer.hpp"
#include "support/mesh_io.hpp"

namespace {

using namespace infolerp;

// CPU time of the whole process: the harness is serial (one Embree thread), so this is the
// configuration's own work, less moved than wall time by the other processes of a shared machine.
double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Forwards to Embree and counts the rays it is asked about.
struct counting_tracer {
  const support::embree_scene* scene;
  std::atomic<std::size_t>* rays;
  bool occluded(const ray& r) const {
    rays->fetch_add(1, std::memory_order_relaxed);
    return scene->occluded(r);
  }
  hit intersect(const ray& r) const {
    rays->fetch_add(1, std::memory_order_relaxed);
    return scene->intersect(r);
  }
  void occluded(std::span<const ray> r, std::span<std::uint8_t> out) const {
    rays->fetch_add(r.size(), std::memory_order_relaxed);
    scene->occluded(r, out);
  }
  void intersect(std::span<const ray> r, std::span<hit> out) const {
    rays->fetch_add(r.size(), std::memory_order_relaxed);
    scene->intersect(r, out);
  }
};

struct config {
  std::string option, setting;
  visibility_channel channel;
  bool stream = false;  // traced through the scene with coherent_streams (Embree's rtcOccluded1M)
};

std::vector<config> configs() {
  const visibility_channel base{.threshold = 0.48, .viewpoints = 64, .samples_per_side = 2};
  std::vector<config> out;
  auto with = [&](std::string option, std::string setting, auto edit) {
    visibility_channel c = base;
    edit(c);
    out.push_back({std::move(option), std::move(setting), c});
  };
  with("default", "n=2", [](visibility_channel&) {});
  with("reference", "n=4", [](visibility_channel& c) { c.samples_per_side = 4; });
  with("exact_coherent", "on", [](visibility_channel& c) { c.coherent = true; });
  with("exact_cull_hull", "on", [](visibility_channel& c) { c.cull_hull = true; });
  with("exact_coherent_cull_hull", "on", [](visibility_channel& c) { c.coherent = c.cull_hull = true; });
  with("exact_coherent", "stream", [](visibility_channel& c) { c.coherent = true; });
  out.back().stream = true;
  with("exact_coherent_cull_hull", "stream", [](visibility_channel& c) { c.coherent = c.cull_hull = true; });
  out.back().stream = true;
  // Approximate: fewer samples, and adaptive sampling (all through coherent streams).
  with("samples", "n1_stream", [](visibility_channel& c) { c.coherent = true; c.samples_per_side = 1; });
  out.back().stream = true;
  for (std::uint32_t n : {2u, 3u, 4u})
    for (std::uint32_t probes : {1u, 2u, 4u}) {
      if (probes >= n * n) continue;
      char setting[32];
      std::snprintf(setting, sizeof setting, "n%u_P%u_stream", n, probes);
      with("adaptive", setting, [=](visibility_channel& c) {
        c.coherent = true;
        c.samples_per_side = n;
        c.adaptive_probes = probes;
      });
      out.back().stream = true;
      std::snprintf(setting, sizeof setting, "n%u_P%u_stream", n, probes);
      with("adaptive_neighbours", setting, [=](visibility_channel& c) {
        c.coherent = true;
        c.samples_per_side = n;
        c.adaptive_probes = probes;
        c.adaptive_neighbours = true;
      });
      out.back().stream = true;
    }
  // The paper's measurement: one image per viewpoint (resolution R, fallback under M pixels).
  for (const auto& [r, m] : std::vector<std::pair<std::uint32_t, double>>{
           {256, 4.0}, {512, 1.0}, {512, 4.0}, {512, 16.0}, {1024, 4.0}}) {
    const std::uint32_t res = r;  // copies: clang 14 cannot capture structured bindings
    const double min_pixels = m;
    char setting[32];
    std::snprintf(setting, sizeof setting, "r%u_m%g_stream", res, min_pixels);
    with("images", setting, [=](visibility_channel& c) {
      c.images = true;
      c.image_resolution = res;
      c.image_min_pixels = min_pixels;
    });
    out.back().stream = true;
  }
  return out;
}

std::vector<std::uint32_t> visibility_clusters(const indexed_mesh& m, const counting_tracer& tr,
                                               const prepared_visibility_channel& p) {
  serial_executor exec;
  auto r = cluster_mesh(m, tr, exec, cluster_options{}, p);
  if (!r) {
    std::fprintf(stderr, "clustering failed: %s\n", r.error().message().c_str());
    std::exit(1);
  }
  return r->cluster_of;
}

visibility_state raw_rows(prepared_visibility_channel p, std::span<const std::uint32_t> all) {
  p.denoise = false;
  return std::move(*p.init(all));
}

// VmHWM of this process in MB (0 when /proc is not there).
double vm_hwm_mb() {
  FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return 0.0;
  char line[256];
  double kb = 0.0;
  while (std::fgets(line, sizeof line, f))
    if (std::strncmp(line, "VmHWM:", 6) == 0) kb = std::atof(line + 6);
  std::fclose(f);
  return kb / 1024.0;
}

// The peak memory of one prepare() of `c` on mesh `name`, in a forked child (before anything of
// the run is allocated in the parent): prints the child's VmHWM before and after.
void report_peak_memory(const std::string& name, const config& c) {
  int fd[2];
  if (pipe(fd) != 0) return;
  const pid_t child = fork();
  if (child == 0) {
    close(fd[0]);
    double out[3] = {0.0, 0.0, 0.0};
    auto m = support::load_mesh(support::cgal_mesh(name));
    auto topo = m ? make_topology(*m) : result<mesh_topology>(make_error(errc::empty_input, no_element, "no mesh"));
    if (m && topo) {
      support::embree_device device("threads=1");
      support::embree_scene scene(device, {.coherent_streams = c.stream});
      if (scene.add_mesh(*m) && scene.commit()) {
        serial_executor exec;
        out[0] = vm_hwm_mb();
        auto p = c.channel.prepare(*m, *topo, scene, exec);
        out[1] = p ? vm_hwm_mb() : 0.0;
        out[2] = static_cast<double>(m->triangles.size() * c.channel.viewpoints) / (1024.0 * 1024.0);
      }
    }
    const ssize_t wrote = write(fd[1], out, sizeof out);
    _exit(wrote == static_cast<ssize_t>(sizeof out) ? 0 : 1);
  }
  close(fd[1]);
  double in[3] = {0.0, 0.0, 0.0};
  const ssize_t got = child > 0 ? read(fd[0], in, sizeof in) : 0;
  close(fd[0]);
  if (child > 0) waitpid(child, nullptr, 0);
  if (got == static_cast<ssize_t>(sizeof in))
    std::printf("%s %s %s: VmHWM %.1f MB before prepare(), %.1f MB after (counts T*N = %.1f MB)\n", name.c_str(),
                c.option.c_str(), c.setting.c_str(), in[0], in[1], in[2]);
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

void write_plot(const std::string& csv) {
  const std::string stem = csv.size() > 4 && csv.ends_with(".csv") ? csv.substr(0, csv.size() - 4) : csv;
  const std::string gp = stem + ".gp", png = stem + ".png";
  FILE* f = std::fopen(gp.c_str(), "w");
  if (!f) return;
  std::fprintf(f,
               "set datafile separator ','\nset terminal pngcairo size 900,560 noenhanced\nset output '%s'\n"
               "set xlabel 'seconds (visibility channel, one core)'\nset ylabel 'mean JS of p(V|t) against n = 4 (bits)'\n"
               "set logscale xy\nset key outside right\nset grid\n"
               "plot for [m in 'refined_elephant armadillo'] '%s' using (strcol(1) eq m ? $4 : 1/0):($6 > 0 ? $6 : 1e-7) "
               "with points pt 7 title m, '' using 4:($6 > 0 ? $6 : 1e-7):(sprintf('%%s %%s', stringcolumn(2), "
               "stringcolumn(3))) with labels font ',7' offset 0,0.6 notitle\n",
               png.c_str(), csv.c_str());
  std::fclose(f);
  const std::string cmd = "gnuplot '" + gp + "'";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed\n");
}

}  // namespace

int pareto_visibility(int argc, char** argv) {
  std::string csv_path, meshes = "refined_elephant,armadillo", options;
  int reps = 3;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--csv" && i + 1 < argc) csv_path = argv[++i];
    else if (a == "--reps" && i + 1 < argc) reps = std::max(1, std::atoi(argv[++i]));
    else if (a == "--meshes" && i + 1 < argc) meshes = argv[++i];
    else if (a == "--options" && i + 1 < argc) options = argv[++i];
    else {
      std::fprintf(stderr, "usage: infolerp_pareto visibility --csv FILE [--reps R] [--meshes a,b] [--options o,o:s]\n");
      return 2;
    }
  }
  if (csv_path.empty()) {
    std::fprintf(stderr, "visibility: --csv FILE is required\n");
    return 2;
  }
  FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (!csv) return 1;
  std::fprintf(csv, "mesh,option,setting,seconds,rays,mean_js,max_js,ari,ari_self\n");
  support::enable_flush_to_zero();
  std::vector<config> cfg = configs();
  if (!options.empty()) {
    const std::string list = "," + options + ",";
    std::erase_if(cfg, [&](const config& c) {
      return c.option != "default" && c.option != "reference" && list.find("," + c.option + ",") == std::string::npos &&
             list.find("," + c.option + ":" + c.setting + ",") == std::string::npos;
    });
  }
  for (std::size_t start = 0; start <= meshes.size();) {
    std::size_t end = meshes.find(',', start);
    if (end == std::string::npos) end = meshes.size();
    const std::string name = meshes.substr(start, end - start);
    start = end + 1;
    if (name.empty()) continue;
    for (const config& c : cfg)
      if (c.option == "default" || (c.option == "images" && c.setting.starts_with("r1024")) ||
          (c.option == "adaptive_neighbours" && c.setting == "n3_P2_stream"))
        report_peak_memory(name, c);
  }
  std::fflush(stdout);
  std::size_t start = 0;
  while (start <= meshes.size()) {
    std::size_t end = meshes.find(',', start);
    if (end == std::string::npos) end = meshes.size();
    const std::string name = meshes.substr(start, end - start);
    start = end + 1;
    if (name.empty()) continue;
    auto m = support::load_mesh(support::cgal_mesh(name));
    if (!m) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), m.error().message().c_str());
      return 1;
    }
    auto topo = make_topology(*m);
    support::embree_device device("threads=1");
    support::embree_scene scene(device);
    support::embree_scene stream_scene(device, {.coherent_streams = true});
    if (!scene.add_mesh(*m) || !scene.commit() || !stream_scene.add_mesh(*m) || !stream_scene.commit()) return 1;
    std::atomic<std::size_t> ray_count{0};
    const counting_tracer tracer{&scene, &ray_count}, stream_tracer{&stream_scene, &ray_count};
    serial_executor exec;
    std::vector<std::vector<double>> seconds(cfg.size()), cpu(cfg.size());
    std::vector<prepared_visibility_channel> prepared(cfg.size());
    std::vector<std::size_t> rays(cfg.size());
    for (int r = 0; r < reps; ++r)
      for (std::size_t c = 0; c < cfg.size(); ++c) {
        ray_count = 0;
        const auto t0 = std::chrono::steady_clock::now();
        const double c0 = process_cpu_seconds();
        auto p = cfg[c].channel.prepare(*m, *topo, cfg[c].stream ? stream_tracer : tracer, exec);
        cpu[c].push_back(process_cpu_seconds() - c0);
        seconds[c].push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        if (!p) {
          std::fprintf(stderr, "%s: %s\n", cfg[c].option.c_str(), p.error().message().c_str());
          return 1;
        }
        rays[c] = ray_count;
        prepared[c] = std::move(*p);
      }
    const std::size_t nt = m->triangles.size();
    std::vector<std::uint32_t> all(nt);
    for (std::size_t t = 0; t < nt; ++t) all[t] = static_cast<std::uint32_t>(t);
    const prepared_visibility_channel& ref = prepared[1];
    const visibility_state ref_rows = raw_rows(ref, all);
    const std::vector<std::uint32_t> ref_labels = visibility_clusters(*m, tracer, ref);
    prepared_visibility_channel moved = ref;
    moved.threshold *= 1.01;
    const double ari_self = support::adjusted_rand_index(visibility_clusters(*m, tracer, moved), ref_labels);
    for (std::size_t c = 0; c < cfg.size(); ++c) {
      const bool exact = cfg[c].option.rfind("exact", 0) == 0;
      if (exact && prepared[c].visible != prepared[0].visible) {
        std::fprintf(stderr, "%s %s: counts differ from the default's\n", name.c_str(), cfg[c].option.c_str());
        return 1;
      }
      const visibility_state rows = raw_rows(prepared[c], all);
      double sum = 0.0, worst = 0.0;
      for (std::uint32_t t = 0; t < nt; ++t) {
        const bool ua = rows.unseen(t), ub = ref_rows.unseen(t);
        const double js = ua || ub ? (ua == ub ? 0.0 : 1.0) : js_divergence(rows.row(t), ref_rows.row(t));
        sum += js;
        worst = std::max(worst, js);
      }
      const double ari = support::adjusted_rand_index(visibility_clusters(*m, tracer, prepared[c]), ref_labels);
      std::vector<double> s = seconds[c];
      std::sort(s.begin(), s.end());
      const double median = s[s.size() / 2];
      std::fprintf(csv, "%s,%s,%s,%.4f,%zu,%.6g,%.6g,%.6f,%.6f\n", name.c_str(), cfg[c].option.c_str(),
                   cfg[c].setting.c_str(), median, rays[c], sum / static_cast<double>(nt), worst, ari, ari_self);
      const auto median_of = [](std::vector<double> v) { std::sort(v.begin(), v.end()); return v[v.size() / 2]; };
      std::printf("%-17s %-26s %-10s min %.3f median %.3f s (%.3fx default median), CPU min %.3f median %.3f s (%.3fx)"
                  "  rays %zu  ari %.4f\n", name.c_str(), cfg[c].option.c_str(), cfg[c].setting.c_str(), s.front(), median,
                  median / median_of(seconds[0]), *std::min_element(cpu[c].begin(), cpu[c].end()), median_of(cpu[c]),
                  median_of(cpu[c]) / median_of(cpu[0]), rays[c], ari);
    }
    std::fflush(csv);
    std::printf("%s: %zu triangles, ari_self %.4f, peak RSS %.0f MB\n", name.c_str(), nt, ari_self, peak_rss_mb());
  }
  std::fclose(csv);
  write_plot(csv_path);
  return 0;
}
