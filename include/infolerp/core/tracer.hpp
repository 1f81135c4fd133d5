#pragma once
// How infolerp casts rays: through the user's tracer. The library never includes a ray tracer;
// examples/embree_tracer.hpp is a small Embree 3 adaptor to copy (tests and benchmarks use the
// fuller tests/support/embree_tracer.hpp).
//
// Required (const, thread-safe for concurrent calls):
//   bool occluded(const ray&)        true when anything lies on the ray within [tnear, tfar]
//   hit  intersect(const ray&)       the closest hit, or an invalid hit
// Optional batch overloads, used when present (e.g. Embree's 16-ray packets):
//   void occluded(std::span<const ray>, std::span<std::uint8_t> out)   out[i] = 0 or 1
//   void intersect(std::span<const ray>, std::span<hit> out)
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"

namespace infolerp {

struct ray {
  glm::vec3 origin{0.0f};
  float tnear = 0.0f;
  glm::vec3 direction{0.0f, 0.0f, 1.0f};  // need not be normalised; distances are in its units
  float tfar = std::numeric_limits<float>::infinity();
};

// A ray hit. The hit point is (1-u-v)·p0 + u·p1 + v·p2 with (u, v) = barycentric (Embree's
// convention) and p0..p2 the triangle's corners in index order.
struct hit {
  std::uint32_t geometry = invalid_id;  // which mesh of the user's scene
  std::uint32_t triangle = invalid_id;  // triangle index within that mesh
  glm::vec2 barycentric{0.0f};
  float distance = std::numeric_limits<float>::infinity();
  [[nodiscard]] constexpr bool valid() const noexcept { return triangle != invalid_id; }
  // The barycentrics lie in the triangle up to barycentric_slack (u, v >= -slack, u + v <=
  // 1 + slack; NaN fails): what any tracer's rounding gives. A hit failing this is a tracer bug;
  // entry points that read hits treat it as a named error or, where they return no status, as a
  // miss.
  static constexpr float barycentric_slack = 1e-3f;
  [[nodiscard]] constexpr bool barycentric_inside() const noexcept {
    return barycentric.x >= -barycentric_slack && barycentric.y >= -barycentric_slack &&
           barycentric.x + barycentric.y <= 1.0f + barycentric_slack;
  }
};

template <class T>
concept tracer = requires(const T& t, const ray& r) {
  { t.occluded(r) } -> std::convertible_to<bool>;
  { t.intersect(r) } -> std::convertible_to<hit>;
};
template <class T>
concept batch_occlusion_tracer = tracer<T> && requires(const T& t, std::span<const ray> rays, std::span<std::uint8_t> out) {
  t.occluded(rays, out);
};
template <class T>
concept batch_intersection_tracer = tracer<T> && requires(const T& t, std::span<const ray> rays, std::span<hit> out) {
  t.intersect(rays, out);
};

// For `static_assert(check_tracer<T>())` at entry points: one readable message per missing
// member, once per type, and nothing else (returns true: the member's own static_assert has
// stopped the build, and trace_occluded / trace_intersect below add no errors of their own).
// Compile time only.
template <class T>
constexpr bool check_tracer() {
  static_assert(requires(const T& t, const ray& r) { { t.occluded(r) } -> std::convertible_to<bool>; },
                "infolerp: tracer type needs `bool occluded(const infolerp::ray&) const`");
  static_assert(requires(const T& t, const ray& r) { { t.intersect(r) } -> std::convertible_to<hit>; },
                "infolerp: tracer type needs `infolerp::hit intersect(const infolerp::ray&) const`");
  return true;
}

// Occlusion of many rays: the tracer's batch overload when it has one, else one ray at a time.
// Preconditions: out.size() >= rays.size(). Complexity: rays.size() tracer queries.
// Allocation: none (the tracer's own aside). Thread-safe when the tracer's const calls are.
template <class T>
void trace_occluded(const T& t, std::span<const ray> rays, std::span<std::uint8_t> out) {
  static_assert(check_tracer<T>());
  if constexpr (!tracer<T>) {
    return;  // not a tracer: check_tracer has stopped the build
  } else if constexpr (batch_occlusion_tracer<T>) {
    t.occluded(rays, out.first(rays.size()));
  } else {
    for (std::size_t i = 0; i < rays.size(); ++i) out[i] = t.occluded(rays[i]) ? 1 : 0;
  }
}

// Closest hits of many rays, batched when the tracer can. Preconditions: out.size() >= rays.size().
// Complexity: rays.size() tracer queries. Allocation: none. Thread-safe when the tracer's const calls are.
template <class T>
void trace_intersect(const T& t, std::span<const ray> rays, std::span<hit> out) {
  static_assert(check_tracer<T>());
  if constexpr (!tracer<T>) {
    return;  // not a tracer: check_tracer has stopped the build
  } else if constexpr (batch_intersection_tracer<T>) {
    t.intersect(rays, out.first(rays.size()));
  } else {
    for (std::size_t i = 0; i < rays.size(); ++i) out[i] = t.intersect(rays[i]);
  }
}

}  // namespace infolerp
