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
//       the clusters cut along texture seams (split_at_uv_seams per object; texcoords are
//       interpolated within an id).
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
#include "infolerp/cluster/uv_seams.hpp"
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

// Splits every object's clusters at texture seams (split_at_uv_seams, cluster/uv_seams.hpp):
// the I-Buffer interpolates texcoords within an id. Ids stay offset per object. Errors: those
// of split_at_uv_seams, for the first object that has one.
inline result<scene_clustering> split_at_texture_seams(const demo_scene& scene, const scene_clustering& in) {
  scene_clustering out{in.name, {}, {}};
  for (std::uint32_t g = 0; g < scene.objects.size(); ++g) {
    auto r = split_at_uv_seams(scene.objects[g].mesh, in.ids[g]);
    if (!r) return r.error();
    const auto offset = static_cast<std::uint32_t>(out.geometry_of.size());
    for (auto& k : r->cluster_of) k += offset;
    out.geometry_of.insert(out.geometry_of.end(), r->cluster_count, g);
    out.ids.push_back(std::move(r->cluster_of));
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
