#pragma once
// The built-in demo scene (procedural, no downloads): a brick-textured ground plane, a
// checker-textured UV sphere (its texture stretches toward the poles), a torus, boxes that cast
// hard shadows, optional user assets (--mesh FILE, repeatable; textured, one object per
// material), a pinhole camera, a sun (hard shadow) and
// a rectangular area light (soft shadow). Z is up. Shared by the demo, tests and benchmarks.
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "support/embree_tracer.hpp"
#include "support/texture.hpp"

namespace infolerp::support {

// A pinhole camera that looks from eye at target.
// A pinhole camera's ray generator with its basis computed once (camera::primary_ray builds it
// on every call, which costs as much as shading a pixel). Same rays, bit for bit.
struct pinhole_rays {
  glm::vec3 eye{0.0f}, forward{0.0f}, right{0.0f}, true_up{0.0f};
  float half_h = 0.0f;
  // Inline: the upsampler's sources call it once or twice per pixel.
  ray operator()(float x, float y, int width, int height) const {
    const float aspect = static_cast<float>(width) / static_cast<float>(height);
    const float sx = (2.0f * x / static_cast<float>(width) - 1.0f) * half_h * aspect;
    const float sy = (1.0f - 2.0f * y / static_cast<float>(height)) * half_h;
    ray r;
    r.origin = eye;
    r.direction = glm::normalize(forward + sx * right + sy * true_up);
    return r;
  }
};

struct camera {
  glm::vec3 eye{0.0f, -10.0f, 3.0f};
  glm::vec3 target{0.0f};
  glm::vec3 up{0.0f, 0.0f, 1.0f};
  float vertical_fov_degrees = 40.0f;

  // The ray through image point (x, y) of a width x height image, in pixels from the top-left
  // corner (pixel (i, j) has its centre at (i + 0.5, j + 0.5)). Unit direction, tnear 0.
  ray primary_ray(float x, float y, int width, int height) const;
  // The basis of primary_ray, for many rays of one camera.
  pinhole_rays rays() const;
};

// The angle one pixel spans at the centre of a `height`-pixel-high image of camera c (radians).
float pixel_angle(const camera& c, int height);

// A directional light with hard shadows. direction points toward the sun (unit length).
struct sun_light {
  glm::vec3 direction{0.0f, 0.0f, 1.0f};
  glm::vec3 radiance{1.0f};  // irradiance on a surface facing the sun
};

// A one-sided rectangle corner + a·edge_u + b·edge_v, (a, b) in [0,1]², emitting toward
// cross(edge_u, edge_v).
struct area_light {
  glm::vec3 corner{0.0f};
  glm::vec3 edge_u{1.0f, 0.0f, 0.0f};
  glm::vec3 edge_v{0.0f, 1.0f, 0.0f};
  glm::vec3 radiance{1.0f};

  glm::vec3 point(float a, float b) const { return corner + a * edge_u + b * edge_v; }
  glm::vec3 center() const { return point(0.5f, 0.5f); }
  glm::vec3 normal() const;  // unit, the emitting side
  float area() const;
};

// Procedural textures looked up through interpolated texcoords, or an image texture.
enum class texture_kind : std::uint8_t { solid, checker, brick, image };
struct material {
  texture_kind texture = texture_kind::solid;
  glm::vec3 color_a{0.7f};              // solid colour, checker even cells, bricks, image factor
  glm::vec3 color_b{0.2f};              // checker odd cells, mortar
  glm::vec2 repeat{1.0f};               // texture cells per unit of texcoord (u, v)
  float specular = 0.0f;                // Blinn-Phong weight (white highlight)
  std::shared_ptr<const support::texture> image{};  // texture_kind::image: the texture (mips)
  float texels_per_unit = 0.0f;         // image: level-0 texels per world unit on the mesh (mean
                                        // over its area), which turns a footprint into a mip level
};
// Albedo of `mat` at texcoord uv (pure, deterministic). lod: log2 of the sample footprint in
// level-0 texels of an image texture (trilinear mip lookup); procedural textures ignore it.
glm::vec3 albedo(const material& mat, glm::vec2 uv, float lod = 0.0f);

// One object of the scene: objects[g] is the tracer's geometry g. Meshes with per-vertex normals
// are shaded smooth, the others flat; texcoords, when present, drive the material's texture.
struct scene_object {
  std::string name;
  indexed_mesh mesh;
  material mat;
  std::string note{};  // for loaded assets: what is missing (texcoords, texture) and what that skips
};

struct demo_scene {
  std::vector<scene_object> objects;
  embree_scene tracer;  // committed; geometry ids are indices into objects
  // Shadow and AO rays go against this scene instead of `tracer` when set (e.g. the full mesh
  // while `tracer` holds a LOD's drawn triangles); it must outlive the shaders.
  const embree_scene* occluders = nullptr;
  camera view;
  sun_light sun;
  area_light area;
  glm::vec3 sky_zenith{0.25f, 0.45f, 0.85f};
  glm::vec3 sky_horizon{0.75f, 0.85f, 0.95f};
  glm::vec3 ambient{0.25f, 0.28f, 0.34f};  // sky light reaching an unoccluded surface (scaled by AO)
  float ao_radius = 1.5f;               // ambient-occlusion rays look this far
  float ray_offset = 1e-3f;             // secondary rays start this far off the surface
  double load_seconds = 0.0;            // make_demo_scene's wall time making and loading the objects
  double bvh_seconds = 0.0;             // and building the tracer's BVH (Embree commit)

  explicit demo_scene(embree_scene t) : tracer(std::move(t)) {}
};

struct demo_scene_options {
  std::vector<std::string> mesh_paths;  // real assets (OFF/OBJ/glTF/PLY ... via assimp) to add
  float mesh_size = 1.8f;         // each asset is scaled so its largest extent is this
  unsigned sphere_slices = 64;    // UV sphere tessellation
  unsigned sphere_stacks = 32;
  unsigned torus_major = 64;      // torus tessellation
  unsigned torus_minor = 24;
  unsigned ground_cells = 16;     // ground plane quads per side
  // Per mesh path, the group it belongs to ("" or missing: alone). A group's files are placed
  // and scaled together, keeping their relative placement and scale (e.g. a car and its wheel).
  std::vector<std::string> mesh_groups{};
  bool z_up = false;              // the assets are Z-up (as this scene); false: Y-up, turned +90° about X
  // §4.1 of the clustering paper: every object's triangles split 1:4 (closure only) until none
  // covers more than this share of a square image of the scene's view (0: not tessellated).
  float tessellate = 0.0f;
};

// Builds the scene on `device` and commits its tracer. Each asset adds one object per material
// (named "FILE [material]"), textured when the material has a diffuse texture and the mesh
// texcoords; assets (a group counts as one) stand side by side in front of the built-in
// objects. Errors: an asset or its texture cannot be loaded (the message names the file) or has
// no triangles Embree accepts, tessellate not in [0, 1].
result<demo_scene> make_demo_scene(const embree_device& device, const demo_scene_options& options = {});

// Level-0 texels per world unit of `image` on mesh m: sqrt(texture area covered / surface area),
// both summed over the triangles (0 without texcoords or area).
float texel_density(const indexed_mesh& m, const texture& image);

// Area-weighted vertex normals (unit; (0,0,1) for a vertex whose triangles have no area).
std::vector<glm::vec3> vertex_normals(const indexed_mesh& m);

}  // namespace infolerp::support
