#pragma once
// Frames along a camera path: the I-Buffer reuses what the previous frame computed (beyond the
// papers: the clustering paper's §4 within a frame, the refinement paper's §2 and reverse
// reprojection caching (Nehab et al. 2007) across views).
//
// Terms. Where the upsampler asks for a full evaluation it hands over the probe it traced
// (refined when the source refines; the coarse first pass is probed here), so no ray is traced
// twice. The probe's hit is projected into the previous pinhole view and the four kept samples
// around that point are weighted bilinearly (perspective-correct, interpolate(probe, a, b, c, d,
// w) of sample_source.hpp). Those that pass §4's test against the probe (compatible, view depth
// within depth_tolerance, young enough: below) keep their weights, renormalised; when they
// include the nearest, hold at least half the weight and agree() pairwise, they give the probe
// its expensive terms; else the source evaluates from the probe. Position, normal and texcoords
// are the probe's, new every frame. A kept sample at the probe's very position (bit for bit)
// is taken whole.
// Colour (only with a Pixel type, a source with view_dependence(s) and records with ==): a
// pixel whose sample was not evaluated this frame takes its kept colour when its record equals
// the kept one there (a camera standing still), or the bilinear blend of the kept colours around its
// reprojection when they pass the same test against its sample, differ by at most
// colour_tolerance per channel (so a blend is that close to each of them: texture detail is
// shaded, not blurred), and the view direction at it has turned, summed since the colour was
// shaded, by at most 1 / view_dependence(s) radians (one display step); else it is shaded.
// Without view_dependence every pixel is shaded.
//
// The error a kept value can carry is bounded by its age: the number of bilinear resamplings
// between it and the evaluation (or shade) it came from. An evaluation is age 0, a taken-whole
// sample keeps its age, a resampled one is 1 + the oldest source's; a sample the upsampler
// interpolated is given the oldest age among the samples it asked for in its coarsest cell
// (2^(passes-1) pixels, the cell all its sources lie in); a colour shaded from aged terms has
// their age. Sources of age max_age or more never serve, so no served value is more than max_age
// resamplings from an evaluation. Besides, while the camera moves each reusable pixel (aged, or
// resampled now) is refreshed once in every refresh_period frames at a phase hashed from its
// position, spreading the refreshes; when it stands still (the same view twice) every aged value
// is refreshed at once, so the frame is the fresh frame bit for bit, and from then on a frame
// with the same view and nothing invalidated copies the kept colours (stats().repeated).
// refresh_period 0 turns refreshes off (ages still bound the resampling).
// invalidate(): the next frame is a fresh one, bit for bit (scene, lights or ids changed);
// invalidate_if(pred): an object changed (pred names the kept samples it touches).
// Preconditions: the source's camera is render()'s pinhole_frame; sample_type has a world
// `position`; a background probe is that pixel's full sample; the scene is static unless
// invalidated. Allocation: create() only. Same output for every executor.
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/refine/pinhole_camera.hpp"
#include "infolerp/upsample/sample_source.hpp"
#include "infolerp/upsample/upsampler.hpp"

namespace infolerp {

struct frame_reuse_options {
  float depth_tolerance = 0.02f;     // a kept sample serves when its view depth is within this share of the probe's
  std::uint32_t refresh_period = 4;  // moving: each reusable pixel is evaluated (shaded) anew once in this many frames (0: never)
  std::uint8_t max_age = 8;          // kept values resampled this many times never serve (1..254)
  float colour_tolerance = 0.0f;     // kept colours blend only where they differ by at most this per channel (0: a
                                     // colour is kept only where the camera stands still; see benchmarks/NOTES.md)
};

// What the last render() did. Counts are of pixels; evaluated includes the cropped border
// (upsampler.hpp), as the upsampler's own count does.
struct frame_reuse_stats {
  std::uint32_t width = 0, height = 0;
  std::size_t evaluated = 0;       // full evaluations of the wrapped source (refreshes included)
  std::size_t refreshed = 0;       // of those, samples that could have been reused (refresh_period)
  std::size_t reused = 0;          // evaluations served from the previous frame
  std::size_t colours_reused = 0;  // pixels whose colour was taken from the previous frame
  bool repeated = false;           // nothing changed: the kept frame was copied (no upsampler run)
  [[nodiscard]] double evaluated_fraction() const noexcept { return fraction(evaluated); }
  [[nodiscard]] double reused_fraction() const noexcept { return fraction(reused); }
  [[nodiscard]] double colour_reused_fraction() const noexcept { return fraction(colours_reused); }

