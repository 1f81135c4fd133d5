#pragma once
// What the I-Buffer upsampler asks of the engine: a sample source.
//
// Clustering paper §4–4.1: a sample holds position, texcoords, cluster id, normal, soft-shadow
// and AO ratios and hard-shadow light bits; texcoords are interpolated, never textured colours
// (§5). Beyond the paper: the default record interpolates perspective-correctly when the engine
// fills inv_depth (1 / view depth).
//
// A sample source S models:
//   typename S::sample_type                               the I-Buffer record (copyable)
//   sample_type evaluate(uint32_t x, uint32_t y) const    full evaluation at pixel (x, y)
//   Pixel shade(const sample_type&, uint32_t x, uint32_t y) const     the sample's colour
// and, as members of S or free functions found by ADL (the default record below has them):
//   bool compatible(const sample_type& a, const sample_type& b)        may a and b be interpolated?
//   sample_type interpolate(const sample_type& a, const sample_type& b)             the midpoint
//   sample_type interpolate(const sample_type& a, b, c, d)                          the centre
// `compatible` is false between background and geometry and between differing light bits; it is
// meant to be an equivalence relation (same cluster id). All four are called concurrently from
// the executor's threads: thread-safe for const calls and deterministic, or the output differs
// across thread counts. Pixels may lie up to 2^(passes-1) - 1 beyond the right and bottom edge
// (the cropped border of §4); a pinhole camera extrapolates naturally.
//
// Optional members (found by concepts below; member or ADL where noted):
//   sample_type probe(uint32_t x, uint32_t y) const      the cheap, sharp part of a sample (a
//        rasteriser's cluster-ID buffer on the CPU): everything but the occlusion terms
//   sample_type interpolate(probe, a, b) / (probe, a, b, c, d)   with probes: the probe completed
//        with the expensive, smooth terms of its sources (member or ADL)
//   bool probe_compatible(probe, s)      default compatible(): for probes that leave out part of it
//   sample_type refine_probe(probe, x, y) const   adds what the probe left out; called only where
//        the agreeing, bracketing sources do not suffice (upsampler.hpp)
//   void probe(uint32_t y, std::span<const uint32_t> xs, std::span<sample_type> out) const
//        out[k] = probe(xs[k], y), xs ascending: e.g. a row's primary rays as packets
//   bool smooth(a, b) const   with probes only where sources differ: may a sample between a and b
//        take its geometry from them unprobed (e.g. normals_within below)
//   bool agree(a, b) const    beyond the paper: a new sample is evaluated unless every pair of its
//        sources agrees (e.g. occlusion_within below); need not be transitive
//   sample_type evaluate(const sample_type& probe, uint32_t x, uint32_t y) const   with probes: the
//        full evaluation of pixel (x, y) from its probe (refined first when the source refines),
//        the same record as evaluate(x, y) without tracing again what the probe traced
// For reuse across frames (frame_reuse.hpp), on the record (member or ADL) and on the source:
//   sample_type interpolate(probe, a, b, c, d, std::array<float, 4> w)   the probe completed with
//        the expensive terms of a, b, c, d at bilinear weights w (sum 1)
//   float view_dependence(const sample_type& s) const    how fast s's colour changes with the view:
//        display steps (1/255 of a channel) per radian the view direction at s turns; 0 for a
//        diffuse material. A source without it has every colour shaded anew each frame
// smooth() and agree() are symmetric, thread-safe and deterministic like compatible().
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/core/status.hpp"

namespace infolerp {

// Placeholder for light bits that a scene without hard-shadow lights compiles out.
struct no_light_bits {
  friend constexpr bool operator==(no_light_bits, no_light_bits) noexcept = default;
};

// The default I-Buffer record (§4). OcclusionTerms: ratios such as ambient occlusion and
// soft-shadow visibility per area light. HardShadowLights = false removes the light bits and
// their test at compile time (§4.1 for scenes without hard-shadow lights).
// Background (a primary ray that hits nothing) has cluster == invalid_id and is never
// compatible with geometry.
template <std::size_t OcclusionTerms = 2, bool HardShadowLights = true>
struct surface_sample {
  using light_bits_type = std::conditional_t<HardShadowLights, std::uint32_t, no_light_bits>;
  static constexpr bool has_light_bits = HardShadowLights;
  static constexpr std::size_t occlusion_terms = OcclusionTerms;

