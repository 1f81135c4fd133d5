#include "support/demo_scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <string_view>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include "infolerp/mesh/adaptors.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/validate.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"
#include "support/mesh_io.hpp"
#include "support/procedural.hpp"

namespace infolerp::support {

namespace {
constexpr float pi = 3.14159265358979323846f;

// A small integer hash (for per-brick colour variation that is the same on every run).
float hash01(int x, int y) {
  auto h = static_cast<std::uint32_t>(x) * 0x8da6b343u ^ static_cast<std::uint32_t>(y) * 0xd8163841u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return static_cast<float>(h & 0xffffu) / 65535.0f;
}
}  // namespace

pinhole_rays camera::rays() const {
  pinhole_rays r;
  r.eye = eye;
  r.forward = glm::normalize(target - eye);
  r.right = glm::normalize(glm::cross(r.forward, up));
  r.true_up = glm::cross(r.right, r.forward);
  r.half_h = std::tan(0.5f * vertical_fov_degrees * pi / 180.0f);
  return r;
}

float pixel_angle(const camera& c, int height) {
  return 2.0f * std::tan(0.5f * c.vertical_fov_degrees * pi / 180.0f) / static_cast<float>(height);
}

ray camera::primary_ray(float x, float y, int width, int height) const { return rays()(x, y, width, height); }

glm::vec3 area_light::normal() const { return glm::normalize(glm::cross(edge_u, edge_v)); }
float area_light::area() const { return glm::length(glm::cross(edge_u, edge_v)); }

glm::vec3 albedo(const material& mat, glm::vec2 uv, float lod) {
  const glm::vec2 p = uv * mat.repeat;
  switch (mat.texture) {
    case texture_kind::solid: return mat.color_a;
    case texture_kind::image: return mat.color_a * mat.image->trilinear(p, lod);
    case texture_kind::checker: {
      const auto cell = static_cast<long>(std::floor(p.x)) + static_cast<long>(std::floor(p.y));
      return (cell & 1) == 0 ? mat.color_a : mat.color_b;
    }
    case texture_kind::brick: {
      // Bricks twice as wide as tall; every other row shifted by half a brick; mortar lines.
      const float row = std::floor(p.y);
      const float shifted = p.x * 0.5f + (static_cast<long>(row) % 2 == 0 ? 0.0f : 0.5f);
      const float col = std::floor(shifted);
      const float fx = shifted - col, fy = p.y - row;
      constexpr float mortar = 0.06f;
      if (fx < mortar * 0.5f || fy < mortar) return mat.color_b;
      const float shade = 0.85f + 0.3f * hash01(static_cast<int>(col), static_cast<int>(row));
      return mat.color_a * shade;
    }
  }
  return mat.color_a;
}

float texel_density(const indexed_mesh& m, const texture& image) {
  if (!m.has_texcoords()) return 0.0f;
  double uv_area = 0.0, area = 0.0;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const glm::dvec2 a(m.texcoord(t, 0)), b(m.texcoord(t, 1)), c(m.texcoord(t, 2));
    uv_area += 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
    area += 0.5 * glm::length(area_vector(corners(m, t)));
  }
  const double texels = uv_area * image.width() * image.height();
  return area > 0.0 && texels > 0.0 ? static_cast<float>(std::sqrt(texels / area)) : 0.0f;
}

std::vector<glm::vec3> vertex_normals(const indexed_mesh& m) {
  std::vector<glm::dvec3> sum(m.positions.size(), glm::dvec3(0.0));
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const glm::dvec3 n = area_vector(corners(m, t));  // length = 2·area: area weighting
    const glm::uvec3 tri = m.triangles[t];
    sum[tri.x] += n;
    sum[tri.y] += n;
    sum[tri.z] += n;
  }
  std::vector<glm::vec3> out(sum.size());
  for (std::size_t v = 0; v < sum.size(); ++v) {
    const double len = glm::length(sum[v]);
    out[v] = len > 0.0 && std::isfinite(len) ? glm::vec3(sum[v] / len) : glm::vec3(0.0f, 0.0f, 1.0f);
  }
  return out;
}

