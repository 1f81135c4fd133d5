#pragma once
// Visibility channel (clustering paper §3.1.1, the viewpoint channel of Feixas et al. [32]):
// an indirect channel V→T measured through the user's tracer, then inverted to T→V by Bayes.
//
//   viewpoints   N points spread uniformly (Fibonacci lattice) on a sphere around the mesh's
//                bounding box (radius = radius_scale × half its diagonal), p(v) = 1/N.
//   OR(t, v)     occlusion ratio: the fraction of n² stratified sample points of t (centroids of
//                t's regular n×n subdivision) from which an occlusion ray toward v is free.
//                Back-facing (n_t·(v − x) <= 0) counts as not visible (OR = 0). Ratios are
//                per triangle area, so the channel is independent of the triangulation.
//   p(t|v) = OR(t,v) / Σ_t' OR(t',v) over the set being clustered, p(t) = Σ_v p(v) p(t|v),
//   p(v|t) = p(v) p(t|v) / p(t)   (Bayes), JS(Y|a,b) weighted by p(a), p(b).
// Viewpoints that see nothing of the set are dropped (p(v) = 1/N_active).
// Triangles seen from no viewpoint (p(t) = 0, e.g. inside a closed cavity) form their own
// class: JS between two of them is 0, between one of them and a seen triangle 1, and their
// I(t;V) is +inf so they are never the first seed.
// Denoising (§3.2.1, on by default): each row is replaced by the mean of the rows of itself and
// its edge neighbours in the set with JS <= Th (most tests are decided by an upper bound on JS
// without logarithms, see visibility_state::surely_within).
// Rows that are bit-identical (row and p(t)) after denoising share their divergences through
// visibility_state::representative (hidden, flat and denoised regions give many such rows).
// visibility_state::estimate (info/js_estimate.hpp, one entropy estimate per row at init) lets
// the clustering decide nearly all its comparisons without the exact JS kernel.
//
// Rays: N·n² per triangle at most, traced in batches (trace_occluded uses the tracer's batch
// overload when it has one), chunks of `grain` triangles in parallel through the executor.
// Options cut them: `coherent` and `cull_hull` exactly (the same counts), `adaptive_probes`
// approximately (see visibility_channel). Option `images` measures OR the paper's way instead:
// one image of primary rays per viewpoint (cluster/visibility_images.hpp).
// OR is stored as visible-sample counts (round(255·OR) with images): T·N bytes. Deterministic: each count depends only on
// its own rays.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <numbers>
#include <span>
#include <utility>
#include <vector>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/cluster/channel.hpp"
#include "infolerp/cluster/visibility_images.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/core/large_buffer.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/info/entropy.hpp"
#include "infolerp/info/jensen_shannon.hpp"
#include "infolerp/info/js_estimate.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/locality_order.hpp"
#include "infolerp/mesh/support_function.hpp"
#include "infolerp/mesh/topology.hpp"

namespace infolerp {

namespace detail {
// Asks for the cache lines of [p, p + bytes): a hint without effect on results (the rows and
// counts the channel reads next are far apart in memory).
inline void prefetch_bytes(const void* p, std::size_t bytes) {
#if defined(__GNUC__)
  for (std::size_t b = 0; b < bytes; b += 64) __builtin_prefetch(static_cast<const char*>(p) + b);
#else
  (void)p, (void)bytes;
#endif
}
}  // namespace detail

// n points on a sphere by the Fibonacci lattice (near-uniform, deterministic). O(n).
inline std::vector<glm::dvec3> fibonacci_sphere(std::size_t n, glm::dvec3 center, double radius) {
  std::vector<glm::dvec3> out(n);
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (std::size_t i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * static_cast<double>(i) + 1.0) / static_cast<double>(n);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden * static_cast<double>(i);
    out[i] = center + radius * glm::dvec3(r * std::cos(phi), r * std::sin(phi), z);
  }
  return out;
}

// Barycentric weights (w1, w2) of the centroids of a triangle's regular n×n subdivision
// (n² stratified samples; the point is (1-w1-w2)p0 + w1 p1 + w2 p2). O(n²).
inline std::vector<glm::dvec2> stratified_triangle_samples(std::uint32_t n) {
  std::vector<glm::dvec2> out;
  const double inv = 1.0 / static_cast<double>(n);
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = 0; i + j < n; ++j) {
      out.emplace_back((i + 1.0 / 3.0) * inv, (j + 1.0 / 3.0) * inv);
      if (i + j + 2 <= n) out.emplace_back((i + 2.0 / 3.0) * inv, (j + 2.0 / 3.0) * inv);
    }
  return out;
}

struct visibility_channel;

// The viewpoints and sample pattern of one visibility measurement.
struct visibility_setup {
  std::vector<glm::dvec3> viewpoints;
  std::vector<glm::dvec2> samples;  // barycentric (w1, w2)
  double offset = 0.0;              // ray origins are lifted by this along the face normal
};

