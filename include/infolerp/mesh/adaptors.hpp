#pragma once
// Ready-made mesh types that model infolerp::mesh (core/mesh_traits.hpp):
//   mesh_view           non-owning spans over the user's arrays (e.g. std::vector<glm::vec3>
//                       positions + std::vector<glm::uvec3> triangles, optional texcoords)
//   strided_mesh_view   zero-copy view over raw pointers with a vertex stride, like
//                       meshoptimizer's (vertex_positions, vertex_count, vertex_positions_stride)
//   indexed_mesh        an owning mesh (used by the library's own outputs and by tests)
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"

namespace infolerp {

// Non-owning view. texcoords, when present, hold 3 per triangle (per corner, so UV seams are
// representable); normals, when present, one per vertex. The viewed arrays must outlive the view.
// Accessors: preconditions v < vertex_count(), t < triangle_count(), corner < 3 (unchecked);
// O(1), no allocation, safe for concurrent const calls.
struct mesh_view {
  std::span<const glm::vec3> positions;
  std::span<const glm::uvec3> triangles;
  std::span<const glm::vec2> texcoords = {};
  std::span<const glm::vec3> normals = {};

  std::size_t vertex_count() const { return positions.size(); }
  std::size_t triangle_count() const { return triangles.size(); }
  glm::vec3 position(std::size_t v) const { return positions[v]; }
  glm::uvec3 triangle(std::size_t t) const { return triangles[t]; }
  bool has_texcoords() const { return !triangles.empty() && texcoords.size() == 3 * triangles.size(); }
  glm::vec2 texcoord(std::size_t t, unsigned corner) const { return texcoords[3 * t + corner]; }
  bool has_normals() const { return !positions.empty() && normals.size() == positions.size(); }
  glm::vec3 normal(std::size_t v) const { return normals[v]; }
};

// Owning mesh. Same layout rules as mesh_view; keyframes[k][v] are animated positions.
// Accessors as mesh_view's (O(1), unchecked, no allocation, concurrent const calls are safe);
// view() is O(1) and does not copy.
struct indexed_mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::uvec3> triangles;
  std::vector<glm::vec2> texcoords;  // empty, or 3 per triangle
  std::vector<glm::vec3> normals;    // empty, or 1 per vertex
  std::vector<std::vector<glm::vec3>> keyframes;

  std::size_t vertex_count() const { return positions.size(); }
  std::size_t triangle_count() const { return triangles.size(); }
  glm::vec3 position(std::size_t v) const { return positions[v]; }
  glm::uvec3 triangle(std::size_t t) const { return triangles[t]; }
  bool has_texcoords() const { return !triangles.empty() && texcoords.size() == 3 * triangles.size(); }
  glm::vec2 texcoord(std::size_t t, unsigned corner) const { return texcoords[3 * t + corner]; }
  bool has_normals() const { return !positions.empty() && normals.size() == positions.size(); }
  glm::vec3 normal(std::size_t v) const { return normals[v]; }
  std::size_t keyframe_count() const { return keyframes.size(); }
  glm::vec3 keyframe_position(std::size_t k, std::size_t v) const { return keyframes[k][v]; }
  std::size_t keyframe_vertex_count(std::size_t k) const { return keyframes[k].size(); }

  mesh_view view() const { return {positions, triangles, texcoords, normals}; }
};

// Zero-copy view over raw arrays: vertex v's position is the three floats at
// positions + v * stride_bytes; triangle t is indices[3t .. 3t+2]. The arrays must outlive the
// view. Accessors: unchecked indices, O(1), no allocation, safe for concurrent const calls.
class strided_mesh_view {
 public:
  std::size_t vertex_count() const { return vertex_count_; }
  std::size_t triangle_count() const { return index_count_ / 3; }
  glm::vec3 position(std::size_t v) const {
    glm::vec3 p;
    std::memcpy(&p, positions_ + v * stride_, sizeof p);  // no alignment assumption
    return p;
  }
  glm::uvec3 triangle(std::size_t t) const {
    return {indices_[3 * t], indices_[3 * t + 1], indices_[3 * t + 2]};
  }

  // Checks the arguments, not the contents (validate_mesh does that).
  // Errors: null pointers with nonzero counts, stride below 12 bytes or not a multiple of 4,
  // index_count not a multiple of 3. Complexity O(1), no allocation.
  friend result<strided_mesh_view> make_strided_mesh_view(const float* positions, std::size_t vertex_count,
                                                         std::size_t stride_bytes, const std::uint32_t* indices,
                                                         std::size_t index_count);

 private:
  const unsigned char* positions_ = nullptr;
  std::size_t vertex_count_ = 0;
  std::size_t stride_ = 0;
  const std::uint32_t* indices_ = nullptr;
  std::size_t index_count_ = 0;
};

inline result<strided_mesh_view> make_strided_mesh_view(const float* positions, std::size_t vertex_count,
                                                       std::size_t stride_bytes, const std::uint32_t* indices,
                                                       std::size_t index_count) {
  if (index_count % 3 != 0)
    return make_error(errc::bad_index_count, index_count, "index count ", index_count,
                      " is not a multiple of 3");
  if (vertex_count != 0 && positions == nullptr)
    return make_error(errc::bad_parameter, no_element, "positions is null but vertex_count is ", vertex_count);
  if (index_count != 0 && indices == nullptr)
    return make_error(errc::bad_parameter, no_element, "indices is null but index_count is ", index_count);
  if (stride_bytes < 3 * sizeof(float) || stride_bytes % sizeof(float) != 0)
    return make_error(errc::bad_parameter, no_element, "vertex stride ", stride_bytes,
                      " bytes: must be at least 12 and a multiple of 4");
  strided_mesh_view view;
  view.positions_ = reinterpret_cast<const unsigned char*>(positions);
  view.vertex_count_ = vertex_count;
  view.stride_ = stride_bytes;
  view.indices_ = indices;
  view.index_count_ = index_count;
  return view;
}

}  // namespace infolerp
