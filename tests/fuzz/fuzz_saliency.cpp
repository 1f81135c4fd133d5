// libFuzzer target: curvature, mesh saliency, salient clustering,
// cluster attributes, cluster-localised saliency, view importance and budget distribution on
// small fuzzed meshes with fuzzed options.
// Input: [flags][epsilon][scale count][scales...][unused byte][clusters][seed][mesh][pool]
// [iterations][camera][capacities...][target u16][lambda].
#include <cmath>
#include <numeric>
#include <vector>
#include "fuzz_common.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/saliency/cluster_importance.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::reader r{data, size};
  const std::uint8_t flags = r.u8();
  infolerp::saliency_options opt;
  opt.epsilon = r.unit() * 0.2;  // up to 20% of the diagonal (NaN/negative/huge after a 255 marker)
  opt.scales.resize(r.u8() % 4);
  for (auto& s : opt.scales) s = 6.0 * r.unit();
  r.unit();  // unused: the seed corpus keeps its byte layout
  opt.grain = 1 + (flags >> 4);
  const std::uint32_t clusters = r.u8() % 10;
  const std::uint64_t seed = r.u8();
  const infolerp::indexed_mesh m = fuzz::read_mesh(r, 40, 60);
  const std::size_t nv = m.positions.size(), nt = m.triangles.size();

  // Curvature from float positions equals curvature from the same values in double.
  auto h = infolerp::mean_curvature(m);
  fuzz::check_error(h.error());
  if (h.ok()) {
    FUZZ_CHECK(h->size() == nv && fuzz::all_finite(*h));
    std::vector<glm::dvec3> dp(m.positions.begin(), m.positions.end());
    auto hd = infolerp::mean_curvature(std::span<const glm::dvec3>(dp), std::span<const glm::uvec3>(m.triangles));
    FUZZ_CHECK(hd.ok() && *hd == *h);
  }

  auto sal = infolerp::compute_saliency(m, opt);
  fuzz::check_error(sal.error());
  if (!sal.ok()) return 0;
  FUZZ_CHECK(sal->saliency.size() == nv && fuzz::all_finite(sal->saliency));
  for (double s : sal->saliency) FUZZ_CHECK(s >= 0.0);
  for (const auto& level : sal->levels) FUZZ_CHECK(level.size() == nv && fuzz::all_finite(level));

  auto c = infolerp::salient_clustering(m, sal->saliency,
                                        {.clusters = clusters, .pool_multiplier = 1.0 + 4.0 * r.unit(), .seed = seed,
                                         .max_iterations = 1u + r.u8() % 8});
  fuzz::check_error(c.error());
  if (!c.ok()) return 0;
  FUZZ_CHECK(c->cluster.size() == nt && c->count >= clusters && c->seeds.size() == clusters);
  for (std::uint32_t id : c->cluster) FUZZ_CHECK(id < c->count);
  for (std::uint32_t v : c->seeds) FUZZ_CHECK(v < nv);

  auto local = infolerp::cluster_localized_saliency(m, sal->saliency, c->cluster, c->count);
  FUZZ_CHECK(local.ok() && local->size() == 3 * nt && fuzz::all_finite(*local));
  auto table = infolerp::compute_cluster_attributes(m, sal->saliency, c->cluster, c->count);
  FUZZ_CHECK(table.ok() && table->clusters.size() == c->count);
  for (const auto& a : table->clusters)
    FUZZ_CHECK(std::isfinite(a.area) && std::isfinite(a.radius) && fuzz::finite(glm::vec3(a.centroid)) &&
               std::isfinite(a.peak_normal_deviation) && std::isfinite(a.mean_saliency));

  const glm::dvec3 camera(r.coord(), r.coord(), r.coord());
  auto view = infolerp::estimate_view_importance(*table, camera);
  fuzz::check_error(view.error());
  if (!view.ok()) return 0;
  std::vector<double> priority(c->count);
  std::vector<std::uint64_t> capacity(c->count);
  for (std::size_t k = 0; k < c->count; ++k) {
    FUZZ_CHECK(!std::isnan(view->area_estimate[k]) && !std::isnan(view->importance_estimate[k]));
    FUZZ_CHECK(view->area_estimate[k] >= 0.0 && view->importance_estimate[k] >= 0.0);
    priority[k] = view->area_estimate[k] * view->importance_estimate[k];
    capacity[k] = r.u8();
  }
  const std::uint64_t target = r.u16();
  auto budget = infolerp::distribute_contractions(priority, capacity, target, r.unit());
  fuzz::check_error(budget.error());
  if (budget.ok()) {
    const std::uint64_t total = std::accumulate(capacity.begin(), capacity.end(), std::uint64_t{0});
    FUZZ_CHECK(std::accumulate(budget->begin(), budget->end(), std::uint64_t{0}) == std::min(target, total));
    for (std::size_t k = 0; k < budget->size(); ++k) FUZZ_CHECK((*budget)[k] <= capacity[k]);
  }
  return 0;
}
