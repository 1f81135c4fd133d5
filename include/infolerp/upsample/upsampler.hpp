#pragma once
// The I-Buffer upsampler: multi-pass rendering that evaluates samples only where the picture
// changes and interpolates everywhere else ("Feature-based clustered geometry for interpolated
// Ray-casting", §4, Fig. 7). The first pass evaluates a coarse grid; each pass goes to
// (2N−1)×(2M−1): samples that coincide with the previous pass are re-used (R), a new sample
// between 2 (edge) or 4 (centre) previous ones is interpolated (I) when they are compatible
// (same cluster id and hard-shadow light bits, §4.1), otherwise evaluated (E). One buffer per pass.
//
// Any output size: the last pass has the image size W×H, and a pass of width w needs
// floor(w/2) + 1 samples of the one before; every kept sample sits where the paper's uncropped
// pyramid puts it, so the result is the crop of the paper's, with at most 2^(passes−1) − 1
// pixels evaluated beyond the right and bottom edges.
//
// Probes (optional, sample_source.hpp): a source that can evaluate a sample's cheap primary hit
// at every pixel gets the §4 test with the new sample's own cluster id; matching sources give
// only the expensive terms (AO, soft shadows), otherwise the sample is evaluated. refine_probe
// adds the hard-shadow rays only where the agreeing, bracketing sources do not suffice. With
// probe_every_sample off, only the samples whose sources fail the §4 test are probed: a primary
// ray per boundary sample rather than per pixel, at the plain I-Buffer's geometric accuracy.
// Agreeing sources (optional, beyond the paper): with agree(a, b), a new sample is evaluated
// unless every pair of its chosen sources agrees (all pairs: agreement is not transitive).
//
// Determinism: each row of a pass depends only on the previous pass, so rows run in parallel
// through the user's executor with identical output for any executor. `Clock` times feed the
// statistics only; only a pass controller fed with them (pass_controller.hpp) changes the
// output, through the pass count. Time against error: benchmarks/NOTES.md.
#include <algorithm>
#include <array>
#include <chrono>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>
#include "infolerp/core/executor.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/upsample/sample_source.hpp"

namespace infolerp {

// Largest pass count the pyramid supports (samples 2^15 pixels apart in the first pass).
inline constexpr std::uint32_t max_upsample_passes = 16;

// How a sample of a pass was obtained (Fig. 7).
enum class sample_kind : std::uint8_t {
  evaluated = 0,     // E: full evaluation by the sample source
  interpolated = 1,  // I: interpolated from 2 or 4 compatible samples of the previous pass
  reused = 2,        // R: copied from the coincident sample of the previous pass
};

struct upsampler_options {
  std::uint32_t passes = 4;         // passes per frame; 1 = plain per-pixel evaluation
  std::uint32_t max_passes = 4;     // pyramid depth allocated up front; passes may change up to it without allocating
  std::uint32_t rows_per_task = 4;  // rows of a pass per executor task (the parallel_for grain)
  bool record_kinds = true;         // keep the R/I/E kind of every pixel of the last pass (kinds())
  bool keep_ibuffer = false;        // keep the last pass's samples (ibuffer()); off: shade straight into the frame
  std::uint32_t min_sources = 2;    // sources with probes only: fewest sources compatible with a new sample's
                                    // probe that it is interpolated from (1 or 2; else it is evaluated). 1 only
                                    // for probes that carry all compatible() tests: one source cannot be
                                    // checked against another
  bool probe_every_sample = true;   // sources with probes only: probe every new sample; false: probe only where
                                    // the paper's test between its sources fails (elsewhere interpolate as
                                    // without probes), a probe per boundary sample instead of per pixel
};

// Statistics of one pass.
struct pass_stats {
  std::uint32_t width = 0;        // size of this pass's buffer (after cropping)
  std::uint32_t height = 0;
  std::size_t reused = 0;         // R samples
  std::size_t interpolated = 0;   // I samples
  std::size_t evaluated = 0;      // E samples
  double seconds = 0.0;           // wall time of the pass (Clock), statistics only
};

// Statistics of one frame: pass[0] is the coarse pass, pass[passes − 1] the full-size one.
struct upsample_stats {
  std::uint32_t passes = 0;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::array<pass_stats, max_upsample_passes> pass{};
  double seconds = 0.0;  // wall time of the whole frame, including shading

