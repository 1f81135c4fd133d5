// libFuzzer target: every option of the LOD family at fuzzed values, extremes included
// (weighting_map_options, simplification_options, view_dependent_lod's lambda_perc and grain,
// the frame's camera and global contraction count), on small fuzzed meshes.
// Input: [flags (16: proxy smoothing)][weighting options][simplification options][lambda_perc][grain][camera position x3,
// looking at the origin]
// [contractions][mesh][per-vertex saliency][cluster per triangle].
// Checks: every error names its problem; weights are finite and >= 0; a frame's index buffer fits
// its bound, has no repeated index in a triangle, and equals the frame of the default grain.
#include <algorithm>
#include <vector>
#include "fuzz_common.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/vertex_contraction.hpp"
#include "infolerp/lod/view_dependent_lod.hpp"
#include "infolerp/lod/weighting_map.hpp"
#include "infolerp/saliency/cluster_importance.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::reader r{data, size};
  const std::uint8_t flags = r.u8();
  infolerp::weighting_map_options wo{.epsilon = r.real(), .smoothing_scale = r.real(),
                                     .amplify_percentile = r.real() * 20.0, .amplification = r.real(),
                                     .grain = r.count<std::size_t>()};
  if (flags & 16) wo.smoothing_method = infolerp::saliency_method::proxy;  // the proxy smoothing at any size
  const infolerp::simplification_options so{.backstop = r.real(), .boundary_weight = r.real(),
                                            .min_normal_cos = r.real(), .cluster_local_first = (flags & 1) != 0};
  const double lambda_perc = r.real();
  const std::size_t grain = r.count<std::size_t>();
  const glm::dvec3 eye(r.real(), r.real(), r.real());
  const infolerp::lod_camera camera{.position = eye, .forward = -eye, .width = 64, .height = 64};
  const std::uint64_t contractions = r.count<std::uint64_t>();
  const std::uint32_t clusters = 1u + r.u8() % 3u;
  const infolerp::indexed_mesh m = fuzz::read_mesh(r, 24, 32);
  std::vector<double> saliency(m.positions.size());
  for (auto& s : saliency) s = (flags & 2) ? r.real() : r.unit();  // flag 2: extreme saliency too
  std::vector<std::uint32_t> cluster(m.triangles.size());
  for (auto& c : cluster) c = r.u8() % clusters;

  auto w = infolerp::weighting_map(m, saliency, cluster, clusters, wo);
  fuzz::check_error(w.error());
  if (!w.ok()) return 0;
  FUZZ_CHECK(w->size() == 3 * m.triangles.size() && fuzz::all_finite(*w));
  for (double x : *w) FUZZ_CHECK(x >= 0.0);
  auto h = infolerp::make_contraction_hierarchy(m, *w, cluster, clusters, so);
  fuzz::check_error(h.error());
  if (!h.ok()) return 0;
  auto table = infolerp::compute_cluster_attributes(m, saliency, cluster, clusters);
  fuzz::check_error(table.error());
  if (!table.ok()) return 0;
  // flag 4: the paper's selection (eqs. 5-9), else the default screen-error selection.
  const infolerp::lod_selection sel = (flags & 4) ? infolerp::lod_selection::paper : infolerp::lod_selection::screen_error;
  infolerp::lod_options opt;
  opt.selection = sel;
  opt.lambda_perc = lambda_perc;
  auto ref = infolerp::view_dependent_lod::create(*h, *table, opt);
  opt.grain = grain;
  auto lod = infolerp::view_dependent_lod::create(*h, *table, opt);
  fuzz::check_error(lod.error());
  if (!lod.ok()) return 0;
  FUZZ_CHECK(ref.ok());
  // Flag 8: the triangle budget as read (up to 2^64 - 1: the full mesh); else folded into
  // [0, triangles + 1].
  const std::uint64_t global = (flags & 8) ? contractions : contractions % (h->triangle_count() + 2);
  std::vector<std::uint32_t> out(infolerp::contracted_index_bound(*h)), out_ref(out.size());
  std::vector<infolerp::index_range> ranges(clusters), ranges_ref(clusters);
  auto st = lod->frame(camera, global, out, ranges);
  fuzz::check_error(st.error());
  if (!st.ok()) return 0;
  auto st_ref = ref->frame(camera, global, out_ref, ranges_ref);
  FUZZ_CHECK(st_ref.ok() && st_ref->indices == st->indices && st->indices % 3 == 0 && st->indices <= out.size());
  FUZZ_CHECK(std::equal(out.begin(), out.begin() + static_cast<long>(st->indices), out_ref.begin()));
  for (std::size_t k = 0; k < st->indices; k += 3)
    FUZZ_CHECK(out[k] != out[k + 1] && out[k + 1] != out[k + 2] && out[k] != out[k + 2]);
  return 0;
}
