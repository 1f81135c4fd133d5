#pragma once
// A view of progressive_refiner (refine/progressive_driver.hpp): its camera checked, one primary
// ray per pixel traced (core/tracer.hpp), each hit located in the subdivision hierarchy and the
// pixel listed under its leaf (Oliveira et al. §4.1's reprojection); after a batch's splits only
// the pixels of the visible leaves that were split are re-located, from their barycentric
// weights (the splits are planar), without tracing. The leaves that cover a pixel are the
// visible set. Memory: about 24 bytes per pixel and 16 per triangle. Not thread-safe.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/refine/detail/id_set.hpp"
#include "infolerp/refine/pinhole_camera.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"

namespace infolerp::detail {

// Largest image a view may have (width · height): 2^25 pixels (8192 x 4096, above 8K UHD).
inline constexpr std::size_t max_view_pixels = std::size_t{1} << 25;

// A camera's image size, and eye/target/up/field of view when it has them (a pinhole camera).
template <class Camera>
status check_camera(const Camera& camera) {
  const std::uint32_t width = camera.width, height = camera.height;
  const std::uint64_t pixels = std::uint64_t(width) * height;
  if (pixels == 0) return make_error(errc::empty_input, no_element, "camera image is ", width, "x", height);
  if (pixels > max_view_pixels)
    return make_error(errc::bad_parameter, no_element, "camera image ", width, "x", height, " has ", pixels,
                      " pixels, more than max_view_pixels (", max_view_pixels, ")");
  if constexpr (requires { camera.eye; camera.target; camera.up; camera.vertical_fov_degrees; }) {
    const glm::vec3 e = camera.eye, t = camera.target, u = camera.up;
    if (!all_finite(e) || !all_finite(t) || !all_finite(u))
      return make_error(errc::non_finite, no_element, "camera eye, target or up is not finite");
    if (e == t) return make_error(errc::bad_parameter, no_element, "camera eye equals target: no view direction");
    const glm::vec3 f = pinhole_camera::forward(e, t);
    if (f == glm::vec3(0.0f))
      return make_error(errc::bad_parameter, no_element, "camera eye and target are too far apart: target - eye overflows float");
    if (!(glm::length(glm::cross(f, unit_or_zero(u))) > 1e-6f))
      return make_error(errc::bad_parameter, no_element, "camera up is zero or parallel to the view direction");
    const float fov = camera.vertical_fov_degrees;
    if (!(fov > 0.0f && fov < 180.0f))
      return make_error(errc::bad_parameter, no_element, "camera vertical_fov_degrees ", fov, " outside (0, 180)");
  }
  return {};
}

// The rays a camera makes: its frame computed once (pinhole_camera::frame()) when it has one,
// else the camera itself.
template <class Camera>
decltype(auto) rays_of(const Camera& camera) {
  if constexpr (requires { camera.frame(); }) return camera.frame();
  else return (camera);
}

// Traces one primary ray per pixel (row-major, in blocks of 256 made and traced together) into
// `hits` and checks every hit against a mesh of `triangles` original triangles; names the pixel.
template <class T, class Camera, class E>
status trace_view(const T& tracer, const Camera& camera, E&& exec, std::size_t grain, std::size_t triangles,
                  std::vector<hit>& hits) {
  static_assert(check_tracer<T>());
  static_assert(check_executor<std::remove_cvref_t<E>>());
  constexpr std::size_t block = 256;
  if (auto st = check_camera(camera); !st) return st;
  const std::uint32_t width = camera.width;
  const std::size_t n = std::size_t(width) * camera.height;
  hits.resize(n);
  for_each_chunk(exec, n, grain, [&](std::size_t, std::size_t begin, std::size_t end) {
    std::array<ray, block> rays;  // on the stack: no allocation per chunk
    const auto& cam = rays_of(camera);
    for (std::size_t b = begin; b < end; b += block) {
      const std::size_t m = std::min(block, end - b);
      for (std::size_t i = 0; i < m; ++i)
        rays[i] = cam.primary_ray(static_cast<std::uint32_t>((b + i) % width), static_cast<std::uint32_t>((b + i) / width));
      trace_intersect(tracer, std::span<const ray>(rays.data(), m), std::span<hit>(hits.data() + b, m));
    }
  });
  for (std::size_t p = 0; p < n; ++p) {
    const hit& h = hits[p];
    if (!h.valid()) continue;
    if (h.triangle >= triangles)
      return make_error(errc::index_out_of_range, p, "pixel ", p, ": hit triangle ", h.triangle, " is not in the mesh (",
                        triangles, " triangles)");
    if (!std::isfinite(h.distance) || !std::isfinite(h.barycentric.x) || !std::isfinite(h.barycentric.y))
      return make_error(errc::non_finite, p, "pixel ", p, ": hit on triangle ", h.triangle,
                        " has a non-finite distance or barycentric");
    if (!h.barycentric_inside())
      return make_error(errc::bad_parameter, p, "pixel ", p, ": hit on triangle ", h.triangle, " has barycentric (",
                        h.barycentric.x, ", ", h.barycentric.y, ") outside the triangle");
  }
  return {};
}

// Pixels located in the hierarchy: per pixel its leaf and barycentric weights in it, per leaf
// its pixel count and list (visible leaves only).
class view_pixels {
 public:
  void grow(std::size_t triangles) {
    leaf_pixels_.resize(triangles, 0);
    leaf_head_.resize(triangles, invalid_id);
    green_first_.resize(triangles, invalid_id);
    visible_.grow(triangles);
  }
  // Forgets the lists (the hierarchy was reset to `mesh`).
  void reset(const subdivision_mesh& mesh) {
    leaf_pixels_.clear();
    leaf_head_.clear();
    visible_.reset();
    index_green_splits(mesh);
  }

