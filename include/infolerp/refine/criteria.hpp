#pragma once
// Refinement criteria: Oliveira, Santos, Proença, "Refinement Criteria for High Fidelity
// Interactive Walkthroughs", §4 (NLD_IS, NLD_OS, RND) and §4.1 (batches of R triangles, large
// triangles always refined). Each criterion looks at the current frame (which leaf is under
// each pixel, projected areas, vertex and pixel luminances) and names up to R leaves to split.
//
// Choices the paper leaves open, pinned down here:
//  - All three criteria skip triangles whose area projected on the image plane is below
//    `min_pixels` pixels (the paper states this 6-pixel rule for the NLD criteria; applying it
//    to RND too keeps RND from spending samples below pixel size, and gives the three the same
//    floor). The area comes from the view's pinhole projection (refinement_frame::projection,
//    which progressive_refiner sets for a pinhole_camera); without one, the count of pixel
//    centres the triangle covers stands in (no bound on size: a sliver under one centre counts 1).
//  - NLD_OS ranks its candidates: triangles above the `always_refine_fraction` of the image
//    first (largest first), then by S (largest first), ties by id; it takes the first R.
//  - NLD_IS is a best-first walk of the image quadtree: the quadrant with the largest S (over
//    its four corner pixels) is expanded first; if S > S_req the triangle under its centre is
//    selected (once), and in either case its four sub-quadrants are queued, down to one pixel
//    (§4: every quadrant is subdivided; S_req gates the triangle's subdivision, not the
//    recursion, so a feature inside a quadrant with equal corners is still found). It ends
//    when a walk to pixel size selects nothing or (§4) once the samples requested in the
//    current view reach `nld_is_pixel_fraction` of the pixel count (checked per batch, so the
//    last batch may overshoot by its own requests; the paper gives no value, so the default is
//    none).
//  - NLD_IS does not split a triangle whose corner colours differ by less than
//    `display_quantum` · L_max in every channel (default half an 8-bit step of a display whose
//    white is the image's L_max; 0: the paper's NLD_IS). Relative to L_max, as NLD is, so that
//    scaling the shader by any factor selects the same triangles. Such a triangle shows one
//    displayed value, and its
//    quadrants' S is high only because their corners fall on other triangles. Triangles above
//    `always_refine_fraction` of the image are exempt (§4.1), so a feature no vertex sees yet is
//    still looked for in large triangles; in smaller ones it is left unfound, as NLD_OS leaves it.
//  - No criterion selects a triangle whose split would give children with coinciding float
//    corners (subdivision_mesh::splittable).
//  - RND draws pixels uniformly (splitmix64 from `seed`, deterministic); a pixel showing a
//    qualifying triangle selects it. A batch draws until it has R triangles or made 8·R draws;
//    RND stops for good after `rnd_point_fraction` of the pixel count has been drawn.
//  - NLD_OS with a random pass (§7's future work): with `random_share` s > 0, NLD_OS takes up to
//    R − round(s·R) triangles and RND's rule fills the batch with others, under RND's point
//    budget; the criterion ends when both find nothing.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <queue>
#include <span>
#include <vector>
#include <glm/common.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/random.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/refine/nld.hpp"
#include "infolerp/refine/pinhole_camera.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"

namespace infolerp {

enum class refinement_criterion : std::uint8_t { nld_os, nld_is, rnd };

inline constexpr const char* to_string(refinement_criterion c) noexcept {
  switch (c) {
    case refinement_criterion::nld_os: return "NLD_OS";
    case refinement_criterion::nld_is: return "NLD_IS";
    case refinement_criterion::rnd: return "RND";
  }
  return "unknown";
}

struct criteria_options {
  refinement_criterion criterion = refinement_criterion::nld_os;  // which criterion selects
  float s_req = 0.05f;                   // NLD threshold S_req in [0, 1]
  float min_pixels = 6.0f;               // skip triangles projecting onto fewer pixels (paper: 6)
  float always_refine_fraction = 0.02f;  // NLD_OS: refine triangles covering more of the image regardless of S
  std::uint32_t batch = 64;              // R: triangles selected per batch
  float rnd_point_fraction = 1.0f;       // RND: stop after drawing this fraction of the pixel count, in [0, max_rnd_point_fraction]
  float nld_is_pixel_fraction = std::numeric_limits<float>::infinity();  // NLD_IS: stop once the view's requests reach this fraction of the pixels
  float random_share = 0.0f;             // NLD_OS: share of each batch given to a random pass (0: none)
  float display_quantum = 0.5f / 255.0f; // NLD_IS: skip triangles whose corners agree within this times L_max in every channel (0: none)
  std::uint64_t seed = 1;                // RND: random sequence

