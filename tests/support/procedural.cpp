#include "support/procedural.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>
#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace infolerp::support {

namespace {
constexpr float pi = 3.14159265358979323846f;
}

indexed_mesh make_icosphere(unsigned level, float radius) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  indexed_mesh m;
  m.positions = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& p : m.positions) p = glm::normalize(p);
  for (unsigned l = 0; l < level; ++l) {
    std::map<std::pair<unsigned, unsigned>, unsigned> mid;
    auto midpoint = [&](unsigned a, unsigned b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      const auto id = static_cast<unsigned>(m.positions.size());
      m.positions.push_back(glm::normalize(m.positions[a] + m.positions[b]));
      mid.emplace(key, id);
      return id;
    };
    std::vector<glm::uvec3> next;
    next.reserve(m.triangles.size() * 4);
    for (const auto& tri : m.triangles) {
      const unsigned a = midpoint(tri.x, tri.y), b = midpoint(tri.y, tri.z), c = midpoint(tri.z, tri.x);
      next.insert(next.end(), {{tri.x, a, c}, {tri.y, b, a}, {tri.z, c, b}, {a, b, c}});
    }
    m.triangles = std::move(next);
  }
  for (auto& p : m.positions) p *= radius;
  return m;
}

indexed_mesh make_torus(unsigned major, unsigned minor, float ring_radius, float tube_radius) {
  indexed_mesh m;
  for (unsigned i = 0; i < major; ++i) {
    const float u = 2.0f * pi * static_cast<float>(i) / static_cast<float>(major);
    for (unsigned j = 0; j < minor; ++j) {
      const float v = 2.0f * pi * static_cast<float>(j) / static_cast<float>(minor);
      const float r = ring_radius + tube_radius * std::cos(v);
      m.positions.push_back({r * std::cos(u), r * std::sin(u), tube_radius * std::sin(v)});
    }
  }
  for (unsigned i = 0; i < major; ++i)
    for (unsigned j = 0; j < minor; ++j) {
      const unsigned i1 = (i + 1) % major, j1 = (j + 1) % minor;
      const unsigned a = i * minor + j, b = i1 * minor + j, c = i1 * minor + j1, d = i * minor + j1;
      m.triangles.push_back({a, b, c});
      m.triangles.push_back({a, c, d});
    }
  return m;
}

indexed_mesh make_uv_sphere(unsigned slices, unsigned stacks, float radius) {
  indexed_mesh m;
  // Vertex grid (stacks+1) x (slices+1) with a seam column; texcoords are copied per corner.
  auto vid = [&](unsigned i, unsigned j) { return i * (slices + 1) + j; };
  std::vector<glm::vec2> uv;
  for (unsigned i = 0; i <= stacks; ++i) {
    const float theta = pi * static_cast<float>(i) / static_cast<float>(stacks);
    for (unsigned j = 0; j <= slices; ++j) {
      // The seam column repeats column 0 and the poles repeat one point, bit for bit, so that
      // weld_positions can join them (float sin(π) and cos(2π) are not exact).
      const float phi = 2.0f * pi * static_cast<float>(j % slices) / static_cast<float>(slices);
      const bool pole = i == 0 || i == stacks;
      const float s = pole ? 0.0f : std::sin(theta), c = i == 0 ? 1.0f : i == stacks ? -1.0f : std::cos(theta);
      m.positions.push_back(radius * glm::vec3(s * std::cos(phi), s * std::sin(phi), c));
      uv.push_back({static_cast<float>(j) / static_cast<float>(slices), static_cast<float>(i) / static_cast<float>(stacks)});
    }
  }
  auto emit = [&](unsigned a, unsigned b, unsigned c) {
    m.triangles.push_back({a, b, c});
    m.texcoords.insert(m.texcoords.end(), {uv[a], uv[b], uv[c]});
  };
  // Quad (i, j): a top-left, b below it, c below-right, d right. At the poles a==d or b==c in
  // position, so a single triangle is emitted there (no zero-area triangles).
  for (unsigned i = 0; i < stacks; ++i)
    for (unsigned j = 0; j < slices; ++j) {
      const unsigned a = vid(i, j), b = vid(i + 1, j), c = vid(i + 1, j + 1), d = vid(i, j + 1);
      if (i == 0) {
        emit(a, b, c);
      } else if (i + 1 == stacks) {
        emit(a, b, d);
      } else {
        emit(a, b, c);
        emit(a, c, d);
      }
    }
  // Pole and seam vertices stay duplicated (a UV seam); positions coincide there.
  return m;
}