namespace {

indexed_mesh transformed(const indexed_mesh& src, const glm::mat4& m) {
  indexed_mesh out;
  append(out, src, m);
  return out;
}

// The same keeping the normals, for a rotation with uniform scale and translation.
indexed_mesh moved(const indexed_mesh& src, const glm::mat4& m) {
  indexed_mesh out = transformed(src, m);
  out.normals.reserve(src.normals.size());
  for (const glm::vec3& n : src.normals) out.normals.push_back(glm::mat3(m) * n);
  return out;
}

// Validates a loaded mesh: indices in range, finite positions (all vertices, as they all enter
// the bounds). Degenerate triangles and non-manifold edges are accepted: the tracer and the
// demo's stages handle them.
status check_mesh(const indexed_mesh& m, const std::string& path) {
  if (auto s = validate_mesh(m, {.allow_degenerate = true, .allow_non_manifold = true, .check_unused_vertices = true}); !s)
    return in_mesh(s, path);
  return {};
}

// An asset's parts: OFF files are read as written (read_off, one untextured part), anything
// else through assimp (load_textured_mesh, one part per material). Every part is validated.
result<std::vector<textured_part>> load_parts(const std::string& path) {
  std::vector<textured_part> parts;
  if (path.ends_with(".off") || path.ends_with(".OFF")) {
    auto m = read_off(path);
    if (!m) return m.error();
    parts.push_back({"", std::move(*m), glm::vec3(0.75f, 0.72f, 0.68f), nullptr, "no texcoords: stretch channel skipped, solid colour"});
  } else {
    auto loaded = load_textured_mesh(path);
    if (!loaded) return loaded.error();
    parts = std::move(*loaded);
  }
  for (const auto& part : parts)
    if (auto s = check_mesh(part.mesh, path); !s) return s;
  return parts;
}

// One part of an asset group with the file it came from.
struct loaded_part {
  std::string path;
  textured_part part;
};

// Loads a group of files that belong together (one --mesh file, or the files of one --group),
// turns them Z-up (a Y-up file is rotated +90° about X; Z-up files stay as they are), scales the
// whole group so that its largest extent is `size` and stands it on the ground at `where` (x,
// y): the files keep their relative placement and scale. One object per part. Normals the file
// lacks are area-weighted vertex normals; the file's are turned with it.
result<std::vector<scene_object>> load_fitted_group(const std::vector<std::string>& paths, bool z_up, float size,
                                                    glm::vec2 where) {
  const glm::mat4 up = z_up ? glm::mat4(1.0f) : glm::rotate(glm::mat4(1.0f), 0.5f * pi, glm::vec3(1.0f, 0.0f, 0.0f));
  std::vector<loaded_part> parts;
  indexed_mesh all;
  for (const auto& path : paths) {
    auto loaded = load_parts(path);
    if (!loaded) return loaded.error();
    for (auto& part : *loaded) {
      part.mesh = moved(part.mesh, up);
      append(all, part.mesh);
      parts.push_back({path, std::move(part)});
    }
  }
  const bounding_box box = mesh_bounds(all);
  const glm::dvec3 extent = box.hi - box.lo;
  const double largest = std::max({extent.x, extent.y, extent.z});
  if (!(largest > 0.0) || !std::isfinite(largest))
    return make_error(errc::degenerate_triangle, no_element, "mesh '", paths.front(), "'", paths.size() > 1 ? " and the rest of its group" : "",
                      " has no extent (or non-finite positions)");
  const auto s = static_cast<float>(size / largest);
  const glm::vec3 c(box.center());
  const glm::vec3 base(c.x, c.y, static_cast<float>(box.lo.z));
  glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(where, 0.0f));
  m = glm::scale(m, glm::vec3(s));
  m = glm::translate(m, -base);
  std::vector<scene_object> out;
  for (auto& [file, part] : parts) {
    const std::string& path = file;  // named, not a binding: lambdas capture it
    indexed_mesh mesh = moved(part.mesh, m);
    if (!mesh.has_normals()) mesh.normals = vertex_normals(mesh);
    for (auto& n : mesh.normals) n = glm::length(n) > 0.0f ? glm::normalize(n) : glm::vec3(0.0f, 0.0f, 1.0f);
    material mat{texture_kind::solid, part.diffuse, {}, {1.0f, 1.0f}, 0.3f, nullptr, 0.0f};
    if (part.image && mesh.has_texcoords()) {
      mat.texture = texture_kind::image;
      mat.image = part.image;
      mat.texels_per_unit = texel_density(mesh, *part.image);
    }
    const bool alone = std::count_if(parts.begin(), parts.end(), [&](const loaded_part& p) { return p.path == path; }) == 1;
    const std::string name = alone && part.material.empty() ? path : path + " [" + part.material + "]";
    out.push_back({name, std::move(mesh), std::move(mat), std::move(part.note)});
  }
  return out;
}