 private:
  [[nodiscard]] double fraction(std::size_t n) const noexcept {
    const double pixels = double(width) * double(height);
    return pixels > 0.0 ? double(n) / pixels : 0.0;
  }
};

// Per-pixel record of the last render (frame_reuse::marks()).
enum class reuse_mark : std::uint8_t { none = 0, reused = 1, evaluated = 2, refreshed = 3 };

template <class S>
concept positioned_sample = requires(const S& s) {
  { s.position } -> std::convertible_to<glm::vec3>;
};

namespace detail {
// The largest difference between two colours' channels.
inline float channel_difference(float a, float b) noexcept { return std::abs(a - b); }
template <glm::length_t N, glm::qualifier Q>
float channel_difference(const glm::vec<N, float, Q>& a, const glm::vec<N, float, Q>& b) noexcept {
  float d = 0.0f;
  for (glm::length_t i = 0; i < N; ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}
}  // namespace detail

// A colour that frame_reuse can keep and blend: float or glm::vec<N, float> (Pixel = void:
// colours are not kept).
template <class P>
concept blendable_pixel = std::is_void_v<P> || (std::copyable<P> && requires(const P& a, float w) {
  { a * w + a } -> std::convertible_to<P>;
  { detail::channel_difference(a, a) } -> std::convertible_to<float>;
});

namespace detail {
// A pixel's refresh phase (fixed, so every executor decides alike).
constexpr std::uint32_t reuse_hash(std::uint32_t x, std::uint32_t y) noexcept {
  std::uint32_t h = x * 0x9E3779B1u ^ (y + 0x7F4A7C15u) * 0x85EBCA77u;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  return h;
}
inline constexpr std::uint8_t not_asked = 0xFF;  // a pixel the upsampler did not ask for (age map)
inline constexpr std::uint8_t shaded_now = 0xFE;  // a colour shaded this frame (its terms' age, later)

// The kept samples around point q of the previous view (pixel units, depth), bilinear weights.
struct reprojection {
  std::array<std::size_t, 4> idx{};  // 00, 10, 01, 11; a weight-0 corner repeats corner 0's index
  std::array<float, 4> w{};
  std::size_t nearest = 0;
};
inline bool reproject(const pinhole_frame& v, const glm::dvec3& q, reprojection& r) {
  if (!(q.z > 0.0)) return false;
  // In pixel-centre units; within half a pixel beyond the edge, the edge pixels alone.
  if (!(q.x >= 0.0 && q.y >= 0.0 && q.x <= double(v.width) && q.y <= double(v.height))) return false;
  const double cx = std::clamp(q.x - 0.5, 0.0, double(v.width - 1)), cy = std::clamp(q.y - 0.5, 0.0, double(v.height - 1));
  const auto x0 = std::min(std::uint32_t(cx), v.width - 1), y0 = std::min(std::uint32_t(cy), v.height - 1);
  const float fx = float(cx - double(x0)), fy = float(cy - double(y0));
  const std::uint32_t x1 = fx > 0.0f ? x0 + 1 : x0, y1 = fy > 0.0f ? y0 + 1 : y0;
  const auto at = [&](std::uint32_t x, std::uint32_t y) { return std::size_t{y} * v.width + x; };
  r.w = {(1.0f - fx) * (1.0f - fy), fx * (1.0f - fy), (1.0f - fx) * fy, fx * fy};
  r.idx = {at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1)};
  r.nearest = at(fx < 0.5f ? x0 : x1, fy < 0.5f ? y0 : y1);
  for (std::size_t k = 1; k < 4; ++k)
    if (!(r.w[k] > 0.0f)) r.idx[k] = r.idx[0];
  if (!(r.w[0] > 0.0f)) r.idx[0] = r.nearest;  // the nearest corner always has a weight
  return true;
}
}  // namespace detail

// The source the upsampler sees during frame_reuse::render (made there; not for direct use).
// Forwards every member the wrapped source has, so that with no history the frame is the
// wrapped source's own, bit for bit.
template <class Source, class Pixel>
class reusing_source {
 public:
  using sample_type = typename Source::sample_type;
  using S = sample_type;
  static constexpr bool keeps_colour =
      !std::is_void_v<Pixel> && detail::member_view_dependence<Source> && std::equality_comparable<sample_type>;
  using colour = std::conditional_t<std::is_void_v<Pixel>, char, Pixel>;

