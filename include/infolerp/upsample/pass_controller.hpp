#pragma once
// Automatic pass control for the I-Buffer upsampler.
//
// Paper: "Feature-based clustered geometry for interpolated Ray-casting", §4.2: "If the current
// average framerate is smaller than the lower bound, the number of passes is increased. If it is
// above the upper bound, the number of passes is reduced", at most 4 passes by default (more
// "provide too blurry results and some noticeable swimming"). §5 (Fig. 13): the controller
// "guarantees at least the performance of Ray Casting": here, whenever plain per-pixel
// evaluation (1 pass) is measured faster than the current pass count, the controller uses it.
//
// The controller is a small state machine fed with measured frame times. It reads no clock
// itself: the user passes the time of each frame (for example upsampler::stats().seconds, which
// the upsampler measures with its Clock). Frame times are the only nondeterministic input of the
// library, and they change the output only through the pass count chosen here; a user who needs
// reproducible frames fixes the pass count instead (upsampler::set_passes).
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/upsample/upsampler.hpp"

namespace infolerp {

struct pass_controller_options {
  double min_frame_seconds = 1.0 / 60.0;  // faster than this (frame rate above the upper bound): fewer passes
  double max_frame_seconds = 1.0 / 30.0;  // slower than this (frame rate below the lower bound): more passes
  std::uint32_t max_passes = 4;           // never more passes than this (§4.2 keeps 4)
  std::uint32_t initial_passes = 1;       // passes of the first frame (1 = plain per-pixel evaluation)
  double smoothing = 0.3;                 // weight of the newest frame in each pass count's running average
  std::uint32_t settle_frames = 3;        // frames measured at a pass count before deciding again
  std::uint32_t forget_frames = 300;      // an average older than this many frames is measured anew
};

// Chooses the pass count of the next frame from the measured times of past frames.
// Decision after settle_frames frames at pass count p with running average t (avg[q] known
// when pass count q was measured within the last forget_frames frames):
//   t > max_frame_seconds: the pass count with the lowest known average if it is below t; else
//                          p + 1 if p < max_passes and avg[p+1] is unknown; else a probe of
//                          plain evaluation (1) if avg[1] is unknown; else stay.
//   t < min_frame_seconds: p − 1 unless avg[p−1] is known to break max_frame_seconds.
//   otherwise:             1 if plain evaluation is known to be at least as fast, else stay.
// So the pass count converges within the bounds when some pass count meets them, to the fastest
// known one when none is fast enough, and never stays on a count measured slower than plain
// evaluation. Allocation: none. Not thread-safe (one per upsampler).
class pass_controller {
 public:
  // A controller, or why not: non-finite or negative bounds, min_frame_seconds above
  // max_frame_seconds, max_passes outside [1, 16], initial_passes outside [1, max_passes],
  // smoothing outside (0, 1], settle_frames 0 (errc::bad_parameter).
  [[nodiscard]] static result<pass_controller> create(pass_controller_options options = {}) {
    const auto& o = options;
    if (!std::isfinite(o.min_frame_seconds) || !std::isfinite(o.max_frame_seconds) || o.min_frame_seconds < 0.0 ||
        o.min_frame_seconds > o.max_frame_seconds)
      return make_error(errc::bad_parameter, no_element, "pass_controller: frame-time bounds [", o.min_frame_seconds,
                        ", ", o.max_frame_seconds, "] s must be finite, non-negative and ordered");
    if (o.max_passes == 0 || o.max_passes > max_upsample_passes)
      return make_error(errc::bad_parameter, no_element, "pass_controller: max_passes ", o.max_passes,
                        " outside [1, ", max_upsample_passes, "]");
    if (o.initial_passes == 0 || o.initial_passes > o.max_passes)
      return make_error(errc::bad_parameter, no_element, "pass_controller: initial_passes ", o.initial_passes,
                        " outside [1, max_passes = ", o.max_passes, "]");
    if (!(o.smoothing > 0.0 && o.smoothing <= 1.0))
      return make_error(errc::bad_parameter, no_element, "pass_controller: smoothing ", o.smoothing,
                        " outside (0, 1]");
    if (o.settle_frames == 0)
      return make_error(errc::bad_parameter, no_element, "pass_controller: settle_frames must be at least 1");
    pass_controller c;
    c.options_ = options;
    c.passes_ = options.initial_passes;
    return c;
  }