// Clustering paper §4.1: m's triangles split 1:4 until each covers at most max_fraction of a
// square image of camera c (subdivision_mesh::tessellate); texcoords and normals carried to
// the new triangles and vertices (leaf_mesh).
status tessellate_for_view(indexed_mesh& m, const camera& c, float max_fraction) {
  auto sub = subdivision_mesh::create(m);
  if (!sub) return sub.error();
  const glm::mat4 view_projection = glm::perspective(glm::radians(c.vertical_fov_degrees), 1.0f, 0.05f, 1000.0f) *
                                    glm::lookAt(c.eye, c.target, c.up);
  sub->tessellate(screen_fraction_test{.view_projection = view_projection, .max_fraction = max_fraction});
  std::vector<std::uint32_t> leaf_source;
  auto leaves = sub->leaf_mesh(m, leaf_source);
  if (!leaves) return leaves.error();
  m = std::move(*leaves);
  return {};
}

// The asset slots: each --group's files together (in the order of their first file), each
// other file alone.
std::vector<std::vector<std::string>> asset_groups(const demo_scene_options& o) {
  std::vector<std::vector<std::string>> groups;
  std::map<std::string, std::size_t> slot;
  for (std::size_t i = 0; i < o.mesh_paths.size(); ++i) {
    const std::string group = i < o.mesh_groups.size() ? o.mesh_groups[i] : std::string();
    if (group.empty()) {
      groups.push_back({o.mesh_paths[i]});
      continue;
    }
    const auto [it, added] = slot.try_emplace(group, groups.size());
    if (added) groups.emplace_back();
    groups[it->second].push_back(o.mesh_paths[i]);
  }
  return groups;
}

}  // namespace

