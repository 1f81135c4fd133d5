// libFuzzer target: every option of the saliency family at fuzzed values, extremes included
// (saliency_options, salient_clustering_options, the cluster-importance camera and the
// contraction distribution), on small fuzzed meshes.
// Input: [flags][saliency options][clustering options][camera x3][lambda_perc][target][mesh].
// Checks: every error names its problem; saliency, importance and distributions are finite and
// well-formed; cluster ids are in range.
#include <algorithm>
#include <numeric>
#include <vector>
#include "fuzz_common.hpp"
#include "infolerp/saliency/cluster_importance.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "infolerp/saliency/salient_clustering.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::reader r{data, size};
  const std::uint8_t flags = r.u8();
  infolerp::saliency_options so{.epsilon = r.real(), .scales = {}, .flat_level_threshold = r.real(),
                                .grain = r.count<std::size_t>()};
  for (unsigned k = 0, n = r.u8() % 5u; k < n; ++k) so.scales.push_back(r.real());
  if (flags & 1) so = {};  // the defaults, so the later stages see saliency more often
  if (flags & 4) so.method = infolerp::saliency_method::proxy;  // the approximation at any size
  const infolerp::salient_clustering_options co{.clusters = r.count<std::uint32_t>(), .pool_multiplier = r.real(),
                                                .normal_weight = r.real(), .seed = r.count<std::uint64_t>(),
                                                .max_iterations = r.count<std::uint32_t>(),
                                                .flat_tie_break = (flags & 2) != 0};
  const glm::dvec3 camera(r.real(), r.real(), r.real());
  const double lambda_perc = r.real();
  const std::uint64_t target = r.count<std::uint64_t>();
  const infolerp::indexed_mesh m = fuzz::read_mesh(r, 24, 32);

  auto sal = infolerp::compute_saliency(m, so);
  fuzz::check_error(sal.error());
  if (!sal.ok()) return 0;
  FUZZ_CHECK(sal->saliency.size() == m.positions.size() && fuzz::all_finite(sal->saliency));
  auto cl = infolerp::salient_clustering(m, sal->saliency, co);
  fuzz::check_error(cl.error());
  if (!cl.ok()) return 0;
  FUZZ_CHECK(cl->cluster.size() == m.triangles.size());
  for (std::uint32_t id : cl->cluster) FUZZ_CHECK(id < cl->count);
  auto table = infolerp::compute_cluster_attributes(m, sal->saliency, cl->cluster, cl->count);
  fuzz::check_error(table.error());
  if (!table.ok()) return 0;
  auto view = infolerp::estimate_view_importance(*table, camera);
  fuzz::check_error(view.error());
  if (!view.ok()) return 0;
  FUZZ_CHECK(fuzz::all_finite(view->area_estimate) && fuzz::all_finite(view->importance_estimate));
  std::vector<std::uint64_t> capacity(cl->count);
  for (auto& c : capacity) c = r.u8();
  const std::uint64_t total = std::accumulate(capacity.begin(), capacity.end(), std::uint64_t{0});
  // Targets above the total capacity are spent up to it; the extreme ones (near 2^64) are the
  // cluster-importance cast that its own header bounds, so they are folded into [0, total + 1].
  const std::uint64_t global = target % (total + 2);
  auto split = infolerp::distribute_contractions(view->importance_estimate, capacity, global, lambda_perc);
  fuzz::check_error(split.error());
  if (!split.ok()) return 0;
  std::uint64_t sum = 0;
  for (std::size_t c = 0; c < capacity.size(); ++c) {
    FUZZ_CHECK((*split)[c] <= capacity[c]);
    sum += (*split)[c];
  }
  FUZZ_CHECK(sum == std::min(global, total));  // eq. 9 spends the target up to the capacity
  return 0;
}