indexed_mesh make_plane(unsigned nx, unsigned ny, float size) {
  indexed_mesh m;
  std::vector<glm::vec2> uv;
  for (unsigned j = 0; j <= ny; ++j)
    for (unsigned i = 0; i <= nx; ++i) {
      const glm::vec2 t{static_cast<float>(i) / static_cast<float>(nx), static_cast<float>(j) / static_cast<float>(ny)};
      m.positions.push_back({(t.x - 0.5f) * size, (t.y - 0.5f) * size, 0.0f});
      uv.push_back(t);
    }
  for (unsigned j = 0; j < ny; ++j)
    for (unsigned i = 0; i < nx; ++i) {
      const unsigned a = j * (nx + 1) + i, b = a + 1, c = a + nx + 2, d = a + nx + 1;
      m.triangles.push_back({a, b, c});
      m.triangles.push_back({a, c, d});
      m.texcoords.insert(m.texcoords.end(), {uv[a], uv[b], uv[c], uv[a], uv[c], uv[d]});
    }
  return m;
}

indexed_mesh make_box(glm::vec3 lo, glm::vec3 hi) {
  indexed_mesh m;
  for (unsigned i = 0; i < 8; ++i)
    m.positions.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
  m.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                 {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return m;
}

void append(indexed_mesh& dst, const indexed_mesh& src, const glm::mat4& m) {
  const bool keep_uv = (dst.triangles.empty() || dst.has_texcoords()) && src.has_texcoords();
  if (!keep_uv) dst.texcoords.clear();
  const auto base = static_cast<unsigned>(dst.positions.size());
  for (const auto& p : src.positions) dst.positions.push_back(glm::vec3(m * glm::vec4(p, 1.0f)));
  for (const auto& t : src.triangles) dst.triangles.push_back(t + glm::uvec3(base));
  if (keep_uv) dst.texcoords.insert(dst.texcoords.end(), src.texcoords.begin(), src.texcoords.end());
  dst.normals.clear();
}

float mean_edge_length(const indexed_mesh& m) {
  double sum = 0.0;
  for (const auto& t : m.triangles)
    sum += static_cast<double>(glm::distance(m.positions[t.x], m.positions[t.y]) + glm::distance(m.positions[t.y], m.positions[t.z]) +
                               glm::distance(m.positions[t.z], m.positions[t.x]));
  return m.triangles.empty() ? 0.0f : static_cast<float>(sum / (3.0 * static_cast<double>(m.triangles.size())));
}

namespace {
// A lattice value in [-1, 1] for integer point (x, y, z) of octave `o`.
float lattice_value(std::int32_t x, std::int32_t y, std::int32_t z, std::uint32_t o) {
  std::uint32_t h = o * 0x9E3779B9u;
  for (std::uint32_t c : {static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z)}) {
    h ^= c + 0x7F4A7C15u + (h << 6) + (h >> 2);
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
  }
  h *= 0xC2B2AE35u;
  h ^= h >> 16;
  return static_cast<float>(h) / 2147483647.5f - 1.0f;
}

// Value noise at p (lattice spacing 1): the lattice values blended with the quintic fade.
float value_noise(glm::vec3 p, std::uint32_t o) {
  const glm::vec3 f = glm::floor(p), u = p - f;
  const glm::vec3 w = u * u * u * (u * (u * 6.0f - 15.0f) + 10.0f);
  const auto x = static_cast<std::int32_t>(f.x), y = static_cast<std::int32_t>(f.y), z = static_cast<std::int32_t>(f.z);
  float sum = 0.0f;
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
    sum += (dx ? w.x : 1.0f - w.x) * (dy ? w.y : 1.0f - w.y) * (dz ? w.z : 1.0f - w.z) * lattice_value(x + dx, y + dy, z + dz, o);
  }
  return sum;
}
}  // namespace

