// A minimal engine integration: the engine's own mesh type, ray tracer and job system handed to
// infolerp through its traits and concepts. No Embree, no support library: infolerp only.
// Runs validation and topology, mesh saliency, and the I-Buffer upsampler with the engine's
// sample source; exits non-zero if any result is not what the library promises.
#include <atomic>
#include <cstdio>
#include <thread>
#include <glm/gtc/type_ptr.hpp>
#include "infolerp/infolerp.hpp"

namespace engine {
struct Mesh {  // the engine's layout: flat float and index arrays
  std::vector<float> xyz;
  std::vector<unsigned> indices;
};
// A bumpy sphere (grid in latitude/longitude) standing over a ground quad.
Mesh make_scene() {
  Mesh m;
  const unsigned slices = 48, stacks = 24;
  for (unsigned j = 0; j <= stacks; ++j)
    for (unsigned i = 0; i < slices; ++i) {
      const float th = 3.14159265f * static_cast<float>(j) / static_cast<float>(stacks);
      const float ph = 6.2831853f * static_cast<float>(i) / static_cast<float>(slices);
      const float r = 1.0f + 0.08f * std::sin(5.0f * th) * std::sin(4.0f * ph);
      m.xyz.insert(m.xyz.end(), {r * std::sin(th) * std::cos(ph), r * std::sin(th) * std::sin(ph), 1.5f + r * std::cos(th)});
    }
  auto v = [&](unsigned i, unsigned j) { return j * slices + i % slices; };
  for (unsigned j = 0; j < stacks; ++j)
    for (unsigned i = 0; i < slices; ++i) {
      if (j > 0) m.indices.insert(m.indices.end(), {v(i, j), v(i, j + 1), v(i + 1, j)});  // skip slivers at the poles
      if (j + 1 < stacks) m.indices.insert(m.indices.end(), {v(i + 1, j), v(i, j + 1), v(i + 1, j + 1)});
    }
  // The poles' rings collapse to one point each: weld them by pointing at the ring's first vertex.
  for (auto& idx : m.indices) idx = idx < slices ? 0 : (idx >= stacks * slices ? stacks * slices : idx);
  const auto g = static_cast<unsigned>(m.xyz.size() / 3);
  m.xyz.insert(m.xyz.end(), {-4, -4, 0, 4, -4, 0, 4, 4, 0, -4, 4, 0});
  m.indices.insert(m.indices.end(), {g, g + 1, g + 2, g, g + 2, g + 3});
  return m;
}
// The engine's tracer: brute force over every triangle (Möller–Trumbore).
struct Tracer {
  const Mesh* mesh;
  infolerp::hit intersect(const infolerp::ray& r) const {
    infolerp::hit best;
    best.distance = r.tfar;
    for (std::size_t t = 0; t < mesh->indices.size() / 3; ++t) {
      glm::vec3 p[3];
      for (int c = 0; c < 3; ++c) p[c] = glm::make_vec3(&mesh->xyz[3 * mesh->indices[3 * t + static_cast<std::size_t>(c)]]);
      const glm::vec3 e1 = p[1] - p[0], e2 = p[2] - p[0], q = glm::cross(r.direction, e2);
      const float det = glm::dot(e1, q);
      if (std::abs(det) < 1e-12f) continue;
      const glm::vec3 s = (r.origin - p[0]) / det;
      const float u = glm::dot(s, q), v = glm::dot(r.direction, glm::cross(s, e1)), d = glm::dot(e2, glm::cross(s, e1));
      if (u < 0 || v < 0 || u + v > 1 || d < r.tnear || d > best.distance) continue;
      best = {0, static_cast<std::uint32_t>(t), {u, v}, d};
    }
    return best;
  }
  bool occluded(const infolerp::ray& r) const { return intersect(r).valid(); }
};
// The engine's job system: each call fans out to `workers` threads (the caller included) that
// pull chunks from an atomic counter. An engine would keep its threads alive between calls.
struct JobSystem {
  unsigned workers;
  template <class F>
  void parallel_for(std::size_t n, std::size_t grain, F&& fn) const {
    grain = std::max<std::size_t>(grain, 1);
    std::atomic<std::size_t> next{0};
    auto work = [&] {
      for (std::size_t b; (b = next.fetch_add(grain)) < n;) fn(b, std::min(n, b + grain));
    };
    std::vector<std::jthread> threads;
    for (unsigned i = 1; i < workers; ++i) threads.emplace_back(work);
    work();
  }  // the jthreads join here
};
}  // namespace engine