  struct history {
    std::span<const S> samples;               // previous frame, row-major
    std::span<const std::uint8_t> valid;      // 1: may serve
    std::span<const std::uint8_t> age;        // resamplings since evaluation
    std::span<const colour> colours;          // previous frame's colours (keeps_colour)
    std::span<const std::uint8_t> colour_age;
    std::span<const float> colour_angle;      // radians the view turned since each colour was shaded
    const pinhole_frame* view = nullptr;      // previous frame's camera; null: no history
    const pinhole_frame* now = nullptr;       // this frame's camera
    bool same_view = false;                   // the camera stands still: kept colours serve whole or not at all
    frame_reuse_options options;
    std::uint32_t frame = 0;
  };
  // Written per pixel (x, y) of this frame by the calls for it.
  struct outputs {
    std::span<std::uint8_t> marks, age, colour_age;
    std::span<float> colour_angle;
  };

  reusing_source(const Source& inner, history h, outputs o, std::uint32_t width, std::uint32_t height)
      : inner_(&inner), h_(h), o_(o), width_(width), height_(height) {}

  // The coarse first pass (no probe yet): probed (and refined) here, once.
  S evaluate(std::uint32_t x, std::uint32_t y) const {
    if (h_.view == nullptr) {
      mark(x, y, reuse_mark::evaluated, 0);
      return inner_->evaluate(x, y);
    }
    S p = inner_->probe(x, y);
    if constexpr (refining_sample_source<Source>) {
      if (!is_background(p)) p = inner_->refine_probe(p, x, y);
    }
    return evaluate(p, x, y);
  }
  // The upsampler's probe p of pixel (x, y), refined when the source refines.
  S evaluate(const S& p, std::uint32_t x, std::uint32_t y) const {
    if (is_background(p) || h_.view == nullptr || x >= width_ || y >= height_)
      return full(p, x, y, reuse_mark::evaluated);
    detail::reprojection r;
    if (!detail::reproject(*h_.view, h_.view->project(p.position), r)) return full(p, x, y, reuse_mark::evaluated);
    const double z = depth(p);
    const S& n = h_.samples[r.nearest];
    if (p.position == n.position && serves_one(p, r.nearest, z, h_.age)) {  // a camera standing still: taken whole
      if (h_.age[r.nearest] > 0 && refresh_now(x, y)) return full(p, x, y, reuse_mark::refreshed);
      return served(S(n), x, y, h_.age[r.nearest]);
    }
    if (!serves(p, r, z, h_.age)) return full(p, x, y, reuse_mark::evaluated);
    if (refresh_now(x, y)) return full(p, x, y, reuse_mark::refreshed);
    const auto& k = h_.samples;
    return served(detail::source_interpolate(*this, p, k[r.idx[0]], k[r.idx[1]], k[r.idx[2]], k[r.idx[3]], r.w), x, y,
                  std::uint8_t(oldest(h_.age, r) + 1));
  }

  pixel_type_of<Source> shade(const S& s, std::uint32_t x, std::uint32_t y) const {
    if constexpr (keeps_colour) {
      if (!h_.colours.empty() && (h_.same_view || h_.options.colour_tolerance > 0.0f) && !is_background(s)) {
        const std::size_t i = std::size_t{y} * width_ + x;
        if (o_.marks[i] < std::uint8_t(reuse_mark::evaluated)) {
          if (auto c = kept_colour(s, x, y, i)) return pixel_type_of<Source>(*c);
        }
      }
      o_.colour_age[std::size_t{y} * width_ + x] = detail::shaded_now;
      o_.colour_angle[std::size_t{y} * width_ + x] = 0.0f;
    }
    return inner_->shade(s, x, y);
  }

