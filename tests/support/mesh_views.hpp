#pragma once
// Images of one mesh alone under the reference shader (reference_shader.hpp), for comparing a
// simplified index buffer with the full one: the triangles indices[3t..3t+2] over `positions`,
// flat shaded in one grey, seen from `views` cameras on a circle around the bounding box of all
// positions (azimuth 2πk/views, elevation +25° for even k and −15° for odd k, the bounding
// sphere filling the 40° field of view), each lit by a sun and an area light fixed relative to
// its camera (above-left of the eye), ambient occlusion within 20% of the box diagonal, sky
// behind. The cameras depend only on `positions`, so a full and a simplified index buffer over
// the same vertices are seen alike.
#include <cstdint>
#include <span>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"
#include "support/embree_tracer.hpp"
#include "support/image.hpp"
#include "support/reference_shader.hpp"

namespace infolerp::support {

struct mesh_view_options {
  int width = 256, height = 256;
  unsigned views = 8;
  shader_options shader{.ao_rays = 16, .soft_shadow_rays = 4};
  int threads = 0;  // render_reference's OpenMP threads (0: OpenMP's default)
  // Triangles (over the same positions) the shadow and AO rays are traced against, their back
  // faces ignored (a closed mesh occludes where a ray enters it, so a LOD's surface drawn just
  // inside the full one does not shadow itself, as a shadow map's bias does); empty: the drawn
  // ones, both faces. A LOD's picture with occlusion from the full mesh, as a shadow map or a
  // separate BVH gives an engine.
  std::span<const std::uint32_t> occluders{};
};

// Camera k of `views` around the bounding box of `positions` (the one render_mesh_views uses;
// view 0 is the same for any number of views).
camera mesh_view_camera(unsigned k, unsigned views, std::span<const glm::vec3> positions);

// One image per view. Errors: no triangles, an index out of range, sizes not positive.
// Cost: views × width × height × (2 + soft + AO rays) rays plus one BVH build.
result<std::vector<image>> render_mesh_views(const embree_device& device, std::span<const glm::vec3> positions,
                                             std::span<const std::uint32_t> indices, const mesh_view_options& opt = {});

// The same from the given cameras (opt.views unused).
result<std::vector<image>> render_mesh_views(const embree_device& device, std::span<const glm::vec3> positions,
                                             std::span<const std::uint32_t> indices, std::span<const camera> cameras,
                                             const mesh_view_options& opt = {});

struct view_similarity {
  double psnr = 0.0;  // mean over the views of support::psnr (dB, 8-bit display values)
  double ssim = 0.0;  // mean over the views of the SSIM of display luma
};

// The images against reference images of the same views and sizes. Errors: counts or sizes
// differ, images below 11×11. An identical view's PSNR (+inf) counts as 99 dB in the mean.
result<view_similarity> compare_views(const std::vector<image>& images, const std::vector<image>& reference);

}  // namespace infolerp::support