  // Evaluated samples over all passes (the expensive work).
  [[nodiscard]] std::size_t evaluated() const noexcept {
    std::size_t n = 0;
    for (std::uint32_t p = 0; p < passes; ++p) n += pass[p].evaluated;
    return n;
  }
  // Interpolated samples over all passes.
  [[nodiscard]] std::size_t interpolated() const noexcept {
    std::size_t n = 0;
    for (std::uint32_t p = 0; p < passes; ++p) n += pass[p].interpolated;
    return n;
  }
  // Evaluated samples per output pixel: 1 for plain evaluation, slightly above 1 at worst
  // (the cropped border), far below 1 when clusters are large.
  [[nodiscard]] double evaluated_fraction() const noexcept {
    const double pixels = static_cast<double>(width) * static_cast<double>(height);
    return pixels > 0.0 ? static_cast<double>(evaluated()) / pixels : 0.0;
  }
};

namespace detail {
// Samples of the previous pass needed by a pass of n samples along one axis.
constexpr std::uint32_t coarser_extent(std::uint32_t n) noexcept { return n / 2 + 1; }  // n >= 1

template <class T>
concept has_background_flag = requires(const T& s) {
  { s.background() } -> std::convertible_to<bool>;
};

// compatible() plus the library's own guarantee that background never mixes with geometry.
template <class S>
[[nodiscard]] inline bool may_interpolate(const S& src, const sample_of<S>& a, const sample_of<S>& b) {
  if constexpr (has_background_flag<sample_of<S>>) {
    if (static_cast<bool>(a.background()) != static_cast<bool>(b.background())) return false;
  }
  return source_compatible(src, a, b);
}

// The same between a new sample's probe p and a source sample a.
template <class S>
[[nodiscard]] inline bool may_complete(const S& src, const sample_of<S>& p, const sample_of<S>& a) {
  if constexpr (has_background_flag<sample_of<S>>) {
    if (static_cast<bool>(p.background()) != static_cast<bool>(a.background())) return false;
  }
  return source_probe_compatible(src, p, a);
}
}  // namespace detail

// The stateful upsampler (geometry-central style: construct once, render every frame).
// Holds one buffer per pass for the largest pass count; rendering allocates nothing.
// Not thread-safe: one render at a time per object (the render itself runs in parallel).
template <class Sample, class Clock = std::chrono::steady_clock>
class upsampler {
 public:
  using sample_type = Sample;

  // An upsampler for a width×height image, or why not: width or height 0 (errc::empty_input),
  // max_passes outside [1, 16], passes outside [1, max_passes], rows_per_task 0, a side above
  // 2^24, or a pyramid above 1 GiB: W·H·sizeof(Sample)/3 bytes (4/3 with keep_ibuffer), e.g.
  // 7680×4320 of 64-byte samples fits, twice that does not (errc::bad_parameter).
  // Allocation: the coarser passes, about (1/3)·W·H samples (precisely Σ_{d≥1} w_d·h_d ≤
  // 1/3·W·H + 4(W+H) + 4·max_passes samples with w_0 = W, w_d = floor(w_{d−1}/2)+1), plus W·H
  // more with keep_ibuffer, W·H bytes with record_kinds, and H row counters.
  [[nodiscard]] static result<upsampler> create(std::uint32_t width, std::uint32_t height,
                                                upsampler_options options = {}) {
    upsampler u;
    u.options_ = options;
    if (options.max_passes == 0 || options.max_passes > max_upsample_passes)
      return make_error(errc::bad_parameter, no_element, "upsampler: max_passes ", options.max_passes,
                        " outside [1, ", max_upsample_passes, "]");
    if (options.min_sources == 0 || options.min_sources > 2)
      return make_error(errc::bad_parameter, no_element, "upsampler: min_sources ", options.min_sources,
                        " outside [1, 2]");
    if (options.rows_per_task == 0)
      return make_error(errc::bad_parameter, no_element, "upsampler: rows_per_task must be at least 1");
    if (status s = u.set_passes(options.passes); !s) return s;
    if (status s = u.resize(width, height); !s) return s;
    return u;
  }

