#pragma once
// The object-space shading cache of progressive_refiner (refine/progressive_driver.hpp), after
// Oliveira et al. §2: one colour per hierarchy vertex (the paper's Lambertian restriction), each
// vertex requested once when first in view, its colour delivered in any order, and past a bound
// the vertices outside the current view evicted least recently in view first.
// Per vertex 20 bytes: a state, the colour, its luminance (nld.hpp), the view clock when last in
// view and the delta epoch of its delivery. Requests wait oldest first until handed out.
// Not thread-safe: one call at a time.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"
#include "infolerp/refine/nld.hpp"
#include "infolerp/refine/refiner_types.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"

namespace infolerp::detail {

// Barycentric weights (w0, w1, w2) of p in the plane of triangle t, in double.
[[nodiscard]] inline glm::dvec3 barycentric_in(const subdivision_mesh& mesh, glm::uvec3 t, glm::dvec3 p) {
  const glm::dvec3 a(mesh.position(t.x)), b(mesh.position(t.y)), c(mesh.position(t.z));
  const glm::dvec3 n = glm::cross(b - a, c - a);
  const double nn = glm::dot(n, n);
  const double u = glm::dot(glm::cross(p - a, c - a), n) / nn, v = glm::dot(glm::cross(b - a, p - a), n) / nn;
  return {1.0 - u - v, u, v};
}

class shading_cache {
 public:
  enum : std::uint8_t { unshaded = 0, requested = 1, shaded = 2, delivering = 3 };

  void grow(std::size_t vertices) {
    vstate_.resize(vertices, unshaded);
    colour_.resize(vertices, glm::vec3(0.0f));
    luminance_.resize(vertices, 0.0f);
    last_seen_.resize(vertices, 0);
    delivered_epoch_.resize(vertices, 0);
  }
  void reset() {
    vstate_.clear();
    colour_.clear();
    luminance_.clear();
    last_seen_.clear();
    delivered_epoch_.clear();
    to_issue_.clear();
    issued_ = outstanding_ = shaded_count_ = in_view_vertices_ = samples_ = view_requests_ = 0;
  }
  // A new view: no vertex of it seen yet, no request issued for it.
  void begin_view() { in_view_vertices_ = view_requests_ = 0; }

  // Vertex v is in the view stamped `clock`: counted once per view and requested if unshaded.
  // Returns whether it still lacks its colour (a triangle of the view waits for it).
  bool see(std::uint32_t v, std::uint32_t clock) {
    if (last_seen_[v] != clock) ++in_view_vertices_;
    last_seen_[v] = clock;
    if (vstate_[v] == unshaded) vstate_[v] = requested, to_issue_.push_back(v), ++outstanding_, ++view_requests_;
    return vstate_[v] != shaded;
  }

  // Appends up to max_count requests not yet handed out, oldest first. O(returned).
  std::size_t take_requests(const subdivision_mesh& mesh, std::vector<shading_point>& out, std::size_t max_count) {
    const std::size_t n = std::min(max_count, to_issue_.size() - issued_);
    for (std::size_t i = 0; i < n; ++i) out.push_back(point_of(mesh, to_issue_[issued_ + i]));
    issued_ += n;
    if (issued_ == to_issue_.size()) to_issue_.clear(), issued_ = 0;
    return n;
  }

  // Stores the colours of requested vertices, stamped with the delta epoch. Errors (nothing
  // stored): sizes differ; a vertex out of range, not requested, already delivered or named
  // twice; a non-finite colour. O(n).
  status deliver(std::span<const std::uint32_t> vertices, std::span<const glm::vec3> colours, std::uint32_t epoch) {
    if (vertices.size() != colours.size())
      return make_error(errc::bad_size, no_element, "deliver: ", vertices.size(), " vertices but ", colours.size(), " colours");
    if (auto st = check_vertices(vertices); !st) return st;
    for (std::size_t i = 0; i < colours.size(); ++i)
      if (!std::isfinite(colours[i].x) || !std::isfinite(colours[i].y) || !std::isfinite(colours[i].z))
        return make_error(errc::non_finite, i, "deliver: entry ", i, ": colour of vertex ", vertices[i], " is not finite");
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      const std::uint32_t v = vertices[i];
      vstate_[v] = shaded;
      colour_[v] = colours[i];
      luminance_[v] = luminance(colours[i]);
      delivered_epoch_[v] = epoch;
    }
    outstanding_ -= vertices.size();
    samples_ += vertices.size();
    shaded_count_ += vertices.size();
    return {};
  }

