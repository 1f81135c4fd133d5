#pragma once
// Frames along a camera path: the I-Buffer reuses what the previous frame shaded (beyond the
// papers: the clustering paper's §4 within a frame, the refinement paper's §2 across views).
// Where the upsampler asks for a full evaluation, the wrapped source's probe (refined when the
// source refines) is reprojected into the previous pinhole view; the kept samples there (the
// nearest pixel within 1/4 of its centre, else the pair or the four around it) that pass §4's
// test against it (compatible, agree(), view depth within depth_tolerance) give it their
// expensive terms through interpolate(probe, ...); else the source evaluates. Position, normal,
// texcoords and shade() are new every frame. A kept sample at the probe's very position is taken
// whole (a camera standing still repeats its frame bit for bit); refresh_period re-evaluates a
// hashed share of the moved ones so that resampling does not drift (benchmarks/NOTES.md).
// invalidate(): the next frame is a fresh one, bit for bit (scene, lights or ids changed);
// invalidate_if(pred): an object changed (pred names the kept samples it touches).
// Preconditions: the source's camera is render()'s pinhole_frame; sample_type has a world
// `position`; a background probe is that pixel's full sample. Allocation: create() only.
// Same output for every executor.
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
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
  std::uint32_t refresh_period = 4;  // moving camera: about 1 in this many reusable samples is evaluated anew (0: never)
};

// What the last render() did, in pixels of the image (the cropped border is not counted).
struct frame_reuse_stats {
  std::uint32_t width = 0, height = 0;
  std::size_t evaluated = 0;  // full evaluations of the wrapped source (refreshes included)
  std::size_t refreshed = 0;  // of those, samples that could have been reused (refresh_period)
  std::size_t reused = 0;     // evaluations served from the previous frame
  [[nodiscard]] double evaluated_fraction() const noexcept { return fraction(evaluated); }
  [[nodiscard]] double reused_fraction() const noexcept { return fraction(reused); }

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
// A mix of pixel and frame for the refresh choice (fixed, so every executor decides alike).
constexpr std::uint32_t reuse_hash(std::uint32_t x, std::uint32_t y, std::uint32_t frame) noexcept {
  std::uint32_t h = x * 0x9E3779B1u ^ (y + 0x7F4A7C15u) * 0x85EBCA77u ^ (frame + 1u) * 0xC2B2AE3Du;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  return h;
}
}  // namespace detail

// The source the upsampler sees during frame_reuse::render (made there; not for direct use).
// Forwards every member the wrapped source has, so that with no history the frame is the
// wrapped source's own, bit for bit.
template <class Source>
class reusing_source {
 public:
  using sample_type = typename Source::sample_type;
  using S = sample_type;

  struct history {
    std::span<const S> samples;            // previous frame, row-major
    std::span<const std::uint8_t> valid;   // 1: may serve
    const pinhole_frame* view = nullptr;   // previous frame's camera; null: no history
    frame_reuse_options options;
    std::uint32_t frame = 0;
  };

  reusing_source(const Source& inner, history h, std::span<std::uint8_t> marks, std::uint32_t width, std::uint32_t height)
      : inner_(&inner), h_(h), marks_(marks), width_(width), height_(height) {}

  S evaluate(std::uint32_t x, std::uint32_t y) const {
    if (h_.view == nullptr) return full(x, y, reuse_mark::evaluated);
    S p = inner_->probe(x, y);
    if constexpr (detail::has_background_flag<S>) {
      if (p.background()) return p;
    }
    // A probe that leaves out part of compatible() (refine_probe) is completed first: a kept
    // sample's light bits are never taken across a hard-shadow edge.
    if constexpr (refining_sample_source<Source>) p = inner_->refine_probe(p, x, y);
    bool identity = false;
    S out;
    if (!reuse(p, out, identity)) return full(x, y, reuse_mark::evaluated);
    if (!identity && h_.options.refresh_period > 0 && detail::reuse_hash(x, y, h_.frame) % h_.options.refresh_period == 0)
      return full(x, y, reuse_mark::refreshed);
    mark(x, y, reuse_mark::reused);
    return out;
  }

  auto shade(const S& s, std::uint32_t x, std::uint32_t y) const { return inner_->shade(s, x, y); }

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
  S full(std::uint32_t x, std::uint32_t y, reuse_mark m) const {
    mark(x, y, m);
    return inner_->evaluate(x, y);
  }
  // Pixels beyond the right and bottom edge (the cropped border, upsampler.hpp) are not marked.
  void mark(std::uint32_t x, std::uint32_t y, reuse_mark m) const {
    if (x < width_ && y < height_) marks_[std::size_t{y} * width_ + x] = static_cast<std::uint8_t>(m);
  }

