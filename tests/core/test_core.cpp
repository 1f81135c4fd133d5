// core/: status and result, the CSR counting sort, mesh traits and concepts, tracer and executor concepts.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <array>
#include <atomic>
#include <cstdint>
#include <limits>
#include <numeric>
#include <vector>
#include "infolerp/core/detail/csr.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/core/large_buffer.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/core/unit_vector.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "support/thread_pool.hpp"

namespace {
// A user mesh with different member names, adapted by specialising mesh_traits.
struct engine_mesh {
  std::vector<float> xyz;
  std::vector<std::uint16_t> idx;
};
struct missing_position {
  std::size_t vertex_count() const { return 0; }
  std::size_t triangle_count() const { return 0; }
  glm::uvec3 triangle(std::size_t) const { return {}; }
};
struct user_tracer {
  bool occluded(const infolerp::ray& r) const { return r.direction.z < 0; }
  infolerp::hit intersect(const infolerp::ray&) const { return {}; }
};
struct batch_tracer : user_tracer {
  using user_tracer::intersect;
  using user_tracer::occluded;
  mutable int batches = 0;
  void occluded(std::span<const infolerp::ray> rays, std::span<std::uint8_t> out) const {
    ++batches;
    for (std::size_t i = 0; i < rays.size(); ++i) out[i] = occluded(rays[i]) ? 1 : 0;
  }
};
}  // namespace

template <>
struct infolerp::mesh_traits<engine_mesh> {
  static std::size_t vertex_count(const engine_mesh& m) { return m.xyz.size() / 3; }
  static std::size_t triangle_count(const engine_mesh& m) { return m.idx.size() / 3; }
  static glm::vec3 position(const engine_mesh& m, std::size_t v) { return {m.xyz[3 * v], m.xyz[3 * v + 1], m.xyz[3 * v + 2]}; }
  static glm::uvec3 triangle(const engine_mesh& m, std::size_t t) { return {m.idx[3 * t], m.idx[3 * t + 1], m.idx[3 * t + 2]}; }
};

TEST_CASE("status and result carry the error and the element") {
  const infolerp::status ok;
  CHECK(ok.ok());
  const auto bad = infolerp::make_error(infolerp::errc::index_out_of_range, 17, "triangle ", 17, ": vertex ", 9u);
  CHECK_FALSE(bad.ok());
  CHECK(bad.code() == infolerp::errc::index_out_of_range);
  CHECK(bad.element() == 17);
  CHECK(bad.message() == "infolerp: triangle 17: vertex 9");
  infolerp::result<int> r = 5;
  REQUIRE(r.ok());
  CHECK(*r == 5);
  infolerp::result<int> e = bad;
  CHECK_FALSE(e.ok());
  CHECK(e.error().message() == bad.message());
  CHECK(std::string(infolerp::to_string(infolerp::errc::non_finite)) == "non-finite value");
  // Floating-point numbers in their shortest round-trip form, neither 300 digits nor 0.000000.
  const auto text = [](auto x) { return infolerp::make_error(infolerp::errc::bad_parameter, 0, "epsilon ", x).message(); };
  CHECK(text(1e300) == "infolerp: epsilon 1e+300");
  CHECK(text(1e-20) == "infolerp: epsilon 1e-20");
  CHECK(text(0.1) == "infolerp: epsilon 0.1");
  CHECK(text(0.1f) == "infolerp: epsilon 0.1");
  CHECK(text(-2.5) == "infolerp: epsilon -2.5");
  CHECK(text(std::numeric_limits<double>::denorm_min()) == "infolerp: epsilon 5e-324");
  CHECK(text(std::numeric_limits<double>::infinity()) == "infolerp: epsilon inf");
  CHECK(text(std::numeric_limits<double>::quiet_NaN()) == "infolerp: epsilon nan");
  CHECK(text(std::numeric_limits<long double>::max()).size() < 18 + 32);  // "infolerp: epsilon " + the number
}

TEST_CASE("mesh concepts: members, traits specialisation, optional capabilities") {
  STATIC_REQUIRE(infolerp::mesh<infolerp::indexed_mesh>);
  STATIC_REQUIRE(infolerp::textured_mesh<infolerp::indexed_mesh>);
  STATIC_REQUIRE(infolerp::keyframed_mesh<infolerp::indexed_mesh>);
  STATIC_REQUIRE(infolerp::mesh<infolerp::mesh_view>);
  STATIC_REQUIRE_FALSE(infolerp::keyframed_mesh<infolerp::mesh_view>);
  STATIC_REQUIRE(infolerp::mesh<infolerp::strided_mesh_view>);
  STATIC_REQUIRE_FALSE(infolerp::textured_mesh<infolerp::strided_mesh_view>);
  STATIC_REQUIRE(infolerp::mesh<engine_mesh>);
  STATIC_REQUIRE_FALSE(infolerp::textured_mesh<engine_mesh>);
  STATIC_REQUIRE_FALSE(infolerp::mesh<missing_position>);
  STATIC_REQUIRE_FALSE(infolerp::mesh<int>);

  const engine_mesh em{{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2}};
  CHECK(infolerp::mesh_vertex_count(em) == 3);
  CHECK(infolerp::mesh_position(em, 1) == glm::vec3(1, 0, 0));
  CHECK(infolerp::mesh_triangle(em, 0) == glm::uvec3(0, 1, 2));
  CHECK_FALSE(infolerp::mesh_has_texcoords(em));

  infolerp::indexed_mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}};
  CHECK_FALSE(infolerp::mesh_has_texcoords(m));  // the type could, this instance does not
  m.texcoords = {{0, 0}, {1, 0}, {0, 1}};
  CHECK(infolerp::mesh_has_texcoords(m));
  CHECK(infolerp::mesh_traits<infolerp::indexed_mesh>::texcoord(m, 0, 2) == glm::vec2(0, 1));
  CHECK(infolerp::mesh_keyframe_count(m) == 0);
}