  // Changes the image size; reallocates the pyramid. Errors as in create(); on error the
  // upsampler keeps its previous size.
  [[nodiscard]] status resize(std::uint32_t width, std::uint32_t height) {
    if (width == 0 || height == 0)
      return make_error(errc::empty_input, no_element, "upsampler: image size ", width, "x", height, " is empty");
    constexpr std::uint32_t limit = 1u << 24;
    if (width > limit || height > limit)
      return make_error(errc::bad_parameter, no_element, "upsampler: image size ", width, "x", height,
                        " above 2^24 per side");
    if (const std::uint64_t bytes = std::uint64_t{width} * height * sizeof(Sample) * (options_.keep_ibuffer ? 4 : 1) / 3;
        bytes > (std::uint64_t{1} << 30))
      return make_error(errc::bad_parameter, no_element, "upsampler: image size ", width, "x", height, " needs ", bytes,
                        " bytes of samples, above the 1 GiB bound");
    width_ = width;
    height_ = height;
    std::uint32_t w = width, h = height;
    for (std::uint32_t d = 0; d < options_.max_passes; ++d) {
      extents_[d] = {w, h};
      const bool stored = d > 0 || options_.keep_ibuffer;
      levels_[d].assign(stored ? static_cast<std::size_t>(w) * h : 0, Sample{});
      w = detail::coarser_extent(w);
      h = detail::coarser_extent(h);
    }
    for (std::uint32_t d = options_.max_passes; d < max_upsample_passes; ++d) {
      extents_[d] = {0, 0};
      levels_[d] = {};
    }
    kinds_.assign(options_.record_kinds ? static_cast<std::size_t>(width) * height : 0, sample_kind::evaluated);
    row_counts_.assign(static_cast<std::size_t>(height), {});
    return {};
  }

  // Passes for the next frames (1 = plain per-pixel evaluation). No allocation.
  [[nodiscard]] status set_passes(std::uint32_t passes) {
    if (passes == 0 || passes > options_.max_passes)
      return make_error(errc::bad_parameter, no_element, "upsampler: passes ", passes, " outside [1, max_passes = ",
                        options_.max_passes, "]");
    options_.passes = passes;
    return {};
  }

  // Renders one frame into `out` (row-major, width·height pixels, pixel (x, y) at y·width + x),
  // out[i] = src.shade(sample, x, y) for the final I-Buffer sample of each pixel.
  // Preconditions: out.size() == width·height (else errc::bad_size, nothing written).
  // Complexity: E·(cost of evaluate) + W·H·(cost of interpolate + shade) over the executor,
  // plus about W·H·(cost of probe) for sources with probes (and refine_probe for the few probes
  // that need it);
  // E ≈ (W·H)/4^(passes−1) + (cluster and shadow boundary samples). Allocation: none.
  // Thread-safety: src's const members are called concurrently (see sample_source.hpp).
  // Output is bit-identical for every executor and thread count.
  template <class S, class Pixel, class E = serial_executor>
  [[nodiscard]] status render(const S& src, std::span<Pixel> out, E&& exec = E{}) {
    static_assert(check_sample_source<S>());
    static_assert(check_executor<std::remove_cvref_t<E>>());
    static_assert(std::same_as<typename S::sample_type, Sample>,
                  "infolerp: the sample source's sample_type differs from the upsampler's Sample");
    static_assert(std::is_assignable_v<Pixel&, pixel_type_of<S>>,
                  "infolerp: the output pixel type cannot be assigned the source's shade() result");
    const std::size_t pixels = static_cast<std::size_t>(width_) * height_;
    if (out.size() != pixels)
      return make_error(errc::bad_size, no_element, "upsampler: output has ", out.size(), " pixels, image ",
                        width_, "x", height_, " needs ", pixels);

    const auto frame_start = Clock::now();
    stats_ = {};
    stats_.passes = options_.passes;
    stats_.width = width_;
    stats_.height = height_;
    for (std::uint32_t k = 0; k < options_.passes; ++k) {
      const std::uint32_t d = options_.passes - 1 - k;  // passes before the last
      const auto pass_start = Clock::now();
      if (k == 0) {
        run_rows(exec, d, [&](std::uint32_t j, std::array<std::size_t, 3>& counts) {
          evaluate_row(src, d, j, out, counts);
        });
      } else {
        run_rows(exec, d, [&](std::uint32_t j, std::array<std::size_t, 3>& counts) {
          if constexpr (probing_sample_source<S>) {
            probe_row(src, d, j, out, counts);
          } else {
            upsample_row(src, d, j, out, counts);
          }
        });
      }
      pass_stats& ps = stats_.pass[k];
      ps.width = extents_[d][0];
      ps.height = extents_[d][1];
      for (std::uint32_t j = 0; j < ps.height; ++j) {
        ps.evaluated += row_counts_[j][0];
        ps.interpolated += row_counts_[j][1];
        ps.reused += row_counts_[j][2];
      }
      ps.seconds = seconds_since(pass_start);
    }
    stats_.seconds = seconds_since(frame_start);
    return {};
  }