  // The previous frame's pixels around probe p's reprojection, when they pass §4's test.
  bool reuse(const S& p, S& out, bool& identity) const {
    const pinhole_frame& v = *h_.view;
    const glm::dvec3 q = v.project(p.position);
    if (!(q.z > 0.0)) return false;
    const double cx = q.x - 0.5, cy = q.y - 0.5;  // in pixel-centre units
    if (!(cx > -0.25 && cy > -0.25 && cx < double(v.width) - 0.75 && cy < double(v.height) - 0.75)) return false;
    const double fx0 = std::floor(cx), fy0 = std::floor(cy);
    const double fx = cx - fx0, fy = cy - fy0;
    identity = (fx < 1e-2 || fx > 1.0 - 1e-2) && (fy < 1e-2 || fy > 1.0 - 1e-2);
    const auto pick = [](double f, double base, std::int64_t& a, std::int64_t& b) {
      a = std::int64_t(base) + (f > 0.75 ? 1 : 0);
      b = (f > 0.25 && f <= 0.75) ? a + 1 : a;
    };
    std::int64_t x0, x1, y0, y1;
    pick(fx, fx0, x0, x1);
    pick(fy, fy0, y0, y1);
    if (x0 < 0 || y0 < 0 || x1 >= std::int64_t(v.width) || y1 >= std::int64_t(v.height)) return false;
    const std::array<std::size_t, 4> idx = {index(x0, y0), index(x1, y0), index(x0, y1), index(x1, y1)};
    for (std::size_t i : idx)
      if (!serves(p, i, q.z)) return false;
    const S& a = h_.samples[idx[0]];
    const S& b = h_.samples[idx[1]];
    const S& c = h_.samples[idx[2]];
    const S& d = h_.samples[idx[3]];
    if (x0 != x1 && y0 != y1) {
      if (!detail::may_interpolate(*this, a, b) || !detail::may_interpolate(*this, a, c) ||
          !detail::may_interpolate(*this, a, d) || !detail::sources_agree(*this, a, b, c, d))
        return false;
      out = detail::source_interpolate(*this, p, a, b, c, d);
      return true;
    }
    const S& e = x0 != x1 ? b : c;  // the other end of an edge, or a itself
    if (&e != &a && (!detail::may_interpolate(*this, a, e) || !detail::sources_agree(*this, a, e))) return false;
    // A kept sample at the probe's very position (a camera standing still) is taken as it is:
    // interpolate(p, a, a) weights a by x·(1/2x), not always 1/2 in float.
    if (&e == &a && p.position == a.position) {
      out = a;
      return true;
    }
    out = detail::source_interpolate(*this, p, a, e);
    return true;
  }
  std::size_t index(std::int64_t x, std::int64_t y) const {
    return static_cast<std::size_t>(y) * h_.view->width + static_cast<std::size_t>(x);
  }
  // Kept sample i may complete probe p, whose depth in the previous view is z.
  bool serves(const S& p, std::size_t i, double z) const {
    if (!h_.valid[i]) return false;
    const S& s = h_.samples[i];
    if constexpr (refining_sample_source<Source>) {
      if (!detail::may_interpolate(*this, p, s)) return false;
    } else {
      if (!detail::may_complete(*this, p, s)) return false;
    }
    const double depth = glm::dot(glm::dvec3(s.position) - glm::dvec3(h_.view->eye), glm::dvec3(h_.view->forward));
    return std::abs(depth - z) <= double(h_.options.depth_tolerance) * z;
  }

  const Source* inner_;
  history h_;
  std::span<std::uint8_t> marks_;
  std::uint32_t width_, height_;
};

// Keeps the last frame and renders the next through a wrapped source (see the top).
// Not thread-safe: one render at a time (the render itself runs in parallel).
template <class Sample>
  requires positioned_sample<Sample>