  // Past `bound` shaded vertices, those not seen in the view `clock` are evicted least recently
  // seen first (ties by id) down to bound − bound/8, so the O(vertices) scan runs once per
  // bound/8 deliveries. Allocation: the candidates.
  void enforce_bound(std::size_t bound, std::uint32_t clock) {
    if (shaded_count_ <= bound) return;
    evict_.clear();
    for (std::uint32_t v = 0; v < vstate_.size(); ++v)
      if (vstate_[v] == shaded && last_seen_[v] != clock) evict_.push_back(v);
    const std::size_t excess = std::min(shaded_count_ - (bound - bound / 8), evict_.size());
    if (excess == 0) return;
    std::nth_element(evict_.begin(), evict_.begin() + std::ptrdiff_t(excess - 1), evict_.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return last_seen_[a] != last_seen_[b] ? last_seen_[a] < last_seen_[b] : a < b; });
    for (std::size_t i = 0; i < excess; ++i) {
      const std::uint32_t v = evict_[i];
      vstate_[v] = unshaded;
      colour_[v] = glm::vec3(0.0f);
      luminance_[v] = 0.0f;
    }
    shaded_count_ -= excess;
  }

  // Every corner of triangle t is shaded.
  [[nodiscard]] bool ready(const subdivision_mesh& mesh, std::uint32_t t) const {
    const glm::uvec3 v = mesh.triangle(t).vertices;
    return vstate_[v.x] == shaded && vstate_[v.y] == shaded && vstate_[v.z] == shaded;
  }
  // A corner of triangle t was delivered in delta epoch `epoch`.
  [[nodiscard]] bool delivered_in(const subdivision_mesh& mesh, std::uint32_t t, std::uint32_t epoch) const {
    const glm::uvec3 v = mesh.triangle(t).vertices;
    return delivered_epoch_[v.x] == epoch || delivered_epoch_[v.y] == epoch || delivered_epoch_[v.z] == epoch;
  }
  // Vertex v holds nothing (neither a colour nor a request) and was not seen in the view `clock`.
  [[nodiscard]] bool holds_nothing(std::uint32_t v, std::uint32_t clock) const {
    return vstate_[v] == unshaded && last_seen_[v] != clock;
  }
  // A vertex id freed by the hierarchy (to be reused): back to its initial values.
  void forget(std::uint32_t v) {
    vstate_[v] = unshaded, colour_[v] = glm::vec3(0.0f), luminance_[v] = 0.0f, last_seen_[v] = 0, delivered_epoch_[v] = 0;
  }

  [[nodiscard]] bool shaded_vertex(std::size_t v) const { return v < vstate_.size() && vstate_[v] == shaded; }
  [[nodiscard]] glm::vec3 colour(std::size_t v) const { return colour_[v]; }
  [[nodiscard]] std::span<const glm::vec3> colours() const noexcept { return colour_; }
  [[nodiscard]] std::span<const float> luminances() const noexcept { return luminance_; }
  [[nodiscard]] std::size_t outstanding() const noexcept { return outstanding_; }
  [[nodiscard]] std::size_t samples() const noexcept { return samples_; }          // delivered since reset()
  [[nodiscard]] std::size_t shaded_count() const noexcept { return shaded_count_; }  // colours held now
  [[nodiscard]] std::size_t in_view_vertices() const noexcept { return in_view_vertices_; }
  [[nodiscard]] std::size_t view_requests() const noexcept { return view_requests_; }
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    return vstate_.capacity() + (colour_.capacity() * sizeof(glm::vec3)) +
           (luminance_.capacity() + last_seen_.capacity() + delivered_epoch_.capacity() + to_issue_.capacity() +
            evict_.capacity()) * 4;
  }

  // The request for vertex v: its position, an original triangle holding it, that triangle's
  // normal and v's (u, v) in it.
  [[nodiscard]] static shading_point point_of(const subdivision_mesh& mesh, std::uint32_t v) {
    shading_point sp;
    sp.vertex = v;
    sp.position = mesh.position(v);
    sp.triangle = mesh.vertex_source(v);
    const glm::uvec3 o = mesh.triangle(sp.triangle).vertices;  // original triangles keep their ids
    const glm::dvec3 a(mesh.position(o.x)), b(mesh.position(o.y)), c(mesh.position(o.z));
    sp.normal = glm::vec3(glm::normalize(glm::cross(b - a, c - a)));
    const glm::dvec3 w = barycentric_in(mesh, o, glm::dvec3(sp.position));
    sp.barycentric = glm::vec2(static_cast<float>(w.y), static_cast<float>(w.z));
    return sp;
  }

 private:
  static constexpr std::size_t no_index = std::numeric_limits<std::size_t>::max();

  // Every entry names a vertex with an outstanding request, once.
  status check_vertices(std::span<const std::uint32_t> vertices) {
    std::size_t bad = no_index;
    bool named_twice = false;
    for (std::size_t i = 0; i < vertices.size() && bad == no_index; ++i) {
      const std::uint32_t v = vertices[i];
      if (v >= vstate_.size() || vstate_[v] != requested) bad = i, named_twice = v < vstate_.size() && vstate_[v] == delivering;
      else vstate_[v] = delivering;
    }
    for (std::size_t i = 0; i < vertices.size(); ++i)  // undo the marks (duplicates stay detectable above)
      if (vertices[i] < vstate_.size() && vstate_[vertices[i]] == delivering) vstate_[vertices[i]] = requested;
    if (bad == no_index) return {};
    const std::uint32_t v = vertices[bad];
    if (v >= vstate_.size())
      return make_error(errc::index_out_of_range, bad, "deliver: entry ", bad, ": vertex ", v, " out of range (",
                        vstate_.size(), " vertices)");
    if (named_twice)
      return make_error(errc::bad_parameter, bad, "deliver: entry ", bad, ": vertex ", v, " is named twice (first at entry ",
                        std::find(vertices.begin(), vertices.end(), v) - vertices.begin(), ")");
    return make_error(errc::bad_parameter, bad, "deliver: entry ", bad, ": vertex ", v,
                      vstate_[v] == shaded ? " was already delivered" : " has no outstanding request");
  }

  std::vector<std::uint8_t> vstate_;            // per vertex: unshaded, requested, shaded (delivering while checked)
  std::vector<glm::vec3> colour_;
  std::vector<float> luminance_;
  std::vector<std::uint32_t> last_seen_;        // per vertex: the view clock when last in view
  std::vector<std::uint32_t> delivered_epoch_;  // per vertex: the delta epoch of its delivery
  std::vector<std::uint32_t> to_issue_, evict_;
  std::size_t issued_ = 0, outstanding_ = 0, shaded_count_ = 0, in_view_vertices_ = 0, samples_ = 0, view_requests_ = 0;
};

}  // namespace infolerp::detail