  bool compatible(const S& a, const S& b) const requires detail::member_compatible<Source> { return inner_->compatible(a, b); }
  S interpolate(const S& a, const S& b) const requires detail::member_interpolate<Source> { return inner_->interpolate(a, b); }
  S interpolate(const S& a, const S& b, const S& c, const S& d) const requires detail::member_interpolate<Source> {
    return inner_->interpolate(a, b, c, d);
  }
  S interpolate(const S& p, const S& a, const S& b) const requires detail::member_probe_interpolate<Source> {
    return inner_->interpolate(p, a, b);
  }
  S interpolate(const S& p, const S& a, const S& b, const S& c, const S& d) const
    requires detail::member_probe_interpolate<Source> {
    return inner_->interpolate(p, a, b, c, d);
  }
  S interpolate(const S& p, const S& a, const S& b, const S& c, const S& d, const std::array<float, 4>& w) const
    requires detail::member_weighted_interpolate<Source> {
    return inner_->interpolate(p, a, b, c, d, w);
  }
  S probe(std::uint32_t x, std::uint32_t y) const { return inner_->probe(x, y); }
  void probe(std::uint32_t y, std::span<const std::uint32_t> xs, std::span<S> out) const
    requires batch_probing_sample_source<Source> {
    inner_->probe(y, xs, out);
  }
  bool probe_compatible(const S& p, const S& s) const requires detail::member_probe_compatible<Source> {
    return inner_->probe_compatible(p, s);
  }
  S refine_probe(const S& p, std::uint32_t x, std::uint32_t y) const requires refining_sample_source<Source> {
    return inner_->refine_probe(p, x, y);
  }
  bool agree(const S& a, const S& b) const requires detail::member_agree<Source> { return inner_->agree(a, b); }
  bool smooth(const S& a, const S& b) const requires detail::member_smooth<Source> { return inner_->smooth(a, b); }

 private:
  static bool is_background(const S& s) {
    if constexpr (detail::has_background_flag<S>) {
      return static_cast<bool>(s.background());
    } else {
      return false;
    }
  }
  // Pixels beyond the right and bottom edge (the cropped border) are not recorded.
  void mark(std::uint32_t x, std::uint32_t y, reuse_mark m, std::uint8_t age) const {
    if (x >= width_ || y >= height_) return;
    o_.marks[std::size_t{y} * width_ + x] = static_cast<std::uint8_t>(m);
    o_.age[std::size_t{y} * width_ + x] = age;
  }
  // The wrapped source's evaluation from probe p.
  S full(const S& p, std::uint32_t x, std::uint32_t y, reuse_mark m) const {
    const bool background = is_background(p);
    mark(x, y, background ? reuse_mark::none : m, 0);
    if (background) return p;
    return detail::source_evaluate(*inner_, p, x, y);
  }
  S served(S&& s, std::uint32_t x, std::uint32_t y, std::uint8_t age) const {
    mark(x, y, reuse_mark::reused, age);
    return std::move(s);
  }
  // A camera standing still refreshes every aged value at once (the moment to correct drift);
  // a moving one each pixel once in refresh_period frames.
  bool refresh_now(std::uint32_t x, std::uint32_t y) const {
    const std::uint32_t k = h_.options.refresh_period;
    return k > 0 && (h_.same_view || (detail::reuse_hash(x, y) + h_.frame) % k == 0);
  }
  static std::uint8_t oldest(std::span<const std::uint8_t> a, const detail::reprojection& r) {
    return std::max(std::max(a[r.idx[0]], a[r.idx[1]]), std::max(a[r.idx[2]], a[r.idx[3]]));
  }