  // Accessors: O(1), no allocation; spans stay valid until the next resize().
  [[nodiscard]] std::uint32_t width() const noexcept { return width_; }
  [[nodiscard]] std::uint32_t height() const noexcept { return height_; }
  [[nodiscard]] std::uint32_t passes() const noexcept { return options_.passes; }
  [[nodiscard]] const upsampler_options& options() const noexcept { return options_; }
  // Statistics of the last render.
  [[nodiscard]] const upsample_stats& stats() const noexcept { return stats_; }
  // The final I-Buffer of the last render (width·height samples, row-major); empty unless
  // options.keep_ibuffer.
  [[nodiscard]] std::span<const Sample> ibuffer() const noexcept { return levels_[0]; }
  // Exchanges the kept final I-Buffer (keep_ibuffer) with `other`, which must hold width·height
  // samples (else errc::bad_size, nothing exchanged): a caller that keeps frames takes the last
  // one without copying it (frame_reuse.hpp). O(1), no allocation.
  [[nodiscard]] status swap_ibuffer(std::vector<Sample>& other) {
    if (!options_.keep_ibuffer || other.size() != levels_[0].size())
      return make_error(errc::bad_size, no_element, "upsampler: swap_ibuffer needs keep_ibuffer and ", levels_[0].size(),
                        " samples, got ", other.size());
    levels_[0].swap(other);
    return {};
  }
  // R/I/E kind of each pixel in the last pass of the last render (empty unless record_kinds).
  [[nodiscard]] std::span<const sample_kind> kinds() const noexcept { return kinds_; }
  // Samples held by the pyramid (memory: this times sizeof(Sample)).
  [[nodiscard]] std::size_t pyramid_samples() const noexcept {
    std::size_t n = 0;
    for (const auto& l : levels_) n += l.size();
    return n;
  }

 private:
  upsampler() = default;

  static double seconds_since(typename Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
  }

  // Calls row_fn(j, counts) for every row j of buffer d through the executor and stores the
  // row's counts. They are counted in a local array: counting straight into row_counts_, whose
  // neighbouring rows share a cache line but run on different threads, was false sharing.
  template <class E, class F>
  void run_rows(E& exec, std::uint32_t d, const F& row_fn) {
    const std::uint32_t rows = extents_[d][1];
    exec.parallel_for(rows, options_.rows_per_task, [&](std::size_t begin, std::size_t end) {
      for (std::size_t j = begin; j < end; ++j) {
        std::array<std::size_t, 3> counts{};
        row_fn(static_cast<std::uint32_t>(j), counts);
        row_counts_[j] = counts;
      }
    });
  }

  // Stores sample s at (i, j) of buffer d; on the last pass (d == 0) also shades and records.
  template <class S, class Pixel>
  void store(const S& src, std::uint32_t d, std::uint32_t i, std::uint32_t j, Sample&& s, sample_kind kind,
             std::span<Pixel> out, std::array<std::size_t, 3>& counts) {
    ++counts[static_cast<std::size_t>(kind)];
    const std::size_t idx = static_cast<std::size_t>(j) * extents_[d][0] + i;
    if (d == 0) {
      out[idx] = src.shade(s, i, j);
      if (!kinds_.empty()) kinds_[idx] = kind;
      if (!options_.keep_ibuffer) return;
    }
    levels_[d][idx] = std::move(s);
  }

  // First pass: every sample evaluated at pixel (i·2^d, j·2^d).
  template <class S, class Pixel>
  void evaluate_row(const S& src, std::uint32_t d, std::uint32_t j, std::span<Pixel> out,
                    std::array<std::size_t, 3>& counts) {
    const std::uint32_t w = extents_[d][0];
    for (std::uint32_t i = 0; i < w; ++i)
      store(src, d, i, j, src.evaluate(i << d, j << d), sample_kind::evaluated, out, counts);
  }