class frame_reuse {
 public:
  // For width×height frames, or why not: an empty size (errc::empty_input), depth_tolerance
  // not finite and >= 0 (bad_parameter). Allocation: W·H samples and 2·W·H bytes.
  [[nodiscard]] static result<frame_reuse> create(std::uint32_t width, std::uint32_t height,
                                                  frame_reuse_options options = {}) {
    if (width == 0 || height == 0)
      return make_error(errc::empty_input, no_element, "frame_reuse: image size ", width, "x", height, " is empty");
    if (!(options.depth_tolerance >= 0.0f) || !std::isfinite(options.depth_tolerance))
      return make_error(non_negative_errc(options.depth_tolerance), no_element,
                        "frame_reuse: depth_tolerance must be finite and >= 0, got ", options.depth_tolerance);
    frame_reuse r;
    r.options_ = options;
    const std::size_t n = std::size_t{width} * height;
    r.history_.assign(n, Sample{});
    r.valid_.assign(n, 0);
    r.marks_.assign(n, 0);
    r.stats_.width = width;
    r.stats_.height = height;
    return r;
  }

  // Renders the frame seen through `view` (the camera of src) with `up` (keep_ibuffer on, same
  // size) into out, reusing the previous frame where §4's test allows, then keeps this frame.
  // ids_version names the meaning of the source's cluster ids: a change without invalidate() is
  // refused (errc::bad_parameter), as a source whose ids changed meaning would reuse wrongly.
  // Errors, nothing rendered or kept: view size or up's size differs from this (bad_size), up
  // without keep_ibuffer (bad_parameter), a view that is not finite or has no field of view
  // (bad_parameter), out of the wrong size (bad_size, from the upsampler).
  // Complexity: the upsampler's, with a probe and 1-4 kept samples read per evaluation it asks
  // for, plus O(W·H) to count the marks. Allocation: none.
  template <class Source, class Pixel, class Clock, class E = serial_executor>
  [[nodiscard]] status render(upsampler<Sample, Clock>& up, const Source& src, const pinhole_frame& view,
                              std::span<Pixel> out, E&& exec = E{}, std::uint64_t ids_version = 0) {
    static_assert(probing_sample_source<Source>,
                  "infolerp: frame_reuse needs a source with probe(x, y) (sample_source.hpp): the primary hit it reuses for");
    static_assert(std::same_as<typename Source::sample_type, Sample>, "infolerp: the source's sample_type differs");
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
    std::fill(marks_.begin(), marks_.end(), std::uint8_t{0});
    typename reusing_source<Source>::history hist{history_, valid_, kept_ ? &view_ : nullptr, options_, frame_};
    const reusing_source<Source> wrapped(src, hist, marks_, w, h);
    if (status s = up.render(wrapped, out, exec); !s) return s;
    if (status s = up.swap_ibuffer(history_); !s) return s;
    std::fill(valid_.begin(), valid_.end(), std::uint8_t{1});
    view_ = view;
    kept_ = true;
    ids_version_ = ids_version;
    ++frame_;
    count_marks();
    return {};
  }

  // Forgets every kept sample: the next frame is a fresh frame (the scene, the lights or the
  // ids changed). O(1).
  void invalidate() noexcept { kept_ = false; }
  // Forgets the kept samples s with pred(s) true (e.g. within reach of a changed object or in
  // its shadow). O(W·H) calls of pred, serial. No allocation.
  template <class Pred>
  void invalidate_if(const Pred& pred) {
    if (!kept_) return;
    for (std::size_t i = 0; i < history_.size(); ++i)
      if (valid_[i] && pred(history_[i])) valid_[i] = 0;
  }

  [[nodiscard]] const frame_reuse_stats& stats() const noexcept { return stats_; }
  // reuse_mark of every pixel in the last render (none: interpolated, or a background probe).
  [[nodiscard]] std::span<const std::uint8_t> marks() const noexcept { return marks_; }
  [[nodiscard]] const frame_reuse_options& options() const noexcept { return options_; }
  // Whether a frame is kept (false after create() and invalidate()).
  [[nodiscard]] bool has_history() const noexcept { return kept_; }

 private:
  frame_reuse() = default;

  void count_marks() {
    std::array<std::size_t, 4> n{};
    for (std::uint8_t m : marks_) ++n[m & 3u];
    stats_.reused = n[1];
    stats_.refreshed = n[3];
    stats_.evaluated = n[2] + n[3];
  }

  frame_reuse_options options_{};
  std::vector<Sample> history_;
  std::vector<std::uint8_t> valid_;
  std::vector<std::uint8_t> marks_;
  pinhole_frame view_{};
  bool kept_ = false;
  std::uint64_t ids_version_ = 0;
  std::uint32_t frame_ = 0;
  frame_reuse_stats stats_{};
};

}  // namespace infolerp