  // p's depth in the previous view.
  double depth(const S& p) const {
    return glm::dot(glm::dvec3(p.position) - glm::dvec3(h_.view->eye), glm::dvec3(h_.view->forward));
  }
  // Whether the kept samples around the reprojection complete p: those that may (serves_one)
  // keep their weights, renormalised, the others get none; it takes the nearest and at least
  // half the weight (a probe beside an edge is completed from its own side), and every pair
  // of those kept must agree. Adjusts r.
  bool serves(const S& p, detail::reprojection& r, double z, std::span<const std::uint8_t> age) const {
    if (!serves_one(p, r.nearest, z, age)) return false;
    float kept = 0.0f;
    for (std::size_t k = 0; k < 4; ++k) {
      if (r.w[k] > 0.0f && !serves_one(p, r.idx[k], z, age)) r.w[k] = 0.0f;
      kept += r.w[k];
    }
    if (!(kept >= 0.5f)) return false;
    for (std::size_t k = 0; k < 4; ++k) {
      r.w[k] /= kept;
      if (!(r.w[k] > 0.0f)) r.idx[k] = r.nearest;
    }
    const auto& s = h_.samples;
    return detail::sources_agree(*this, s[r.idx[0]], s[r.idx[1]], s[r.idx[2]], s[r.idx[3]]);
  }
  bool serves_one(const S& p, std::size_t i, double z, std::span<const std::uint8_t> age) const {
    if (!h_.valid[i] || age[i] >= h_.options.max_age) return false;
    const S& s = h_.samples[i];
    if constexpr (refining_sample_source<Source>) {
      if (!detail::may_interpolate(*this, p, s)) return false;
    } else {
      if (!detail::may_complete(*this, p, s)) return false;
    }
    const double depth = glm::dot(glm::dvec3(s.position) - glm::dvec3(h_.view->eye), glm::dvec3(h_.view->forward));
    return std::abs(depth - z) <= double(h_.options.depth_tolerance) * z;
  }

  // The kept colour of pixel i (sample s) when its reprojection serves it (see the top).
  std::optional<colour> kept_colour(const S& s, std::uint32_t x, std::uint32_t y, std::size_t i) const {
    detail::reprojection r;
    if (!detail::reproject(*h_.view, h_.view->project(s.position), r)) return std::nullopt;
    const double z = depth(s);
    // Taken whole only for the very record it was shaded from: a sample the upsampler
    // interpolated anew from changed sources is shaded again.
    const bool whole = s == h_.samples[r.nearest];
    if (h_.same_view && !whole) return std::nullopt;  // the record changed where the view did not: shade it
    if (whole ? !serves_one(s, r.nearest, z, h_.colour_age) : !serves(s, r, z, h_.colour_age)) return std::nullopt;
    const std::uint8_t age = whole ? h_.colour_age[r.nearest] : std::uint8_t(oldest(h_.colour_age, r) + 1);
    if ((age > 0 || !whole || h_.colour_angle[r.nearest] > 0.0f) && refresh_now(x, y)) return std::nullopt;
    const auto& a = h_.colour_angle;
    const float turned = whole ? a[r.nearest]
                               : std::max(std::max(a[r.idx[0]], a[r.idx[1]]), std::max(a[r.idx[2]], a[r.idx[3]])) +
                                     view_turn(s.position);
    if (!(inner_->view_dependence(s) * turned <= 1.0f)) return std::nullopt;
    const auto& c = h_.colours;
    if (!whole) {  // a blend is within the corners' spread of each of them: keep it below the tolerance
      const float t = h_.options.colour_tolerance;
      for (std::size_t k = 1; k < 4; ++k)
        for (std::size_t l = 0; l < k; ++l)
          if (!(detail::channel_difference(c[r.idx[k]], c[r.idx[l]]) <= t)) return std::nullopt;
    }
    o_.colour_age[i] = age;
    o_.colour_angle[i] = turned;
    if (whole) return c[r.nearest];
    return colour((c[r.idx[0]] * r.w[0] + c[r.idx[1]] * r.w[1]) + (c[r.idx[2]] * r.w[2] + c[r.idx[3]] * r.w[3]));
  }
  // The angle between the directions from the previous and this frame's eye to point q.
  float view_turn(const glm::vec3& q) const {
    const glm::vec3 a = q - h_.view->eye, b = q - h_.now->eye;
    return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
  }

