#pragma once
// Information channels for clustering (clustering paper §3.1: input distribution p(X),
// transition rows p(Y|x), output distribution p(Y) by Eq. (1), per-element mutual information
// I(x;Y), and the similarity JS(Y|a,b) between two elements).
//
// Two layers, both concepts any user type can model:
//   channel_state  a channel initialised on one set of M elements (the triangles of one
//                  cluster, Algorithm 1's ch.init(cl)). Elements are grouped into classes:
//                  elements of one class have identical rows and input probability, so every
//                  divergence is asked per class (a planar patch is one class, a binned normal
//                  histogram has at most K). The simplest model is class_of(i) == i.
//   channel        what cluster_mesh receives: a `threshold` in [0,1] and
//                  init(span of triangle ids) -> result<channel_state>. A channel may also offer
//                  prepare(mesh, topology, tracer, executor) -> result<prepared channel>, run once
//                  per mesh before Algorithm 1 (normals, stretch, ray-traced visibility), and
//                  skip_reason() -> const char* (nullptr = active) to say it does not apply.
//
// Direct channels (T→T, §3.1.2–3.1.3) never build the M×M matrix: their rows are aggregated per
// class with direct_channel_state below.
#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>
#include "infolerp/core/status.hpp"
#include "infolerp/info/entropy.hpp"
#include "infolerp/info/jensen_shannon.hpp"
#include "infolerp/info/js_estimate.hpp"

