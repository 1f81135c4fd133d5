#pragma once
// What an engine draws instead of view_dependent_lod: a uniform LOD (meshopt_simplify of the
// whole mesh) with the same culling, at the same drawn triangle count as the frame compared.
//   meshopt_culled:   culled per triangle by the library's own test (hidden_triangle with the
//                     same camera); back faces are hidden where the FULL mesh's part is closed
//                     (closed_part_triangles of the full mesh), whatever the simplified mesh's
//                     topology, as an engine culls a one-sided material's back faces, and drawn
//                     when the eye is inside a closed part (the crossings of a ray from the eye
//                     with the full mesh's closed triangles do not sum to 0);
//   meshopt_meshlets: the LOD split into meshlets (meshopt_buildMeshlets, 64 vertices / 124
//                     triangles, cone weight 0.25), each culled whole by its bounding sphere
//                     against the frustum's planes and by its normal cone (meshopt_computeMeshletBounds),
//                     what a mesh-shader engine does.
// The simplification target is searched (secant steps, then bisection) for the largest LOD whose
// drawn count after culling is at most the count asked, so that the peer draws what we draw.
// Header-only; needs meshoptimizer (Debian libmeshoptimizer-dev).
#include <meshoptimizer.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>
#include <glm/geometric.hpp>
#include "infolerp/lod/hidden_triangles.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "support/mesh_views.hpp"

namespace infolerp::support {

// The LOD harness's cameras: the 8 orbit cameras of mesh_views.hpp (whole mesh in frame) and 8
// close ones between them, the eye at 1.2 bounding radii from the box centre (the mesh
// overflows the frustum).
inline std::vector<camera> lod_view_cameras(const indexed_mesh& m) {
  std::vector<camera> cams;
  for (unsigned k = 0; k < 8; ++k) cams.push_back(mesh_view_camera(k, 8, m.positions));
  const auto close = static_cast<float>(1.2 * 0.5 * mesh_bounds(m).diagonal());
  for (unsigned k = 0; k < 8; ++k) {
    camera c = mesh_view_camera(2 * k + 1, 16, m.positions);
    c.eye = c.target + close * glm::normalize(c.eye - c.target);
    cams.push_back(c);
  }
  return cams;
}

// view_dependent_lod's camera for a support camera on a size x size viewport.
inline lod_camera to_lod_camera(const camera& c, std::uint32_t size) {
  return {glm::dvec3(c.eye), glm::dvec3(c.target - c.eye), glm::dvec3(c.up),
          static_cast<double>(c.vertical_fov_degrees) * 3.141592653589793 / 180.0, size, size};
}

// What culling needs from the full mesh, built once per mesh.
struct cull_source {
  const infolerp::indexed_mesh* mesh = nullptr;
  std::vector<std::uint8_t> one_sided_vertex;  // on a closed part of the full mesh
  std::vector<glm::vec3> closed;               // corners of the full mesh's closed triangles
};

inline cull_source make_cull_source(const infolerp::indexed_mesh& m) {
  cull_source s;
  s.mesh = &m;
  const std::span<const std::uint32_t> idx(&m.triangles[0].x, 3 * m.triangle_count());
  const std::vector<std::uint8_t> closed = infolerp::closed_part_triangles(idx, m.positions);
  s.one_sided_vertex.assign(m.vertex_count(), 0);
  for (std::size_t t = 0; t < closed.size(); ++t) {
    if (!closed[t]) continue;
    for (int j = 0; j < 3; ++j) {
      const std::uint32_t v = m.triangles[t][j];
      s.one_sided_vertex[v] = 1;
      s.closed.push_back(m.positions[v]);
    }
  }
  return s;
}

// Whether back faces may be culled for this camera: the eye outside every closed part.
inline bool eye_outside(const cull_source& s, const infolerp::view_frustum& v) {
  long winding = 0;
  for (std::size_t i = 0; i < s.closed.size(); i += 3)
    winding += infolerp::eye_ray_crossing(v, s.closed[i], s.closed[i + 1], s.closed[i + 2]);
  return winding == 0;
}

struct peer_frame {
  std::vector<std::uint32_t> lod;    // the uniform LOD (the whole simplified mesh)
  std::vector<std::uint32_t> drawn;  // what survives culling
  double cull_seconds = 0.0;         // the per-frame step: culling the LOD
};

// The triangles of `lod` the camera may see (hidden_triangle per triangle), into out.
inline void cull_triangles(const cull_source& s, const infolerp::view_frustum& v, bool back_faces,
                           std::span<const std::uint32_t> lod, std::vector<std::uint32_t>& out) {
  const auto& p = s.mesh->positions;
  out.clear();
  for (std::size_t k = 0; k < lod.size(); k += 3) {
    const std::uint32_t a = lod[k], b = lod[k + 1], c = lod[k + 2];
    const bool one_sided = back_faces && s.one_sided_vertex[a];
    if (!infolerp::hidden_triangle(v, p[a], p[b], p[c], one_sided)) out.insert(out.end(), {a, b, c});
  }
}

// Meshlets of `lod` the camera may see: sphere against the frustum's side planes and the plane
// through the eye, normal cone (meshoptimizer's test) where the meshlet lies on a closed part.
inline void cull_meshlets(const cull_source& s, const infolerp::view_frustum& v, bool back_faces,
                          std::span<const std::uint32_t> lod, std::vector<std::uint32_t>& out) {
  out.clear();
  if (lod.empty()) return;  // meshoptimizer builds no meshlets of nothing
  const auto& pos = s.mesh->positions;
  const std::size_t max_v = 64, max_t = 124;
  const std::size_t bound = meshopt_buildMeshletsBound(lod.size(), max_v, max_t);
  std::vector<meshopt_Meshlet> meshlets(bound);
  std::vector<unsigned int> verts(bound * max_v);
  std::vector<unsigned char> tris(bound * max_t * 3);
  const std::size_t n = meshopt_buildMeshlets(meshlets.data(), verts.data(), tris.data(), lod.data(), lod.size(), &pos[0].x,
                                              pos.size(), sizeof(glm::vec3), max_v, max_t, 0.25f);
  out.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const meshopt_Meshlet& ml = meshlets[i];
    const meshopt_Bounds b = meshopt_computeMeshletBounds(&verts[ml.vertex_offset], &tris[ml.triangle_offset], ml.triangle_count,
                                                          &pos[0].x, pos.size(), sizeof(glm::vec3));
    const glm::dvec3 centre(b.center[0], b.center[1], b.center[2]);
    bool hidden = false;
    for (const glm::dvec3& n_in : v.inward) hidden = hidden || glm::dot(glm::normalize(n_in), centre - v.eye) < -double(b.radius);
    bool one_sided = back_faces;
    for (std::size_t j = 0; j < ml.vertex_count && one_sided; ++j) one_sided = s.one_sided_vertex[verts[ml.vertex_offset + j]] != 0;
    if (one_sided && !hidden) {
      const glm::dvec3 apex(b.cone_apex[0], b.cone_apex[1], b.cone_apex[2]), axis(b.cone_axis[0], b.cone_axis[1], b.cone_axis[2]);
      const glm::dvec3 d = apex - v.eye;
      const double len = glm::length(d);
      hidden = len > 0.0 && glm::dot(d, axis) >= double(b.cone_cutoff) * len;
    }
    if (hidden) continue;
    for (std::size_t t = 0; t < ml.triangle_count; ++t)
      for (int j = 0; j < 3; ++j) out.push_back(verts[ml.vertex_offset + tris[ml.triangle_offset + 3 * t + static_cast<std::size_t>(j)]]);
  }
}

