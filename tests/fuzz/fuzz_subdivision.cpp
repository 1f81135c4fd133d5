// libFuzzer target: the hierarchical subdivision mesh under random selections.
// Input: [flags][bisect ratio][propagation depth][mesh, or a built-in grid when flags & 1]
// then operations: split one id, split a child of the previous deep selection (chains past
// the 255 levels a subdivision_triangle counts), split a selection,
// locate a point, tessellate. Checks after every operation that the leaves form a conforming
// triangulation (every leaf edge has at most two leaves and no midpoint: no T-vertex), that
// counts agree, and that location lands on a leaf with finite weights.
#include <cmath>
#include <vector>
#include "fuzz_common.hpp"
#include "infolerp/mesh/topology.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"

namespace {
infolerp::indexed_mesh grid(unsigned n) {  // n×n quads on z = 0, 2 triangles each
  infolerp::indexed_mesh m;
  for (unsigned y = 0; y <= n; ++y)
    for (unsigned x = 0; x <= n; ++x) m.positions.push_back({static_cast<float>(x), static_cast<float>(y), 0.0f});
  for (unsigned y = 0; y < n; ++y)
    for (unsigned x = 0; x < n; ++x) {
      const unsigned a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      m.triangles.push_back({a, b, d});
      m.triangles.push_back({a, d, c});
    }
  return m;
}

void check_conforming(const infolerp::subdivision_mesh& s) {
  std::size_t leaves = 0;
  for (std::size_t t = 0; t < s.triangle_count(); ++t) {
    const auto& n = s.triangle(t);
    leaves += n.is_leaf();
    FUZZ_CHECK(n.original < s.original_triangle_count());
    if (n.parent != infolerp::invalid_id) FUZZ_CHECK(n.level >= s.triangle(n.parent).level && n.level > 0);
    if (!n.is_leaf()) continue;
    for (int k = 0; k < 3; ++k) {
      FUZZ_CHECK(n.vertices[k] < s.vertex_count());
      FUZZ_CHECK(s.edge_midpoint(n.vertices[k], n.vertices[(k + 1) % 3]) == infolerp::invalid_id);
    }
  }
  FUZZ_CHECK(leaves == s.leaf_count());
  const infolerp::indexed_mesh lm = s.leaf_mesh();
  FUZZ_CHECK(lm.triangles.size() == leaves);
  auto topo = infolerp::make_topology(lm);
  FUZZ_CHECK(topo.ok());
  for (std::size_t e = 0; e < topo->edge_count(); ++e) FUZZ_CHECK(topo->edge_valence(e) <= 2);
  for (const auto& t : lm.triangles)  // unused input vertices may hold anything
    for (int k = 0; k < 3; ++k) FUZZ_CHECK(fuzz::finite(lm.positions[t[k]]));
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::reader r{data, size};
  const std::uint8_t flags = r.u8();
  infolerp::subdivision_options opt;
  opt.bisect_ratio = static_cast<float>(r.unit() * 2.0);
  opt.propagation_depth = r.u8() % 5;
  const infolerp::indexed_mesh m = (flags & 1) ? grid(1 + (flags >> 1) % 4) : fuzz::read_mesh(r, 24, 32);
  auto built = infolerp::subdivision_mesh::create(m, opt);
  fuzz::check_error(built.error());
  if (!built.ok()) return 0;
  infolerp::subdivision_mesh& s = *built;
  FUZZ_CHECK(s.leaf_count() == m.triangles.size());

  std::uint32_t deep = 0;
  constexpr std::size_t max_triangles = 3000;  // bounds time and memory per input
  for (int op = 0; op < 400 && !r.empty() && s.triangle_count() < max_triangles; ++op) {
    const std::uint8_t code = r.u8();
    const std::size_t before = s.triangle_count();
    switch (code % 5) {
      case 0: {  // one id, possibly out of range or not a leaf
        const std::uint32_t t = r.u16();
        const infolerp::status st = s.split(t, r.u8() % 4);
        fuzz::check_error(st);
        FUZZ_CHECK(st.ok() == (t < before));
        break;
      }
      case 1: {  // a child of the previous deep selection: one region deeper and deeper
        const std::uint32_t pick = r.u8();
        const auto& n = s.triangle(deep);
        deep = n.child_count ? n.first_child + pick % n.child_count : static_cast<std::uint32_t>(before - 1);
        FUZZ_CHECK(s.split(deep).ok());
        break;
      }
      case 2: {  // a selection; a bad id anywhere leaves the mesh unchanged
        std::vector<std::uint32_t> sel(r.u8() % 6);
        for (auto& t : sel) t = r.u16();
        bool all_in = true;
        for (auto t : sel) all_in = all_in && t < before;
        const std::size_t leaves = s.leaf_count();
        const infolerp::status st = s.split(std::span<const std::uint32_t>(sel));
        fuzz::check_error(st);
        FUZZ_CHECK(st.ok() == all_in);
        if (!st.ok()) FUZZ_CHECK(s.triangle_count() == before && s.leaf_count() == leaves);
        break;
      }
      case 3: {  // locate a point of an original triangle
        const auto original = static_cast<std::uint32_t>(r.u8() % s.original_triangle_count());
        const float u = static_cast<float>(r.unit()), v = static_cast<float>(r.unit());
        if (!(std::isfinite(u) && std::isfinite(v) && u >= 0.0f && v >= 0.0f && u + v <= 1.0f)) break;
        const infolerp::point_location loc = s.locate(original, {u, v});
        FUZZ_CHECK(loc.leaf < s.triangle_count() && s.is_leaf(loc.leaf));
        FUZZ_CHECK(s.triangle(loc.leaf).original == original);
        FUZZ_CHECK(fuzz::finite(loc.weights));
        break;
      }
      case 4: {  // tessellate until every leaf is smaller than a fuzzed area
        const float limit = static_cast<float>(r.unit());
        s.tessellate([&](glm::vec3 a, glm::vec3 b, glm::vec3 c) { return 0.5f * glm::length(glm::cross(b - a, c - a)) > limit; },
                     r.u8() % 4);
        break;
      }
    }
    if ((code & 0xE0) == 0xE0) check_conforming(s);  // 1 op in 8 (it is O(triangles))
  }
  check_conforming(s);
  return 0;
}