  // Later passes (Fig. 7): R at even (i, j), I or E between 2 (edge) or 4 (centre) samples.
  template <class S, class Pixel>
  void upsample_row(const S& src, std::uint32_t d, std::uint32_t j, std::span<Pixel> out,
                    std::array<std::size_t, 3>& counts) {
    const std::uint32_t w = extents_[d][0];
    const std::uint32_t pw = extents_[d + 1][0];
    const Sample* r0 = levels_[d + 1].data() + static_cast<std::size_t>(j / 2) * pw;  // previous row at or above
    const Sample* r1 = (j & 1u) ? r0 + pw : r0;                                      // previous row below (odd j)
    for (std::uint32_t i = 0; i < w; ++i) {
      if ((j & 1u) == 0 && (i & 1u) == 0) {
        store(src, d, i, j, Sample(r0[i / 2]), sample_kind::reused, out, counts);
      } else if (!interpolate_between<false>(src, d, i, j, r0, r1, out, counts)) {
        store(src, d, i, j, src.evaluate(i << d, j << d), sample_kind::evaluated, out, counts);
      }
    }
  }

  // §4's test for the new sample (i, j): when its 2 (edge) or 4 (centre) previous-pass samples
  // may be interpolated with each other (and agree, and with Unprobed are smooth), stores their
  // interpolation and returns true.
  template <bool Unprobed, class S, class Pixel>
  bool interpolate_between(const S& src, std::uint32_t d, std::uint32_t i, std::uint32_t j, const Sample* r0,
                           const Sample* r1, std::span<Pixel> out, std::array<std::size_t, 3>& counts) {
    const std::uint32_t a = i / 2;
    if ((j & 1u) == 0 || (i & 1u) == 0) {  // edge: horizontal on even rows, vertical on odd ones
      const Sample& s0 = r0[a];
      const Sample& s1 = (j & 1u) ? r1[a] : r0[a + 1];
      if (!detail::may_interpolate(src, s0, s1) || !detail::sources_agree(src, s0, s1) ||
          (Unprobed && !detail::sources_smooth(src, s0, s1)))
        return false;
      store(src, d, i, j, detail::source_interpolate(src, s0, s1), sample_kind::interpolated, out, counts);
      return true;
    }
    const Sample& s00 = r0[a];
    const Sample& s10 = r0[a + 1];
    const Sample& s01 = r1[a];
    const Sample& s11 = r1[a + 1];
    if (!detail::may_interpolate(src, s00, s10) || !detail::may_interpolate(src, s00, s01) ||
        !detail::may_interpolate(src, s00, s11) || !detail::sources_agree(src, s00, s10, s01, s11) ||
        (Unprobed && !detail::sources_smooth(src, s00, s10, s01, s11)))
      return false;
    store(src, d, i, j, detail::source_interpolate(src, s00, s10, s01, s11), sample_kind::interpolated, out, counts);
    return true;
  }

  // Later passes with probes: R as above; every new sample (with probe_every_sample false, every
  // one that fails interpolate_between) probes its own pixel and is
  // interpolated from the sources compatible with its probe (choose_sources). A source that
  // can refine its probes (refine_probe, sample_source.hpp) probes cheaply first and needs
  // sources that agree with each other and bracket the new sample (both of an edge; all four
  // corners or a diagonal of a centre, whose midpoint it is), so that what the cheap probe
  // leaves out is taken from sources on both sides of it; only where that fails is the probe
  // refined and tested again, now with compatible() and min_sources. Otherwise, or when the
  // chosen sources do not all agree() pairwise (a source's optional tolerance), evaluated: from
  // the probe (refined first) when the source has evaluate(probe, x, y), so that no ray is traced twice.
  template <class S, class Pixel>
  void probe_row(const S& src, std::uint32_t d, std::uint32_t j, std::span<Pixel> out,
                 std::array<std::size_t, 3>& counts) {
    const std::uint32_t w = extents_[d][0];
    const std::uint32_t pw = extents_[d + 1][0];
    const Sample* r0 = levels_[d + 1].data() + static_cast<std::size_t>(j / 2) * pw;
    const Sample* r1 = (j & 1u) ? r0 + pw : r0;
    // The new samples to probe, gathered in blocks so that a batch-probing source traces them
    // together (at most 4 KiB of samples on the stack).
    constexpr std::size_t block = std::clamp<std::size_t>(4096 / sizeof(Sample), 1, 64);
    std::array<std::uint32_t, block> xs;
    std::array<Sample, block> probes;
    std::size_t n = 0;
    const auto flush = [&] {
      const std::span<const std::uint32_t> pending(xs.data(), n);
      if constexpr (batch_probing_sample_source<S>) {
        src.probe(j << d, pending, std::span<Sample>(probes.data(), n));
      } else {
        for (std::size_t k = 0; k < n; ++k) probes[k] = src.probe(xs[k], j << d);
      }
      for (std::size_t k = 0; k < n; ++k) complete(src, d, xs[k] >> d, j, std::move(probes[k]), r0, r1, out, counts);
      n = 0;
    };
    for (std::uint32_t i = 0; i < w; ++i) {
      if ((j & 1u) == 0 && (i & 1u) == 0) {
        store(src, d, i, j, Sample(r0[i / 2]), sample_kind::reused, out, counts);
        continue;
      }
      if (!options_.probe_every_sample && interpolate_between<true>(src, d, i, j, r0, r1, out, counts)) continue;
      xs[n++] = i << d;
      if (n == block) flush();
    }
    flush();
  }

