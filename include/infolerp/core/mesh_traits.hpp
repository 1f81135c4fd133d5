#pragma once
// How infolerp reads a user's mesh: through mesh_traits<M>, which by default forwards to
// members of M. Specialise mesh_traits for a type you cannot change (nanoflann's adaptor idea).
//
// Required (all const):   vertex_count() -> size_t      triangle_count() -> size_t
//                         position(v) -> glm::vec3      triangle(t) -> glm::uvec3
// Optional capabilities, detected at compile time and checked at run time:
//   texcoords:  texcoord(t, corner) -> glm::vec2, has_texcoords() -> bool (true if absent)
//   normals:    normal(v) -> glm::vec3,           has_normals() -> bool (true if absent)
//   keyframes:  keyframe_count() -> size_t, keyframe_position(k, v) -> glm::vec3, and
//               keyframe_vertex_count(k) -> size_t (positions stored for keyframe k): with it,
//               entry points report a short keyframe; without it, every keyframe must hold a
//               position per vertex (unchecked)
// The library never stores a reference to the mesh beyond the call that received it.
#include <concepts>
#include <cstddef>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace infolerp {

// Every accessor is called from the library's worker threads concurrently (const calls only),
// is expected to be O(1) and should not allocate; the library reads each value as often as it
// needs it and keeps no copy of the mesh.
template <class M>
struct mesh_traits {
  static std::size_t vertex_count(const M& m) requires requires { { m.vertex_count() } -> std::convertible_to<std::size_t>; }
  { return static_cast<std::size_t>(m.vertex_count()); }
  static std::size_t triangle_count(const M& m) requires requires { { m.triangle_count() } -> std::convertible_to<std::size_t>; }
  { return static_cast<std::size_t>(m.triangle_count()); }
  static glm::vec3 position(const M& m, std::size_t v) requires requires { { m.position(v) } -> std::convertible_to<glm::vec3>; }
  { return m.position(v); }
  static glm::uvec3 triangle(const M& m, std::size_t t) requires requires { { m.triangle(t) } -> std::convertible_to<glm::uvec3>; }
  { return m.triangle(t); }

  static glm::vec2 texcoord(const M& m, std::size_t t, unsigned corner) requires requires { { m.texcoord(t, corner) } -> std::convertible_to<glm::vec2>; }
  { return m.texcoord(t, corner); }
  static bool has_texcoords(const M& m) requires requires { m.texcoord(std::size_t{}, 0u); } {
    if constexpr (requires { { m.has_texcoords() } -> std::convertible_to<bool>; }) return m.has_texcoords();
    else return true;
  }
  static glm::vec3 normal(const M& m, std::size_t v) requires requires { { m.normal(v) } -> std::convertible_to<glm::vec3>; }
  { return m.normal(v); }
  static bool has_normals(const M& m) requires requires { m.normal(std::size_t{}); } {
    if constexpr (requires { { m.has_normals() } -> std::convertible_to<bool>; }) return m.has_normals();
    else return true;
  }
  static std::size_t keyframe_count(const M& m) requires requires { { m.keyframe_count() } -> std::convertible_to<std::size_t>; }
  { return static_cast<std::size_t>(m.keyframe_count()); }
  static glm::vec3 keyframe_position(const M& m, std::size_t k, std::size_t v) requires requires { { m.keyframe_position(k, v) } -> std::convertible_to<glm::vec3>; }
  { return m.keyframe_position(k, v); }
  static std::size_t keyframe_vertex_count(const M& m, std::size_t k) requires requires { { m.keyframe_vertex_count(k) } -> std::convertible_to<std::size_t>; }
  { return static_cast<std::size_t>(m.keyframe_vertex_count(k)); }
};

namespace detail {
template <class M> concept has_vertex_count = requires(const M& m) { mesh_traits<M>::vertex_count(m); };
template <class M> concept has_triangle_count = requires(const M& m) { mesh_traits<M>::triangle_count(m); };
template <class M> concept has_position = requires(const M& m, std::size_t i) { mesh_traits<M>::position(m, i); };
template <class M> concept has_triangle = requires(const M& m, std::size_t i) { mesh_traits<M>::triangle(m, i); };
}  // namespace detail

// A triangle mesh infolerp can read.
template <class M>
concept mesh = detail::has_vertex_count<M> && detail::has_triangle_count<M> &&
               detail::has_position<M> && detail::has_triangle<M>;
