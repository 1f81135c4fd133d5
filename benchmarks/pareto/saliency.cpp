// infolerp_pareto saliency --csv FILE [--mesh PATH]... [--only-given] [--only NAME]... [--reps N]
//                          [--threads N] [--setting C]... [--no-lod] [--lod-seeds N]
// (--only-given: only the --mesh meshes; --only: only the built-in meshes of these names;
// --setting: the proxy's cells per σ to measure, default 1 2 3 4; --no-lod: leave the LOD column
// empty, skipping its salient clustering and hierarchies; --lod-seeds: clustering seeds per LOD,
// default 3)
//
// Mesh saliency (compute_saliency): run time against error of the proxy approximation
// (saliency_method::proxy, one row per proxy_cells_per_sigma) against exact (saliency_method::exact),
// on bunny00, bunny00 split 1:4 at edge midpoints once (bunny00_x4, 301,632 triangles) and twice
// (bunny00_x16, 1,206,528), bunny00_x16_detail (bunny00_x16 with noise along the normals at every
// scale from 3 edge lengths up, pareto.hpp's with_noise_detail: the midpoint split's new vertices
// carry no detail, these do), and each --mesh.
// CSV: mesh,method,setting,vertices,seconds,relative_l2,top10_overlap,lod_salient_distance_ratio
//   method: exact, proxy, or default (the default options: the automatic choice, whose setting
//   column names the method it took); setting: proxy_cells_per_sigma (empty for exact); one more
//   exact row, setting "epsilon x1.001", is exact saliency with ε 0.1% larger: the noise floor of
//   each column (how much a change that small moves it), timed once;
//   seconds: the minimum over --reps calls (default 3) with --threads workers (default 2), the
//   methods interleaved in each repetition (stdout adds the median and the ratio to exact's);
//   relative_l2: ‖S − S_exact‖₂ / ‖S_exact‖₂ over the vertices;
//   top10_overlap: the share of exact's 10% most salient vertices that the row also ranks in its
//   10% most salient (ties broken by vertex index);
//   lod_salient_distance_ratio: LODs at 5% of the triangles (salient clustering with 10 clusters,
//   weighting map, contraction hierarchy with one global order, its global prefix), built on the
//   row's saliency and on exact's; the salient distance of each, Σ S·d / Σ S over exact's 10% most
//   salient vertices with S the exact saliency and d the distance from the vertex to the
//   simplified surface; the column is the first's divided by the second's, each the mean over
//   clustering seeds 1..--lod-seeds (the clusters' walk is chaotic: stdout gives exact's distance
//   per seed, the spread that chance alone makes).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numeric>
#include <optional>
#include <string>
#include <vector>
#include "infolerp/core/executor.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/vertex_contraction.hpp"
#include "infolerp/lod/weighting_map.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"
#include "pareto.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"
#include "support/surface_distance.hpp"

namespace {

using namespace infolerp;
using clk = std::chrono::steady_clock;

struct method_row {
  std::string method, setting;
  saliency_options opt;
  std::vector<double> saliency;
  std::vector<double> seconds;
};

// The k most salient vertices (ties by index), as a mask.
std::vector<char> top_mask(const std::vector<double>& s, std::size_t k) {
  std::vector<std::uint32_t> order(s.size());
  std::iota(order.begin(), order.end(), 0u);
  std::nth_element(order.begin(), order.begin() + static_cast<long>(k), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return s[a] != s[b] ? s[a] > s[b] : a < b; });
  std::vector<char> mask(s.size(), 0);
  for (std::size_t i = 0; i < k; ++i) mask[order[i]] = 1;
  return mask;
}

// Index buffer of the 5% LOD built on saliency s (see the top of the file); empty on failure.
std::vector<std::uint32_t> lod_at_5(const indexed_mesh& m, const std::vector<double>& s, std::uint64_t seed) {
  auto cl = salient_clustering(m, s, {.clusters = 10, .seed = seed});
  if (!cl.ok()) return std::fprintf(stderr, "clustering: %s\n", cl.error().message().c_str()), std::vector<std::uint32_t>{};
  auto w = weighting_map(m, s, cl->cluster, cl->count);
  if (!w.ok()) return std::fprintf(stderr, "weighting map: %s\n", w.error().message().c_str()), std::vector<std::uint32_t>{};
  auto h = make_contraction_hierarchy(m, *w, cl->cluster, cl->count, {.backstop = 0.005, .cluster_local_first = false});
  if (!h.ok()) return std::fprintf(stderr, "hierarchy: %s\n", h.error().message().c_str()), std::vector<std::uint32_t>{};
  const auto target = static_cast<std::size_t>(std::lround(0.05 * static_cast<double>(m.triangle_count())));
  std::size_t tris = h->triangle_count();
  std::uint32_t k = 0;
  while (tris > target && k < h->contraction_count()) tris -= h->faces_removed[k++];
  contraction_workspace ws = make_contraction_workspace(*h);
  std::vector<index_range> ranges(h->cluster_count);
  std::vector<std::uint32_t> out(contracted_index_bound(*h));
  const std::vector<std::uint32_t> stop(h->cluster_count, k);
  auto n = contract_indices(*h, stop, ws, out, ranges);
  out.resize(n.ok() ? *n : 0);
  return out;
}

