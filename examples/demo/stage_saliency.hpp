#pragma once
// Demo stage: per-vertex mesh saliency as heat-map colours (for saliency.png).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>
#include <glm/vec3.hpp>
#include "demo.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "support/procedural.hpp"

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

// Stage: saliency of every scene object (Lee et al. 2005, salient-clustering paper §III.A; each
// object its own mesh with coincident seam vertices welded, ε relative to its own bounding box),
// written as DIR/saliency.png: the scene from the camera, coloured by saliency interpolated from
// the vertices, one scale for the whole scene (square-root tone curve so mid values show). Each
// object's values over its welded vertices stay in ctx.welded_saliency for the LOD stage.
inline bool stage_saliency(demo_context& ctx) {
  std::vector<std::vector<double>> values;  // per object, per original vertex
  double top = 0.0;
  const stopwatch watch;
  for (const auto& object : ctx.scene.objects) {
    std::vector<std::uint32_t> remap;
    const indexed_mesh welded = support::weld_positions(object.mesh, remap);
    progress_line line("saliency " + object.name);
    auto s = compute_saliency(welded, {}, with_progress(ctx.options, line));
    line.finish();
    if (!s) {
      report(s.error());
      return false;
    }
    ctx.welded_saliency.push_back(s->saliency);
    std::vector<double> per_vertex(remap.size());
    for (std::size_t v = 0; v < remap.size(); ++v) per_vertex[v] = s->saliency[remap[v]];
    top = std::max(top, *std::max_element(per_vertex.begin(), per_vertex.end()));
    values.push_back(std::move(per_vertex));
  }
  record_time(ctx, "saliency (" + std::to_string(ctx.scene.objects.size()) + " objects)", watch.seconds());
  const stopwatch image_watch;
  const auto img = render_false_colour(ctx, [&](std::uint32_t g, std::uint32_t t, glm::vec2 b) {
    const glm::uvec3 tri = ctx.scene.objects[g].mesh.triangles[t];
    const double s = (1.0 - b.x - b.y) * values[g][tri.x] + b.x * values[g][tri.y] + b.y * values[g][tri.z];
    return heat_colour(top > 0.0 ? static_cast<float>(std::sqrt(s / top)) : 0.0f);
  });
  const bool saved = save_png(ctx, img, "saliency.png");
  record_time(ctx, "saliency.png", image_watch.seconds());
  return saved;
}

}  // namespace infolerp::demo