// Appends the occlusion rays of triangles [first, last) to `rays`, and for each ray its slot
// (t − first)·N + v to `slots`. Back-facing sample/viewpoint pairs get no ray (OR term 0).
// In detail: not part of the API; benchmarks call it to time the same rays alone.
// O((last − first)·N·n²).
namespace detail {
template <class M>
void make_visibility_rays(const M& m, const visibility_setup& setup, std::size_t first, std::size_t last,
                          std::vector<ray>& rays, std::vector<std::uint32_t>& slots) {
  static_assert(check_mesh<M>());
  const std::size_t nv = setup.viewpoints.size();
  for (std::size_t t = first; t < last; ++t) {
    const triangle_corners c = corners(m, t);
    const glm::dvec3 n = glm::dvec3(triangle_normal(c));
    if (n == glm::dvec3(0.0)) continue;
    for (const glm::dvec2& w : setup.samples) {
      const glm::dvec3 x = (1.0 - w.x - w.y) * c.p0 + w.x * c.p1 + w.y * c.p2 + setup.offset * n;
      for (std::size_t v = 0; v < nv; ++v) {
        const glm::dvec3 d = setup.viewpoints[v] - x;
        if (glm::dot(n, d) <= 0.0) continue;  // back-facing
        rays.push_back(ray{glm::vec3(x), 0.0f, glm::vec3(d), 1.0f});
        slots.push_back(static_cast<std::uint32_t>((t - first) * nv + v));
      }
    }
  }
}

// What cull_hull tests rays against: the support function of m's vertices, and the margin a
// ray must clear beyond a supporting plane, 2⁻¹⁸ of the largest coordinate magnitude of the mesh
// and the viewpoints (a tracer working in float errs by a few 2⁻²⁴ of it).
// O(V log V), allocation O(V).
struct visibility_hull {
  point_support support;
  double margin = 0.0;
};
template <class M>
visibility_hull make_visibility_hull(const M& m, const visibility_setup& su) {
  std::vector<glm::dvec3> points(mesh_vertex_count(m));
  for (std::size_t v = 0; v < points.size(); ++v) points[v] = glm::dvec3(mesh_position(m, v));
  double largest = 0.0;
  auto widen = [&](const glm::dvec3& q) { largest = std::max({largest, std::abs(q.x), std::abs(q.y), std::abs(q.z)}); };
  for (const glm::dvec3& q : points) widen(q);
  for (const glm::dvec3& q : su.viewpoints) widen(q);
  return {point_support(points), largest * 0x1p-18};
}

// The rays of the triangles `tris` (any order), with the exact savings of visibility_channel:
// the same rays make_visibility_rays makes, bit for bit, with slot i·N + v for tris[i].
//   by_viewpoint   rays grouped by viewpoint (then triangle, then sample) instead of by sample,
//                  so that consecutive rays start close together and run nearly parallel.
//   hull           when given, a ray whose segment lies beyond the plane n_t·y = h(n_t) + margin
//                  (h the support function of every point the tracer's scene holds) cannot be
//                  occluded: its slot goes to `free_slots` instead of `rays`. The test uses the
//                  float origin and end the tracer would get.
//   sample_on      when not empty, only the samples s with sample_on[s] != 0 get rays.
//   pair_mode      when not empty, per slot: 0 no ray, 1 traced (as above), 2 counted free
//                  without tracing (its slot goes to `free_slots` when front-facing).
// O(|tris|·N·n²) + one support query per triangle, allocation of the
// output vectors and |tris|·n² points in `scratch`.
template <class M>
void make_grouped_visibility_rays(const M& m, const visibility_setup& setup, std::span<const std::uint32_t> tris,
                                  bool by_viewpoint, const visibility_hull* hull,
                                  std::vector<glm::dvec3>& scratch, std::vector<ray>& rays,
                                  std::vector<std::uint32_t>& slots, std::vector<std::uint32_t>& free_slots,
                                  std::span<const std::uint8_t> sample_on = {}, std::span<const std::uint8_t> pair_mode = {}) {
  static_assert(check_mesh<M>());
  const std::size_t nv = setup.viewpoints.size(), ns = setup.samples.size(), k = tris.size();
  // Per triangle: its normal (row i·(ns + 2)), then the plane bound (x = h + margin, +inf when no
  // ray of it can be proven free), then its sample origins.
  scratch.assign(k * (ns + 2), glm::dvec3(0.0));
  for (std::size_t i = 0; i < k; ++i) {
    const triangle_corners c = corners(m, tris[i]);
    const glm::dvec3 n = glm::dvec3(triangle_normal(c));
    glm::dvec3* row = scratch.data() + i * (ns + 2);
    row[0] = n;
    double highest = -std::numeric_limits<double>::infinity();  // of n·(float origin)
    for (std::size_t s = 0; s < ns; ++s) {
      const glm::dvec2 w = setup.samples[s];
      row[2 + s] = (1.0 - w.x - w.y) * c.p0 + w.x * c.p1 + w.y * c.p2 + setup.offset * n;
      highest = std::max(highest, glm::dot(n, glm::dvec3(glm::vec3(row[2 + s]))));
    }
    double bound = std::numeric_limits<double>::infinity();  // above every origin: nothing is free
    if (hull != nullptr && n != glm::dvec3(0.0))
      bound = hull->support.support_up_to(n, glm::dot(n, c.p0), highest - hull->margin) + hull->margin;
    row[1].x = bound;
  }
  auto emit = [&](std::size_t i, std::size_t s, std::size_t v) {
    const auto slot = static_cast<std::uint32_t>(i * nv + v);
    const std::uint8_t mode = pair_mode.empty() ? 1 : pair_mode[slot];
    if (mode == 0 || (!sample_on.empty() && sample_on[s] == 0)) return;
    const glm::dvec3* row = scratch.data() + i * (ns + 2);
    const glm::dvec3 n = row[0], x = row[2 + s];
    const glm::dvec3 d = setup.viewpoints[v] - x;
    if (glm::dot(n, d) <= 0.0) return;  // back-facing
    const ray r{glm::vec3(x), 0.0f, glm::vec3(d), 1.0f};
    const glm::dvec3 o(r.origin), e = o + glm::dvec3(r.direction);
    if (mode == 2 || std::min(glm::dot(n, o), glm::dot(n, e)) > row[1].x) {
      free_slots.push_back(slot);
    } else {
      rays.push_back(r);
      slots.push_back(slot);
    }
  };
  if (by_viewpoint) {
    for (std::size_t v = 0; v < nv; ++v)
      for (std::size_t i = 0; i < k; ++i)
        if (scratch[i * (ns + 2)] != glm::dvec3(0.0))
          for (std::size_t s = 0; s < ns; ++s) emit(i, s, v);
  } else {
    for (std::size_t i = 0; i < k; ++i)
      if (scratch[i * (ns + 2)] != glm::dvec3(0.0))
        for (std::size_t s = 0; s < ns; ++s)
          for (std::size_t v = 0; v < nv; ++v) emit(i, s, v);
  }
}

}  // namespace detail

