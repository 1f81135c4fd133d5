#pragma once
// Entropy, conditional entropy, mutual information of an information channel X → Y, and the
// per-element mutual information I(x;Y) (Cover & Thomas ch. 2; clustering paper §3.1 and
// §3.2.2, where the element with the minimum I(x;Y), the most representative, becomes the
// first seed). All in bits.
//
// A channel is given as p(x) (size X) and its rows p(Y|x), row-major (size X·Y).
// Robust forms only: every quantity is a sum of per-term contributions p·log₂(p/q) in double,
// never a difference of entropies such as H(Y) − H(Y|X) (which cancels and can go negative);
// results are clamped at 0, zero probabilities contribute 0, nothing returns NaN.
//
// Unchecked kernels (noexcept, for inner loops) take normalised, finite, non-negative input.
// The checked_* variants take user data: they validate it and normalise p(x) and every row
// with p(x) > 0 by its sum. Errors: empty input (empty_input); rows.size() not a multiple of
// p(x).size() (bad_size); NaN/Inf (non_finite) or negative entries (bad_distribution), with
// element() = the offending index into p(x) or rows; an all-zero p(x), or an all-zero row
// whose p(x) > 0 (bad_distribution, element() = the row). All-zero rows with p(x) == 0 are
// allowed (I(x;Y) = 0 for them).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>
#include "infolerp/core/status.hpp"
#include "infolerp/info/jensen_shannon.hpp"
#include "infolerp/info/log2.hpp"