  // Accessors: O(1), no allocation.
  // Pass count for the next frame, in [1, max_passes]; 1 is plain per-pixel evaluation.
  [[nodiscard]] std::uint32_t passes() const noexcept { return passes_; }
  [[nodiscard]] const pass_controller_options& options() const noexcept { return options_; }

  // Running average frame time of a pass count, or NaN when it has not been measured recently.
  [[nodiscard]] double average_seconds(std::uint32_t passes) const noexcept {
    return known(passes) ? average_[passes] : std::nan("");
  }

  // Records the measured time of a frame rendered with passes() and picks the next pass count.
  // A non-finite or negative time is rejected (errc::non_finite / bad_parameter) and ignored.
  // Complexity O(max_passes). Allocation: none (an error message only on error).
  [[nodiscard]] status update(double frame_seconds) {
    if (!std::isfinite(frame_seconds))
      return make_error(errc::non_finite, no_element, "pass_controller: frame time is not finite");
    if (frame_seconds < 0.0)
      return make_error(errc::bad_parameter, no_element, "pass_controller: negative frame time ", frame_seconds);
    ++frame_;
    const std::uint32_t p = passes_;
    average_[p] = known(p) ? average_[p] + options_.smoothing * (frame_seconds - average_[p]) : frame_seconds;
    measured_at_[p] = frame_;
    if (++frames_at_current_ < options_.settle_frames) return {};

    const double t = average_[p];
    std::uint32_t next = p;
    if (t > options_.max_frame_seconds) {
      const std::uint32_t best = fastest_known();
      if (best != p && average_[best] < t) {
        next = best;
      } else if (p < options_.max_passes && !known(p + 1)) {
        next = p + 1;
      } else if (p != 1 && !known(1)) {
        next = 1;  // probe plain evaluation: it may be the fastest
      }
    } else if (t < options_.min_frame_seconds) {
      if (p > 1 && (!known(p - 1) || average_[p - 1] <= options_.max_frame_seconds)) next = p - 1;
    } else if (p != 1 && known(1) && average_[1] <= t) {
      next = 1;
    }
    if (next != passes_) {
      passes_ = next;
      frames_at_current_ = 0;
    }
    return {};
  }

 private:
  pass_controller() = default;

  [[nodiscard]] bool known(std::uint32_t q) const noexcept {
    return q >= 1 && q <= options_.max_passes && measured_at_[q] != 0 &&
           frame_ - measured_at_[q] <= options_.forget_frames;
  }
  [[nodiscard]] std::uint32_t fastest_known() const noexcept {
    std::uint32_t best = passes_;
    for (std::uint32_t q = 1; q <= options_.max_passes; ++q)
      if (known(q) && average_[q] < average_[best]) best = q;
    return best;
  }

  pass_controller_options options_{};
  std::uint32_t passes_ = 1;
  std::uint32_t frames_at_current_ = 0;
  std::uint64_t frame_ = 0;                                   // frames recorded so far
  std::array<double, max_upsample_passes + 1> average_{};     // [passes] running average
  std::array<std::uint64_t, max_upsample_passes + 1> measured_at_{};  // [passes] frame of the last measurement, 0 = never
};

// One controlled frame: renders with the controller's pass count, then feeds it the frame time
// the upsampler measured (stats().seconds). Errors: the controller's max_passes above the
// upsampler's (errc::bad_parameter), and those of upsampler::render. Allocation: none.
template <class Sample, class Clock, class S, class Pixel, class E = serial_executor>
[[nodiscard]] status render_controlled(upsampler<Sample, Clock>& up, pass_controller& controller, const S& src,
                                       std::span<Pixel> out, E&& exec = E{}) {
  static_assert(check_sample_source<S>());
  static_assert(check_executor<std::remove_cvref_t<E>>());
  if (controller.options().max_passes > up.options().max_passes)
    return make_error(errc::bad_parameter, no_element, "render_controlled: controller max_passes ",
                      controller.options().max_passes, " above the upsampler's ", up.options().max_passes);
  if (status s = up.set_passes(controller.passes()); !s) return s;
  if (status s = up.render(src, out, std::forward<E>(exec)); !s) return s;
  return controller.update(up.stats().seconds);
}

}  // namespace infolerp
