#pragma once
// The procedural walkthrough scene of the refinement experiment (Oliveira, Santos, Proença, §5,
// §6): a street with a portico (six columns under a roof slab), a long wall and a tall
// temple-like column on a coarse ground of large triangles (10 m each), lit by a low sun so that
// hard shadows cross triangles without touching their vertices. Used by infolerp_pareto refine
// and examples/refine_wireframe.cpp.
#include <cstdint>
#include <memory>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "infolerp/refine/progressive_driver.hpp"
#include "support/embree_tracer.hpp"
#include "support/image.hpp"

namespace infolerp::support {

struct walkthrough_scene {
  indexed_mesh mesh;              // one mesh: ground, columns, roof, wall, temple column
  std::vector<glm::vec3> albedo;  // per triangle
  std::vector<glm::vec3> normal;  // per triangle, unit
  glm::vec3 to_sun{0.0f, 0.0f, 1.0f};  // unit, toward the sun

  // Traced with Embree 3; committed by make_walkthrough_scene().
  std::unique_ptr<embree_device> device;
  std::unique_ptr<embree_scene> tracer;
  hit intersect(const ray& r) const { return tracer->intersect(r); }
  bool occluded(const ray& r) const { return tracer->occluded(r); }

  // Lambert with a hard sun shadow (one ray) and a constant sky term, at point p of triangle t.
  // Thread-safe; sets flush-to-zero on the calling thread (embree_tracer.hpp).
  glm::vec3 shade(glm::vec3 p, std::uint32_t t) const;
};

// Builds the scene and commits its tracer. Errors: Embree rejects the mesh.
result<walkthrough_scene> make_walkthrough_scene();

// The street view of the experiment: from the end of the street toward the portico.
pinhole_camera walkthrough_camera(std::uint32_t width, std::uint32_t height);

// The paper's three kinds of view (§5): down the street with the portico's column shadows, along
// the long city wall (many triangles in view once refined), and the temple column whose long
// shadow crosses large ground triangles without touching a vertex.
enum class walkthrough_view : std::uint8_t { street, wall, temple };
pinhole_camera walkthrough_camera(walkthrough_view view, std::uint32_t width, std::uint32_t height);

// Frame `frame` of a path of `frames` cameras: from the street view into the temple view over
// the first half, back along the same way over the second (frame f and frames - 1 - f coincide).
pinhole_camera walkthrough_path(std::uint32_t frame, std::uint32_t frames, std::uint32_t width, std::uint32_t height);

// A street of `blocks` repeated blocks along +y, each 40 m long with its own ground (4 × 4 quads,
// no vertex shared with the next block), a portico of six columns under a roof slab, a wall and
// a tall column, under the same low sun: a scene larger than any view, for walks that keep
// entering new parts of it.
result<walkthrough_scene> make_long_street_scene(std::uint32_t blocks);
// Frame `frame` of a walk of `frames` cameras down the long street, from the first block to the
// last, looking ahead: it never comes back.
pinhole_camera long_street_path(std::uint32_t frame, std::uint32_t frames, std::uint32_t blocks, std::uint32_t width,
                                std::uint32_t height);

// The refiner's current image with the boundaries between the leaves under neighbouring
// pixels drawn in a wire colour (so hidden edges are not drawn).
image leaf_wireframe(const progressive_refiner& r, std::uint32_t width, std::uint32_t height);

}  // namespace infolerp::support