TEST_CASE("strided view reads interleaved vertices without copying, and checks its arguments") {
  struct vertex { float p[3]; float uv[2]; };
  const std::array<vertex, 3> verts{{{{0, 0, 0}, {0, 0}}, {{2, 0, 0}, {1, 0}}, {{0, 3, 0}, {0, 1}}}};
  const std::array<std::uint32_t, 3> idx{0, 1, 2};
  auto view = infolerp::make_strided_mesh_view(verts[0].p, 3, sizeof(vertex), idx.data(), 3);
  REQUIRE(view.ok());
  CHECK(view->triangle_count() == 1);
  CHECK(view->position(2) == glm::vec3(0, 3, 0));
  auto bad_count = infolerp::make_strided_mesh_view(verts[0].p, 3, sizeof(vertex), idx.data(), 2);
  REQUIRE_FALSE(bad_count.ok());
  CHECK(bad_count.error().code() == infolerp::errc::bad_index_count);
  CHECK(bad_count.error().message().find("index count 2") != std::string::npos);
  CHECK(infolerp::make_strided_mesh_view(verts[0].p, 3, 8, idx.data(), 3).error().code() == infolerp::errc::bad_parameter);
  CHECK(infolerp::make_strided_mesh_view(nullptr, 3, 12, idx.data(), 3).error().code() == infolerp::errc::bad_parameter);
  CHECK(infolerp::make_strided_mesh_view(verts[0].p, 3, 20, nullptr, 3).error().code() == infolerp::errc::bad_parameter);
}

TEST_CASE("tracer concepts: batch overload is used when present") {
  STATIC_REQUIRE(infolerp::tracer<user_tracer>);
  STATIC_REQUIRE_FALSE(infolerp::batch_occlusion_tracer<user_tracer>);
  STATIC_REQUIRE(infolerp::batch_occlusion_tracer<batch_tracer>);
  STATIC_REQUIRE_FALSE(infolerp::tracer<int>);
  const std::vector<infolerp::ray> rays{{{0, 0, 0}, 0, {0, 0, 1}}, {{0, 0, 0}, 0, {0, 0, -1}}};
  std::vector<std::uint8_t> out(2, 7);
  infolerp::trace_occluded(user_tracer{}, rays, out);
  CHECK(out == std::vector<std::uint8_t>{0, 1});
  batch_tracer bt;
  std::fill(out.begin(), out.end(), std::uint8_t{7});
  infolerp::trace_occluded(bt, rays, out);
  CHECK(out == std::vector<std::uint8_t>{0, 1});
  CHECK(bt.batches == 1);
  CHECK_FALSE(infolerp::hit{}.valid());
}

TEST_CASE("executors cover every index once, and chunked reductions do not depend on them") {
  STATIC_REQUIRE(infolerp::executor<infolerp::serial_executor>);
  STATIC_REQUIRE(infolerp::executor<infolerp::openmp_executor>);
  STATIC_REQUIRE(infolerp::executor<infolerp::support::thread_pool_executor>);
  STATIC_REQUIRE_FALSE(infolerp::executor<int>);
  const std::size_t n = 100003;
  std::vector<double> values(n);
  for (std::size_t i = 0; i < n; ++i) values[i] = 1.0 / static_cast<double>(i + 1);
  auto chunked_sum = [&](auto&& exec) {
    std::vector<double> partial(infolerp::chunk_count(n, 1000), 0.0);
    std::vector<std::atomic<int>> seen(n);
    infolerp::for_each_chunk(exec, n, 1000, [&](std::size_t c, std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        partial[c] += values[i];
        seen[i].fetch_add(1);
      }
    });
    for (const auto& s : seen) REQUIRE(s.load() == 1);
    return std::accumulate(partial.begin(), partial.end(), 0.0);
  };
  const double serial = chunked_sum(infolerp::serial_executor{});
  CHECK(chunked_sum(infolerp::openmp_executor{}) == serial);
  for (unsigned w : {1u, 2u, 8u}) CHECK(chunked_sum(infolerp::support::thread_pool_executor{w}) == serial);
  int calls = 0;
  infolerp::serial_executor{}.parallel_for(0, 4, [&](std::size_t, std::size_t) { ++calls; });
  CHECK(calls == 0);
}

