#pragma once
// Shared by the loader fuzz targets (fuzz_load_*.cpp): the input's parts written as files of one
// directory of this process (the loaders read paths, as the demo and examples call them), and
// the checks every loaded result must pass: an error names the file; a mesh has triangles whose
// indices are in range, arrays of consistent sizes, finite texcoords and usable textures.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <vector>
#include <unistd.h>
#include "fuzz_common.hpp"
#include "support/mesh_io.hpp"

namespace fuzz {

inline const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("infolerp_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

// Writes `bytes` to scratch_dir()/name; returns the path.
inline std::string write_file(const std::string& name, std::span<const std::uint8_t> bytes) {
  const auto path = scratch_dir() / name;
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return path.string();
}

// The input cut at its first `parts - 1` NUL bytes (the last part keeps any further NULs).
inline std::vector<std::span<const std::uint8_t>> split(const std::uint8_t* data, std::size_t size, std::size_t parts) {
  std::vector<std::span<const std::uint8_t>> out;
  std::size_t begin = 0;
  for (std::size_t i = 0; i < size && out.size() + 1 < parts; ++i)
    if (data[i] == 0) {
      out.emplace_back(data + begin, i - begin);
      begin = i + 1;
    }
  out.emplace_back(data + begin, size - begin);
  out.resize(parts, std::span<const std::uint8_t>{});
  return out;
}

inline void check_error_names(const infolerp::status& s, const std::string& path) {
  check_error(s);
  if (!s.ok()) FUZZ_CHECK(std::string(s.message()).find(path) != std::string::npos);
}

// A loaded mesh: triangles, indices in range, per-vertex normals or none, per-corner texcoords
// (finite) or none.
inline void check_mesh(const infolerp::indexed_mesh& m) {
  FUZZ_CHECK(!m.triangles.empty());
  FUZZ_CHECK(indices_in_range(m));
  FUZZ_CHECK(m.normals.empty() || m.normals.size() == m.positions.size());
  FUZZ_CHECK(m.texcoords.empty() || m.texcoords.size() == 3 * m.triangles.size());
  for (const auto& uv : m.texcoords) FUZZ_CHECK(std::isfinite(uv.x) && std::isfinite(uv.y));
}

inline void check_load_mesh(const std::string& path) {
  const auto m = infolerp::support::load_mesh(path);
  check_error_names(m.error(), path);
  if (m) check_mesh(*m);
}

// Every part checked; each texture looked up at every texcoord on its smallest and largest level.
inline void check_load_textured_mesh(const std::string& path) {
  const auto parts = infolerp::support::load_textured_mesh(path);
  check_error_names(parts.error(), path);
  if (!parts) return;
  for (const auto& part : *parts) {
    check_mesh(part.mesh);
    if (!part.image) continue;
    FUZZ_CHECK(part.image->width() > 0 && part.image->height() > 0);
    for (const auto& uv : part.mesh.texcoords) {
      const glm::vec3 a = part.image->bilinear(uv, 0), b = part.image->trilinear(uv, 100.0f);
      FUZZ_CHECK(finite(a) && finite(b));
    }
  }
}

}  // namespace fuzz