// A visibility channel initialised on a set of triangles. Classes are elements.
class visibility_state {
 public:
  std::size_t element_count() const { return p_.size(); }
  std::size_t class_count() const { return p_.size(); }
  std::uint32_t class_of(std::uint32_t i) const { return i; }
  bool all_alike() const { return all_alike_; }
  std::size_t viewpoint_count() const { return n_; }
  // p(V|t) (zeros when t is unseen) and p(t).
  std::span<const float> row(std::uint32_t t) const { return {rows_.data() + std::size_t{t} * n_, n_}; }
  double input_probability(std::uint32_t t) const { return p_[t]; }
  bool unseen(std::uint32_t t) const { return !(p_[t] > 0.0); }
  // The smallest element whose row and p(t) are bit-identical to t's (t itself when none):
  // every divergence from it is bit-identical to t's, so JS columns and memos are shared.
  std::uint32_t representative(std::uint32_t t) const { return rep_[t]; }

  double divergence(std::uint32_t a, std::uint32_t b) const {
    if (a == b) return 0.0;
    const bool ua = unseen(a), ub = unseen(b);
    if (ua || ub) return ua == ub ? 0.0 : 1.0;
    return js_channel(row(a), row(b), p_[a], p_[b]);
  }
  // Within estimate_error() of divergence(a, b) (info/js_estimate.hpp; the unseen cases are
  // exact). O(N), no allocation.
  double estimate(std::uint32_t a, std::uint32_t b) const {
    if (a == b) return 0.0;
    const bool ua = unseen(a), ub = unseen(b);
    if (ua || ub) return ua == ub ? 0.0 : 1.0;
    const double total = p_[a] + p_[b];  // the weight js_channel uses
    return js_estimate(rows_.data() + std::size_t{a} * n_, rows_.data() + std::size_t{b} * n_, n_, p_[a] / total,
                       entropy_[a], entropy_[b]);
  }
  double estimate_error() const { return js_estimate_error(n_); }
  // True only if divergence(a, b) <= threshold, decided without logarithms by the upper bound
  //   JS_π(P,Q) <= h(π)·Σ_{p>q}(p − q) + h(1 − π)·Σ_{q>p}(q − p) <= h_max·Σ|p − q|,
  // h(x) = −x·log₂x <= h_max = 1/(e·ln 2) ≈ 0.53074 (the per-bin term f(p,q) is convex and
  // 1-homogeneous, so for p >= q f(p,q) <= f(q,q) + f(p − q, 0) = (p − q)·h(π), and
  // symmetrically). The bound must be 2⁻²² below the threshold: more than the kernel's error
  // (~1e-15) and than the rounding of a JS value to a float column entry (region_growing.hpp),
  // so a true answer always agrees with divergence() and with that entry; false means "not
  // decided".
  // Σ|p − q| is summed in float (8 lanes, twice the SSE width of doubles) and inflated by
  // (N + 16)·2⁻²², more than its rounding (at most (N/8 + 4) float ulps, relative).
  // O(N), no allocation.
  bool surely_within(std::uint32_t a, std::uint32_t b, double threshold) const {
    if (a == b || unseen(a) || unseen(b)) return false;
    return surely_within(rows_.data() + std::size_t{a} * n_, rows_.data() + std::size_t{b} * n_, n_, threshold);
  }
  // The same bound for two rows of n entries.
  static bool surely_within(const float* ra, const float* rb, std::size_t n, double threshold) {
    float l1[8] = {};  // 8 independent sums
    std::size_t v = 0;
    for (; v + 8 <= n; v += 8)
      for (std::size_t lane = 0; lane < 8; ++lane) l1[lane] += std::abs(ra[v + lane] - rb[v + lane]);
    for (; v < n; ++v) l1[0] += std::abs(ra[v] - rb[v]);
    const double sum = static_cast<double>(((l1[0] + l1[1]) + (l1[2] + l1[3])) + ((l1[4] + l1[5]) + (l1[6] + l1[7])));
    constexpr double h_max = 0.53074;  // > 1/(e·ln 2) = 0.5307378...
    return h_max * sum * (1.0 + static_cast<double>(n + 16) * 0x1p-22) <= threshold - 0x1p-22;
  }
  // divergence(a, b) <= threshold, by the bound where it decides.
  bool within(std::uint32_t a, std::uint32_t b, double threshold) const {
    if (a == b || unseen(a) || unseen(b)) return divergence(a, b) <= threshold;
    return within(row(a), row(b), p_[a], p_[b], threshold);
  }
  // The same for two seen rows with input probabilities pa, pb (denoising's raw rows).
  static bool within(std::span<const float> ra, std::span<const float> rb, double pa, double pb, double threshold) {
    return surely_within(ra.data(), rb.data(), ra.size(), threshold) || js_channel(ra, rb, pa, pb) <= threshold;
  }
  // Asks for t's row in cache, a hint without effect on results: region growing calls it a
  // few classes ahead (the rows a seed search reads are far apart and each is read once).
  void prefetch(std::uint32_t t) const { detail::prefetch_bytes(rows_.data() + std::size_t{t} * n_, n_ * sizeof(float)); }
  double mutual_information(std::uint32_t t) const {
    if (unseen(t)) return std::numeric_limits<double>::infinity();
    return element_mutual_information(row(t), output_);
  }
  // A lower bound of mutual_information(t) without logarithms (info/entropy.hpp), +inf when
  // unseen. Most rows of a mesh are far from p(V), so the seed search evaluates few MIs.
  // O(N), no allocation.
  double mutual_information_lower_bound(std::uint32_t t) const {
    if (unseen(t)) return std::numeric_limits<double>::infinity();
    return infolerp::mutual_information_lower_bound(row(t), std::span<const double>(output_));
  }