  // Largest rnd_point_fraction: a million draws per pixel, far past where RND finds anything new,
  // and small enough that the point budget of any image fits an integer exactly.
  static constexpr float max_rnd_point_fraction = 1e6f;
};

// Checks option ranges (NaN fails every check). An infinite min_pixels or always_refine_fraction
// is defined (no leaf qualifies / none is forced), an infinite nld_is_pixel_fraction is the
// default (no pixel budget). Errors name the member. O(1); allocation: the message on error.
inline status validate(const criteria_options& o) {
  if (!(o.s_req >= 0.0f && o.s_req <= 1.0f))
    return make_error(errc::bad_parameter, no_element, "criteria_options.s_req ", o.s_req, " outside [0, 1]");
  if (!(o.min_pixels >= 0.0f))
    return make_error(errc::bad_parameter, no_element, "criteria_options.min_pixels ", o.min_pixels, " must be >= 0");
  if (!(o.always_refine_fraction > 0.0f))
    return make_error(errc::bad_parameter, no_element, "criteria_options.always_refine_fraction must be > 0");
  if (o.batch == 0) return make_error(errc::bad_parameter, no_element, "criteria_options.batch must be >= 1");
  if (!(o.nld_is_pixel_fraction >= 0.0f))
    return make_error(errc::bad_parameter, no_element, "criteria_options.nld_is_pixel_fraction must be >= 0");
  if (!(o.rnd_point_fraction >= 0.0f && o.rnd_point_fraction <= criteria_options::max_rnd_point_fraction))
    return make_error(errc::bad_parameter, no_element, "criteria_options.rnd_point_fraction ", o.rnd_point_fraction,
                      " outside [0, ", criteria_options::max_rnd_point_fraction, "]");
  if (!(o.display_quantum >= 0.0f && std::isfinite(o.display_quantum)))
    return make_error(errc::bad_parameter, no_element, "criteria_options.display_quantum ", o.display_quantum,
                      " must be finite and >= 0");
  if (!(o.random_share >= 0.0f && o.random_share <= 1.0f))
    return make_error(errc::bad_parameter, no_element, "criteria_options.random_share ", o.random_share, " outside [0, 1]");
  return {};
}

// What a criterion sees of the current frame. Spans are indexed by pixel (y·width + x), by
// hierarchy triangle or by vertex as named.
struct refinement_frame {
  std::uint32_t width = 0, height = 0;
  const subdivision_mesh* mesh = nullptr;
  std::span<const std::uint32_t> pixel_leaf;       // per pixel: leaf shown, or invalid_id (background)
  std::span<const float> pixel_luminance;          // per pixel: interpolated luminance (NLD_IS only)
  std::span<const std::uint32_t> leaf_pixels;      // per triangle: pixels it covers (projected area)
  std::span<const std::uint32_t> visible;          // the leaves with leaf_pixels > 0, in any order
  std::span<const float> vertex_luminance;         // per vertex (valid for vertices of visible leaves)
  std::span<const glm::vec3> vertex_colour;        // per vertex, as vertex_luminance (NLD_IS's display_quantum; empty: not applied)
  float l_max = 0.0f;                              // L_max: largest luminance of the current image
  std::size_t view_samples = 0;                    // shading samples requested since the view was set
  const pinhole_frame* projection = nullptr;       // the view's camera when it is a pinhole one (NLD_IS's areas)
};

// What a criterion keeps between batches (RND's random stream and point count).
struct criterion_state {
  splitmix64 rng;
  std::uint64_t points_drawn = 0;
  bool exhausted = false;  // RND: point budget used up
};

namespace detail {
inline float leaf_nld(const refinement_frame& f, std::uint32_t t) {
  const glm::uvec3 v = f.mesh->triangle(t).vertices;
  return nld(f.vertex_luminance[v.x], f.vertex_luminance[v.y], f.vertex_luminance[v.z], f.l_max);
}
// Leaf t's size for the min_pixels rule: its projected area in pixels with the frame's
// projection, else the pixel centres it covers (see the prologue). O(1).
inline double projected_pixels(const refinement_frame& f, std::uint32_t t) {
  if (!f.projection) return double(f.leaf_pixels[t]);
  const glm::uvec3 v = f.mesh->triangle(t).vertices;
  return f.projection->projected_area(f.mesh->position(v.x), f.mesh->position(v.y), f.mesh->position(v.z));
}
// Large enough to refine (min_pixels; an infinite one admits nothing, not even a triangle
// spanning the view) and small enough to split in float (splittable). O(1).
inline bool qualifies(const refinement_frame& f, const criteria_options& o, std::uint32_t t) {
  return std::isfinite(o.min_pixels) && projected_pixels(f, t) >= double(o.min_pixels) && f.mesh->splittable(t);
}
// Leaf t covers more than always_refine_fraction of the image (§4.1's large triangles). O(1).
inline bool large(const refinement_frame& f, const criteria_options& o, std::uint32_t t) {
  return double(f.leaf_pixels[t]) > double(o.always_refine_fraction) * double(f.width) * double(f.height);
}
// NLD_IS's display rule: leaf t's corner colours differ by less than display_quantum · L_max in
// every channel, and it is not large (see the prologue). O(1).
inline bool shows_one_value(const refinement_frame& f, const criteria_options& o, std::uint32_t t) {
  if (f.vertex_colour.empty() || large(f, o, t)) return false;
  const glm::uvec3 v = f.mesh->triangle(t).vertices;
  const glm::vec3 a = f.vertex_colour[v.x], b = f.vertex_colour[v.y], c = f.vertex_colour[v.z];
  const glm::vec3 spread = glm::max(a, glm::max(b, c)) - glm::min(a, glm::min(b, c));
  return std::max(spread.x, std::max(spread.y, spread.z)) < o.display_quantum * f.l_max;
}
}  // namespace detail

// NLD_OS (§4, §4.1): visible leaves with S > S_req and a size of at least min_pixels, plus leaves
// covering more than always_refine_fraction of the image. Appends up to `limit` ids to `out`.
// Complexity O(visible · log R); allocation O(candidates).
inline void select_nld_os(const refinement_frame& f, const criteria_options& o, std::vector<std::uint32_t>& out,
                          std::size_t limit) {
  struct candidate {
    bool forced;
    float key;
    std::uint32_t id;
  };
  std::vector<candidate> c;
  for (std::uint32_t t : f.visible) {
    const auto px = f.leaf_pixels[t];
    if (detail::large(f, o, t)) {
      c.push_back({true, float(px), t});
    } else if (detail::qualifies(f, o, t)) {
      const float s = detail::leaf_nld(f, t);
      if (s > o.s_req) c.push_back({false, s, t});
    }
  }
  const auto before = [](const candidate& a, const candidate& b) {
    if (a.forced != b.forced) return a.forced;
    if (a.key != b.key) return a.key > b.key;
    return a.id < b.id;
  };
  const std::size_t n = std::min(limit, c.size());
  std::partial_sort(c.begin(), c.begin() + static_cast<std::ptrdiff_t>(n), c.end(), before);
  for (std::size_t i = 0; i < n; ++i) out.push_back(c[i].id);
}

// NLD_IS (§4): best-first quadtree walk over the interpolated image (see the header comment).
// Appends up to R ids after what `out` holds. Complexity O(Q log Q) for the Q quadrants visited
// (Q <= 4/3 · pixels; all of them in a batch that finds fewer than R); allocation O(Q).
inline void select_nld_is(const refinement_frame& f, const criteria_options& o, std::vector<std::uint32_t>& out) {
  if (f.width == 0 || f.height == 0) return;
  if (double(f.view_samples) >= double(o.nld_is_pixel_fraction) * double(f.width) * double(f.height)) return;
  struct quad {
    float s;
    std::uint32_t x0, y0, x1, y1;  // [x0, x1) × [y0, y1)
    bool operator<(const quad& q) const {  // max-heap on S, ties by position (deterministic)
      if (s != q.s) return s < q.s;
      if (y0 != q.y0) return y0 > q.y0;
      return x0 > q.x0;
    }
  };
  const auto L = [&](std::uint32_t x, std::uint32_t y) { return f.pixel_luminance[std::size_t(y) * f.width + x]; };
  std::priority_queue<quad> heap;
  const auto push_children = [&](std::uint32_t x0, std::uint32_t y0, std::uint32_t x1, std::uint32_t y1) {
    const std::uint32_t xm = x0 + (x1 - x0 + 1) / 2, ym = y0 + (y1 - y0 + 1) / 2;
    const std::uint32_t xs[3] = {x0, xm, x1}, ys[3] = {y0, ym, y1};
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const std::uint32_t a = xs[i], b = xs[i + 1], c = ys[j], d = ys[j + 1];
        if (a >= b || c >= d) continue;
        heap.push({nld(L(a, c), L(b - 1, c), L(a, d - 1), L(b - 1, d - 1), f.l_max), a, c, b, d});
      }
  };
  push_children(0, 0, f.width, f.height);
  std::vector<std::uint32_t> chosen;
  const std::size_t goal = out.size() + o.batch;
  while (!heap.empty() && out.size() < goal) {
    const quad q = heap.top();
    heap.pop();
    const std::uint32_t leaf = f.pixel_leaf[std::size_t((q.y0 + q.y1) / 2) * f.width + (q.x0 + q.x1) / 2];
    if (q.s > o.s_req && leaf != invalid_id && std::find(chosen.begin(), chosen.end(), leaf) == chosen.end() &&
        detail::qualifies(f, o, leaf) && !detail::shows_one_value(f, o, leaf)) {
      chosen.push_back(leaf);
      out.push_back(leaf);
    }
    if (q.x1 - q.x0 > 1 || q.y1 - q.y0 > 1) push_children(q.x0, q.y0, q.x1, q.y1);
  }
}

