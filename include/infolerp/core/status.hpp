#pragma once
// Status and result types: how every infolerp entry point reports bad input.
// The library throws nothing and builds with -fno-exceptions -fno-rtti; a failing entry point
// returns a status whose message names the offending element (triangle 17, bin 3, ...). The one
// exception it does not catch is the standard library's: built with exceptions, an allocation
// that fails (a status's message, a result's vectors) throws std::bad_alloc as any std::vector
// would; without them it terminates. Sizes that inputs or options control are bounded and refused
// with a status before allocating.
#include <cassert>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>

// Internal invariants (not input validation). Override before including any infolerp header.
#ifndef INFOLERP_ASSERT
#define INFOLERP_ASSERT(condition) assert(condition)
#endif

namespace infolerp {

// What went wrong. Input errors only; internal invariants use INFOLERP_ASSERT.
enum class errc : std::uint8_t {
  ok = 0,
  empty_input,          // no vertices, no triangles, no bins, zero viewpoints, 0x0 image ...
  bad_index_count,      // index count not a multiple of 3
  index_out_of_range,   // a triangle names a vertex that does not exist
  non_finite,           // NaN or Inf in positions, texcoords, distributions, distances
  degenerate_triangle,  // zero-area triangle, or repeated vertex index
  non_manifold_edge,    // an edge shared by more than two triangles
  bad_parameter,        // threshold outside [0,1], negative weight, bad option value
  bad_distribution,     // negative entries, all-zero row, mismatched lengths
  bad_size,             // buffer sizes that do not match
  unsupported,          // the input needs a capability the type does not offer
};

inline constexpr std::uint64_t no_element = ~std::uint64_t{0};
// The "none" value of 32-bit ids (triangles, clusters, edges).
inline constexpr std::uint32_t invalid_id = 0xffffffffu;

// A short English name of the code (static storage). O(1), no allocation, thread-safe.
inline constexpr const char* to_string(errc code) noexcept {
  switch (code) {
    case errc::ok: return "ok";
    case errc::empty_input: return "empty input";
    case errc::bad_index_count: return "index count not a multiple of 3";
    case errc::index_out_of_range: return "index out of range";
    case errc::non_finite: return "non-finite value";
    case errc::degenerate_triangle: return "degenerate triangle";
    case errc::non_manifold_edge: return "non-manifold edge";
    case errc::bad_parameter: return "bad parameter";
    case errc::bad_distribution: return "bad distribution";
    case errc::bad_size: return "bad size";
    case errc::unsupported: return "unsupported";
  }
  return "unknown";
}

// The outcome of an operation: ok, or an error code with a message and the offending element
// (a triangle, vertex, bin or pixel index; no_element when none applies).
// Allocation: the message string, only on error. Accessors O(1), no allocation; like any value
// type, safe to read from several threads, not to modify concurrently.
class [[nodiscard]] status {
 public:
  status() = default;
  status(errc code, std::string message, std::uint64_t element = no_element)
      : code_(code), element_(element), message_(std::move(message)) {}

  [[nodiscard]] bool ok() const noexcept { return code_ == errc::ok; }
  explicit operator bool() const noexcept { return ok(); }
  [[nodiscard]] errc code() const noexcept { return code_; }
  [[nodiscard]] std::uint64_t element() const noexcept { return element_; }
  [[nodiscard]] const std::string& message() const noexcept { return message_; }

 private:
  errc code_ = errc::ok;
  std::uint64_t element_ = no_element;
  std::string message_;
};

// A value or the status that explains why there is none (std::expected is C++23).
// Accessors O(1), no allocation; thread-safety as for T.
template <class T>
class [[nodiscard]] result {
 public:
  result(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  result(status error) : error_(std::move(error)) {  // NOLINT: implicit by design
    INFOLERP_ASSERT(!error_.ok() && "a result without a value needs an error status");
  }

  [[nodiscard]] bool ok() const noexcept { return value_.has_value(); }
  explicit operator bool() const noexcept { return ok(); }
  // Preconditions for the accessors below: ok().
  [[nodiscard]] T& value() & { INFOLERP_ASSERT(ok()); return *value_; }
  [[nodiscard]] const T& value() const& { INFOLERP_ASSERT(ok()); return *value_; }
  [[nodiscard]] T&& value() && { INFOLERP_ASSERT(ok()); return std::move(*value_); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  // The error; an ok status when the result holds a value.
  [[nodiscard]] const status& error() const noexcept { return error_; }

 private:
  std::optional<T> value_;
  status error_;
};

namespace detail {
// Builds messages without iostreams: text as is, integers in decimal, floating-point numbers
// in their shortest round-trip form (std::to_chars: 1e+300, 0.1, 5e-324, nan, inf).
inline void append_part(std::string& s, const char* part) { s += part; }
inline void append_part(std::string& s, const std::string& part) { s += part; }
template <class N>
  requires std::is_integral_v<N>
void append_part(std::string& s, N part) {
  s += std::to_string(part);
}
template <class N>
  requires std::is_floating_point_v<N>
void append_part(std::string& s, N part) {
  char text[64];  // the shortest form of a long double takes at most about 30 characters
  s.append(text, std::to_chars(text, text + sizeof text, part).ptr);
}
}  // namespace detail

// An error status with a message built from pieces, for example
//   make_error(errc::index_out_of_range, t, "triangle ", t, ": vertex ", v, " out of range")
// Complexity O(total message length). Allocation: the message string. Thread-safe.
template <class... Parts>
status make_error(errc code, std::uint64_t element, const Parts&... parts) {
  std::string message = "infolerp: ";
  (detail::append_part(message, parts), ...);
  return status(code, std::move(message), element);
}

// Input checks shared by the entry points. all_finite: every component of a GLM vector (any
// type with a static length() and operator[]) is finite. O(components).
template <class V>
  requires requires { V::length(); }
[[nodiscard]] bool all_finite(const V& v) {
  for (decltype(V::length()) i = 0; i < V::length(); ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}
// The code for a value that must be finite and >= 0 but is not: non_finite for NaN or ±Inf,
// bad_parameter for a finite negative value.
[[nodiscard]] inline errc non_negative_errc(double x) { return std::isfinite(x) ? errc::bad_parameter : errc::non_finite; }

}  // namespace infolerp