 private:
  friend struct prepared_visibility_channel;
  std::size_t n_ = 0;
  std::vector<float, large_buffer_allocator<float>> rows_;  // M × N (huge pages where offered)
  std::vector<double> p_;       // p(t)
  std::vector<double> output_;  // p(v)
  std::vector<std::uint32_t> rep_;  // representative(t)
  std::vector<double> entropy_;     // entropy_estimate of each row (0 when unseen)
  bool all_alike_ = false;

  // rep_ by an open-addressing hash table of rows (bit patterns of the row and of p(t)), and
  // entropy_ (estimated once per representative). O(M·N), allocation O(M).
  void find_representatives() {
    const std::size_t m = p_.size();
    rep_.resize(m);
    entropy_.resize(m);
    std::size_t size = 1;
    while (size < 2 * m) size *= 2;
    std::vector<std::uint32_t> table(size, invalid_id), home(m);
    for (std::uint32_t t = 0; t < m; ++t) {  // first each row's home slot, then the probes
      const float* r = rows_.data() + std::size_t{t} * n_;
      constexpr std::uint64_t k = 0x9E3779B97F4A7C15ull;
      std::uint64_t h0 = std::bit_cast<std::uint64_t>(p_[t]), h1 = 1, h2 = 2, h3 = 3;  // independent chains
      std::size_t v = 0;
      for (; v + 4 <= n_; v += 4) {
        h0 = (h0 ^ std::bit_cast<std::uint32_t>(r[v])) * k;
        h1 = (h1 ^ std::bit_cast<std::uint32_t>(r[v + 1])) * k;
        h2 = (h2 ^ std::bit_cast<std::uint32_t>(r[v + 2])) * k;
        h3 = (h3 ^ std::bit_cast<std::uint32_t>(r[v + 3])) * k;
      }
      for (; v < n_; ++v) h0 = (h0 ^ std::bit_cast<std::uint32_t>(r[v])) * k;
      const std::uint64_t h = h0 ^ (h1 >> 13) ^ (h2 >> 26) ^ (h3 >> 39);
      home[t] = static_cast<std::uint32_t>((h ^ (h >> 29)) & (size - 1));
    }
    const std::size_t bytes = n_ * sizeof(float);
    for (std::uint32_t t = 0; t < m; ++t) {
      if (t + 8 < m) detail::prefetch_bytes(table.data() + home[t + 8], 1);  // random slots: ask ahead
      const float* r = rows_.data() + std::size_t{t} * n_;
      for (std::size_t slot = home[t];; slot = (slot + 1) & (size - 1)) {
        const std::uint32_t o = table[slot];
        if (o == invalid_id) {
          table[slot] = rep_[t] = t;
          break;
        }
        if (std::bit_cast<std::uint64_t>(p_[o]) == std::bit_cast<std::uint64_t>(p_[t]) &&
            std::memcmp(rows_.data() + std::size_t{o} * n_, r, bytes) == 0) {
          rep_[t] = o;
          break;
        }
      }
      entropy_[t] = rep_[t] != t ? entropy_[rep_[t]] : unseen(t) ? 0.0 : entropy_estimate(r, n_);
    }
  }
};

// Visibility measured once for a mesh: visible-sample counts per (triangle, viewpoint).
struct prepared_visibility_channel {
  double threshold = 0.48;
  bool denoise = true;
  std::size_t viewpoints = 0;
  std::uint32_t samples = 0;           // the count meaning OR = 1: n² per triangle (255 with images)
  std::vector<std::uint8_t> visible;   // T × N: samples with a free ray toward v (round(255·OR) with images)
  std::vector<std::uint32_t> neighbour_offsets, neighbours;  // the mesh's dual graph

  // OR(t, v) in [0, 1].
  double occlusion_ratio(std::size_t t, std::size_t v) const {
    return static_cast<double>(visible[t * viewpoints + v]) / static_cast<double>(samples);
  }