  glm::vec3 position{0.0f};                  // world-space hit point
  glm::vec3 normal{0.0f};                    // shading normal (interpolated unnormalised: normalise in shade)
  glm::vec2 texcoord{0.0f};                  // texture coordinates, interpolated (never colours)
  std::uint32_t cluster = invalid_id;        // cluster id of the hit triangle; invalid_id = background
  [[no_unique_address]] light_bits_type lights{};  // bit i: light i (of up to 32) is visible
  std::array<float, OcclusionTerms> occlusion{};   // unoccluded ratios (AO, soft shadows) in [0, 1]
  float inv_depth = 1.0f;  // 1 / view-space depth (> 0) for perspective-correct weights; all 1: screen-linear

  [[nodiscard]] constexpr bool background() const noexcept { return cluster == invalid_id; }
  // Member by member (frame_reuse.hpp keeps a colour whole only for an equal record).
  friend constexpr bool operator==(const surface_sample&, const surface_sample&) noexcept = default;
};

// Same cluster (background counts as its own cluster) and, when compiled in, same light bits.
// Complexity O(1). Equivalence relation.
template <std::size_t K, bool L>
[[nodiscard]] constexpr bool compatible(const surface_sample<K, L>& a, const surface_sample<K, L>& b) noexcept {
  if constexpr (L) {
    return a.cluster == b.cluster && a.lights == b.lights;
  } else {
    return a.cluster == b.cluster;
  }
}

// Weights: with a pinhole camera an attribute that is affine on a plane in the world is not
// affine in screen space, but attribute·inv_depth and inv_depth are; so the perspective-correct
// value at the screen midpoint weights each sample by its inv_depth (normalised by one
// reciprocal of the sum), and the new inv_depth is the plain mean. With inv_depth = 1 everywhere the weights are exactly 1/2 (1/4):
// screen-linear interpolation, exact for attributes linear in screen space.
// Each interpolation builds its result member by member: copying a whole record and then
// overwriting most of it was measurably slower (benchmarks/NOTES.md, BM_UpsampleInterpolatedPixel).

// Midpoint of an edge: continuous attributes weighted by inv_depth, cluster and light bits
// taken from a (equal to b's whenever compatible(a, b)). O(1), no allocation.
template <std::size_t K, bool L>
[[nodiscard]] constexpr surface_sample<K, L> interpolate(const surface_sample<K, L>& a,
                                                         const surface_sample<K, L>& b) noexcept {
  const float sum = a.inv_depth + b.inv_depth;
  const float r = 1.0f / sum;
  const float ta = a.inv_depth * r, tb = b.inv_depth * r;
  surface_sample<K, L> s;
  s.cluster = a.cluster;
  s.lights = a.lights;
  s.position = ta * a.position + tb * b.position;
  s.normal = ta * a.normal + tb * b.normal;
  s.texcoord = ta * a.texcoord + tb * b.texcoord;
  for (std::size_t i = 0; i < K; ++i) s.occlusion[i] = ta * a.occlusion[i] + tb * b.occlusion[i];
  s.inv_depth = 0.5f * sum;
  return s;
}

// Centre of a cell from its four corners, weighted by inv_depth, summed as (a + b) + (c + d).
template <std::size_t K, bool L>
[[nodiscard]] constexpr surface_sample<K, L> interpolate(const surface_sample<K, L>& a, const surface_sample<K, L>& b,
                                                         const surface_sample<K, L>& c,
                                                         const surface_sample<K, L>& d) noexcept {
  const float sum = (a.inv_depth + b.inv_depth) + (c.inv_depth + d.inv_depth);
  const float r = 1.0f / sum;
  const float ta = a.inv_depth * r, tb = b.inv_depth * r, tc = c.inv_depth * r, td = d.inv_depth * r;
  surface_sample<K, L> s;
  s.cluster = a.cluster;
  s.lights = a.lights;
  s.position = (ta * a.position + tb * b.position) + (tc * c.position + td * d.position);
  s.normal = (ta * a.normal + tb * b.normal) + (tc * c.normal + td * d.normal);
  s.texcoord = (ta * a.texcoord + tb * b.texcoord) + (tc * c.texcoord + td * d.texcoord);
  for (std::size_t i = 0; i < K; ++i)
    s.occlusion[i] = (ta * a.occlusion[i] + tb * b.occlusion[i]) + (tc * c.occlusion[i] + td * d.occlusion[i]);
  s.inv_depth = 0.25f * sum;
  return s;
}

// Whether every occlusion term (AO, soft-shadow ratios) of a and b differs by at most
// `tolerance` (>= 0; +infinity: always). A source's agree() for the default record. O(K).
template <std::size_t K, bool L>
[[nodiscard]] constexpr bool occlusion_within(const surface_sample<K, L>& a, const surface_sample<K, L>& b,
                                              float tolerance) noexcept {
  for (std::size_t i = 0; i < K; ++i)
    if (!(a.occlusion[i] - b.occlusion[i] <= tolerance && b.occlusion[i] - a.occlusion[i] <= tolerance)) return false;
  return true;
}

// Whether the normals of a and b (unit or not) make an angle whose cosine is at least
// `min_cos` (-1 or below: always); otherwise false when either normal is zero. A source's
// smooth() for the default record. O(1).
template <std::size_t K, bool L>
[[nodiscard]] inline bool normals_within(const surface_sample<K, L>& a, const surface_sample<K, L>& b,
                                         float min_cos) noexcept {
  if (min_cos <= -1.0f) return true;
  // dot >= min_cos·|a|·|b| without a square root: x·|x| is increasing, so square both sides that way.
  const float dot = glm::dot(a.normal, b.normal);
  const float norms2 = glm::dot(a.normal, a.normal) * glm::dot(b.normal, b.normal);
  return norms2 > 0.0f && dot * std::abs(dot) >= min_cos * std::abs(min_cos) * norms2;
}

namespace detail {
// The primary-hit part of a probe (member by member, see above).
template <std::size_t K, bool L>
[[nodiscard]] constexpr surface_sample<K, L> probe_part(const surface_sample<K, L>& probe) noexcept {
  surface_sample<K, L> s;
  s.position = probe.position;
  s.normal = probe.normal;
  s.texcoord = probe.texcoord;
  s.cluster = probe.cluster;
  s.inv_depth = probe.inv_depth;
  return s;
}
}  // namespace detail

// With a probe (see the top of this file): the primary-hit part (position, normal, texcoords,
// cluster, inv_depth) from the probe, light bits from a, occlusion terms from the sources,
// weighted by their inv_depth as above (1/2 each when equal) ... a's light bits equal the
// probe's whenever the probe carries them (compatible(probe, a)); a probe that leaves them out
// (refine_probe) is completed only from sources that agree on them.
template <std::size_t K, bool L>
[[nodiscard]] constexpr surface_sample<K, L> interpolate(const surface_sample<K, L>& probe, const surface_sample<K, L>& a,
                                                         const surface_sample<K, L>& b) noexcept {
  const float sum = a.inv_depth + b.inv_depth;
  const float r = 1.0f / sum;
  const float ta = a.inv_depth * r, tb = b.inv_depth * r;
  surface_sample<K, L> s = detail::probe_part(probe);
  s.lights = a.lights;
  for (std::size_t i = 0; i < K; ++i) s.occlusion[i] = ta * a.occlusion[i] + tb * b.occlusion[i];
  return s;
}

// ... or from four sources (1/4 each when equal), summed as (a + b) + (c + d).
template <std::size_t K, bool L>
[[nodiscard]] constexpr surface_sample<K, L> interpolate(const surface_sample<K, L>& probe, const surface_sample<K, L>& a,
                                                         const surface_sample<K, L>& b, const surface_sample<K, L>& c,
                                                         const surface_sample<K, L>& d) noexcept {
  const float sum = (a.inv_depth + b.inv_depth) + (c.inv_depth + d.inv_depth);
  const float r = 1.0f / sum;
  const float ta = a.inv_depth * r, tb = b.inv_depth * r, tc = c.inv_depth * r, td = d.inv_depth * r;
  surface_sample<K, L> s = detail::probe_part(probe);
  s.lights = a.lights;
  for (std::size_t i = 0; i < K; ++i)
    s.occlusion[i] = (ta * a.occlusion[i] + tb * b.occlusion[i]) + (tc * c.occlusion[i] + td * d.occlusion[i]);
  return s;
}

// With a probe, for reuse across frames: the primary-hit part from the probe, light bits from
// a, occlusion terms from a, b, c, d at bilinear weights w (sum 1; a weight-0 source is read
// only for its bits), made perspective-correct by their inv_depth in the view they were taken
// in (w_i·inv_depth_i normalised), so that a term affine on a plane in the world is reproduced
// exactly at any sub-pixel position. O(K), no allocation.
template <std::size_t K, bool L>
[[nodiscard]] constexpr surface_sample<K, L> interpolate(const surface_sample<K, L>& probe, const surface_sample<K, L>& a,
                                                         const surface_sample<K, L>& b, const surface_sample<K, L>& c,
                                                         const surface_sample<K, L>& d, const std::array<float, 4>& w) noexcept {
  const float wa = w[0] * a.inv_depth, wb = w[1] * b.inv_depth, wc = w[2] * c.inv_depth, wd = w[3] * d.inv_depth;
  const float r = 1.0f / ((wa + wb) + (wc + wd));
  surface_sample<K, L> s = detail::probe_part(probe);
  s.lights = a.lights;
  for (std::size_t i = 0; i < K; ++i)
    s.occlusion[i] = ((wa * a.occlusion[i] + wb * b.occlusion[i]) + (wc * c.occlusion[i] + wd * d.occlusion[i])) * r;
  return s;
}

namespace detail {
template <class S>
using sample_of = typename S::sample_type;

template <class S>
concept member_compatible = requires(const S& s, const sample_of<S>& a) {
  { s.compatible(a, a) } -> std::convertible_to<bool>;
};
template <class S>
concept member_interpolate = requires(const S& s, const sample_of<S>& a) {
  { s.interpolate(a, a) } -> std::convertible_to<sample_of<S>>;
  { s.interpolate(a, a, a, a) } -> std::convertible_to<sample_of<S>>;
};
template <class S>
concept member_probe_interpolate = requires(const S& s, const sample_of<S>& a) {
  { s.interpolate(a, a, a) } -> std::convertible_to<sample_of<S>>;
  { s.interpolate(a, a, a, a, a) } -> std::convertible_to<sample_of<S>>;
};
template <class T>
concept adl_probe_interpolate = requires(const T& a) {
  { interpolate(a, a, a) } -> std::convertible_to<T>;
  { interpolate(a, a, a, a, a) } -> std::convertible_to<T>;
};
template <class S>
concept member_probe_compatible = requires(const S& s, const sample_of<S>& a) {
  { s.probe_compatible(a, a) } -> std::convertible_to<bool>;
};
template <class T>
concept adl_probe_compatible = requires(const T& a) {
  { probe_compatible(a, a) } -> std::convertible_to<bool>;
};
template <class S>
concept member_agree = requires(const S& s, const sample_of<S>& a) {
  { s.agree(a, a) } -> std::convertible_to<bool>;
};
template <class S>
concept member_smooth = requires(const S& s, const sample_of<S>& a) {
  { s.smooth(a, a) } -> std::convertible_to<bool>;
};
template <class S>
concept member_probe_evaluate = requires(const S& s, const sample_of<S>& a, std::uint32_t x) {
  { s.evaluate(a, x, x) } -> std::convertible_to<sample_of<S>>;
};
template <class S>
concept member_weighted_interpolate = requires(const S& s, const sample_of<S>& a, const std::array<float, 4>& w) {
  { s.interpolate(a, a, a, a, a, w) } -> std::convertible_to<sample_of<S>>;
};
template <class T>
concept adl_weighted_interpolate = requires(const T& a, const std::array<float, 4>& w) {
  { interpolate(a, a, a, a, a, w) } -> std::convertible_to<T>;
};
template <class S>
concept member_view_dependence = requires(const S& s, const sample_of<S>& a) {
  { s.view_dependence(a) } -> std::convertible_to<float>;
};
template <class T>
concept adl_compatible = requires(const T& a) {
  { compatible(a, a) } -> std::convertible_to<bool>;
};
template <class T>
concept adl_interpolate = requires(const T& a) {
  { interpolate(a, a) } -> std::convertible_to<T>;
  { interpolate(a, a, a, a) } -> std::convertible_to<T>;
};
}  // namespace detail

template <class S>
concept sample_source = requires { typename S::sample_type; } &&
    std::copyable<typename S::sample_type> &&
    requires(const S& s, std::uint32_t x, const typename S::sample_type& a) {
      { s.evaluate(x, x) } -> std::convertible_to<typename S::sample_type>;
      s.shade(a, x, x);
    } &&
    (detail::member_compatible<S> || detail::adl_compatible<typename S::sample_type>) &&
    (detail::member_interpolate<S> || detail::adl_interpolate<typename S::sample_type>);

// A sample source that also evaluates the cheap part of every pixel (see the top of this file).
template <class S>
concept probing_sample_source = sample_source<S> &&
    requires(const S& s, std::uint32_t x) {
      { s.probe(x, x) } -> std::convertible_to<typename S::sample_type>;
    } &&
    (detail::member_probe_interpolate<S> || detail::adl_probe_interpolate<typename S::sample_type>);

// A probing source whose probes may leave out part of what compatible() compares (e.g. the
// hard-shadow bits, tested only with probe_compatible()) and that can add it afterwards
// (see the top of this file).
template <class S>
concept refining_sample_source = probing_sample_source<S> &&
    requires(const S& s, std::uint32_t x, const typename S::sample_type& p) {
      { s.refine_probe(p, x, x) } -> std::convertible_to<typename S::sample_type>;
    };

// A probing source that also probes many pixels of one row in a call (see the top of this file).
template <class S>
concept batch_probing_sample_source = probing_sample_source<S> &&
    requires(const S& s, std::uint32_t y, std::span<const std::uint32_t> xs, std::span<typename S::sample_type> out) {
      s.probe(y, xs, out);
    };

// One readable message per missing piece instead of template noise.
template <class S>
constexpr bool check_sample_source() {
  static_assert(requires { typename S::sample_type; },
                "infolerp: sample source needs a member type `sample_type` (the I-Buffer record)");
  if constexpr (requires { typename S::sample_type; }) {
    static_assert(requires(const S& s, std::uint32_t x) {
                    { s.evaluate(x, x) } -> std::convertible_to<typename S::sample_type>;
                  },
                  "infolerp: sample source needs `sample_type evaluate(uint32_t x, uint32_t y) const`");
    static_assert(requires(const S& s, std::uint32_t x, const typename S::sample_type& a) { s.shade(a, x, x); },
                  "infolerp: sample source needs `Pixel shade(const sample_type&, uint32_t x, uint32_t y) const`");
    static_assert(detail::member_compatible<S> || detail::adl_compatible<typename S::sample_type>,
                  "infolerp: sample source needs `bool compatible(const sample_type&, const sample_type&)` "
                  "(member, or a free function found by ADL)");
    static_assert(detail::member_interpolate<S> || detail::adl_interpolate<typename S::sample_type>,
                  "infolerp: sample source needs `interpolate(a, b)` and `interpolate(a, b, c, d)` returning "
                  "sample_type (members, or free functions found by ADL)");
  }
  return sample_source<S>;
}

// The pixel type a source shades into.
template <class S>
using pixel_type_of = std::remove_cvref_t<decltype(std::declval<const S&>().shade(
    std::declval<const typename S::sample_type&>(), std::uint32_t{}, std::uint32_t{}))>;

namespace detail {
template <class S>
[[nodiscard]] inline bool source_compatible(const S& s, const sample_of<S>& a, const sample_of<S>& b) {
  if constexpr (member_compatible<S>) {
    return s.compatible(a, b);
  } else {
    return compatible(a, b);
  }
}
// Whether the sources of one interpolation agree pairwise (true for a source without agree()).
template <class S>
[[nodiscard]] inline bool sources_agree(const S& s, const sample_of<S>& a, const sample_of<S>& b) {
  if constexpr (member_agree<S>) {
    return &a == &b || static_cast<bool>(s.agree(a, b));
  } else {
    return true;
  }
}
template <class S>
[[nodiscard]] inline bool sources_agree(const S& s, const sample_of<S>& a, const sample_of<S>& b, const sample_of<S>& c,
                                        const sample_of<S>& d) {
  return sources_agree(s, a, b) && sources_agree(s, a, c) && sources_agree(s, a, d) && sources_agree(s, b, c) &&
         sources_agree(s, b, d) && sources_agree(s, c, d);
}
// Whether the sources of one interpolation are smooth pairwise (true for a source without smooth()).
template <class S>
[[nodiscard]] inline bool sources_smooth(const S& s, const sample_of<S>& a, const sample_of<S>& b) {
  if constexpr (member_smooth<S>) {
    return static_cast<bool>(s.smooth(a, b));
  } else {
    return true;
  }
}
// Of a cell's corners a, b, c, d (00, 10, 01, 11): its two diagonals, the pairs furthest apart.
template <class S>
[[nodiscard]] inline bool sources_smooth(const S& s, const sample_of<S>& a, const sample_of<S>& b, const sample_of<S>& c,
                                         const sample_of<S>& d) {
  return sources_smooth(s, a, d) && sources_smooth(s, b, c);
}
template <class S>
[[nodiscard]] inline sample_of<S> source_interpolate(const S& s, const sample_of<S>& a, const sample_of<S>& b) {
  if constexpr (member_interpolate<S>) {
    return s.interpolate(a, b);
  } else {
    return interpolate(a, b);
  }
}
template <class S>
[[nodiscard]] inline sample_of<S> source_interpolate(const S& s, const sample_of<S>& a, const sample_of<S>& b,
                                                     const sample_of<S>& c, const sample_of<S>& d) {
  if constexpr (member_interpolate<S>) {
    return s.interpolate(a, b, c, d);
  } else {
    return interpolate(a, b, c, d);
  }
}
template <class S>
[[nodiscard]] inline bool source_probe_compatible(const S& s, const sample_of<S>& p, const sample_of<S>& a) {
  if constexpr (member_probe_compatible<S>) {
    return s.probe_compatible(p, a);
  } else if constexpr (adl_probe_compatible<sample_of<S>>) {
    return probe_compatible(p, a);
  } else {
    return source_compatible(s, p, a);
  }
}
template <class S>
[[nodiscard]] inline sample_of<S> source_interpolate(const S& s, const sample_of<S>& p, const sample_of<S>& a,
                                                     const sample_of<S>& b) {
  if constexpr (member_probe_interpolate<S>) {
    return s.interpolate(p, a, b);
  } else {
    return interpolate(p, a, b);
  }
}
template <class S>
[[nodiscard]] inline sample_of<S> source_interpolate(const S& s, const sample_of<S>& p, const sample_of<S>& a,
                                                     const sample_of<S>& b, const sample_of<S>& c,
                                                     const sample_of<S>& d) {
  if constexpr (member_probe_interpolate<S>) {
    return s.interpolate(p, a, b, c, d);
  } else {
    return interpolate(p, a, b, c, d);
  }
}
// The full evaluation of pixel (x, y) whose probe p the caller holds (refined when the source
// refines): from p when the source can, else evaluate(x, y).
template <class S>
[[nodiscard]] inline sample_of<S> source_evaluate(const S& s, const sample_of<S>& p, std::uint32_t x, std::uint32_t y) {
  if constexpr (member_probe_evaluate<S>) {
    return s.evaluate(p, x, y);
  } else {
    return s.evaluate(x, y);
  }
}
template <class S>
[[nodiscard]] inline sample_of<S> source_interpolate(const S& s, const sample_of<S>& p, const sample_of<S>& a,
                                                     const sample_of<S>& b, const sample_of<S>& c,
                                                     const sample_of<S>& d, const std::array<float, 4>& w) {
  if constexpr (member_weighted_interpolate<S>) {
    return s.interpolate(p, a, b, c, d, w);
  } else {
    return interpolate(p, a, b, c, d, w);
  }
}
}  // namespace detail

}  // namespace infolerp