// Σ S·d / Σ S over the masked vertices, d the distance to the simplified surface.
double salient_distance(const indexed_mesh& m, const std::vector<double>& s, const std::vector<char>& mask,
                        const std::vector<std::uint32_t>& simplified) {
  support::surface_distance to_simplified(m.positions, simplified);
  double num = 0.0, den = 0.0;
  for (std::size_t v = 0; v < m.vertex_count(); ++v)
    if (mask[v]) num += s[v] * to_simplified(glm::dvec3(m.positions[v])), den += s[v];
  return den > 0.0 ? num / den : 0.0;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void mesh_rows(std::FILE* csv, const std::string& name, const indexed_mesh& m, const std::vector<double>& settings,
               int reps, unsigned threads, bool lod, std::uint64_t lod_seeds) {
  std::vector<method_row> rows;
  rows.push_back({"exact", "", saliency_options{.method = saliency_method::exact}, {}, {}});
  for (double c : settings) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", c);
    rows.push_back({"proxy", buf, saliency_options{.method = saliency_method::proxy, .proxy_cells_per_sigma = c}, {}, {}});
  }
  rows.push_back({"default", "", saliency_options{}, {}, {}});
  const openmp_executor exec{static_cast<int>(threads)};
  for (int r = 0; r < reps; ++r)
    for (method_row& row : rows) {
      const auto t0 = clk::now();
      auto s = compute_saliency(m, row.opt, exec);
      row.seconds.push_back(std::chrono::duration<double>(clk::now() - t0).count());
      if (!s.ok()) return void(std::fprintf(stderr, "%s: %s\n", name.c_str(), s.error().message().c_str()));
      if (row.method == "default") {
        char buf[48];
        std::snprintf(buf, sizeof buf, "proxy %g", row.opt.proxy_cells_per_sigma);
        row.setting = s->method == saliency_method::exact ? "exact" : buf;
      }
      row.saliency = std::move(s->saliency);
    }
  // The noise floor: exact saliency with ε 0.1% larger (exact itself moves ~0.4% in L2 there),
  // computed once, outside the timed repetitions.
  {
    method_row jitter{"exact", "epsilon x1.001", saliency_options{.epsilon = 0.003 * 1.001, .method = saliency_method::exact}, {}, {}};
    const auto t0 = clk::now();
    auto s = compute_saliency(m, jitter.opt, exec);
    jitter.seconds.push_back(std::chrono::duration<double>(clk::now() - t0).count());
    if (!s.ok()) return void(std::fprintf(stderr, "%s: %s\n", name.c_str(), s.error().message().c_str()));
    jitter.saliency = std::move(s->saliency);
    rows.insert(rows.begin() + 1, std::move(jitter));
  }
  const std::vector<double>& exact = rows[0].saliency;
  const std::size_t nv = exact.size(), k = std::max<std::size_t>(1, nv / 10);
  const std::vector<char> exact_top = top_mask(exact, k);
  double exact_norm = 0.0;
  for (double x : exact) exact_norm += x * x;
  exact_norm = std::sqrt(exact_norm);
  // Salient distance of the 5% LODs built on saliency s, one per clustering seed (the clusters'
  // walk is chaotic: seeds give the spread that chance alone makes).
  auto lod_distances = [&](const std::vector<double>& s) {
    std::vector<double> d;
    for (std::uint64_t seed = 1; seed <= lod_seeds; ++seed)
      d.push_back(salient_distance(m, exact, exact_top, lod_at_5(m, s, seed)));
    return d;
  };
  auto mean = [](const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()); };
  std::vector<double> exact_dist;
  if (lod) {
    exact_dist = lod_distances(exact);
    std::printf("# %s: exact saliency's LOD salient distance per clustering seed:", name.c_str());
    for (double d : exact_dist) std::printf(" %.6g (%.4f of the mean)", d, d / mean(exact_dist));
    std::printf("\n");
  }
  std::vector<std::pair<const std::vector<double>*, std::string>> done;  // rows with the same saliency share the LOD
  for (const method_row& row : rows) {
    double diff = 0.0;
    for (std::size_t v = 0; v < nv; ++v) diff += (row.saliency[v] - exact[v]) * (row.saliency[v] - exact[v]);
    const std::vector<char> top = top_mask(row.saliency, k);
    std::size_t both = 0;
    for (std::size_t v = 0; v < nv; ++v) both += exact_top[v] && top[v];
    std::string ratio;
    if (lod) {
      for (const auto& [sal, r] : done)
        if (*sal == row.saliency) ratio = r;
      if (ratio.empty()) {
        const double d = &row == &rows[0] ? mean(exact_dist) : mean(lod_distances(row.saliency));
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.4f", mean(exact_dist) > 0.0 ? d / mean(exact_dist) : 1.0);
        ratio = buf;
        done.emplace_back(&row.saliency, ratio);
      }
    }
    const double t = *std::min_element(row.seconds.begin(), row.seconds.end());
    for (std::FILE* o : {csv, stdout})
      std::fprintf(o, "%s,%s,%s,%zu,%.4f,%.5f,%.4f,%s\n", name.c_str(), row.method.c_str(), row.setting.c_str(), nv, t,
                   std::sqrt(diff) / exact_norm, static_cast<double>(both) / static_cast<double>(k), ratio.c_str());
    std::printf("#   %s %s: median %.4f s; exact/this %.2fx (min) %.2fx (median)\n", row.method.c_str(), row.setting.c_str(),
                median(row.seconds), *std::min_element(rows[0].seconds.begin(), rows[0].seconds.end()) / t,
                median(rows[0].seconds) / median(row.seconds));
    std::fflush(csv);
  }
}

}  // namespace