  // Algorithm 1's ch.init(cl): p(t|v), p(t), Bayes inversion, optional denoising.
  // Errors: empty set, id out of range. Complexity O(M·N) (+ O(M·N·degree) denoising, + O(M log M)
  // to find neighbours in the set when it is under 1/8 of the mesh, + O(M·N) to find the
  // representatives). Allocation O(M·N) floats (+ T ids for a set of at least 1/8 of the mesh,
  // + 3M ids for the representatives and their hash table).
  result<visibility_state> init(std::span<const std::uint32_t> triangles) const {
    const std::size_t m = triangles.size(), n = viewpoints;
    if (m == 0) return make_error(errc::empty_input, no_element, "visibility channel: empty triangle set");
    const std::size_t nt = neighbour_offsets.empty() ? 0 : neighbour_offsets.size() - 1;
    for (std::uint32_t t : triangles)
      if (t >= nt) return make_error(errc::index_out_of_range, t, "visibility channel: triangle ", t, " out of range");
    // p(t|v) = OR(t,v) / Σ_t' OR(t',v) = c(t,v) / C(v) with c the visible-sample counts and
    // C(v) = Σ_t' c(t',v), an exact integer. With p(v) = 1/N_active on the viewpoints of C(v) > 0,
    // p(t) = p(v)·S(t) and p(v|t) = p(v) p(t|v) / p(t) = p(t|v) / S(t), S(t) = Σ_v p(t|v).
    std::vector<std::uint64_t> total(n, 0);
    for (std::uint32_t t : triangles) {
      const std::uint8_t* vis = visible.data() + std::size_t{t} * n;
      for (std::size_t v = 0; v < n; ++v) total[v] += vis[v];
    }
    std::size_t active = 0;
    for (std::uint64_t c : total) active += c > 0 ? 1 : 0;
    visibility_state s;
    s.n_ = n;
    s.p_.assign(m, 0.0);
    s.output_.assign(n, 0.0);
    if (active == 0) {  // nothing of the set is seen from anywhere: one class, all alike
      s.rows_.assign(m * n, 0.0f);
      s.all_alike_ = true;
      s.rep_.assign(m, 0);
      s.entropy_.assign(m, 0.0);
      return s;
    }
    const double pv = 1.0 / static_cast<double>(active);
    std::vector<double> inv_total(n, 0.0);  // 1 / C(v), 0 where C(v) = 0
    for (std::size_t v = 0; v < n; ++v)
      if (total[v] > 0) {
        s.output_[v] = pv;
        inv_total[v] = 1.0 / static_cast<double>(total[v]);
      }
    // 1 / S(t) per row; the rows themselves are written once, denoised or not.
    std::vector<double> inv_sum(m, 0.0);
    for (std::size_t i = 0; i < m; ++i) {
      const std::uint8_t* vis = visible.data() + std::size_t{triangles[i]} * n;
      double lane[4] = {};  // S(t) in 4 independent sums (a serial sum is latency-bound)
      std::size_t v = 0;
      for (; v + 4 <= n; v += 4)
        for (std::size_t l = 0; l < 4; ++l) lane[l] += static_cast<double>(vis[v + l]) * inv_total[v + l];
      for (; v < n; ++v) lane[0] += static_cast<double>(vis[v]) * inv_total[v];
      const double sum = (lane[0] + lane[1]) + (lane[2] + lane[3]);
      s.p_[i] = pv * sum;
      if (sum > 0.0) inv_sum[i] = 1.0 / sum;
    }
    if (denoise && threshold > 0.0) {
      denoise_rows(triangles, inv_total, inv_sum, s);
    } else {
      std::vector<float> row(n);
      s.rows_.reserve(m * n);  // appended row by row: no M×N zero fill first
      for (std::size_t i = 0; i < m; ++i) {
        raw_row(triangles[i], inv_total, inv_sum[i], row.data());
        s.rows_.insert(s.rows_.end(), row.begin(), row.end());
      }
    }
    s.find_representatives();
    s.all_alike_ = std::all_of(s.rep_.begin(), s.rep_.end(), [](std::uint32_t r) { return r == 0; });
    return s;
  }

 private:
  // p(v|t) of mesh triangle t from its counts, with inv_sum = 1 / S(t) (0 where S(t) = 0): the
  // same bits wherever it is computed. O(N), no allocation.
  void raw_row(std::uint32_t t, std::span<const double> inv_total, double inv_sum, float* out) const {
    const std::uint8_t* vis = visible.data() + std::size_t{t} * viewpoints;
    for (std::size_t v = 0; v < viewpoints; ++v) out[v] = static_cast<float>(static_cast<double>(vis[v]) * inv_total[v] * inv_sum);
  }