TEST_CASE("large_buffer_allocator: 2 MiB aligned from 4 MiB, values kept through growth and copies") {
  using buffer = std::vector<float, infolerp::large_buffer_allocator<float>>;
  const auto aligned = [](const buffer& b) { return reinterpret_cast<std::uintptr_t>(b.data()) % (std::size_t{2} << 20) == 0; };
  buffer small(1000);
  std::iota(small.begin(), small.end(), 0.0f);
  CHECK(small[999] == 999.0f);
  buffer b;
  for (int i = 0; i < (3 << 20); ++i) b.push_back(static_cast<float>(i % 4099));  // 12 MiB, several reallocations
  REQUIRE(b.size() * sizeof(float) >= (std::size_t{4} << 20));
  CHECK(aligned(b));
  bool same = true;
  for (int i = 0; i < (3 << 20); ++i) same = same && b[static_cast<std::size_t>(i)] == static_cast<float>(i % 4099);
  CHECK(same);
  const buffer copy = b;
  CHECK(aligned(copy));
  CHECK(copy == b);
  buffer moved = std::move(small);
  CHECK(moved.size() == 1000);
  CHECK(moved[500] == 500.0f);
}

TEST_CASE("group_by_key: stable CSR buckets, empty buckets, skipped items, reused buffers") {
  using infolerp::detail::group_by_key, infolerp::detail::no_bucket;
  std::vector<std::uint32_t> offsets, grouped;
  // Items 0..6 with keys {2, 0, 2, skip, 0, 2, 4} over 5 buckets; the value of item i is 10 * i.
  const std::vector<std::uint32_t> keys{2, 0, 2, no_bucket, 0, 2, 4};
  group_by_key(
      5, keys.size(), [&](std::size_t i) { return keys[i]; }, [](std::size_t i) { return static_cast<std::uint32_t>(10 * i); },
      offsets, grouped);
  CHECK(offsets == std::vector<std::uint32_t>{0, 2, 2, 5, 5, 6});
  CHECK(grouped == std::vector<std::uint32_t>{10, 40, 0, 20, 50, 60});

  // Reused buffers with fewer buckets and more items: same as a stable sort by key.
  std::vector<std::uint32_t> many(1000);
  for (std::size_t i = 0; i < many.size(); ++i) many[i] = static_cast<std::uint32_t>((i * 7919u) % 3u);
  group_by_key(
      3, many.size(), [&](std::size_t i) { return many[i]; }, [](std::size_t i) { return static_cast<std::uint32_t>(i); },
      offsets, grouped);
  std::vector<std::uint32_t> expected(many.size());
  std::iota(expected.begin(), expected.end(), 0u);
  std::stable_sort(expected.begin(), expected.end(), [&](std::uint32_t a, std::uint32_t b) { return many[a] < many[b]; });
  CHECK(grouped == expected);
  REQUIRE(offsets.size() == 4);
  for (std::uint32_t k = 0; k < 3; ++k) {
    CHECK(offsets[k + 1] - offsets[k] == static_cast<std::uint32_t>(std::count(many.begin(), many.end(), k)));
    for (std::uint32_t j = offsets[k]; j < offsets[k + 1]; ++j) CHECK(many[grouped[j]] == k);
  }

  // No items: every bucket empty.
  group_by_key(
      3, 0, [](std::size_t) { return 0u; }, [](std::size_t) { return 0u; }, offsets, grouped);
  CHECK(offsets == std::vector<std::uint32_t>{0, 0, 0, 0});
  CHECK(grouped.empty());
}

TEMPLATE_TEST_CASE("unit_or_zero: glm::normalize's bits for ordinary vectors, unit length at any finite scale, zero otherwise",
                   "", float, double) {
  using v3 = glm::vec<3, TestType>;
  using lim = std::numeric_limits<TestType>;
  const v3 d(TestType(3), TestType(-4), TestType(12));
  CHECK(infolerp::unit_or_zero(d) == glm::normalize(d));
  // Scales whose squared length overflows, underflows or is subnormal: the direction survives.
  for (const TestType s : {lim::max() / TestType(16), std::sqrt(lim::max()) * TestType(4), std::sqrt(lim::min()),
                           lim::min(), lim::denorm_min() * TestType(13)}) {
    const v3 u = infolerp::unit_or_zero(d * s / TestType(13));
    INFO("scale " << s);
    CHECK(std::abs(glm::length(u) - TestType(1)) < TestType(8) * lim::epsilon());
    CHECK(glm::length(u - glm::normalize(d)) < TestType(0.05));  // subnormals keep few digits
  }
  CHECK(infolerp::unit_or_zero(v3(TestType(0))) == v3(TestType(0)));
  CHECK(infolerp::unit_or_zero(v3(lim::quiet_NaN(), TestType(1), TestType(0))) == v3(TestType(0)));
  CHECK(infolerp::unit_or_zero(v3(TestType(1), lim::quiet_NaN(), TestType(0))) == v3(TestType(0)));
  CHECK(infolerp::unit_or_zero(v3(lim::infinity(), TestType(1), TestType(0))) == v3(TestType(0)));
}