  const Source* inner_;
  history h_;
  outputs o_;
  std::uint32_t width_, height_;
};

// Keeps the last frame and renders the next through a wrapped source (see the top). Pixel:
// the output's pixel type, kept for colour reuse (void: colours are not kept).
// Not thread-safe: one render at a time (the render itself runs in parallel).
template <class Sample, class Pixel = void>
  requires positioned_sample<Sample> && blendable_pixel<Pixel>
class frame_reuse {
  using colour = std::conditional_t<std::is_void_v<Pixel>, char, Pixel>;

 public:
  // For width×height frames, or why not: an empty size (errc::empty_input), depth_tolerance
  // or colour_tolerance not finite and >= 0, max_age outside [1, 254] (bad_parameter). Allocation: W·H samples,
  // 4·W·H bytes, and with a Pixel type W·H pixels and 10·W·H bytes.
  [[nodiscard]] static result<frame_reuse> create(std::uint32_t width, std::uint32_t height,
                                                  frame_reuse_options options = {}) {
    if (width == 0 || height == 0)
      return make_error(errc::empty_input, no_element, "frame_reuse: image size ", width, "x", height, " is empty");
    if (!(options.depth_tolerance >= 0.0f) || !std::isfinite(options.depth_tolerance))
      return make_error(non_negative_errc(options.depth_tolerance), no_element,
                        "frame_reuse: depth_tolerance must be finite and >= 0, got ", options.depth_tolerance);
    if (!(options.colour_tolerance >= 0.0f) || !std::isfinite(options.colour_tolerance))
      return make_error(non_negative_errc(options.colour_tolerance), no_element,
                        "frame_reuse: colour_tolerance must be finite and >= 0, got ", options.colour_tolerance);
    if (options.max_age == 0 || options.max_age > 254)
      return make_error(errc::bad_parameter, no_element, "frame_reuse: max_age must lie in [1, 254], got ",
                        unsigned(options.max_age));
    frame_reuse r;
    r.options_ = options;
    const std::size_t n = std::size_t{width} * height;
    r.history_.assign(n, Sample{});
    r.valid_.assign(n, 0);
    r.marks_.assign(n, 0);
    r.age_.assign(n, 0);
    r.new_age_.assign(n, 0);
    if constexpr (!std::is_void_v<Pixel>) {
      r.colours_.assign(n, colour{});
      r.colour_age_.assign(n, 0);
      r.new_colour_age_.assign(n, 0);
      r.colour_angle_.assign(n, 0.0f);
      r.new_colour_angle_.assign(n, 0.0f);
    }
    r.stats_.width = width;
    r.stats_.height = height;
    return r;
  }

