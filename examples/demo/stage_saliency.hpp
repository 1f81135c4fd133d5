#pragma once
// Demo stage: per-vertex mesh saliency as heat-map colours (for saliency.png).
#include <algorithm>
#include <cmath>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"

namespace infolerp::demo {

// Heat map: 0 → dark blue, then cyan, green, yellow, 1 → red.
inline glm::vec3 heat_colour(float t) {
  t = std::clamp(t, 0.0f, 1.0f);
  const glm::vec3 stops[5] = {{0.05f, 0.05f, 0.5f}, {0.0f, 0.8f, 1.0f}, {0.1f, 0.9f, 0.1f}, {1.0f, 0.9f, 0.0f},
                              {0.9f, 0.05f, 0.05f}};
  const float x = t * 4.0f;
  const int i = std::min(3, static_cast<int>(x));
  const float f = x - static_cast<float>(i);
  return stops[i] * (1.0f - f) + stops[i + 1] * f;
}

// Per-vertex RGB in [0,1]³ from the mesh's saliency (Lee et al. 2005, salient-clustering paper
// §III.A), normalised by the largest value with a square-root tone curve so that mid values are
// visible. `method` picks exact or approximate saliency. Errors: those of compute_saliency.
inline result<std::vector<glm::vec3>> saliency_vertex_colours(const indexed_mesh& mesh,
                                                              saliency_method method = saliency_method::exact) {
#ifdef _OPENMP
  auto s = compute_saliency(mesh, {.method = method}, openmp_executor{});
#else
  auto s = compute_saliency(mesh, {.method = method});
#endif
  if (!s.ok()) return s.error();
  const double top = *std::max_element(s->saliency.begin(), s->saliency.end());
  std::vector<glm::vec3> colours(s->saliency.size());
  for (std::size_t v = 0; v < colours.size(); ++v)
    colours[v] = heat_colour(top > 0.0 ? static_cast<float>(std::sqrt(s->saliency[v] / top)) : 0.0f);
  return colours;
}

}  // namespace infolerp::demo