namespace infolerp {

// A channel initialised on M elements (local ids 0..M-1) grouped into U classes.
//   element_count() -> M, class_count() -> U (1 <= U <= M when M > 0)
//   class_of(i) -> class of element i (< U)
//   mutual_information(c) -> I(x;Y) in bits for an element x of class c
//   divergence(a, b) -> JS(Y|a,b) in [0,1] between elements of classes a and b (symmetric, 0 for a == b)
// Optional, used when present:
//   divergences(a, first, out) -> out[i] = divergence(a, first + i), a batch that may share work
//   all_alike() -> bool: every row is identical (the clustering then skips all work)
//   surely_within(a, b, th) -> bool: a cheap test, true only if divergence(a, b) <= th − 2⁻²²
//       (false may mean either; the margin keeps the float JS columns of region growing on the
//       same side of th); growth then needs the exact JS only where two seeds claim an element
//   estimate(a, b) -> double and estimate_error() -> double: an estimate of divergence(a, b)
//       within ±estimate_error() (absolute; +inf when the state has none), much cheaper;
//       seeds, growth and boundary smoothing then evaluate divergence() only where the
//       estimate cannot decide their comparison (same results, see region_growing.hpp)
//   mutual_information_lower_bound(c) -> double: <= mutual_information(c) up to 1e-9; the first
//       seed then evaluates MI only for classes whose bound can reach the smallest MI
//   representative(c) -> class r <= c whose divergences to every class are bit-identical to
//       c's (r == c when none); JS columns and smoothing memos are then shared within a group
//   prefetch(c) -> void: a hint that class c's row is read soon (no effect on results); the
//       seed search and boundary smoothing call it a few classes ahead
// Thread-safety: const members are called concurrently from the executor's threads.
template <class S>
concept channel_state = requires(const S& s, std::uint32_t a, std::uint32_t b) {
  { s.element_count() } -> std::convertible_to<std::size_t>;
  { s.class_count() } -> std::convertible_to<std::size_t>;
  { s.class_of(a) } -> std::convertible_to<std::uint32_t>;
  { s.mutual_information(a) } -> std::convertible_to<double>;
  { s.divergence(a, b) } -> std::convertible_to<double>;
};

namespace detail {
template <class R> struct result_value {};
template <class T> struct result_value<result<T>> { using type = T; };
template <class R> using result_value_t = typename result_value<std::remove_cvref_t<R>>::type;
}  // namespace detail

// A channel ready to initialise on sets of triangles (global triangle ids).
template <class C>
concept channel = requires(const C& c, std::span<const std::uint32_t> triangles) {
  { c.threshold } -> std::convertible_to<double>;
  { c.init(triangles) };
  requires channel_state<detail::result_value_t<decltype(c.init(triangles))>>;
};

// The state type a channel's init produces.
template <channel C>
using channel_state_of = detail::result_value_t<decltype(std::declval<const C&>().init(
    std::declval<std::span<const std::uint32_t>>()))>;

// Checks a clustering threshold: finite and in [0, 1]. `what` names the channel in the message.
inline status check_threshold(double threshold, const char* what) {
  if (!(threshold >= 0.0 && threshold <= 1.0))  // also rejects NaN
    return make_error(errc::bad_parameter, no_element, what, ": threshold ", threshold,
                      " outside [0, 1] (or NaN)");
  return {};
}

// The paper's membership test "JS < Th", with Th = 1 meaning "everything is alike" (JS can reach
// exactly 1 for disjoint rows, and the paper wants Th = 1 to give one cluster).
inline bool is_similar(double js, double threshold) noexcept { return threshold >= 1.0 || js < threshold; }

namespace detail {
// Binned channels: the occupied cells of `cells` possible ones, numbered in ascending cell order.
// id[i] = the number of the element i's cell; returns the occupied count. A direct table when
// cells <= 4·M + 4096, otherwise a sort of the M cell numbers, so memory follows the cells in
// use and never the option value: O(M + min(cells, 4·M + 4096)) time (O(M log M) when sorting),
// allocation O(M + min(cells, 4·M + 4096)).
inline std::uint32_t number_occupied_cells(std::span<const std::uint32_t> cell, std::size_t cells,
                                           std::vector<std::uint32_t>& id) {
  id.resize(cell.size());
  std::uint32_t u = 0;
  if (cells <= 4 * cell.size() + 4096) {
    std::vector<std::uint32_t> number(cells, invalid_id);
    for (std::uint32_t c : cell) number[c] = 0;
    for (auto& c : number)
      if (c != invalid_id) c = u++;
    for (std::size_t i = 0; i < cell.size(); ++i) id[i] = number[cell[i]];
    return u;
  }
  std::vector<std::uint32_t> used(cell.begin(), cell.end());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  for (std::size_t i = 0; i < cell.size(); ++i)
    id[i] = static_cast<std::uint32_t>(std::lower_bound(used.begin(), used.end(), cell[i]) - used.begin());
  return static_cast<std::uint32_t>(used.size());
}
}  // namespace detail

// A direct channel (T→T) aggregated over classes. Rows are asked per row class a (elements
// with identical rows); their entries are per column c, a group of output elements:
//   row_a(c) = mass(a, c) / Σ_c' mass(a, c')      (mass = summed kernel over c's elements)
// Exact channels use the row classes as columns: the M-entry row is constant inside each class,
// and JS over the M-entry rows equals js_divergence over these U-entry rows exactly (each JS
// term is homogeneous in the entry). Binned channels use C cells as columns: the channel to the
// cells, whose JS is at most the exact one (data-processing inequality). Input probabilities
// are uniform (1/M), so JS weights are ½.
// A row whose masses are all 0 (e.g. a planar patch under orientation: 1 − n·n' = 0
// everywhere) is taken as the column sizes over M, so all such rows are alike.
//
// Kernel requirements: class_count() (U row classes), count(a) (elements in row class a, as
//   double), column_count() (C), column_size(c) (elements in column c), mass(a, c) >= 0,
//   total(a) = Σ_c mass(a, c).
// Allocation: U·C doubles and U·C floats at construction when U·C <= max_stored_entries (65,536:
// 768 KB): the rows built for Eq. (1) are kept (with a float copy and U entropy estimates for
// estimate()) and divergence(), divergences() and mutual_information() read them without
// allocating; above that O(U + C), there is no estimate, and those build their rows in up to
// 2C doubles per call (small next to the O(C) work of building a row; no state is kept between
// calls).
// Thread-safe for concurrent const calls.
template <class Kernel>
class direct_channel_state {
 public:
  direct_channel_state(std::vector<std::uint32_t> class_of, Kernel kernel)
      : class_of_(std::move(class_of)), kernel_(std::move(kernel)) {
    const std::size_t u = kernel_.class_count(), c = kernel_.column_count();
    output_.assign(c, 0.0);
    if (u * c <= max_stored_entries) rows_.resize(u * c);
    std::vector<double> scratch_row(rows_.empty() ? c : 0);
    if (!rows_.empty()) {
      entropy_.resize(u);
      rows_f_.resize(u * c);
    }
    const double m = static_cast<double>(class_of_.size());
    // Eq. (1): p(c) = Σ_a p(a) row_a(c), p(a) = count(a)/M.  O(U·C).
    for (std::uint32_t a = 0; a < u; ++a) {
      const std::span<double> r = rows_.empty() ? std::span<double>(scratch_row) : std::span<double>(rows_.data() + a * c, c);
      row(a, r);
      if (!entropy_.empty()) {
        for (std::size_t j = 0; j < c; ++j) rows_f_[a * c + j] = static_cast<float>(r[j]);
        entropy_[a] = entropy_estimate(rows_f_.data() + a * c, c);
      }
      const double w = kernel_.count(a) / m;
      for (std::size_t j = 0; j < c; ++j) output_[j] += w * r[j];
    }
  }
  // Up to this many row entries (U·C) the rows built for Eq. (1) are kept (768 KB at most, with
  // their float copy).
  static constexpr std::size_t max_stored_entries = 256 * 256;