  // The new sample (i, j) from its probe p: interpolated from the sources that complete it
  // (choose_sources, refining the probe first where the source can and must), else evaluated.
  template <class S, class Pixel>
  void complete(const S& src, std::uint32_t d, std::uint32_t i, std::uint32_t j, Sample&& p, const Sample* r0,
                const Sample* r1, std::span<Pixel> out, std::array<std::size_t, 3>& counts) {
    const bool single = options_.min_sources <= 1;
    // Sources that match the probe match each other (compatible() is an equivalence), unless
    // the probe is tested with a probe_compatible() that leaves something out.
    constexpr bool cross_check = detail::member_probe_compatible<S> || detail::adl_probe_compatible<Sample>;
    const auto probe_match = [&](const Sample& q, const Sample& s) { return detail::may_complete(src, q, s); };
    const std::uint32_t x = i << d, y = j << d;
    chosen k;
    [[maybe_unused]] bool refined = false;
    if constexpr (refining_sample_source<S>) {
      k = choose_sources(src, p, r0, r1, i, j, {.single = false, .cross = cross_check, .bracket = true}, probe_match);
      if (k.n == 0) {
        p = src.refine_probe(p, x, y);
        refined = true;
        const auto full_match = [&](const Sample& q, const Sample& t) { return detail::may_interpolate(src, q, t); };
        k = choose_sources(src, p, r0, r1, i, j, {.single = single, .cross = false, .bracket = false}, full_match);
      }
    } else {
      k = choose_sources(src, p, r0, r1, i, j, {.single = single, .cross = cross_check, .bracket = false}, probe_match);
    }
    if (k.n == 0 || !(k.n == 4 ? detail::sources_agree(src, *k.c[0], *k.c[1], *k.c[2], *k.c[3])
                               : detail::sources_agree(src, *k.c[0], *k.c[1]))) {
      if constexpr (detail::member_probe_evaluate<S> && refining_sample_source<S>) {
        if (!refined) p = src.refine_probe(p, x, y);  // evaluate(probe, x, y) takes a refined probe
      }
      store(src, d, i, j, detail::source_evaluate(src, p, x, y), sample_kind::evaluated, out, counts);
    } else if (k.n == 4) {
      store(src, d, i, j, detail::source_interpolate(src, p, *k.c[0], *k.c[1], *k.c[2], *k.c[3]),
            sample_kind::interpolated, out, counts);
    } else {
      store(src, d, i, j, detail::source_interpolate(src, p, *k.c[0], *k.c[1]), sample_kind::interpolated, out, counts);
    }
  }

  // The previous-pass sources that complete probe p: all four corners (n = 4), two sources or
  // one twice (n = 2), or none (n = 0).
  struct chosen {
    std::array<const Sample*, 4> c{};
    unsigned n = 0;
  };

  // What choose_sources accepts besides match(p, source).
  struct source_rule {
    bool single = false;   // one matching source suffices (an edge's, or a lone corner)
    bool cross = false;    // the chosen sources must also be compatible() with each other
    bool bracket = false;  // an adjacent pair of corners (the centre is not between them) does not do
  };

