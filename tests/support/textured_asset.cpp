#include "support/textured_asset.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <array>
#include <cstring>
#include <fstream>
#include <iterator>
#include <glm/geometric.hpp>

namespace infolerp::support {

namespace {

constexpr float padding = 1.0f / 64.0f;  // of a tile's width and height, on every side

// An exact 8-bit sRGB colour as linear RGB (so that writing and reading a PNG is lossless).
glm::vec3 srgb8(int r, int g, int b) {
  return {srgb_to_linear(static_cast<float>(r) / 255.0f), srgb_to_linear(static_cast<float>(g) / 255.0f),
          srgb_to_linear(static_cast<float>(b) / 255.0f)};
}

// Material k's texture at texel (x, y) of an n x n image: bricks, checker or rings, tinted by
// the tile (chart) so that seams between charts show.
glm::vec3 texel(unsigned k, int x, int y, int n, unsigned tiles) {
  const int tile = std::min(static_cast<int>(tiles) - 1, x * static_cast<int>(tiles) / n);
  const int tint = 40 * tile;
  switch (k % 3) {
    case 0: {  // bricks 16 x 8 texels, mortar lines
      const int row = y / 8, col = (x + (row % 2) * 8) / 16;
      if (y % 8 == 0 || (x + (row % 2) * 8) % 16 == 0) return srgb8(200, 196, 180);
      return srgb8(150 + (col * 37 + row * 11) % 60, 70 + tint, 50);
    }
    case 1:  // checker of 8-texel cells
      return ((x / 8 + y / 8) % 2 == 0) ? srgb8(230, 230, 215 - tint) : srgb8(40 + tint, 70, 150);
    default: {  // rings around the image centre, 6 texels apart
      const double d = std::hypot(x - n / 2, y - n / 2);
      const int ring = static_cast<int>(d / 6.0) % 3;
      return ring == 0 ? srgb8(40, 140 + tint / 2, 60) : ring == 1 ? srgb8(220, 200, 60) : srgb8(90, 60, 30 + tint);
    }
  }
}

// Point (s, t) in [0,1]² of cube face f, on the bumpy sphere, and its outward direction.
glm::vec3 face_point(unsigned f, float s, float t) {
  const float a = 2.0f * s - 1.0f, b = 2.0f * t - 1.0f;
  const unsigned axis = f / 2;
  const float sign = f % 2 == 0 ? 1.0f : -1.0f;
  glm::vec3 p;
  p[static_cast<int>(axis)] = sign;
  p[static_cast<int>((axis + 1) % 3)] = sign * a;  // keeps every face counter-clockwise outward
  p[static_cast<int>((axis + 2) % 3)] = b;
  const glm::vec3 d = glm::normalize(p);
  const float bump = 1.0f + 0.05f * std::sin(9.0f * d.x) * std::sin(9.0f * d.y) * std::sin(9.0f * d.z);
  return d * bump;
}

status write_png_checked(const image& img, const std::filesystem::path& path) { return write_png(img, path.string()); }

std::string png_name(const std::string& name, unsigned k) { return name + "_" + std::to_string(k) + ".png"; }

status write_textures(const textured_asset& a, const std::filesystem::path& dir, const std::string& name) {
  for (unsigned k = 0; k < a.materials; ++k)
    if (auto s = write_png_checked(a.textures[k], dir / png_name(name, k)); !s) return s;
  return {};
}

// Triangles of material k, in order.
std::vector<std::size_t> triangles_of(const textured_asset& a, unsigned k) {
  std::vector<std::size_t> out;
  for (std::size_t t = 0; t < a.material.size(); ++t)
    if (a.material[t] == k) out.push_back(t);
  return out;
}

}  // namespace

std::uint32_t textured_asset::chart_at(glm::vec2 uv, std::uint32_t material_id) const {
  const float u = uv.x - std::floor(uv.x), v = uv.y - std::floor(uv.y);
  const float tile_w = 1.0f / static_cast<float>(tiles);
  const auto tile = std::min(tiles - 1, static_cast<unsigned>(u / tile_w));
  const float su = u / tile_w - static_cast<float>(tile);
  if (su < padding * 0.5f || su > 1.0f - padding * 0.5f || v < padding * 0.5f || v > 1.0f - padding * 0.5f) return charts;
  const unsigned c = tile * materials + material_id;
  return c < charts ? c : charts;
}

textured_asset make_textured_asset(const textured_asset_options& o) {
  textured_asset a;
  a.materials = std::clamp(o.materials, 1u, 6u);
  a.tiles = (6 + a.materials - 1) / a.materials;
  const unsigned n = std::max(o.cells, 1u);
  for (unsigned f = 0; f < 6; ++f) {
    const auto base = static_cast<unsigned>(a.mesh.positions.size());
    const unsigned k = f % a.materials, tile = f / a.materials;
    for (unsigned j = 0; j <= n; ++j)
      for (unsigned i = 0; i <= n; ++i)
        a.mesh.positions.push_back(face_point(f, static_cast<float>(i) / static_cast<float>(n), static_cast<float>(j) / static_cast<float>(n)));
    auto uv = [&](unsigned i, unsigned j) {
      const float s = padding + (1.0f - 2.0f * padding) * static_cast<float>(i) / static_cast<float>(n);
      const float t = padding + (1.0f - 2.0f * padding) * static_cast<float>(j) / static_cast<float>(n);
      return glm::vec2((static_cast<float>(tile) + s) / static_cast<float>(a.tiles), t);
    };
    auto id = [&](unsigned i, unsigned j) { return base + j * (n + 1) + i; };
    for (unsigned j = 0; j < n; ++j)
      for (unsigned i = 0; i < n; ++i) {
        const unsigned q[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
        for (const auto& tri : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
          a.mesh.triangles.push_back({id(q[tri[0]][0], q[tri[0]][1]), id(q[tri[1]][0], q[tri[1]][1]), id(q[tri[2]][0], q[tri[2]][1])});
          for (int c : tri) a.mesh.texcoords.push_back(uv(q[c][0], q[c][1]));
          a.material.push_back(k);
          a.chart.push_back(f);
        }
      }
  }
  // Vertex normals from the triangles (area weighted), per face grid: faces meet at hard seams.
  a.mesh.normals.assign(a.mesh.positions.size(), glm::vec3(0.0f));
  for (const glm::uvec3& t : a.mesh.triangles) {
    const glm::vec3 nrm = glm::cross(a.mesh.positions[t.y] - a.mesh.positions[t.x], a.mesh.positions[t.z] - a.mesh.positions[t.x]);
    for (int c = 0; c < 3; ++c) a.mesh.normals[t[c]] += nrm;
  }
  for (auto& nrm : a.mesh.normals) nrm = glm::normalize(nrm);
  const int size = std::max(o.texture_size, 8);
  for (unsigned k = 0; k < a.materials; ++k) {
    image img(size, size);
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) img.at(x, y) = texel(k, x, y, size, a.tiles);
    a.textures.push_back(std::move(img));
  }
  return a;
}

result<std::string> write_obj(const textured_asset& a, const std::filesystem::path& dir, const std::string& name) {
  const auto obj = dir / (name + ".obj"), mtl = dir / (name + ".mtl");
  {
    std::ofstream out(mtl);
    for (unsigned k = 0; k < a.materials; ++k)
      out << "newmtl material_" << k << "\nKd 1 1 1\nmap_Kd " << png_name(name, k) << "\n";
    if (!out) return make_error(errc::bad_parameter, no_element, "cannot write '", mtl.string(), "'");
  }
  std::FILE* f = std::fopen(obj.string().c_str(), "w");
  if (f == nullptr) return make_error(errc::bad_parameter, no_element, "cannot write '", obj.string(), "'");
  std::fprintf(f, "mtllib %s.mtl\n", name.c_str());
  for (const auto& p : a.mesh.positions) std::fprintf(f, "v %.9g %.9g %.9g\n", double{p.x}, double{p.y}, double{p.z});
  for (const auto& nrm : a.mesh.normals) std::fprintf(f, "vn %.9g %.9g %.9g\n", double{nrm.x}, double{nrm.y}, double{nrm.z});
  for (const auto& t : a.mesh.texcoords) std::fprintf(f, "vt %.9g %.9g\n", double{t.x}, double{t.y});
  for (unsigned k = 0; k < a.materials; ++k) {
    std::fprintf(f, "usemtl material_%u\n", k);
    for (const std::size_t t : triangles_of(a, k)) {
      const glm::uvec3 v = a.mesh.triangles[t] + 1u;
      const auto c = static_cast<unsigned long>(3 * t + 1);
      std::fprintf(f, "f %u/%lu/%u %u/%lu/%u %u/%lu/%u\n", v.x, c, v.x, v.y, c + 1, v.y, v.z, c + 2, v.z);
    }
  }
  const bool ok = std::fclose(f) == 0;
  if (!ok) return make_error(errc::bad_parameter, no_element, "cannot write '", obj.string(), "'");
  if (auto s = write_textures(a, dir, name); !s) return s;
  return obj.string();
}

namespace {

// The glTF document of `a` with its binary buffer in `bin`: per material, positions, normals and
// texcoords of its corners. Images are the PNG files DIR/NAME_K.png, referenced by file name, or
// (embed, for GLB) copied into the buffer after the geometry.
result<std::string> gltf_json(const textured_asset& a, const std::filesystem::path& dir, const std::string& name, bool embed,
                              std::vector<unsigned char>& bin) {
  std::vector<float> data;
  std::string accessors, views, primitives;
  std::size_t view_count = 0;
  auto add_view = [&](std::size_t offset, std::size_t bytes) {
    views += (view_count++ == 0 ? "" : ",");
    views += "{\"buffer\":0,\"byteOffset\":" + std::to_string(offset) + ",\"byteLength\":" + std::to_string(bytes) + "}";
  };
  std::size_t accessor = 0;
  for (unsigned k = 0; k < a.materials; ++k) {
    const auto tris = triangles_of(a, k);
    const std::size_t corners = 3 * tris.size();
    glm::vec3 lo(1e30f), hi(-1e30f);
    const std::size_t pos_at = data.size();
    for (const std::size_t t : tris)
      for (int c = 0; c < 3; ++c) {
        const glm::vec3 p = a.mesh.positions[a.mesh.triangles[t][c]];
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
        data.insert(data.end(), {p.x, p.y, p.z});
      }
    const std::size_t nrm_at = data.size();
    for (const std::size_t t : tris)
      for (int c = 0; c < 3; ++c) {
        const glm::vec3 nrm = a.mesh.normals[a.mesh.triangles[t][c]];
        data.insert(data.end(), {nrm.x, nrm.y, nrm.z});
      }
    const std::size_t uv_at = data.size();
    for (const std::size_t t : tris)
      for (unsigned c = 0; c < 3; ++c) {
        const glm::vec2 uv = a.mesh.texcoord(t, c);
        data.insert(data.end(), {uv.x, 1.0f - uv.y});  // glTF's v runs down the image
      }
    add_view(4 * pos_at, 4 * (nrm_at - pos_at));
    add_view(4 * nrm_at, 4 * (uv_at - nrm_at));
    add_view(4 * uv_at, 4 * (data.size() - uv_at));
    char minmax[160];
    std::snprintf(minmax, sizeof minmax, "\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]", double{lo.x}, double{lo.y},
                  double{lo.z}, double{hi.x}, double{hi.y}, double{hi.z});
    const std::string count = std::to_string(corners);
    if (!accessors.empty()) accessors += ",";
    accessors += "{\"bufferView\":" + std::to_string(accessor) + ",\"componentType\":5126,\"count\":" + count +
                 ",\"type\":\"VEC3\"," + minmax + "},";
    accessors += "{\"bufferView\":" + std::to_string(accessor + 1) + ",\"componentType\":5126,\"count\":" + count + ",\"type\":\"VEC3\"},";
    accessors += "{\"bufferView\":" + std::to_string(accessor + 2) + ",\"componentType\":5126,\"count\":" + count + ",\"type\":\"VEC2\"}";
    if (!primitives.empty()) primitives += ",";
    primitives += "{\"attributes\":{\"POSITION\":" + std::to_string(accessor) + ",\"NORMAL\":" + std::to_string(accessor + 1) +
                  ",\"TEXCOORD_0\":" + std::to_string(accessor + 2) + "},\"material\":" + std::to_string(k) + "}";
    accessor += 3;
  }
  bin.resize(4 * data.size());
  std::memcpy(bin.data(), data.data(), bin.size());
  std::string materials, textures, images;
  for (unsigned k = 0; k < a.materials; ++k) {
    const std::string sep = k == 0 ? "" : ",";
    materials += sep + "{\"name\":\"material_" + std::to_string(k) +
                 "\",\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":" + std::to_string(k) +
                 "},\"metallicFactor\":0,\"roughnessFactor\":1}}";
    textures += sep + "{\"source\":" + std::to_string(k) + ",\"sampler\":0}";
    if (!embed) {
      images += sep + "{\"uri\":\"" + png_name(name, k) + "\"}";
      continue;
    }
    const auto png = dir / png_name(name, k);
    std::ifstream in(png, std::ios::binary);
    const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (bytes.empty()) return make_error(errc::bad_parameter, no_element, "cannot read '", png.string(), "'");
    images += sep + "{\"bufferView\":" + std::to_string(view_count) + ",\"mimeType\":\"image/png\"}";
    add_view(bin.size(), bytes.size());
    bin.insert(bin.end(), bytes.begin(), bytes.end());
    bin.resize((bin.size() + 3) / 4 * 4, 0);
  }
  const std::string buffer = embed ? "{\"byteLength\":" + std::to_string(bin.size()) + "}"
                                   : "{\"uri\":\"" + name + ".bin\",\"byteLength\":" + std::to_string(bin.size()) + "}";
  return "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
         "\"meshes\":[{\"primitives\":[" + primitives + "]}],\"materials\":[" + materials + "],\"textures\":[" + textures +
         "],\"samplers\":[{\"wrapS\":10497,\"wrapT\":10497}],\"images\":[" + images + "],\"accessors\":[" + accessors +
         "],\"bufferViews\":[" + views + "],\"buffers\":[" + buffer + "]}";
}

}  // namespace

result<std::string> write_gltf(const textured_asset& a, const std::filesystem::path& dir, const std::string& name) {
  const auto gltf = dir / (name + ".gltf"), bin_path = dir / (name + ".bin");
  if (auto s = write_textures(a, dir, name); !s) return s;
  std::vector<unsigned char> bin;
  auto json = gltf_json(a, dir, name, false, bin);
  if (!json) return json.error();
  std::ofstream b(bin_path, std::ios::binary);
  b.write(reinterpret_cast<const char*>(bin.data()), static_cast<std::streamsize>(bin.size()));
  if (!b) return make_error(errc::bad_parameter, no_element, "cannot write '", bin_path.string(), "'");
  std::ofstream out(gltf);
  out << *json << "\n";
  if (!out) return make_error(errc::bad_parameter, no_element, "cannot write '", gltf.string(), "'");
  return gltf.string();
}

result<std::string> write_ply(const textured_asset& a, const std::filesystem::path& dir, const std::string& name) {
  const auto ply = dir / (name + ".ply");
  if (auto s = write_textures(a, dir, name); !s) return s;
  // Each vertex belongs to one chart's grid, so one texcoord per vertex holds every corner's.
  std::vector<glm::vec2> uv(a.mesh.positions.size());
  for (std::size_t t = 0; t < a.mesh.triangles.size(); ++t)
    for (unsigned c = 0; c < 3; ++c) uv[a.mesh.triangles[t][static_cast<int>(c)]] = a.mesh.texcoord(t, c);
  std::FILE* f = std::fopen(ply.string().c_str(), "w");
  if (f == nullptr) return make_error(errc::bad_parameter, no_element, "cannot write '", ply.string(), "'");
  std::fprintf(f, "ply\nformat ascii 1.0\ncomment TextureFile %s\nelement vertex %zu\nproperty float x\nproperty float y\n"
               "property float z\nproperty float s\nproperty float t\nelement face %zu\nproperty list uchar int vertex_indices\nend_header\n",
               png_name(name, 0).c_str(), a.mesh.positions.size(), a.mesh.triangles.size());
  for (std::size_t v = 0; v < uv.size(); ++v) {
    const glm::vec3 p = a.mesh.positions[v];
    std::fprintf(f, "%.9g %.9g %.9g %.9g %.9g\n", double{p.x}, double{p.y}, double{p.z}, double{uv[v].x}, double{uv[v].y});
  }
  for (const glm::uvec3& t : a.mesh.triangles) std::fprintf(f, "3 %u %u %u\n", t.x, t.y, t.z);
  if (std::fclose(f) != 0) return make_error(errc::bad_parameter, no_element, "cannot write '", ply.string(), "'");
  return ply.string();
}

result<std::string> write_glb(const textured_asset& a, const std::filesystem::path& dir, const std::string& name) {
  const auto glb = dir / (name + ".glb");
  if (auto s = write_textures(a, dir, name); !s) return s;
  std::vector<unsigned char> bin;
  auto json = gltf_json(a, dir, name, true, bin);
  if (!json) return json.error();
  json->resize((json->size() + 3) / 4 * 4, ' ');
  // Header (magic "glTF", version 2, total length), then the JSON and BIN chunks.
  const auto u32 = [](std::size_t v) { return static_cast<std::uint32_t>(v); };
  const std::uint32_t header[3] = {0x46546C67u, 2u, u32(12 + 8 + json->size() + 8 + bin.size())};
  const std::uint32_t json_chunk[2] = {u32(json->size()), 0x4E4F534Au}, bin_chunk[2] = {u32(bin.size()), 0x004E4942u};
  std::ofstream out(glb, std::ios::binary);
  out.write(reinterpret_cast<const char*>(header), sizeof header);
  out.write(reinterpret_cast<const char*>(json_chunk), sizeof json_chunk);
  out.write(json->data(), static_cast<std::streamsize>(json->size()));
  out.write(reinterpret_cast<const char*>(bin_chunk), sizeof bin_chunk);
  out.write(reinterpret_cast<const char*>(bin.data()), static_cast<std::streamsize>(bin.size()));
  if (!out) return make_error(errc::bad_parameter, no_element, "cannot write '", glb.string(), "'");
  return glb.string();
}

}  // namespace infolerp::support
