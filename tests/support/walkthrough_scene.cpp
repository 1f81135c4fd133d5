#include "support/walkthrough_scene.hpp"

#include <algorithm>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include "support/procedural.hpp"

namespace infolerp::support {

namespace {

// A box with its own four vertices per face, so a vertex never straddles a crease (a vertex has
// one shading value; a shared corner would be lit for one face and dark for another).
void add_box(indexed_mesh& m, std::vector<glm::vec3>& albedo_of_tri, glm::vec3 lo, glm::vec3 hi, glm::vec3 albedo) {
  const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                          {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  for (const auto& f : faces) {
    const auto base = static_cast<unsigned>(m.positions.size());
    for (int i = 0; i < 4; ++i) m.positions.push_back(c[f[i]]);
    m.triangles.push_back({base, base + 1, base + 2});
    m.triangles.push_back({base, base + 2, base + 3});
    albedo_of_tri.push_back(albedo);
    albedo_of_tri.push_back(albedo);
  }
}

}  // namespace

glm::vec3 walkthrough_scene::shade(glm::vec3 p, std::uint32_t t) const {
  const glm::vec3 n = normal[t];
  const float cosine = glm::dot(n, to_sun);
  float sun = 0.0f;
  if (cosine > 0.0f) {
    enable_flush_to_zero();  // every thread traces alike (embree_tracer.hpp)
    ray sr;
    sr.origin = p + 1e-3f * n;
    sr.direction = to_sun;
    sr.tnear = 1e-4f;
    sun = occluded(sr) ? 0.0f : cosine;
  }
  return albedo[t] * (0.18f + 0.85f * sun);
}

namespace {
result<walkthrough_scene> commit(walkthrough_scene s) {
  for (const glm::uvec3 t : s.mesh.triangles)
    s.normal.push_back(glm::normalize(glm::cross(s.mesh.positions[t.y] - s.mesh.positions[t.x],
                                                 s.mesh.positions[t.z] - s.mesh.positions[t.x])));
  // The sun is behind the portico, so its shadows fall into the street toward the viewer.
  s.to_sun = glm::normalize(glm::vec3(-0.4f, 0.55f, 0.5f));
  s.device = std::make_unique<embree_device>();
  s.tracer = std::make_unique<embree_scene>(*s.device);
  if (auto id = s.tracer->add_mesh(s.mesh); !id) return id.error();
  if (auto st = s.tracer->commit(); !st) return st;
  return s;
}
}  // namespace

result<walkthrough_scene> make_long_street_scene(std::uint32_t blocks) {
  walkthrough_scene s;
  for (std::uint32_t b = 0; b < blocks; ++b) {
    const float y0 = 40.0f * float(b);
    indexed_mesh ground = make_plane(4, 4, 40.0f);  // centred on the origin
    const auto base = static_cast<unsigned>(s.mesh.positions.size());
    for (glm::vec3 p : ground.positions) s.mesh.positions.push_back(p + glm::vec3(0.0f, y0, 0.0f));
    for (glm::uvec3 t : ground.triangles) s.mesh.triangles.push_back(t + glm::uvec3(base));
    s.albedo.resize(s.mesh.triangles.size(), glm::vec3(0.75f, 0.68f, 0.55f));
    for (int i = 0; i < 6; ++i) {  // the portico runs along the street, on its left
      const float y = y0 - 11.0f + 4.0f * float(i);
      add_box(s.mesh, s.albedo, {-9.0f, y, 0.0f}, {-8.3f, y + 0.7f, 5.0f}, glm::vec3(0.85f, 0.83f, 0.78f));
    }
    add_box(s.mesh, s.albedo, {-10.0f, y0 - 12.0f, 5.0f}, {-5.6f, y0 + 11.5f, 5.6f}, glm::vec3(0.6f, 0.35f, 0.3f));
    add_box(s.mesh, s.albedo, {-16.0f, y0 - 14.0f, 0.0f}, {-15.0f, y0 + 3.0f, 4.0f}, glm::vec3(0.7f, 0.62f, 0.5f));
    add_box(s.mesh, s.albedo, {-3.0f, y0 + 8.0f, 0.0f}, {-1.8f, y0 + 9.2f, 10.0f}, glm::vec3(0.9f, 0.9f, 0.86f));
  }
  return commit(std::move(s));
}

pinhole_camera long_street_path(std::uint32_t frame, std::uint32_t frames, std::uint32_t blocks, std::uint32_t width,
                                std::uint32_t height) {
  const float length = 40.0f * float(blocks > 1 ? blocks - 1 : 1);
  const float y = -18.0f + length * float(frame) / float(frames > 1 ? frames - 1 : 1);
  return {.eye = {0.0f, y, 5.5f}, .target = {0.0f, y + 20.0f, 1.0f}, .up = {0, 0, 1}, .vertical_fov_degrees = 55.0f,
          .width = width, .height = height};
}

result<walkthrough_scene> make_walkthrough_scene() {
  walkthrough_scene s;
  // Ground: 40 × 40 m in 4 × 4 quads (32 triangles, 10 m each): vertex shading alone sees no shadow.
  s.mesh = make_plane(4, 4, 40.0f);
  s.albedo.assign(s.mesh.triangles.size(), glm::vec3(0.75f, 0.68f, 0.55f));
  // Portico: six columns under a roof slab along the street.
  for (int i = 0; i < 6; ++i) {
    const float x = -11.0f + 4.0f * float(i);
    add_box(s.mesh, s.albedo, {x, 4.0f, 0.0f}, {x + 0.7f, 4.7f, 5.0f}, glm::vec3(0.85f, 0.83f, 0.78f));
  }
  add_box(s.mesh, s.albedo, {-12.0f, 3.6f, 5.0f}, {11.5f, 8.0f, 5.6f}, glm::vec3(0.6f, 0.35f, 0.3f));
  // City wall along the left of the street.
  add_box(s.mesh, s.albedo, {-16.0f, -14.0f, 0.0f}, {-15.0f, 3.0f, 4.0f}, glm::vec3(0.7f, 0.62f, 0.5f));
  // Temple column: tall, casting a long shadow across the street toward the viewer.
  add_box(s.mesh, s.albedo, {1.0f, -2.6f, 0.0f}, {2.2f, -1.4f, 10.0f}, glm::vec3(0.9f, 0.9f, 0.86f));
  return commit(std::move(s));
}

pinhole_camera walkthrough_camera(std::uint32_t width, std::uint32_t height) {
  return {.eye = {0.0f, -19.0f, 5.5f}, .target = {0.0f, 1.0f, 1.0f}, .up = {0, 0, 1}, .vertical_fov_degrees = 55.0f,
          .width = width, .height = height};
}

pinhole_camera walkthrough_camera(walkthrough_view view, std::uint32_t width, std::uint32_t height) {
  pinhole_camera c = walkthrough_camera(width, height);
  switch (view) {
    case walkthrough_view::street: break;
    case walkthrough_view::wall:
      c.eye = {-5.0f, -13.0f, 2.2f};
      c.target = {-15.0f, -3.0f, 1.8f};
      break;
    case walkthrough_view::temple:
      c.eye = {9.0f, -15.0f, 4.0f};
      c.target = {2.5f, -5.0f, 1.0f};
      break;
  }
  return c;
}

pinhole_camera walkthrough_path(std::uint32_t frame, std::uint32_t frames, std::uint32_t width, std::uint32_t height) {
  const pinhole_camera a = walkthrough_camera(walkthrough_view::street, width, height);
  const pinhole_camera b = walkthrough_camera(walkthrough_view::temple, width, height);
  const std::uint32_t last = frames > 1 ? frames - 1 : 1;
  const std::uint32_t k = std::min(frame, last - std::min(frame, last));  // frames from the nearer end
  const float t = std::min(1.0f, 2.0f * float(k) / float(last));
  const float s = t * t * (3.0f - 2.0f * t);  // smoothstep: slow at both ends
  pinhole_camera c = a;
  c.eye = glm::mix(a.eye, b.eye, s);
  c.target = glm::mix(a.target, b.target, s);
  return c;
}

image leaf_wireframe(const progressive_refiner& r, std::uint32_t w, std::uint32_t h) {
  image img(static_cast<int>(w), static_cast<int>(h));
  r.reconstruct(img.pixels);
  const auto leaf = r.pixel_leaves();
  std::vector<glm::vec3> out = img.pixels;
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x) {
      const std::size_t p = std::size_t(y) * w + x;
      const bool edge = (x + 1 < w && leaf[p + 1] != leaf[p]) || (y + 1 < h && leaf[p + w] != leaf[p]);
      if (edge && leaf[p] != invalid_id) out[p] = glm::vec3(0.05f, 0.9f, 1.0f) * 0.6f + 0.4f * img.pixels[p];
    }
  img.pixels = std::move(out);
  return img;
}

}  // namespace infolerp::support
