// libFuzzer target: mesh validation, topology and the strided view on arbitrary small meshes.
// Input: [flags][mesh (fuzz_common.hpp)]. Checks that nothing reads out of bounds (ASan), that
// validate_mesh, make_topology and the strided view agree on index errors, the topology's
// invariants, and that a mesh validate_mesh accepts gives finite geometry and curvature.
#include <algorithm>
#include <cmath>
#include <vector>
#include "fuzz_common.hpp"
#include "infolerp/mesh/curvature.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/topology.hpp"
#include "infolerp/mesh/validate.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::reader r{data, size};
  const std::uint8_t flags = r.u8();
  const infolerp::indexed_mesh m = fuzz::read_mesh(r, 48, 64);
  const std::size_t nv = m.positions.size(), nt = m.triangles.size();
  const infolerp::validate_options opt{.allow_degenerate = (flags & 1) != 0, .allow_non_manifold = (flags & 2) != 0,
                                       .check_unused_vertices = (flags & 4) != 0};
  const infolerp::status v = infolerp::validate_mesh(m, opt);
  fuzz::check_error(v);
  const bool in_range = fuzz::indices_in_range(m);
  if (nv > 0 && nt > 0) FUZZ_CHECK(in_range == (v.code() != infolerp::errc::index_out_of_range));

  auto topo = infolerp::make_topology(m);
  fuzz::check_error(topo.error());
  FUZZ_CHECK(topo.ok() == in_range);
  if (topo.ok()) {
    const auto& tp = *topo;
    FUZZ_CHECK(tp.triangle_count() == nt);
    for (std::size_t e = 0; e < tp.edge_count(); ++e) {
      FUZZ_CHECK(tp.edges[e].x < tp.edges[e].y && tp.edges[e].y < nv);
      const auto faces = tp.faces_of_edge(e);
      FUZZ_CHECK(!faces.empty() && std::is_sorted(faces.begin(), faces.end()));
      FUZZ_CHECK(std::adjacent_find(faces.begin(), faces.end()) == faces.end());
      for (std::uint32_t f : faces) {
        bool has = false;
        for (int c = 0; c < 3; ++c) has = has || tp.triangle_edges[3 * f + static_cast<std::size_t>(c)] == e;
        FUZZ_CHECK(has);
      }
    }
    for (std::size_t t = 0; t < nt; ++t)
      for (std::uint32_t n : tp.neighbours_of(t)) {
        FUZZ_CHECK(n != t && n < nt);
        const auto back = tp.neighbours_of(n);
        FUZZ_CHECK(std::find(back.begin(), back.end(), static_cast<std::uint32_t>(t)) != back.end());
      }
    const auto comp = infolerp::connected_components(tp);
    for (std::uint32_t l : comp.label) FUZZ_CHECK(l < comp.count);
    for (std::uint32_t e : infolerp::boundary_edges(tp)) FUZZ_CHECK(tp.edge_valence(e) == 1);
  }

  if (v.ok()) {  // an accepted mesh: finite geometry and curvature
    for (const auto& n : infolerp::face_normals(m)) {
      FUZZ_CHECK(fuzz::finite(n));
      const float len = glm::length(n);
      FUZZ_CHECK(len == 0.0f || std::abs(len - 1.0f) < 1e-4f);
    }
    if (!opt.allow_degenerate)
      for (double a : infolerp::face_areas(m)) FUZZ_CHECK(a > 0.0);
    auto h = infolerp::mean_curvature(m);
    FUZZ_CHECK(h.ok());
    FUZZ_CHECK(fuzz::all_finite(*h));
  }

  // The same data through the zero-copy strided view (fuzzed stride and index count).
  const std::size_t stride_floats = 3 + ((flags >> 4) & 3);
  std::vector<float> raw(nv * stride_floats, -1.0f);
  for (std::size_t i = 0; i < nv; ++i) std::memcpy(&raw[i * stride_floats], &m.positions[i], sizeof(glm::vec3));
  std::vector<std::uint32_t> idx;
  for (const auto& t : m.triangles) idx.insert(idx.end(), {t.x, t.y, t.z});
  const std::size_t drop = (flags >> 6) % 3;  // 0..2 indices short of whole triangles
  const std::size_t count = idx.size() >= drop ? idx.size() - drop : 0;
  auto sv = infolerp::make_strided_mesh_view(raw.data(), nv, stride_floats * sizeof(float), idx.data(), count);
  fuzz::check_error(sv.error());
  FUZZ_CHECK(sv.ok() == (count % 3 == 0));
  if (sv.ok() && count == idx.size()) FUZZ_CHECK(infolerp::validate_mesh(*sv, opt).code() == v.code());
  return 0;
}