// The largest meshopt_simplify LOD whose culled count (cull = cull_triangles or cull_meshlets)
// is at most `drawn`; its culling pass timed once more on warm data.
template <class Cull>
peer_frame uniform_lod_drawing(const cull_source& s, const infolerp::lod_camera& cam, std::size_t drawn, Cull cull) {
  const infolerp::indexed_mesh& m = *s.mesh;
  const infolerp::view_frustum v = infolerp::make_view_frustum(cam);
  const bool back_faces = eye_outside(s, v);
  const std::size_t nt = m.triangle_count();
  const auto* idx = &m.triangles[0].x;
  peer_frame best, trial;
  auto at = [&](std::size_t target, peer_frame& f) {
    f.lod.resize(3 * nt);
    f.lod.resize(meshopt_simplify(f.lod.data(), idx, 3 * nt, &m.positions[0].x, m.vertex_count(), sizeof(glm::vec3),
                                  3 * target, std::numeric_limits<float>::max(), 0, nullptr));
    cull(s, v, back_faces, f.lod, f.drawn);
    return f.drawn.size() / 3;
  };
  // Bracket: lo draws at most `drawn` (the best so far), hi more; secant steps on the visible
  // share, then bisection to 1/1000 of the count.
  std::size_t lo = 0, hi = nt + 1, target = std::max<std::size_t>(drawn, 1);
  if (at(nt, trial) <= drawn) lo = hi = nt, std::swap(best, trial);  // the full mesh fits
  for (int step = 0; step < 40 && hi > lo && hi - lo > std::max<std::size_t>(1, drawn / 1000); ++step) {
    const std::size_t got = at(target, trial);
    if (got <= drawn) {
      lo = target;
      std::swap(best, trial);
      if (got == drawn || target >= nt) break;
    } else {
      hi = target;
    }
    const double share = got > 0 ? static_cast<double>(got) / static_cast<double>(target) : 0.0;
    std::size_t next = step < 4 && share > 0.0 ? static_cast<std::size_t>(static_cast<double>(drawn) / share) : (lo + hi) / 2;
    if (next <= lo || next >= hi) next = lo + (hi - lo) / 2;
    if (next == lo) break;
    target = std::min(next, nt);
  }
  std::vector<std::uint32_t> scratch;
  const auto t0 = std::chrono::steady_clock::now();
  cull(s, v, back_faces, best.lod, scratch);
  best.cull_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return best;
}

inline peer_frame meshopt_culled(const cull_source& s, const infolerp::lod_camera& cam, std::size_t drawn) {
  return uniform_lod_drawing(s, cam, drawn, cull_triangles);
}

inline peer_frame meshopt_meshlets(const cull_source& s, const infolerp::lod_camera& cam, std::size_t drawn) {
  return uniform_lod_drawing(s, cam, drawn, cull_meshlets);
}

}  // namespace infolerp::support