  // §3.2.1: p(Y|t) <- mean of p(Y|t') over t' in {t} ∪ {edge neighbours in the set, JS <= Th},
  // all rows as raw_row writes them from the visible counts (a neighbour costs its N bytes of
  // counts, not a 4N-byte row kept in an M×N buffer). The tests go through
  // visibility_state::within, whose bound mostly decides without JS.
  void denoise_rows(std::span<const std::uint32_t> triangles, std::span<const double> inv_total,
                    std::span<const double> inv_sum, visibility_state& s) const {
    const std::size_t m = triangles.size(), n = viewpoints, nt = neighbour_offsets.size() - 1;
    // Local id of a mesh triangle: a table when the set is a large part of the mesh, else a
    // binary search in (global, local) pairs.
    std::vector<std::uint32_t> table;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> sorted;
    if (8 * m >= nt) {
      table.assign(nt, invalid_id);
      for (std::size_t i = 0; i < m; ++i) table[triangles[i]] = static_cast<std::uint32_t>(i);
    } else {
      sorted.resize(m);
      for (std::size_t i = 0; i < m; ++i) sorted[i] = {triangles[i], static_cast<std::uint32_t>(i)};
      std::sort(sorted.begin(), sorted.end());
    }
    auto local_of = [&](std::uint32_t t) {
      if (!table.empty()) return table[t];
      const auto it = std::lower_bound(sorted.begin(), sorted.end(), std::pair{t, 0u});
      return it != sorted.end() && it->first == t ? it->second : invalid_id;
    };
    s.rows_.reserve(m * n);  // appended row by row: no M×N zero fill first
    std::vector<float> rows;  // row i, then the accepted neighbours' rows (and one being tested)
    std::vector<float> out(n);
    for (std::uint32_t i = 0; i < m; ++i) {
      const std::uint32_t g = triangles[i];
      // The neighbours' counts are far apart in memory: ask for those of a triangle a few
      // iterations ahead.
      if (constexpr std::uint32_t ahead = 4; i + ahead < m) {
        const std::uint32_t h = triangles[i + ahead];
        for (std::uint32_t k = neighbour_offsets[h]; k < neighbour_offsets[h + 1]; ++k)
          detail::prefetch_bytes(visible.data() + std::size_t{neighbours[k]} * n, n);
      }
      if (s.unseen(i)) {  // stays 0
        s.rows_.insert(s.rows_.end(), n, 0.0f);
        continue;
      }
      const std::size_t degree = neighbour_offsets[g + 1] - neighbour_offsets[g];
      if (rows.size() < (degree + 1) * n) rows.resize((degree + 1) * n);
      raw_row(g, inv_total, inv_sum[i], rows.data());
      std::size_t count = 1;
      for (std::uint32_t k = neighbour_offsets[g]; k < neighbour_offsets[g + 1]; ++k) {
        const std::uint32_t j = local_of(neighbours[k]);
        if (j == invalid_id || s.unseen(j)) continue;
        float* rj = rows.data() + count * n;
        raw_row(neighbours[k], inv_total, inv_sum[j], rj);
        if (visibility_state::within({rows.data(), n}, {rj, n}, s.p_[i], s.p_[j], threshold)) ++count;
      }
      // The sum in double, rows in order, 8 entries at a time in registers; then / count, by a
      // power of two as a product by its inverse (the same bits, no division).
      const auto c = static_cast<double>(count);
      const bool pow2 = (count & (count - 1)) == 0;
      const double inv = 1.0 / c;
      auto mean = [&](std::size_t v, std::size_t lanes) {
        double a[8];
        for (std::size_t l = 0; l < lanes; ++l) a[l] = rows[v + l];
        for (std::size_t k = 1; k < count; ++k)
          for (std::size_t l = 0; l < lanes; ++l) a[l] += rows[k * n + v + l];
        for (std::size_t l = 0; l < lanes; ++l) out[v + l] = static_cast<float>(pow2 ? a[l] * inv : a[l] / c);
      };
      std::size_t v = 0;
      for (; v + 8 <= n; v += 8) mean(v, 8);
      if (v < n) mean(v, n - v);
      s.rows_.insert(s.rows_.end(), out.begin(), out.end());
    }
  }
};

struct visibility_channel {
  double threshold = 0.48;             // JS threshold Th in [0,1]
  std::uint32_t viewpoints = 64;       // N viewpoints on the bounding sphere (1..2^20, 24 bytes of
                                       // points each; T·N <= 2^28: the counts stay under 256 MiB)
  std::uint32_t samples_per_side = 2;  // n: n² stratified samples per triangle (1..15)
  double radius_scale = 1.0;           // sphere radius in half bounding-box diagonals (>= 1)
  bool denoise = true;                 // §3.2.1 row denoising
  std::size_t grain = 64;              // triangles per parallel task
  // Called on the calling thread between waves of tasks with (triangles done, total).
  std::function<void(std::size_t, std::size_t)> progress = {};
  // Exact savings: the counts (and so every result) stay bit-identical to the plain tracing.
  //   coherent    triangles are traced in Morton order of their centroids (chunks of `grain`),
  //               and each chunk's rays are grouped by viewpoint, so the tracer's batch call gets
  //               runs of nearly parallel rays from close origins (packet and stream tracers gain).
  //               Exact for any tracer whose answer for a ray does not depend on its batch mates.
  //   cull_hull   rays beyond a supporting plane of the mesh's convex hull are counted free
  //               without tracing: every ray from a triangle lying on the hull toward a viewpoint
  //               it faces (the sample offset lifts the origin off that plane). Exact when the
  //               tracer's scene holds nothing outside the convex hull of m's vertices and the
  //               tracer finds no hit on a segment farther than 2⁻¹⁸ of the largest coordinate
  //               magnitude from every triangle (Embree's robust mode; rays closer are traced).
  //               With other geometry around the mesh, leave it off.
  bool coherent = false;
  bool cull_hull = false;
  // Approximate saving (adaptive sampling): with adaptive_probes = P in 1..n²−1, each
  // (triangle, viewpoint) first traces P probe samples spread over its n² (indices ⌊j·n²/P⌋);
  // when every probe faces the viewpoint and all are free (or all occluded), the other samples
  // are counted the same without tracing (free ones only where they face it); otherwise they
  // are traced. Rule: agreement of the probes alone (see adaptive_neighbours for the stricter rule).
  // Error: an entry is wrong only where a shadow or silhouette edge crosses the triangle
  // between probes, by at most (n² − P)/n² of OR; benchmarks/NOTES.md has the measured JS and
  // ARI. 0 (or P >= n²) traces every sample. Implies the grouped path (as with coherent).
  std::uint32_t adaptive_probes = 0;
  // Neighbour rule for adaptive_probes: the rest of (t, v) is skipped only when t's probes agree
  // and every edge neighbour's probes toward v agree the same way (all faced and free, or all
  // faced and occluded); otherwise traced. All probes are traced first (a second pass traces the
  // rest), holding one verdict byte per (triangle, viewpoint): T·N bytes more.
  // Error: every pair traced by the probe rule alone is traced here too, so each entry is exact
  // or equals the probe rule's (off by at most (n² − P)/n² of OR), and no more entries are wrong
  // than with probes alone; benchmarks/NOTES.md has the measured JS and ARI.
  bool adaptive_neighbours = false;
  // The paper's measurement (cluster/visibility_images.hpp): with images = true, OR(t, v) =
  // min(1, a/u) from one image_resolution² image of primary rays per viewpoint, stored as
  // round(255·OR) (error ≤ 1/510 from rounding). Triangles projecting to fewer than
  // image_min_pixels pixels, or not wholly in the view, use the n² sample rays. The mesh must be
  // geometry 0 of the tracer's scene. Not combinable with cull_hull or adaptive_probes
  // (coherent has no effect: rays already go viewpoint by viewpoint).
  bool images = false;
  std::uint32_t image_resolution = 512;  // 1..16384
  double image_min_pixels = 4.0;         // >= 0