int pareto_saliency(int argc, char** argv) {
  std::string csv_path;
  std::vector<std::string> extra, only;
  std::vector<double> settings;
  int reps = 3;
  unsigned threads = 2;
  std::uint64_t lod_seeds = 3;
  bool builtin = true, lod = true;
  for (int i = 1; i < argc; ++i) {
    const auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (!std::strcmp(argv[i], "--csv")) csv_path = next();
    else if (!std::strcmp(argv[i], "--mesh")) extra.push_back(next());
    else if (!std::strcmp(argv[i], "--only-given")) builtin = false;
    else if (!std::strcmp(argv[i], "--only")) only.push_back(next());
    else if (!std::strcmp(argv[i], "--reps")) reps = std::max(1, std::atoi(next().c_str()));
    else if (!std::strcmp(argv[i], "--threads")) threads = static_cast<unsigned>(std::max(1, std::atoi(next().c_str())));
    else if (!std::strcmp(argv[i], "--setting")) settings.push_back(std::atof(next().c_str()));
    else if (!std::strcmp(argv[i], "--no-lod")) lod = false;
    else if (!std::strcmp(argv[i], "--lod-seeds")) lod_seeds = static_cast<std::uint64_t>(std::max(1, std::atoi(next().c_str())));
    else csv_path.clear(), i = argc;
  }
  if (csv_path.empty()) {
    std::fprintf(stderr, "usage: infolerp_pareto saliency --csv FILE [--mesh PATH]... [--only-given] [--only NAME]..."
                 " [--reps N] [--threads N] [--setting C]... [--no-lod] [--lod-seeds N]\n");
    return 2;
  }
  if (settings.empty()) settings = {1.0, 2.0, 3.0, 4.0};
  std::FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (!csv) return std::fprintf(stderr, "cannot write %s\n", csv_path.c_str()), 1;
  std::fprintf(csv, "mesh,method,setting,vertices,seconds,relative_l2,top10_overlap,lod_salient_distance_ratio\n");
  std::vector<std::pair<std::string, indexed_mesh>> meshes;
  if (builtin) {
    auto bunny = support::load_mesh(support::cgal_mesh("bunny00"));
    if (!bunny.ok()) return std::fprintf(stderr, "bunny00: %s\n", bunny.error().message().c_str()), 1;
    indexed_mesh x4 = support::subdivide_midpoint(*bunny);
    indexed_mesh x16 = support::subdivide_midpoint(x4);
    indexed_mesh x16_detail = with_noise_detail(x16);
    meshes.emplace_back("bunny00", std::move(*bunny));
    meshes.emplace_back("bunny00_x4", std::move(x4));
    meshes.emplace_back("bunny00_x16", std::move(x16));
    meshes.emplace_back("bunny00_x16_detail", std::move(x16_detail));
    if (!only.empty())
      std::erase_if(meshes, [&](const auto& nm) { return std::find(only.begin(), only.end(), nm.first) == only.end(); });
  }
  for (const std::string& path : extra) {
    auto m = support::load_mesh(path);
    if (!m.ok()) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), m.error().message().c_str());
      continue;
    }
    const std::size_t slash = path.find_last_of('/'), dot = path.find_last_of('.');
    const std::size_t b = slash == std::string::npos ? 0 : slash + 1;
    meshes.emplace_back(path.substr(b, dot == std::string::npos || dot < b ? std::string::npos : dot - b), std::move(*m));
  }
  for (const auto& [name, m] : meshes) {
    std::printf("# %s: %zu triangles, %zu vertices, %u threads, %d repetitions\n", name.c_str(), m.triangle_count(),
                m.vertex_count(), threads, reps);
    mesh_rows(csv, name, m, settings, reps, threads, lod, lod_seeds);
  }
  std::fclose(csv);
  return 0;
}
