#include "support/mesh_views.hpp"

#include <cmath>
#include <numbers>
#include <glm/geometric.hpp>
#include "infolerp/mesh/geometry.hpp"
#include "support/demo_upsample.hpp"
#include "support/ssim.hpp"

namespace infolerp::support {

namespace {

// Camera k of n around a sphere (centre c, radius r), Z up.
camera view_camera(unsigned k, unsigned n, const glm::dvec3& c, double r) {
  const double azimuth = 2.0 * std::numbers::pi * k / n;
  const double elevation = (k % 2 == 0 ? 25.0 : -15.0) * std::numbers::pi / 180.0;
  const double fov = 40.0;
  const double dist = r / std::sin(0.5 * fov * std::numbers::pi / 180.0);
  const glm::dvec3 dir(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  return {glm::vec3(c + dist * dir), glm::vec3(c), {0.0f, 0.0f, 1.0f}, static_cast<float>(fov)};
}

bounding_box box_of(std::span<const glm::vec3> positions) {
  bounding_box box;
  for (const glm::vec3& p : positions) box.extend(glm::dvec3(p));
  return box;
}

}  // namespace

camera mesh_view_camera(unsigned k, unsigned views, std::span<const glm::vec3> positions) {
  const bounding_box box = box_of(positions);
  return view_camera(k, views, box.center(), 0.5 * box.diagonal());
}

result<std::vector<image>> render_mesh_views(const embree_device& device, std::span<const glm::vec3> positions,
                                             std::span<const std::uint32_t> indices, const mesh_view_options& opt) {
  const bounding_box box = box_of(positions);
  std::vector<camera> cams(opt.views);
  for (unsigned k = 0; k < opt.views; ++k) cams[k] = view_camera(k, opt.views, box.center(), 0.5 * box.diagonal());
  return render_mesh_views(device, positions, indices, cams, opt);
}

result<std::vector<image>> render_mesh_views(const embree_device& device, std::span<const glm::vec3> positions,
                                             std::span<const std::uint32_t> indices, std::span<const camera> cameras,
                                             const mesh_view_options& opt) {
  if (indices.empty() || indices.size() % 3 != 0)
    return make_error(errc::bad_size, indices.size(), "render_mesh_views: ", indices.size(),
                      " indices is not a positive multiple of 3");
  if (opt.width <= 0 || opt.height <= 0 || cameras.empty())
    return make_error(errc::bad_parameter, no_element, "render_mesh_views: size ", opt.width, "x", opt.height, " and ",
                      cameras.size(), " views must be positive");
  auto mesh_of = [&](std::span<const std::uint32_t> idx) -> result<indexed_mesh> {
    indexed_mesh m;
    m.positions.assign(positions.begin(), positions.end());
    m.triangles.resize(idx.size() / 3);
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      m.triangles[t] = {idx[3 * t], idx[3 * t + 1], idx[3 * t + 2]};
      for (int j = 0; j < 3; ++j)
        if (m.triangles[t][j] >= positions.size())
          return make_error(errc::index_out_of_range, t, "render_mesh_views: triangle ", t, " uses vertex ",
                            m.triangles[t][j], " of ", positions.size());
    }
    return m;
  };
  auto drawn = mesh_of(indices);
  if (!drawn) return drawn.error();
  indexed_mesh m = std::move(*drawn);
  if (opt.occluders.size() % 3 != 0)
    return make_error(errc::bad_size, opt.occluders.size(), "render_mesh_views: ", opt.occluders.size(),
                      " occluder indices is not a multiple of 3");
  embree_scene occluders{device, {.occlude_front_faces_only = true}};
  if (!opt.occluders.empty()) {
    auto occ = mesh_of(opt.occluders);
    if (!occ) return occ.error();
    if (auto id = occluders.add_mesh(*occ); !id) return id.error();
    if (auto s = occluders.commit(); !s) return s;
  }
  const bounding_box box = box_of(positions);
  const double r = 0.5 * box.diagonal();
  embree_scene tracer{device};
  if (auto id = tracer.add_mesh(m); !id) return id.error();
  if (auto s = tracer.commit(); !s) return s;
  demo_scene scene{std::move(tracer)};
  if (!opt.occluders.empty()) scene.occluders = &occluders;
  scene.objects.push_back({"mesh", std::move(m), {texture_kind::solid, {0.75f, 0.72f, 0.68f}, {}, {1.0f, 1.0f}, 0.3f}});
  scene.ao_radius = static_cast<float>(0.4 * r);
  scene.ray_offset = static_cast<float>(1e-4 * r);
  std::vector<image> out(cameras.size());
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    scene.view = cameras[k];
    const glm::vec3 fwd = glm::normalize(scene.view.target - scene.view.eye);
    const glm::vec3 right = glm::normalize(glm::cross(fwd, scene.view.up)), up = glm::cross(right, fwd);
    scene.sun = {glm::normalize(-fwd - 0.6f * right + 0.8f * up), {1.0f, 0.92f, 0.8f}};
    const float s = static_cast<float>(r);
    const glm::vec3 light_centre = scene.view.eye + s * (2.0f * up - 1.5f * right);
    scene.area = {light_centre - 0.5f * s * (right + fwd), s * fwd, s * right, {2.2f, 2.2f, 2.4f}};
    const reference_shader shader(scene, opt.shader);
    auto stats = render_reference(shader, opt.width, opt.height, out[k], opt.threads);
    if (!stats) return stats.error();
  }
  return out;
}

result<view_similarity> compare_views(const std::vector<image>& images, const std::vector<image>& reference) {
  if (images.size() != reference.size() || images.empty())
    return make_error(errc::bad_size, images.size(), "compare_views: ", images.size(), " images against ",
                      reference.size(), " references");
  view_similarity sum;
  for (std::size_t k = 0; k < images.size(); ++k) {
    const auto p = psnr(reference[k], images[k]);
    if (!p) return p.error();
    sum.psnr += std::isfinite(*p) ? *p : 99.0;
    std::vector<float> a(images[k].pixels.size()), b(a.size());
    for (std::size_t i = 0; i < a.size(); ++i)
      a[i] = display_luma(images[k].pixels[i]), b[i] = display_luma(reference[k].pixels[i]);
    const auto s = ssim(a, b, images[k].width, images[k].height);
    if (!s) return s.error();
    sum.ssim += *s;
  }
  sum.psnr /= static_cast<double>(images.size());
  sum.ssim /= static_cast<double>(images.size());
  return sum;
}

}  // namespace infolerp::support