  std::size_t element_count() const { return class_of_.size(); }
  std::size_t class_count() const { return kernel_.class_count(); }
  std::uint32_t class_of(std::uint32_t i) const { return class_of_[i]; }
  bool all_alike() const { return class_count() <= 1; }
  const Kernel& kernel() const { return kernel_; }
  std::span<const double> output_distribution() const { return output_; }

  // p(Y|a) per column. Preconditions: out.size() == column_count(). O(C), no allocation.
  void row(std::uint32_t a, std::span<double> out) const {
    const double total = kernel_.total(a);
    const double m = static_cast<double>(class_of_.size());
    if (total > 0.0) {
      for (std::uint32_t c = 0; c < out.size(); ++c) out[c] = kernel_.mass(a, c) / total;
    } else {
      for (std::uint32_t c = 0; c < out.size(); ++c) out[c] = kernel_.column_size(c) / m;
    }
  }

  double mutual_information(std::uint32_t a) const {
    std::vector<double> buf;
    return element_mutual_information(row_of(a, buf), output_);
  }

  // Pinsker's inequality, I(x;Y) = KL(row ‖ p(Y)) >= ‖row − p(Y)‖₁² / (2 ln 2) bits, without
  // logarithms, when the rows are stored (else 0, which bounds nothing). O(C), no allocation.
  double mutual_information_lower_bound(std::uint32_t a) const {
    if (rows_.empty()) return 0.0;
    const std::size_t c = kernel_.column_count();
    const double* r = rows_.data() + a * c;
    double l1 = 0.0;
    for (std::size_t j = 0; j < c; ++j) l1 += std::abs(r[j] - output_[j]);
    return l1 * l1 * (0.5 / std::numbers::ln2) * (1.0 - 1e-12);
  }

  double divergence(std::uint32_t a, std::uint32_t b) const {
    if (a == b) return 0.0;
    std::vector<double> buf_a, buf_b;
    return js_divergence(row_of(a, buf_a), row_of(b, buf_b), 0.5);
  }

  // Within estimate_error() of divergence(a, b) (info/js_estimate.hpp) when the rows are
  // stored; estimate_error() is +inf otherwise. O(C), no allocation.
  double estimate(std::uint32_t a, std::uint32_t b) const {
    if (a == b || entropy_.empty()) return 0.0;
    const std::size_t c = kernel_.column_count();
    return js_estimate(rows_f_.data() + a * c, rows_f_.data() + b * c, c, 0.5, entropy_[a], entropy_[b]);
  }
  double estimate_error() const {
    return entropy_.empty() ? std::numeric_limits<double>::infinity() : js_estimate_error(kernel_.column_count());
  }

  // out[i] = divergence(a, first + i); the row of a is built once. O(C·out.size()).
  void divergences(std::uint32_t a, std::uint32_t first, std::span<float> out) const {
    std::vector<double> buf_a, buf_b;
    const std::span<const double> ra = row_of(a, buf_a);
    for (std::size_t i = 0; i < out.size(); ++i) {
      const auto b = static_cast<std::uint32_t>(first + i);
      if (b == a) {
        out[i] = 0.0f;
        continue;
      }
      out[i] = static_cast<float>(js_divergence(ra, row_of(b, buf_b), 0.5));
    }
  }

 private:
  // The row of class a: stored, or built into buf (resized to C on first use).
  std::span<const double> row_of(std::uint32_t a, std::vector<double>& buf) const {
    const std::size_t c = kernel_.column_count();
    if (!rows_.empty()) return {rows_.data() + a * c, c};
    buf.resize(c);
    row(a, buf);
    return buf;
  }

  std::vector<std::uint32_t> class_of_;
  Kernel kernel_;
  std::vector<double> output_;
  std::vector<double> rows_;  // U × C when U·C <= max_stored_entries, else empty
  std::vector<float> rows_f_;    // rows_ rounded to float, read by estimate() (empty without rows_)
  std::vector<double> entropy_;  // entropy_estimate of each row of rows_f_ (empty without rows_)
};

}  // namespace infolerp