  // The viewpoints and samples this configuration uses for mesh m.
  template <class M>
  visibility_setup setup(const M& m) const {
    const bounding_box box = mesh_bounds(m);
    const double radius = 0.5 * box.diagonal();
    return {fibonacci_sphere(viewpoints, box.center(), radius_scale * radius), stratified_triangle_samples(samples_per_side),
            1e-5 * radius};
  }

  static constexpr std::size_t max_visibility_entries = std::size_t{1} << 28;  // T·N bound (bytes of counts)
  static constexpr std::uint32_t max_viewpoints = std::uint32_t{1} << 20;       // N bound (points, per-viewpoint sums)

  // Traces the occlusion rays. Errors: viewpoints outside 1..2^20 or T·N above 2^28, samples_per_side outside 1..15,
  // radius_scale < 1 or NaN, and the image options (see images). Complexity O(T·N·n²) rays
  // (images: N·R² primary rays + n² per fallback triangle and viewpoint), allocation T·N bytes +
  // one ray buffer per task (+ T·N verdict bytes with adaptive_neighbours; + V points and
  // T doubles and T bytes per task with images). Thread-safety: the tracer is called
  // concurrently from the executor's threads.
  template <class M, class T, class E>
  result<prepared_visibility_channel> prepare(const M& m, const mesh_topology& topo, const T& tr, E& exec) const {
    static_assert(check_mesh<M>());
    static_assert(check_tracer<T>());
    static_assert(check_executor<std::remove_cvref_t<E>>());
    if (viewpoints == 0 || viewpoints > max_viewpoints)
      return make_error(errc::bad_parameter, no_element, "visibility channel: viewpoints ", viewpoints, " outside 1..2^20");
    if (std::size_t{viewpoints} * mesh_triangle_count(m) > max_visibility_entries)
      return make_error(errc::bad_parameter, no_element, "visibility channel: ", viewpoints, " viewpoints x ",
                        mesh_triangle_count(m), " triangles exceed the 2^28 visibility counts");
    if (samples_per_side == 0 || samples_per_side > 15)
      return make_error(errc::bad_parameter, no_element, "visibility channel: samples_per_side ", samples_per_side,
                        " outside 1..15");
    if (!(radius_scale >= 1.0) || !std::isfinite(radius_scale))
      return make_error(errc::bad_parameter, no_element, "visibility channel: radius_scale ", radius_scale, " must be >= 1");
    if (images) {
      if (image_resolution == 0 || image_resolution > 16384)
        return make_error(errc::bad_parameter, no_element, "visibility channel: image_resolution ", image_resolution,
                          " outside 1..16384");
      if (!(image_min_pixels >= 0.0) || !std::isfinite(image_min_pixels))
        return make_error(errc::bad_parameter, no_element, "visibility channel: image_min_pixels ", image_min_pixels,
                          " must be finite and >= 0");
      if (cull_hull || (adaptive_probes > 0 && adaptive_probes < samples_per_side * samples_per_side))
        return make_error(errc::bad_parameter, no_element,
                          "visibility channel: images cannot be combined with cull_hull or adaptive_probes");
    }
    const std::size_t nt = mesh_triangle_count(m), nv = viewpoints;
    const visibility_setup su = setup(m);
    prepared_visibility_channel p;
    p.threshold = threshold;
    p.denoise = denoise;
    p.viewpoints = nv;
    p.samples = images ? 255u : static_cast<std::uint32_t>(su.samples.size());
    p.visible.assign(nt * nv, 0);
    p.neighbour_offsets = topo.neighbour_offsets;
    p.neighbours = topo.neighbours;
    if (images) {
      prepare_images(m, su, tr, exec, p);
      return p;
    }
    const std::size_t g = std::max<std::size_t>(grain, 1);
    const std::size_t ns = su.samples.size();
    const std::size_t probes = adaptive_probes < ns ? adaptive_probes : 0;
    const bool grouped = coherent || cull_hull || probes > 0;
    std::vector<std::uint8_t> probe_on(ns, 0), rest_on(ns, 1);
    for (std::size_t j = 0; j < probes; ++j) {
      probe_on[j * ns / probes] = 1;
      rest_on[j * ns / probes] = 0;
    }
    std::vector<std::uint32_t> order;  // triangles in tracing order (grouped only)
    if (coherent) {
      order = morton_triangle_order(m);
    } else if (grouped) {
      order.resize(nt);
      for (std::size_t t = 0; t < nt; ++t) order[t] = static_cast<std::uint32_t>(t);
    }
    const detail::visibility_hull hull = cull_hull ? detail::make_visibility_hull(m, su) : detail::visibility_hull{};
    // The neighbour rule runs the probes of every triangle first (phase 0), keeping their verdicts
    // (0 all occluded, 1 traced, 2 all free) per (triangle, viewpoint), then the rest (phase 1).
    const bool two_phases = probes > 0 && adaptive_neighbours;
    std::vector<std::uint8_t> verdict(two_phases ? nt * nv : 0);
    auto neighbour_verdict = [&](std::uint32_t t, std::size_t v) -> std::uint8_t {
      const std::uint8_t own = verdict[std::size_t{t} * nv + v];
      for (std::uint32_t k = p.neighbour_offsets[t]; own != 1 && k < p.neighbour_offsets[t + 1]; ++k)
        if (verdict[std::size_t{p.neighbours[k]} * nv + v] != own) return 1;
      return own;
    };
    const std::size_t chunks = chunk_count(nt, g), per_wave = 64, phases = two_phases ? 2 : 1;
    for (std::size_t phase = 0; phase < phases; ++phase)
    for (std::size_t w0 = 0; w0 < chunks; w0 += per_wave) {
      const std::size_t w1 = std::min(chunks, w0 + per_wave);
      exec.parallel_for(w1 - w0, 1, [&](std::size_t cb, std::size_t ce) {
        std::vector<ray> rays;
        std::vector<std::uint32_t> slots;
        std::vector<std::uint8_t> hit;
        std::vector<std::uint32_t> free_slots;
        std::vector<glm::dvec3> scratch;
        std::vector<std::uint8_t> faced, free_probes, mode;  // adaptive sampling, per slot
        for (std::size_t c = w0 + cb; c < w0 + ce; ++c) {
          const auto [first, last] = chunk_at(nt, g, c);
          rays.clear();
          slots.clear();
          if (!grouped) {
            detail::make_visibility_rays(m, su, first, last, rays, slots);
            hit.resize(rays.size());
            trace_occluded(tr, std::span<const ray>(rays), std::span<std::uint8_t>(hit));
            std::uint8_t* out = p.visible.data() + first * nv;
            for (std::size_t r = 0; r < rays.size(); ++r) if (!hit[r]) ++out[slots[r]];
            continue;
          }
          free_slots.clear();
          const std::span<const std::uint32_t> tris(order.data() + first, last - first);
          auto count = [&](std::uint32_t slot) { ++p.visible[std::size_t{tris[slot / nv]} * nv + slot % nv]; };
          const detail::visibility_hull* h = cull_hull ? &hull : nullptr;
          if (probes > 0 && phase == 1) {  // the rest where the probes or the neighbours' disagree
            mode.resize(tris.size() * nv);
            for (std::size_t q = 0; q < mode.size(); ++q) mode[q] = neighbour_verdict(tris[q / nv], q % nv);
            detail::make_grouped_visibility_rays(m, su, tris, coherent, h, scratch, rays, slots, free_slots, rest_on, mode);
          } else if (probes > 0) {  // the probes, then the rest where they disagree
            detail::make_grouped_visibility_rays(m, su, tris, coherent, h, scratch, rays, slots, free_slots, probe_on);
            hit.resize(rays.size());
            trace_occluded(tr, std::span<const ray>(rays), std::span<std::uint8_t>(hit));
            faced.assign(tris.size() * nv, 0);
            free_probes.assign(tris.size() * nv, 0);
            for (std::size_t r = 0; r < rays.size(); ++r) {
              ++faced[slots[r]];
              if (!hit[r]) ++free_probes[slots[r]];
            }
            for (std::uint32_t slot : free_slots) ++faced[slot], ++free_probes[slot];
            mode.resize(faced.size());
            for (std::size_t q = 0; q < faced.size(); ++q) {
              const auto slot = static_cast<std::uint32_t>(q);
              for (std::uint8_t f = 0; f < free_probes[q]; ++f) count(slot);
              mode[q] = faced[q] < probes ? 1 : free_probes[q] == probes ? 2 : free_probes[q] == 0 ? 0 : 1;
              if (two_phases) verdict[std::size_t{tris[q / nv]} * nv + q % nv] = mode[q];
            }
            if (two_phases) continue;
            rays.clear();
            slots.clear();
            free_slots.clear();
            detail::make_grouped_visibility_rays(m, su, tris, coherent, h, scratch, rays, slots, free_slots, rest_on, mode);
          } else {
            detail::make_grouped_visibility_rays(m, su, tris, coherent, h, scratch, rays, slots, free_slots);
          }
          hit.resize(rays.size());
          trace_occluded(tr, std::span<const ray>(rays), std::span<std::uint8_t>(hit));
          for (std::size_t r = 0; r < rays.size(); ++r) if (!hit[r]) count(slots[r]);
          for (std::uint32_t slot : free_slots) count(slot);
        }
      });
      if (progress) progress((phase * nt + std::min(nt, w1 * g)) / phases, nt);
    }
    return p;
  }

