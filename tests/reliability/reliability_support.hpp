#pragma once
// Shared by the reliability tests and the fuzz targets: a deterministic synthetic sample source
// for the upsampler whose cluster ids come from a user table (so fuzzers can choose them).
#include <cstdint>
#include <span>
#include <glm/vec3.hpp>
#include "infolerp/upsample/sample_source.hpp"

namespace infolerp::reliability {

// Pixel (x, y) belongs to cluster ids[(x / cell + 7·(y / cell)) mod ids.size()] (invalid_id =
// background); attributes are smooth functions of (x, y). Deterministic and thread-safe.
struct table_source {
  using sample_type = surface_sample<2, true>;
  std::span<const std::uint32_t> ids;
  std::uint32_t cell = 8;

  sample_type evaluate(std::uint32_t x, std::uint32_t y) const {
    sample_type s;
    const std::uint32_t c = cell == 0 ? 1 : cell;
    s.cluster = ids.empty() ? 0u : ids[(x / c + 7u * (y / c)) % ids.size()];
    const float fx = static_cast<float>(x), fy = static_cast<float>(y);
    s.position = {0.25f * fx, 0.5f * fy, 1.0f + 0.125f * fx};
    s.normal = {0.0f, 0.0f, 1.0f};
    s.texcoord = {fx / 64.0f, fy / 64.0f};
    s.lights = ((x ^ y) >> 4) & 1u;
    s.occlusion = {0.5f, fx / (fx + fy + 1.0f)};
    return s;
  }
  glm::vec3 shade(const sample_type& s, std::uint32_t, std::uint32_t) const {
    if (s.background()) return glm::vec3(0.0f);
    return glm::vec3(s.texcoord.x, s.texcoord.y, s.occlusion[1]) * (0.5f + 0.5f * s.occlusion[0]) +
           glm::vec3(static_cast<float>(s.lights));
  }
};

}  // namespace infolerp::reliability
