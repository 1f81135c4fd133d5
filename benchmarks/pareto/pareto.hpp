#pragma once
// Subcommands of infolerp_pareto, the time-against-error harness: each lives in its own
// benchmarks/pareto/<sub>.cpp. Weak, so that the binary links while a subcommand's file is absent.
#include <cmath>
#include <vector>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "support/procedural.hpp"

[[gnu::weak]] int pareto_refine(int argc, char** argv);
[[gnu::weak]] int pareto_upsample(int argc, char** argv);
[[gnu::weak]] int pareto_upsample_textured(int argc, char** argv);  // upsample --textured DIR
[[gnu::weak]] int pareto_upsample_path(int argc, char** argv);      // upsample --path
[[gnu::weak]] int pareto_walk(int argc, char** argv);
[[gnu::weak]] int pareto_lod(int argc, char** argv);
[[gnu::weak]] int pareto_visibility(int argc, char** argv);
[[gnu::weak]] int pareto_saliency(int argc, char** argv);
[[gnu::weak]] int pareto_pipeline(int argc, char** argv);
[[gnu::weak]] int pareto_lod_dag(int argc, char** argv);  // reference cluster DAG (meshoptimizer + METIS)

// PSNR in dB of image a against reference b on linear colours clamped to [0, 1] (99 when equal),
// as the refinement harnesses measure it.
inline double linear_psnr(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  double se = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const glm::dvec3 d = glm::dvec3(glm::clamp(a[i], 0.0f, 1.0f)) - glm::dvec3(glm::clamp(b[i], 0.0f, 1.0f));
    se += glm::dot(d, d) / 3.0;
  }
  const double mse = se / double(a.size());
  return mse <= 0.0 ? 99.0 : 10.0 * std::log10(1.0 / mse);
}

// Mesh m with detail at every scale of its resolution: noise octaves along the normals
// (support::add_noise_detail) from 3 mean edge lengths up to 1/8 of the bounding box's diagonal,
// each octave's amplitude 5% of its wavelength. The scale figures of `saliency` and `pipeline`
// measure on it beside the midpoint-split meshes, whose new vertices carry no detail.
inline infolerp::indexed_mesh with_noise_detail(const infolerp::indexed_mesh& m) {
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  return infolerp::support::add_noise_detail(m, 3.0f * infolerp::support::mean_edge_length(m), glm::distance(lo, hi) / 8.0f,
                                             0.05f);
}