// RND (§4): uniformly drawn pixels select the qualifying leaf under them, skipping leaves
// already in out[first, end). Appends up to `count` ids. Complexity O(points drawn · count);
// allocation O(count).
inline void select_rnd(const refinement_frame& f, const criteria_options& o, criterion_state& st,
                       std::vector<std::uint32_t>& out, std::size_t first, std::size_t count) {
  const std::uint64_t pixels = std::uint64_t(f.width) * f.height;
  // validate() bounds the fraction; the clamp keeps the cast defined for any frame.
  const double budget = std::min(double(o.rnd_point_fraction) * double(pixels), 0x1p63);
  const auto cap = budget >= 0.0 ? static_cast<std::uint64_t>(budget) : std::uint64_t{0};
  const std::size_t goal = out.size() + count;
  // At most 8·count draws per batch, so one batch cannot burn the whole point budget on the
  // same few triangles; a batch whose draws all miss ends the random work (returns nothing).
  for (std::uint64_t draws = 0; out.size() < goal && draws < 8ull * count; ++draws) {
    if (st.points_drawn >= cap || pixels == 0) {
      st.exhausted = true;
      return;
    }
    ++st.points_drawn;
    const std::uint64_t p = st.rng.uniform(pixels);
    const std::uint32_t leaf = f.pixel_leaf[p];
    if (leaf == invalid_id || !detail::qualifies(f, o, leaf)) continue;
    if (std::find(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(), leaf) == out.end()) out.push_back(leaf);
  }
}