  // Renders the frame seen through `view` (the camera of src) with `up` (keep_ibuffer on, same
  // size) into out, reusing the previous frame where the rules at the top allow, then keeps
  // this frame. ids_version names the meaning of the source's cluster ids: a change without
  // invalidate() is refused (errc::bad_parameter), as a source whose ids changed meaning would
  // reuse wrongly. Errors, nothing rendered or kept: view size or up's size differs from this
  // (bad_size), up without keep_ibuffer (bad_parameter), a view that is not finite or has no
  // field of view (bad_parameter), out of the wrong size (bad_size, from the upsampler).
  // Complexity: the upsampler's, with 4 kept samples read per evaluation it asks for (and per
  // pixel shaded, with colour reuse), plus O(W·H) for the ages; a repeated frame O(W·H) copies.
  // Allocation: none.
  template <class Source, class Out, class Clock, class E = serial_executor>
  [[nodiscard]] status render(upsampler<Sample, Clock>& up, const Source& src, const pinhole_frame& view,
                              std::span<Out> out, E&& exec = E{}, std::uint64_t ids_version = 0) {
    static_assert(probing_sample_source<Source>,
                  "infolerp: frame_reuse needs a source with probe(x, y) (sample_source.hpp): the primary hit it reuses for");
    static_assert(std::same_as<typename Source::sample_type, Sample>, "infolerp: the source's sample_type differs");
    static_assert(detail::member_weighted_interpolate<Source> || detail::adl_weighted_interpolate<Sample>,
                  "infolerp: frame_reuse needs interpolate(probe, a, b, c, d, std::array<float, 4> w) (sample_source.hpp)");
    static_assert(std::is_void_v<Pixel> || std::same_as<Out, Pixel>, "infolerp: out's pixel type is not frame_reuse's Pixel");
    using wrapped_t = reusing_source<Source, Pixel>;
    const std::uint32_t w = stats_.width, h = stats_.height;
    if (view.width != w || view.height != h)
      return make_error(errc::bad_size, no_element, "frame_reuse: the camera's image is ", view.width, "x", view.height,
                        ", the kept frames ", w, "x", h, " (resize: create a new frame_reuse)");
    if (up.width() != w || up.height() != h)
      return make_error(errc::bad_size, no_element, "frame_reuse: the upsampler renders ", up.width(), "x", up.height(),
                        ", the kept frames are ", w, "x", h);
    if (!up.options().keep_ibuffer)
      return make_error(errc::bad_parameter, no_element, "frame_reuse: the upsampler must keep its I-Buffer (keep_ibuffer)");
    if (!all_finite(view.eye) || !all_finite(view.forward) || !(view.tan_half_fov > 0.0f) ||
        !std::isfinite(view.tan_half_fov) || glm::dot(view.forward, view.forward) < 0.5f)
      return make_error(errc::bad_parameter, no_element, "frame_reuse: the camera frame is not finite or has no field of view");
    if (kept_ && ids_version != ids_version_)
      return make_error(errc::bad_parameter, no_element, "frame_reuse: the source's ids changed meaning (version ",
                        ids_version_, " -> ", ids_version, ") without invalidate()");
    if (out.size() != std::size_t{w} * h)
      return make_error(errc::bad_size, no_element, "frame_reuse: output has ", out.size(), " pixels, image ", w, "x", h);
    if constexpr (wrapped_t::keeps_colour) {
      if (kept_ && settled_ && colours_kept_ && same_view(view, view_)) {  // nothing changed: the kept frame
        std::copy(colours_.begin(), colours_.end(), out.begin());
        std::fill(marks_.begin(), marks_.end(), std::uint8_t{0});
        stats_.evaluated = stats_.refreshed = stats_.reused = stats_.colours_reused = 0;
        stats_.repeated = true;
        ++frame_;
        return {};
      }
    }
    std::fill(marks_.begin(), marks_.end(), std::uint8_t{0});
    std::fill(new_age_.begin(), new_age_.end(), detail::not_asked);
    const bool colour_history = kept_ && colours_kept_ && wrapped_t::keeps_colour;
    typename wrapped_t::history hist{history_, valid_, age_, colours_, colour_age_, colour_angle_,
                                     kept_ ? &view_ : nullptr, &view, false, options_, frame_};
    if (!colour_history) hist.colours = {};
    hist.same_view = kept_ && same_view(view, view_);
    const wrapped_t wrapped(src, hist, {marks_, new_age_, new_colour_age_, new_colour_angle_}, w, h);
    if (status s = up.render(wrapped, out, exec); !s) return s;
    if (status s = up.swap_ibuffer(history_); !s) return s;
    std::fill(valid_.begin(), valid_.end(), std::uint8_t{1});
    spread_ages(up.passes());
    colours_kept_ = false;
    stats_.colours_reused = 0;
    if constexpr (wrapped_t::keeps_colour) {
      std::copy(out.begin(), out.end(), colours_.begin());
      colours_kept_ = true;
      settle_colours();
    }
    const bool moved = kept_ && !same_view(view, view_);
    view_ = view;
    kept_ = true;
    ids_version_ = ids_version;
    ++frame_;
    count_marks(up.stats().evaluated());
    settled_ = !moved && all_fresh();
    return {};
  }

  // Forgets every kept sample: the next frame is a fresh frame (the scene, the lights or the
  // ids changed). O(1).
  void invalidate() noexcept { kept_ = false; }
  // Forgets the kept samples s with pred(s) true (e.g. within reach of a changed object or in
  // its shadow), and their colours. O(W·H) calls of pred, serial. No allocation.
  template <class Pred>
  void invalidate_if(const Pred& pred) {
    if (!kept_) return;
    for (std::size_t i = 0; i < history_.size(); ++i)
      if (valid_[i] && pred(history_[i])) valid_[i] = 0, settled_ = false;
  }