result<demo_scene> make_demo_scene(const embree_device& device, const demo_scene_options& options) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  std::vector<scene_object> objects;

  // Ground: 16 x 16 units of bricks (48 rows).
  objects.push_back({"ground", make_plane(options.ground_cells, options.ground_cells, 16.0f),
                     {texture_kind::brick, {0.62f, 0.32f, 0.22f}, {0.8f, 0.78f, 0.72f}, {24.0f, 48.0f}, 0.0f}});

  // UV sphere, poles on the Z axis: the checker shows the texture stretch toward the poles.
  {
    const glm::vec3 center{-1.7f, 0.4f, 1.1f};
    indexed_mesh sphere = transformed(make_uv_sphere(options.sphere_slices, options.sphere_stacks, 1.1f),
                                      glm::translate(glm::mat4(1.0f), center));
    sphere.normals.resize(sphere.positions.size());
    for (std::size_t v = 0; v < sphere.positions.size(); ++v)
      sphere.normals[v] = glm::normalize(sphere.positions[v] - center);
    objects.push_back({"uv sphere", std::move(sphere),
                       {texture_kind::checker, {0.9f, 0.9f, 0.85f}, {0.15f, 0.3f, 0.6f}, {16.0f, 8.0f}, 0.4f}});
  }

  // Torus, tilted so that its hole and inner side show.
  {
    glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(1.5f, -0.6f, 0.75f));
    m = glm::rotate(m, 0.6f, glm::vec3(1.0f, 0.3f, 0.0f));
    indexed_mesh torus = transformed(make_torus(options.torus_major, options.torus_minor, 0.75f, 0.28f), m);
    torus.normals = vertex_normals(torus);
    objects.push_back({"torus", std::move(torus), {texture_kind::solid, {0.85f, 0.55f, 0.12f}, {}, {1.0f, 1.0f}, 0.6f}});
  }

  // Boxes (flat shaded): hard shadow casters.
  {
    indexed_mesh boxes;
    append(boxes, make_box({0.1f, 1.6f, 0.0f}, {1.0f, 2.5f, 2.2f}));
    append(boxes, make_box({2.4f, 0.9f, 0.0f}, {3.3f, 1.8f, 0.8f}));
    append(boxes, make_box({-3.6f, -2.2f, 0.0f}, {-2.8f, -1.4f, 0.6f}));
    append(boxes, make_box({-0.6f, -0.4f, 0.0f}, {-0.2f, 0.0f, 1.4f}));
    objects.push_back({"boxes", std::move(boxes), {texture_kind::solid, {0.55f, 0.6f, 0.55f}, {}, {1.0f, 1.0f}, 0.0f}});
  }

  // Assets (groups) side by side along x in front of the built-in objects, then a row further back.
  const auto groups = asset_groups(options);
  for (std::size_t i = 0; i < groups.size(); ++i) {
    const float step = options.mesh_size * 1.2f;
    const std::size_t k = i % 5;  // columns at 0, +1, -1, +2, -2 steps
    const float column = static_cast<float>((k + 1) / 2) * (k % 2 == 1 ? 1.0f : -1.0f);
    const glm::vec2 where{0.2f + column * step, -2.4f - static_cast<float>(i / 5) * step};
    auto user = load_fitted_group(groups[i], options.z_up, options.mesh_size, where);
    if (!user) return user.error();
    for (auto& object : *user) objects.push_back(std::move(object));
  }

  const camera view{{6.5f, -8.5f, 5.0f}, {0.0f, 0.0f, 0.7f}, {0.0f, 0.0f, 1.0f}, 36.0f};
  if (!(options.tessellate >= 0.0f && options.tessellate <= 1.0f))
    return make_error(errc::bad_parameter, no_element, "tessellate = ", options.tessellate, ": a share of the image in [0, 1]");
  for (auto& object : objects)
    if (options.tessellate > 0.0f)
      if (auto s = tessellate_for_view(object.mesh, view, options.tessellate); !s) return s;

  const auto t1 = clock::now();
  embree_scene tracer{device};
  for (const auto& object : objects) {
    auto id = tracer.add_mesh(object.mesh);
    if (!id) return id.error();
  }
  if (auto s = tracer.commit(); !s) return s;

  demo_scene scene{std::move(tracer)};
  scene.objects = std::move(objects);
  scene.load_seconds = std::chrono::duration<double>(t1 - t0).count();
  scene.bvh_seconds = std::chrono::duration<double>(clock::now() - t1).count();
  scene.view = view;
  scene.sun = {glm::normalize(glm::vec3(0.6f, -0.35f, 0.75f)), {1.0f, 0.92f, 0.8f}};
  scene.area = {{-1.2f, -1.2f, 4.5f}, {0.0f, 2.4f, 0.0f}, {2.4f, 0.0f, 0.0f}, {2.2f, 2.2f, 2.4f}};
  return scene;
}

}  // namespace infolerp::support
