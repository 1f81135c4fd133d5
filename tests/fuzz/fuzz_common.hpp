#pragma once
// Shared by the libFuzzer targets: a byte reader that consumes the input from the
// front (so seed files are easy to write by hand), a check macro that aborts (libFuzzer then
// saves the input), and a small-mesh decoder that can produce every kind of bad mesh.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <vector>
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/adaptors.hpp"

#define FUZZ_CHECK(condition)                                                                  \
  do {                                                                                         \
    if (!(condition)) {                                                                        \
      std::fprintf(stderr, "FUZZ_CHECK failed: %s (%s:%d)\n", #condition, __FILE__, __LINE__); \
      std::abort();                                                                            \
    }                                                                                          \
  } while (0)

namespace fuzz {

struct reader {
  const std::uint8_t* p;
  std::size_t n;

  [[nodiscard]] bool empty() const { return n == 0; }
  // The next sizeof(T) bytes (zero-padded at the end of the input).
  template <class T>
  T take() {
    unsigned char bytes[sizeof(T)] = {};
    const std::size_t k = std::min(sizeof(T), n);
    std::memcpy(bytes, p, k);
    p += k;
    n -= k;
    T v;
    std::memcpy(&v, bytes, sizeof v);
    return v;
  }
  std::uint8_t u8() { return take<std::uint8_t>(); }
  std::uint16_t u16() { return take<std::uint16_t>(); }
  std::uint32_t u32() { return take<std::uint32_t>(); }
  // A coordinate: a value on a 1/16 grid (coincident points, collinear triangles and slivers
  // are likely), or raw float bits after a 255 marker (NaN, Inf, subnormals, huge values).
  float coord() {
    const std::uint8_t s = u8();
    return s == 255 ? take<float>() : (static_cast<float>(s) - 127.0f) / 16.0f;
  }
  // A vertex index: small values (mostly in range), or a raw 32-bit value after a 255 marker.
  std::uint32_t index() {
    const std::uint8_t s = u8();
    return s == 255 ? u32() : s;
  }
  // A parameter in [0, 1] on a grid, or raw double bits (NaN, negative, huge) after 255.
  double unit() {
    const std::uint8_t s = u8();
    return s == 255 ? take<double>() : static_cast<double>(s) / 254.0;
  }
  // An option value of type double: a small value on a 1/32 grid in [-2, 5.97] (most in range),
  // one of the extremes after a 254 marker (NaN, ±Inf, ±max, the smallest subnormal, -0), or raw
  // double bits after a 255 marker.
  double real() {
    const std::uint8_t s = u8();
    if (s == 255) return take<double>();
    if (s == 254) {
      constexpr double lim[7] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                                 -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::max(),
                                 std::numeric_limits<double>::lowest(), std::numeric_limits<double>::denorm_min(), -0.0};
      return lim[u8() % 7];
    }
    return (static_cast<double>(s) - 64.0) / 32.0;
  }
  float real_f() {  // the same for a float member (saturated to ±Inf)
    const double x = real();
    if (std::isnan(x)) return std::numeric_limits<float>::quiet_NaN();
    if (x > std::numeric_limits<float>::max()) return std::numeric_limits<float>::infinity();
    if (x < std::numeric_limits<float>::lowest()) return -std::numeric_limits<float>::infinity();
    return static_cast<float>(x);
  }
  // A count option of unsigned type T: small values (0..253), the type's largest after 254, raw
  // bits after 255.
  template <class T>
  T count() {
    const std::uint8_t s = u8();
    if (s == 255) return take<T>();
    if (s == 254) return std::numeric_limits<T>::max();
    return static_cast<T>(s);
  }
};

// [vertex count][triangle count][scale exponent] then 3 coordinates per vertex and 3 indices
// per triangle. Counts are capped; a missing tail reads as zeros.
inline infolerp::indexed_mesh read_mesh(reader& r, std::size_t max_vertices, std::size_t max_triangles) {
  infolerp::indexed_mesh m;
  const std::size_t nv = r.u8() % (max_vertices + 1), nt = r.u8() % (max_triangles + 1);
  const float scale = std::ldexp(1.0f, static_cast<std::int8_t>(r.u8()));  // 2^-128 .. 2^127 (may overflow)
  m.positions.resize(nv);
  for (auto& p : m.positions) p = glm::vec3(r.coord(), r.coord(), r.coord()) * scale;
  m.triangles.resize(nt);
  for (auto& t : m.triangles) t = glm::uvec3(r.index(), r.index(), r.index());
  return m;
}

inline bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline bool all_finite(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}
inline bool indices_in_range(const infolerp::indexed_mesh& m) {
  for (const auto& t : m.triangles)
    if (t.x >= m.positions.size() || t.y >= m.positions.size() || t.z >= m.positions.size()) return false;
  return true;
}
// An error status must carry a message (naming the problem).
inline void check_error(const infolerp::status& s) {
  if (!s.ok()) FUZZ_CHECK(s.message().size() > 10);
}

}  // namespace fuzz