  [[nodiscard]] const frame_reuse_stats& stats() const noexcept { return stats_; }
  // reuse_mark of every pixel in the last render (none: interpolated, or a background probe).
  [[nodiscard]] std::span<const std::uint8_t> marks() const noexcept { return marks_; }
  // Resamplings between each kept sample's terms and their evaluation (see the top).
  [[nodiscard]] std::span<const std::uint8_t> ages() const noexcept { return age_; }
  [[nodiscard]] const frame_reuse_options& options() const noexcept { return options_; }
  // Whether a frame is kept (false after create() and invalidate()).
  [[nodiscard]] bool has_history() const noexcept { return kept_; }

 private:
  frame_reuse() = default;

  static bool same_view(const pinhole_frame& a, const pinhole_frame& b) {
    return a.eye == b.eye && a.forward == b.forward && a.right == b.right && a.up == b.up &&
           a.tan_half_fov == b.tan_half_fov && a.aspect == b.aspect;
  }

  // age_ of every pixel: its own when the upsampler asked for it, else the oldest asked-for
  // pixel's of its coarsest cell (all its sources lie in that closed cell). O(W·H).
  void spread_ages(std::uint32_t passes) {
    const std::uint32_t w = stats_.width, h = stats_.height, cell = 1u << (passes - 1);
    for (std::uint32_t cy = 0; cy * cell < h; ++cy)
      for (std::uint32_t cx = 0; cx * cell < w; ++cx) {
        std::uint8_t oldest = 0;
        for (std::uint32_t y = cy * cell; y <= std::min(h - 1, (cy + 1) * cell); ++y)
          for (std::uint32_t x = cx * cell; x <= std::min(w - 1, (cx + 1) * cell); ++x)
            if (const std::uint8_t a = new_age_[std::size_t{y} * w + x]; a != detail::not_asked) oldest = std::max(oldest, a);
        for (std::uint32_t y = cy * cell; y < std::min(h, (cy + 1) * cell); ++y)
          for (std::uint32_t x = cx * cell; x < std::min(w, (cx + 1) * cell); ++x) {
            const std::size_t i = std::size_t{y} * w + x;
            age_[i] = new_age_[i] != detail::not_asked ? new_age_[i] : oldest;
          }
      }
  }
  // A colour shaded this frame is as old as the terms it was shaded from.
  void settle_colours() {
    stats_.colours_reused = 0;
    for (std::size_t i = 0; i < age_.size(); ++i) {
      const bool shaded = new_colour_age_[i] == detail::shaded_now;
      stats_.colours_reused += shaded ? 0 : 1;
      colour_age_[i] = shaded ? age_[i] : new_colour_age_[i];
      colour_angle_[i] = new_colour_angle_[i];
    }
  }
  bool all_fresh() const {
    for (std::size_t i = 0; i < age_.size(); ++i)
      if (age_[i] != 0 || (colours_kept_ && (colour_age_[i] != 0 || colour_angle_[i] != 0.0f))) return false;
    return true;
  }

  void count_marks(std::size_t asked) {
    std::array<std::size_t, 4> n{};
    for (std::uint8_t m : marks_) ++n[m & 3u];
    stats_.reused = n[1];
    stats_.refreshed = n[3];
    stats_.evaluated = asked - n[1];  // the upsampler's E samples, border included, less those served
    stats_.repeated = false;
  }

  frame_reuse_options options_{};
  std::vector<Sample> history_;
  std::vector<std::uint8_t> valid_, marks_, age_, new_age_;
  std::vector<colour> colours_;
  std::vector<std::uint8_t> colour_age_, new_colour_age_;
  std::vector<float> colour_angle_, new_colour_angle_;
  pinhole_frame view_{};
  bool kept_ = false, colours_kept_ = false, settled_ = false;
  std::uint64_t ids_version_ = 0;
  std::uint32_t frame_ = 0;
  frame_reuse_stats stats_{};
};

}  // namespace infolerp
