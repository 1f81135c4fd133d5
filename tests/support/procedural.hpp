#pragma once
// Procedural meshes with known geometry, for analytic tests and the built-in demo scene.
#include <cstdint>
#include <glm/mat4x4.hpp>
#include "infolerp/mesh/adaptors.hpp"

namespace infolerp::support {

// Icosahedron subdivided `level` times (1:4, midpoints pushed to the sphere). Outward winding.
indexed_mesh make_icosphere(unsigned level, float radius = 1.0f);
// Torus around +Z: `major` segments around the ring, `minor` around the tube. Outward winding.
indexed_mesh make_torus(unsigned major, unsigned minor, float ring_radius, float tube_radius);
// Latitude/longitude sphere around +Z with per-corner texcoords u = longitude/2π,
// v = colatitude/π (stretch grows toward the poles). slices >= 3, stacks >= 2.
indexed_mesh make_uv_sphere(unsigned slices, unsigned stacks, float radius = 1.0f);
// Plane z = 0 over [-size/2, size/2]², nx by ny quads, normal +Z, texcoords in [0,1]².
indexed_mesh make_plane(unsigned nx, unsigned ny, float size);
// Axis-aligned box, 8 shared vertices, 12 triangles, outward winding.
indexed_mesh make_box(glm::vec3 lo, glm::vec3 hi);
// Midpoint 1:4 subdivision: each triangle into four, new vertices at edge midpoints (shared
// between the two triangles of an edge). Texcoords and normals are dropped. O(T log T).
indexed_mesh subdivide_midpoint(const indexed_mesh& in);
// Mean edge length over the triangles' corners (each interior edge counted twice). O(T).
float mean_edge_length(const indexed_mesh& m);
// Detail at every scale from `finest` up to `coarsest` (world units): each vertex moves along its
// area-weighted normal by a sum of octaves of 3D value noise of its rest position, wavelengths
// finest, 2·finest, 4·finest, ... up to coarsest, each with amplitude `relative_amplitude` times
// its wavelength (a 1/f spectrum: every scale equally rough). Deterministic in `seed`; texcoords
// and normals are dropped. O(V · octaves + T).
indexed_mesh add_noise_detail(const indexed_mesh& in, float finest, float coarsest, float relative_amplitude,
                              std::uint32_t seed = 1);
// Appends `src` transformed by `m` to `dst` (texcoords kept only if both have them, or dst is empty).
void append(indexed_mesh& dst, const indexed_mesh& src, const glm::mat4& m = glm::mat4(1.0f));

}  // namespace infolerp::support

namespace infolerp::support {
// Merges vertices at identical positions (UV seams, repeated poles) so that curvature and
// saliency see one connected surface. remap[v] is the welded index of original vertex v.
// Texcoords (per corner) are kept; normals are dropped. O(V log V).
indexed_mesh weld_positions(const indexed_mesh& m, std::vector<std::uint32_t>& remap);
}  // namespace infolerp::support