  // A new view from its hits: every pixel located from its hit's original triangle and listed;
  // the previous view's lists are dropped through its visible leaves, so the hierarchy outside
  // both views costs nothing. fresh() is then the visible set, ascending. Preconditions: grow()
  // covers the mesh. O(pixels · level + previous visible).
  template <class E>
  void locate(const subdivision_mesh& mesh, std::span<const hit> hits, E&& exec, std::size_t grain) {
    for (std::uint32_t t : visible_.unordered()) leaf_pixels_[t] = 0, leaf_head_[t] = invalid_id;
    const std::size_t n = hits.size();
    pixel_leaf_.resize(n);
    pixel_weights_.resize(n);
    exec.parallel_for(n, grain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t p = begin; p < end; ++p) {
        const hit& h = hits[p];
        point_location loc;  // a miss: no leaf
        const glm::vec2 b = h.barycentric;
        if (h.valid()) loc = mesh.locate_from(h.triangle, glm::vec3(1.0f - b.x - b.y, b.x, b.y));  // a leaf returns at once
        pixel_leaf_[p] = loc.leaf;
        pixel_weights_[p] = loc.weights;
      }
    });
    pixel_next_.resize(n);
    fresh_.clear();
    for (std::size_t p = 0; p < n; ++p)
      if (pixel_leaf_[p] != invalid_id) add_pixel(static_cast<std::uint32_t>(p), pixel_leaf_[p]);
    std::sort(fresh_.begin(), fresh_.end());
    visible_.assign(fresh_);
  }

  // The visible leaves a batch's splits took out of the leaf set, found from the triangles it
  // created (subdivision_mesh::created): a split leaf is the parent of new children, a retired
  // 1:2 child is a child of a parent resplit 1:4. Ascending, in split(); fresh() is emptied for
  // relocate(). O(new triangles · log).
  void find_split_leaves(const subdivision_mesh& mesh) {
    split_.clear();
    fresh_.clear();
    for (std::uint32_t c : mesh.created()) {
      const std::uint32_t p = mesh.triangle(c).parent;
      const subdivision_triangle& n = mesh.triangle(p);
      if (n.first_child != c) continue;  // one visit per split (a 1:2 split resplit in this batch has another first child)
      if (leaf_pixels_[p] > 0) split_.push_back(p);
      if (n.child_count == 4 && green_first_[p] != invalid_id) {
        for (std::uint32_t g = green_first_[p]; g < green_first_[p] + 2; ++g)
          if (leaf_pixels_[g] > 0) split_.push_back(g);
        green_first_[p] = invalid_id;
      }
      if (n.child_count == 2) green_first_[p] = c;
    }
    std::sort(split_.begin(), split_.end());
  }
  // The pixels of split leaf t follow it down to their new leaves; leaves that gain their first
  // pixel join fresh(). O(t's pixels · levels descended).
  void relocate(const subdivision_mesh& mesh, std::uint32_t t) {
    std::uint32_t p = leaf_head_[t];
    leaf_head_[t] = invalid_id;
    leaf_pixels_[t] = 0;
    while (p != invalid_id) {
      const std::uint32_t next = pixel_next_[p];
      const point_location loc = mesh.locate_from(t, pixel_weights_[p]);
      pixel_leaf_[p] = loc.leaf;
      pixel_weights_[p] = loc.weights;
      add_pixel(p, loc.leaf);
      p = next;
    }
  }
  // After relocate() of every split leaf: fresh() sorted, the visible set without the split leaves
  // and with the fresh ones. O(changed · log).
  void update_visible() {
    std::sort(fresh_.begin(), fresh_.end());
    for (std::uint32_t t : split_) visible_.erase(t);
    for (std::uint32_t t : fresh_) visible_.insert(t);
  }

  // Calls f(p) for each pixel listed under leaf t.
  template <class F>
  void for_each_pixel(std::uint32_t t, F&& f) const {
    for (std::uint32_t p = leaf_head_[t]; p != invalid_id; p = pixel_next_[p]) f(p);
  }
  // A triangle id freed or coarsened by the hierarchy: no pixels, not split 1:2.
  void forget(std::uint32_t t) { leaf_pixels_[t] = 0, leaf_head_[t] = invalid_id, green_first_[t] = invalid_id; }
  void forget_split(std::uint32_t t) { green_first_[t] = invalid_id; }

  [[nodiscard]] std::span<const std::uint32_t> pixel_leaf() const noexcept { return pixel_leaf_; }
  [[nodiscard]] glm::vec3 weights(std::size_t p) const { return pixel_weights_[p]; }
  [[nodiscard]] std::span<const std::uint32_t> leaf_pixels() const noexcept { return leaf_pixels_; }
  [[nodiscard]] const id_set& visible() const noexcept { return visible_; }
  [[nodiscard]] std::span<const std::uint32_t> fresh() const noexcept { return fresh_; }
  [[nodiscard]] std::span<const std::uint32_t> split() const noexcept { return split_; }
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    return visible_.memory_bytes() + pixel_weights_.capacity() * sizeof(glm::vec3) +
           (pixel_leaf_.capacity() + leaf_pixels_.capacity() + leaf_head_.capacity() + pixel_next_.capacity() + fresh_.capacity() +
            split_.capacity() + green_first_.capacity()) * 4;
  }

 private:
  // The first children of every 1:2 split (their parent's 1:4 resplit retires both).
  void index_green_splits(const subdivision_mesh& mesh) {
    green_first_.assign(mesh.triangle_count(), invalid_id);
    for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t)
      if (mesh.triangle(t).child_count == 2) green_first_[t] = mesh.triangle(t).first_child;
  }
  // Puts pixel p on its leaf's list; a leaf's first pixel makes it visible (fresh_).
  void add_pixel(std::uint32_t p, std::uint32_t leaf) {
    pixel_next_[p] = leaf_head_[leaf];
    leaf_head_[leaf] = p;
    if (leaf_pixels_[leaf]++ == 0) fresh_.push_back(leaf);
  }

  std::vector<std::uint32_t> pixel_leaf_;     // per pixel: its leaf, invalid_id for a miss
  std::vector<glm::vec3> pixel_weights_;      // per pixel: its barycentric weights in that leaf
  std::vector<std::uint32_t> leaf_pixels_;    // per triangle: pixels listed under it
  std::vector<std::uint32_t> leaf_head_;      // per triangle: first pixel of its list, else invalid_id
  std::vector<std::uint32_t> pixel_next_;     // per pixel: the next pixel of its leaf's list
  std::vector<std::uint32_t> fresh_;          // leaves that gained their first pixel
  std::vector<std::uint32_t> split_;          // a batch's split visible leaves
  std::vector<std::uint32_t> green_first_;    // per triangle split 1:2: its first child, else invalid_id
  id_set visible_;                            // the visible leaves
};

}  // namespace infolerp::detail