// A mesh with per-corner texture coordinates (the stretch channel needs them).
template <class M>
concept textured_mesh = mesh<M> && requires(const M& m, std::size_t t, unsigned c) {
  mesh_traits<M>::texcoord(m, t, c);
  { mesh_traits<M>::has_texcoords(m) } -> std::convertible_to<bool>;
};
// A mesh with per-vertex normals.
template <class M>
concept mesh_with_normals = mesh<M> && requires(const M& m, std::size_t v) { mesh_traits<M>::normal(m, v); };
// A mesh with keyframed vertex positions (animation, clustering paper §3.4).
template <class M>
concept keyframed_mesh = mesh<M> && requires(const M& m, std::size_t k, std::size_t v) {
  mesh_traits<M>::keyframe_count(m);
  mesh_traits<M>::keyframe_position(m, k, v);
};

// Entry points take `template <class M>` (unconstrained) and start with
// static_assert(check_mesh<M>()): a type that is not a mesh then gets one message per member it
// lacks, naming it, and nothing else. Instantiated once per type, so the messages appear once
// however many entry points a translation unit calls; returns true (the failed member's own
// static_assert has already stopped the build), so the caller's static_assert adds no second
// error. Compile time only.
template <class M>
constexpr bool check_mesh() {
  static_assert(detail::has_vertex_count<M>,
                "infolerp: mesh type needs `size_t vertex_count() const` (or mesh_traits<M>::vertex_count)");
  static_assert(detail::has_triangle_count<M>,
                "infolerp: mesh type needs `size_t triangle_count() const` (or mesh_traits<M>::triangle_count)");
  static_assert(detail::has_position<M>,
                "infolerp: mesh type needs `glm::vec3 position(size_t vertex) const` (or mesh_traits<M>::position)");
  static_assert(detail::has_triangle<M>,
                "infolerp: mesh type needs `glm::uvec3 triangle(size_t t) const` (or mesh_traits<M>::triangle)");
  return true;
}

// Shorthands used throughout the library: O(1) forwarding to mesh_traits, no allocation.
// Unconstrained, and checked by check_mesh: on a type that is not a mesh the build stops at
// check_mesh's message, and these compile to a placeholder value instead of adding a cascade of
// "no matching function" errors from every body that reads the mesh.
template <class M> std::size_t mesh_vertex_count(const M& m) {
  static_assert(check_mesh<M>());
  if constexpr (mesh<M>) return mesh_traits<M>::vertex_count(m);
  else return 0;
}
template <class M> std::size_t mesh_triangle_count(const M& m) {
  static_assert(check_mesh<M>());
  if constexpr (mesh<M>) return mesh_traits<M>::triangle_count(m);
  else return 0;
}
template <class M> glm::vec3 mesh_position(const M& m, std::size_t v) {
  static_assert(check_mesh<M>());
  if constexpr (mesh<M>) return mesh_traits<M>::position(m, v);
  else return glm::vec3(0.0f);
}
template <class M> glm::uvec3 mesh_triangle(const M& m, std::size_t t) {
  static_assert(check_mesh<M>());
  if constexpr (mesh<M>) return mesh_traits<M>::triangle(m, t);
  else return glm::uvec3(0u);
}
// True when the type offers texcoords and this instance has them.
template <class M> bool mesh_has_texcoords(const M& m) {
  if constexpr (textured_mesh<M>) return mesh_traits<M>::has_texcoords(m);
  else return false;
}
template <class M> bool mesh_has_normals(const M& m) {
  if constexpr (mesh_with_normals<M>) return mesh_traits<M>::has_normals(m);
  else return false;
}
template <class M> std::size_t mesh_keyframe_count(const M& m) {
  if constexpr (keyframed_mesh<M>) return mesh_traits<M>::keyframe_count(m);
  else return 0;
}
// Positions stored for keyframe k: keyframe_vertex_count(k) where the type offers it, else
// vertex_count() (the documented precondition of keyframes without it).
template <class M> std::size_t mesh_keyframe_vertex_count(const M& m, std::size_t k) {
  if constexpr (requires { mesh_traits<M>::keyframe_vertex_count(m, k); }) return mesh_traits<M>::keyframe_vertex_count(m, k);
  else return mesh_vertex_count(m);
}

}  // namespace infolerp