// The mesh type cannot change, so infolerp reads it through a traits specialisation.
template <>
struct infolerp::mesh_traits<engine::Mesh> {
  static std::size_t vertex_count(const engine::Mesh& m) { return m.xyz.size() / 3; }
  static std::size_t triangle_count(const engine::Mesh& m) { return m.indices.size() / 3; }
  static glm::vec3 position(const engine::Mesh& m, std::size_t v) { return glm::make_vec3(&m.xyz[3 * v]); }
  static glm::uvec3 triangle(const engine::Mesh& m, std::size_t t) { return glm::make_vec3(&m.indices[3 * t]); }
};

// The engine's shading as an I-Buffer sample source: primary ray + a hard shadow toward the sun.
struct SampleSource {
  using sample_type = infolerp::surface_sample<0, true>;
  const engine::Mesh* mesh;
  const engine::Tracer* tracer;
  unsigned size;
  glm::vec3 eye{0, -7, 3}, sun = glm::normalize(glm::vec3(0.5f, -0.3f, 1.0f));
  infolerp::ray primary(std::uint32_t x, std::uint32_t y) const {
    const float u = (static_cast<float>(x) + 0.5f) / static_cast<float>(size) - 0.5f, v = 0.5f - (static_cast<float>(y) + 0.5f) / static_cast<float>(size);
    return {eye, 0.0f, glm::normalize(glm::vec3(u, 1.0f, v - 0.2f)), 100.0f};
  }
  sample_type evaluate(std::uint32_t x, std::uint32_t y) const {
    const infolerp::ray r = primary(x, y);
    const infolerp::hit h = tracer->intersect(r);
    sample_type s;
    if (!h.valid()) return s;  // background
    s.position = r.origin + h.distance * r.direction;
    s.normal = glm::vec3(glm::normalize(infolerp::area_vector(infolerp::corners(*mesh, h.triangle))));
    s.cluster = h.triangle >= mesh->indices.size() / 3 - 2 ? 1 : 0;  // ground, sphere
    s.lights = tracer->occluded({s.position + 1e-3f * s.normal, 0.0f, sun, 100.0f}) ? 0u : 1u;
    return s;
  }
  float shade(const sample_type& s, std::uint32_t, std::uint32_t) const {
    if (s.background()) return 0.1f;
    return 0.2f + 0.8f * static_cast<float>(s.lights) * std::max(0.0f, glm::dot(glm::normalize(s.normal), sun));
  }
};

int main() {
  const engine::Mesh mesh = engine::make_scene();
  const engine::JobSystem jobs{3};
  if (auto s = infolerp::validate_mesh(mesh); !s) return std::printf("%s\n", s.message().c_str()), 1;
  engine::Mesh broken = mesh;
  broken.indices[7] = 100000;
  std::printf("broken mesh: %s\n", infolerp::validate_mesh(broken).message().c_str());
  const auto topo = infolerp::make_topology(mesh);
  if (!topo) return 1;
  std::printf("mesh: %zu vertices, %zu triangles, %zu edges, %u components\n", infolerp::mesh_vertex_count(mesh),
              infolerp::mesh_triangle_count(mesh), topo->edge_count(), infolerp::connected_components(*topo).count);

  const auto sal = infolerp::compute_saliency(mesh, {}, jobs);
  const auto serial = infolerp::compute_saliency(mesh);
  if (!sal || !serial) return 1;
  const auto top = std::max_element(sal->saliency.begin(), sal->saliency.end()) - sal->saliency.begin();
  std::printf("saliency: most salient vertex %td (%.3f); job system == serial: %s\n", top, sal->saliency[static_cast<std::size_t>(top)],
              sal->saliency == serial->saliency ? "yes" : "NO");

  const engine::Tracer tracer{&mesh};
  static_assert(infolerp::check_tracer<engine::Tracer>());
  const SampleSource src{&mesh, &tracer, 96};
  std::vector<float> full(96 * 96), fast(96 * 96);
  auto up = infolerp::upsampler<SampleSource::sample_type>::create(96, 96, {.passes = 1});
  if (!up || !up->render(src, std::span<float>(full), jobs) || !up->set_passes(4) || !up->render(src, std::span<float>(fast), jobs))
    return 1;
  double err = 0.0;
  for (std::size_t i = 0; i < full.size(); ++i) err += std::abs(full[i] - fast[i]) / static_cast<double>(full.size());
  const auto& st = up->stats();
  std::printf("upsampler: 4 passes, evaluated %.1f%% of pixels, mean |error| %.4f against per-pixel shading\n",
              100.0 * st.evaluated_fraction(), err);
  return sal->saliency == serial->saliency && st.evaluated_fraction() < 0.5 ? 0 : 1;
}
