#pragma once
// The demo scene clustered with the library's feature-based clustering (clustering paper §3,
// Algorithm 1: visibility → orientation → stretch; include/infolerp/cluster/cluster_mesh.hpp),
// as scene-wide cluster ids for the I-Buffer (tests/support/demo_upsample.hpp). Shared by the
// demo's clusters stage and the time-against-error harness, so both use the same clusters.
//   cluster_object(mesh, tracer, exec, thresholds, progress)   one mesh
//   cluster_by_features(scene, exec, thresholds, progress, on_object)
//       every object (positions welded first so that the clustering sees one surface; the
//       triangles keep their order), ids offset per object; the I-Buffer then takes
//   split_at_texture_seams(scene, clustering)
//       the clusters cut along texture seams (texcoords are interpolated within an id).
// thresholds maps a channel name (visibility, orientation, stretch) to its Jensen-Shannon
// threshold; missing ones take the demo's defaults (0.48, 0.05, 0.1). progress(label, done,
// total) reports the visibility rays of each object; on_object(name, clustering) is called after
// each object (for the demo's per-channel counts).
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>
#include "infolerp/cluster/cluster_mesh.hpp"
#include "support/demo_scene.hpp"
#include "support/demo_upsample.hpp"
#include "support/procedural.hpp"

namespace infolerp::support {

using cluster_thresholds = std::map<std::string, float>;
using cluster_progress = std::function<void(const std::string& label, std::size_t done, std::size_t total)>;

template <class Tracer, class Exec>
result<mesh_clustering> cluster_object(const indexed_mesh& mesh, const Tracer& tracer, Exec&& exec,
                                       const cluster_thresholds& thresholds = {}, const std::string& label = {},
                                       const cluster_progress& progress = {}) {
  const auto th = [&](const char* channel, double fallback) {
    const auto it = thresholds.find(channel);
    return it == thresholds.end() ? fallback : static_cast<double>(it->second);
  };
  return cluster_mesh(mesh, tracer, exec, cluster_options{},
                      visibility_channel{.threshold = th("visibility", 0.48), .viewpoints = 64,
                                         .progress = [&](std::size_t done, std::size_t total) {
                                           if (progress) progress(label, done, total);
                                         }},
                      orientation_channel{.threshold = th("orientation", 0.05), .bins = 256},
                      stretch_channel{.threshold = th("stretch", 0.1), .bins = 256});
}

// Splits every cluster at texture seams: the I-Buffer interpolates texcoords, which is wrong
// across a seam (u = 0.99 and u = 0.01 average to 0.5), and the paper's models use multi-chart
// parameterisations. Ids become the connected pieces of (cluster ∩ texture chart): triangles
// are connected through a shared vertex index at which both have the same texcoords (the demo's
// meshes duplicate vertices along seams). Objects without texcoords keep their clusters, split
// into connected pieces only. O(triangles) with union-find. A cluster that reaches around a
// seam (connected the other way round, e.g. a whole UV sphere) stays one id: a limitation.
// One mesh: ids[t] -> new ids 0..count-1 (returned in out), the count returned.
inline std::uint32_t split_at_texture_seams(const indexed_mesh& m, const std::vector<std::uint32_t>& ids,
                                            std::vector<std::uint32_t>& out) {
  const std::size_t n = m.triangle_count();
  std::vector<std::uint32_t> parent(n);
  for (std::size_t t = 0; t < n; ++t) parent[t] = static_cast<std::uint32_t>(t);
  const auto find = [&](std::uint32_t t) {
    while (parent[t] != t) t = parent[t] = parent[parent[t]];
    return t;
  };
  std::vector<std::vector<std::pair<std::uint32_t, glm::vec2>>> at_vertex(m.vertex_count());  // (triangle, uv)
  for (std::size_t t = 0; t < n; ++t)
    for (unsigned k = 0; k < 3; ++k)
      at_vertex[m.triangles[t][static_cast<int>(k)]].push_back(
          {static_cast<std::uint32_t>(t), m.has_texcoords() ? m.texcoord(t, k) : glm::vec2(0.0f)});
  for (const auto& ts : at_vertex)
    for (std::size_t i = 1; i < ts.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (ids[ts[i].first] == ids[ts[j].first] && ts[i].second == ts[j].second)
          parent[find(ts[i].first)] = find(ts[j].first);
  out.assign(n, invalid_id);
  std::vector<std::uint32_t> id_of_root(n, invalid_id);
  std::uint32_t count = 0;
  for (std::size_t t = 0; t < n; ++t) {
    const std::uint32_t r = find(static_cast<std::uint32_t>(t));
    if (id_of_root[r] == invalid_id) id_of_root[r] = count++;
    out[t] = id_of_root[r];
  }
  return count;
}

inline scene_clustering split_at_texture_seams(const demo_scene& scene, const scene_clustering& in) {
  scene_clustering out{in.name, {}, {}};
  for (std::uint32_t g = 0; g < scene.objects.size(); ++g) {
    std::vector<std::uint32_t> local;
    const std::uint32_t count = split_at_texture_seams(scene.objects[g].mesh, in.ids[g], local);
    const auto offset = static_cast<std::uint32_t>(out.geometry_of.size());
    for (auto& k : local) k += offset;
    out.geometry_of.insert(out.geometry_of.end(), count, g);
    out.ids.push_back(std::move(local));
  }
  return out;
}

template <class Exec>
result<scene_clustering> cluster_by_features(
    const demo_scene& scene, Exec&& exec, const cluster_thresholds& thresholds = {}, const cluster_progress& progress = {},
    const std::function<void(const std::string&, const mesh_clustering&)>& on_object = {}) {
  scene_clustering out{"feature", {}, {}};
  std::uint32_t offset = 0;
  for (std::uint32_t g = 0; g < scene.objects.size(); ++g) {
    const auto& object = scene.objects[g];
    std::vector<std::uint32_t> remap;
    const indexed_mesh welded = weld_positions(object.mesh, remap);  // seams joined; same triangles
    auto r = cluster_object(welded, scene.tracer, exec, thresholds, object.name, progress);
    if (!r) return r.error();
    if (on_object) on_object(object.name, *r);
    for (auto& k : r->cluster_of) k += offset;
    offset += r->cluster_count;
    out.ids.push_back(std::move(r->cluster_of));
    out.geometry_of.insert(out.geometry_of.end(), r->cluster_count, g);
  }
  return out;
}

}  // namespace infolerp::support