// Runs the configured criterion, NLD_OS through nld_os(out, limit) (select_nld_os or a selection
// kept between batches that returns the same, refine/nld_os_queue.hpp). Returns the number of
// ids appended (0: nothing qualifies). Complexity and allocation: those of the selection used.
// Serial; not thread-safe for the same criterion_state (RND advances its random sequence).
template <class NldOs>
std::size_t select_for_refinement(const refinement_frame& f, const criteria_options& o, criterion_state& st,
                                  std::vector<std::uint32_t>& out, NldOs&& nld_os) {
  const std::size_t before = out.size();
  switch (o.criterion) {
    case refinement_criterion::nld_os: {
      const auto random = static_cast<std::size_t>(std::lround(double(o.random_share) * double(o.batch)));
      nld_os(out, o.batch - random);
      if (random > 0 && !st.exhausted) select_rnd(f, o, st, out, before, o.batch - (out.size() - before));
      break;
    }
    case refinement_criterion::nld_is: select_nld_is(f, o, out); break;
    case refinement_criterion::rnd: select_rnd(f, o, st, out, before, o.batch); break;
  }
  return out.size() - before;
}
inline std::size_t select_for_refinement(const refinement_frame& f, const criteria_options& o, criterion_state& st,
                                         std::vector<std::uint32_t>& out) {
  return select_for_refinement(f, o, st, out, [&](std::vector<std::uint32_t>& ids, std::size_t limit) {
    select_nld_os(f, o, ids, limit);
  });
}

}  // namespace infolerp