indexed_mesh add_noise_detail(const indexed_mesh& in, float finest, float coarsest, float relative_amplitude, std::uint32_t seed) {
  indexed_mesh out;
  out.positions = in.positions;
  out.triangles = in.triangles;
  std::vector<glm::vec3> normal(in.positions.size(), glm::vec3(0.0f));
  for (const auto& t : in.triangles) {
    const glm::vec3 n = glm::cross(in.positions[t.y] - in.positions[t.x], in.positions[t.z] - in.positions[t.x]);
    normal[t.x] += n, normal[t.y] += n, normal[t.z] += n;
  }
  for (std::size_t v = 0; v < in.positions.size(); ++v) {
    const float len = glm::length(normal[v]);
    if (!(len > 0.0f)) continue;
    float d = 0.0f;
    std::uint32_t o = seed * 64u;
    for (float wavelength = finest; wavelength <= coarsest; wavelength *= 2.0f, ++o)
      d += relative_amplitude * wavelength * value_noise(in.positions[v] / wavelength, o);
    out.positions[v] += d / len * normal[v];
  }
  return out;
}

indexed_mesh subdivide_midpoint(const indexed_mesh& in) {
  indexed_mesh out;
  out.positions = in.positions;
  std::map<std::pair<unsigned, unsigned>, unsigned> mid;
  auto midpoint = [&](unsigned a, unsigned b) {
    const auto key = std::minmax(a, b);
    auto [it, inserted] = mid.emplace(key, static_cast<unsigned>(out.positions.size()));
    if (inserted) out.positions.push_back(0.5f * (in.positions[a] + in.positions[b]));
    return it->second;
  };
  for (const auto& t : in.triangles) {
    const unsigned a = midpoint(t.x, t.y), b = midpoint(t.y, t.z), c = midpoint(t.z, t.x);
    out.triangles.insert(out.triangles.end(), {{t.x, a, c}, {t.y, b, a}, {t.z, c, b}, {a, b, c}});
  }
  return out;
}

}  // namespace infolerp::support

namespace infolerp::support {
indexed_mesh weld_positions(const indexed_mesh& m, std::vector<std::uint32_t>& remap) {
  // Sorted by position, ties by index (a std::map of the positions took 8x the time for 4x the
  // vertices at 150k to 600k): each vertex joins the first of its equal run, and the kept
  // positions come in order of first occurrence. The positions are sorted with their indices,
  // side by side, so that the sort reads memory in order.
  struct keyed {
    glm::vec3 p;
    std::uint32_t v;
  };
  auto less = [](const glm::vec3& a, const glm::vec3& b) {
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
  };
  const std::size_t n = m.positions.size();
  std::vector<keyed> order(n);
  for (std::size_t v = 0; v < n; ++v) order[v] = {m.positions[v], static_cast<std::uint32_t>(v)};
  std::sort(order.begin(), order.end(), [&](const keyed& a, const keyed& b) { return less(a.p, b.p) || (!less(b.p, a.p) && a.v < b.v); });
  std::vector<std::uint32_t> first(n);
  for (std::size_t k = 0; k < n; ++k)
    first[order[k].v] = k > 0 && !less(order[k - 1].p, order[k].p) ? first[order[k - 1].v] : order[k].v;
  indexed_mesh out;
  remap.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    if (first[v] == v) {
      remap[v] = static_cast<std::uint32_t>(out.positions.size());
      out.positions.push_back(m.positions[v]);
    } else {
      remap[v] = remap[first[v]];
    }
  }
  out.triangles.reserve(m.triangles.size());
  for (const auto& t : m.triangles) out.triangles.push_back({remap[t.x], remap[t.y], remap[t.z]});
  out.texcoords = m.texcoords;
  return out;
}
}  // namespace infolerp::support