namespace infolerp {

// H(p) = −Σ p log₂ p. Preconditions: entries finite, >= 0, summing to 1. O(n), no allocation.
inline double entropy(std::span<const double> p) noexcept {
  double sum = 0.0;
  for (double v : p)
    if (v > 0.0) sum -= v * detail::log2_accurate(v);
  return std::max(sum, 0.0);
}

// I(x;Y) = Σ_y p(y|x) log₂(p(y|x)/p(y)): how much observing x tells about Y (KL divergence of
// the row from the output distribution). Preconditions: row and p_y normalised, same size,
// p_y(y) > 0 wherever row(y) > 0 (true when p_y is the channel's output distribution; bins
// where it fails are skipped). O(Y), no allocation. Vectorised (info/jensen_shannon.hpp's
// dispatch): each term p·log₂(p/q) as log2_accurate gives it, summed in 4 interleaved partial
// sums. A float row (the visibility channel stores its rows as floats) is read as doubles.
inline double element_mutual_information(std::span<const double> row, std::span<const double> p_y) noexcept {
  return detail::kl_kernel(row.data(), p_y.data(), std::min(row.size(), p_y.size()));
}
inline double element_mutual_information(std::span<const float> row, std::span<const double> p_y) noexcept {
  return detail::kl_kernel(row.data(), p_y.data(), std::min(row.size(), p_y.size()));
}

// A lower bound of element_mutual_information(row, p_y) without logarithms: each bin the
// kernel sums (p > 0, q > 0) has p·ln(p/q) >= p − q, so I(x;Y) >= log₂e·Σ(p − q) over those
// bins (the kernel's rounding, ~1e-15, is far inside the 1e-9 margin of the seed search that
// uses it, cluster/region_growing.hpp). Vectorised like element_mutual_information. O(Y), no
// allocation.
inline double mutual_information_lower_bound(std::span<const float> row, std::span<const double> p_y) noexcept {
  return detail::kl_lower_bound(row.data(), p_y.data(), std::min(row.size(), p_y.size()));
}

// p(y) = Σ_x p(x) p(y|x). Preconditions: rows.size() is a multiple of p_x.size() (>0).
// O(X·Y), allocates Y doubles.
inline std::vector<double> output_distribution(std::span<const double> p_x, std::span<const double> rows) {
  const std::size_t ny = p_x.empty() ? 0 : rows.size() / p_x.size();
  std::vector<double> p_y(ny, 0.0);
  for (std::size_t x = 0; x < p_x.size(); ++x)
    if (p_x[x] > 0.0)
      for (std::size_t y = 0; y < ny; ++y) p_y[y] += p_x[x] * rows[x * ny + y];
  return p_y;
}

// H(Y|X) = Σ_x p(x) H(Y|x). Preconditions as output_distribution, rows normalised.
// O(X·Y), no allocation.
inline double conditional_entropy(std::span<const double> p_x, std::span<const double> rows) noexcept {
  const std::size_t ny = p_x.empty() ? 0 : rows.size() / p_x.size();
  double sum = 0.0;
  for (std::size_t x = 0; x < p_x.size(); ++x)
    if (p_x[x] > 0.0) sum += p_x[x] * entropy(rows.subspan(x * ny, ny));
  return std::max(sum, 0.0);
}

// I(X;Y) = Σ_x p(x) I(x;Y). Preconditions as conditional_entropy. O(X·Y), allocates Y doubles.
inline double mutual_information(std::span<const double> p_x, std::span<const double> rows) {
  const std::vector<double> p_y = output_distribution(p_x, rows);
  const std::size_t ny = p_y.size();
  double sum = 0.0;
  for (std::size_t x = 0; x < p_x.size(); ++x)
    if (p_x[x] > 0.0) sum += p_x[x] * element_mutual_information(rows.subspan(x * ny, ny), p_y);
  return std::max(sum, 0.0);
}

namespace detail {
// A normalised copy of user data, or the error that explains why there is none.
inline result<std::vector<double>> normalised_copy(std::span<const double> x, const char* what, const char* name,
                                                   std::size_t index) {
  auto scale = check_distribution(x, what, name, index);
  if (!scale) return scale.error();
  std::vector<double> out(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) out[i] = x[i] * scale->pre * scale->inv;
  return out;
}
// Normalised copies of p(x) and of the rows (an all-zero row is an error only when p(x) > 0).
struct checked_channel {
  std::vector<double> p_x, rows;
};
inline result<checked_channel> check_channel(std::span<const double> p_x, std::span<const double> rows, const char* what) {
  auto px = normalised_copy(p_x, what, "p(x)", no_element);
  if (!px) return px.error();
  if (rows.empty() || rows.size() % p_x.size() != 0)
    return make_error(errc::bad_size, no_element, what, ": ", rows.size(), " row entries for ", p_x.size(),
                      " inputs (must be a positive multiple)");
  const std::size_t ny = rows.size() / p_x.size();
  checked_channel c{std::move(*px), std::vector<double>(rows.begin(), rows.end())};
  for (std::size_t x = 0; x < p_x.size(); ++x) {
    const auto row = rows.subspan(x * ny, ny);
    // A row with p(x) == 0 may be all zero (say, a triangle no viewpoint sees): kept as zeros.
    if (c.p_x[x] == 0.0 && std::all_of(row.begin(), row.end(), [](double v) { return v == 0.0; })) continue;
    auto normalised = normalised_copy(row, what, "row", x);
    if (!normalised) {
      const status& e = normalised.error();
      // Point element() into rows[] for bad entries, at the row for an all-zero row.
      return status(e.code(), e.message(), e.element() == no_element ? x : x * ny + e.element());
    }
    std::copy(normalised->begin(), normalised->end(), c.rows.begin() + static_cast<std::ptrdiff_t>(x * ny));
  }
  return c;
}
}  // namespace detail

// Checked variants for user data (see the header comment for errors). Allocation: normalised
// copies of the input (O(n) or O(X·Y)) plus the message on error.
inline result<double> checked_entropy(std::span<const double> p) {
  auto n = detail::normalised_copy(p, "entropy", "p", no_element);
  if (!n) return n.error();
  return entropy(*n);
}
inline result<double> checked_conditional_entropy(std::span<const double> p_x, std::span<const double> rows) {
  auto c = detail::check_channel(p_x, rows, "conditional_entropy");
  if (!c) return c.error();
  return conditional_entropy(c->p_x, c->rows);
}
inline result<double> checked_mutual_information(std::span<const double> p_x, std::span<const double> rows) {
  auto c = detail::check_channel(p_x, rows, "mutual_information");
  if (!c) return c.error();
  return mutual_information(c->p_x, c->rows);
}
// Per-element I(x;Y) for every x (the seed criterion of §3.2.2), from user data.
// O(X·Y), allocates the result and the normalised copies.
inline result<std::vector<double>> checked_element_mutual_information(std::span<const double> p_x,
                                                                      std::span<const double> rows) {
  auto c = detail::check_channel(p_x, rows, "element_mutual_information");
  if (!c) return c.error();
  const std::vector<double> p_y = output_distribution(c->p_x, c->rows);
  const std::size_t ny = p_y.size();
  std::vector<double> out(c->p_x.size(), 0.0);
  for (std::size_t x = 0; x < out.size(); ++x)
    out[x] = element_mutual_information(std::span<const double>(c->rows).subspan(x * ny, ny), p_y);
  return out;
}

}  // namespace infolerp