  // Chooses the sources of probe p of the new sample (i, j) among the previous-pass samples
  // (rows r0 and r1) that match(p, source) accepts. Edge: both sources, or one when
  // rule.single. Centre, by the matching corners: all four (weights 1/4); three, the diagonal
  // opposite the missing corner (the centre is its midpoint, so a plane through the three
  // corners is reproduced exactly); two, that pair unless rule.bracket and they are adjacent;
  // one, that corner when rule.single. With rule.cross, the chosen sources must also be
  // compatible() with each other.
  template <class S, class M>
  static chosen choose_sources(const S& src, const Sample& p, const Sample* r0, const Sample* r1, std::uint32_t i,
                               std::uint32_t j, source_rule rule, const M& match) {
    const bool single = rule.single, cross = rule.cross, bracket = rule.bracket;
    const std::uint32_t a = i / 2;
    if (!((i & 1u) && (j & 1u))) {  // edge
      const Sample* s0 = &r0[a];
      const Sample* s1 = (j & 1u) ? &r1[a] : &r0[a + 1];
      const bool m0 = match(p, *s0), m1 = match(p, *s1);
      if (m0 && m1 && (!cross || detail::may_interpolate(src, *s0, *s1))) return {{s0, s1}, 2};
      if (single && (m0 || m1)) return {{m0 ? s0 : s1, m0 ? s0 : s1}, 2};
      return {};
    }
    const std::array<const Sample*, 4> c = {&r0[a], &r0[a + 1], &r1[a], &r1[a + 1]};  // 00, 10, 01, 11: diagonals {0, 3}, {1, 2}
    unsigned mask = 0;
    for (unsigned k = 0; k < 4; ++k) mask |= match(p, *c[k]) ? 1u << k : 0u;
    if (mask == 0xF) {
      if (!cross || (detail::may_interpolate(src, *c[0], *c[1]) && detail::may_interpolate(src, *c[0], *c[2]) &&
                     detail::may_interpolate(src, *c[0], *c[3])))
        return {c, 4};
      return {};  // the four disagree among themselves (e.g. light bits the probe leaves out)
    }
    const Sample* s0 = nullptr;
    const Sample* s1 = nullptr;
    switch (mask) {
      case 0xE: case 0x7: case 0x6: s0 = c[1]; s1 = c[2]; break;  // no 00 or no 11: diagonal 10-01
      case 0xD: case 0xB: case 0x9: s0 = c[0]; s1 = c[3]; break;  // no 10 or no 01: diagonal 00-11
      case 0x3: case 0xC: case 0x5: case 0xA:  // adjacent pairs
        if (!bracket) {
          s0 = c[mask == 0xC ? 2 : mask == 0xA ? 1 : 0];
          s1 = c[mask == 0x3 ? 1 : mask == 0x5 ? 2 : 3];
        }
        break;
      case 0x1: case 0x2: case 0x4: case 0x8:
        if (single) s0 = s1 = c[mask == 0x1 ? 0 : mask == 0x2 ? 1 : mask == 0x4 ? 2 : 3];
        break;
      default: break;
    }
    if (s0 == nullptr || (cross && !detail::may_interpolate(src, *s0, *s1))) return {};
    return {{s0, s1}, 2};
  }

  upsampler_options options_{};
  std::uint32_t width_ = 0;
  std::uint32_t height_ = 0;
  std::array<std::array<std::uint32_t, 2>, max_upsample_passes> extents_{};  // [d] = {w, h}, d passes before the last
  std::array<std::vector<Sample>, max_upsample_passes> levels_{};
  std::vector<sample_kind> kinds_;
  std::vector<std::array<std::size_t, 3>> row_counts_;  // per row of the current pass: E, I, R
  upsample_stats stats_{};
};

// One-shot upsampling into out (width·height pixels) with a temporary pyramid.
// Errors as upsampler::create and upsampler::render. Allocation: the pyramid (see create).
// Prefer a kept `upsampler` for every-frame use.
template <class S, class Pixel, class E = serial_executor>
[[nodiscard]] status upsample(const S& src, std::uint32_t width, std::uint32_t height, std::span<Pixel> out,
                              upsampler_options options = {}, E&& exec = E{}) {
  static_assert(check_sample_source<S>());
  options.max_passes = std::max(options.max_passes, options.passes);
  auto u = upsampler<typename S::sample_type>::create(width, height, options);
  if (!u) return u.error();
  return u->render(src, out, exec);
}

}  // namespace infolerp