 private:
  // Option `images`: viewpoints in parallel (one task each, waves of 8 between progress calls),
  // each writing only its own column of counts.
  template <class M, class T, class E>
  void prepare_images(const M& m, const visibility_setup& su, const T& tr, E& exec, prepared_visibility_channel& p) const {
    const std::size_t nt = mesh_triangle_count(m), nv = su.viewpoints.size(), per_wave = 8;
    const bounding_box box = mesh_bounds(m);
    std::vector<glm::dvec3> points(mesh_vertex_count(m));
    for (std::size_t i = 0; i < points.size(); ++i) points[i] = glm::dvec3(mesh_position(m, i));
    for (std::size_t w0 = 0; w0 < nv; w0 += per_wave) {
      const std::size_t w1 = std::min(nv, w0 + per_wave);
      exec.parallel_for(w1 - w0, 1, [&](std::size_t vb, std::size_t ve) {
        for (std::size_t v = w0 + vb; v < w0 + ve; ++v)
          detail::image_occlusion_ratios(m, tr, su.viewpoints[v], box, points, image_resolution, image_min_pixels, su.samples,
                                         su.offset, 255.0, p.visible.data() + v, nv);
      });
      if (progress) progress(nt * w1 / nv, nt);
    }
  }
};

}  // namespace infolerp
