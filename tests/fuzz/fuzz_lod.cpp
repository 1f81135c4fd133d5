// libFuzzer target: the contraction pass (weighted quadric simplification into a contraction
// hierarchy, stop points, neighbour matching, vertex contraction into an index buffer) on small
// fuzzed meshes with fuzzed corner weights, cluster ids and per-cluster budgets.
// Input: [flags][backstop][cluster count][mesh][cluster id per triangle][weight per corner]
// [budget per cluster]. Checks: every error names its problem; the output fits the bound, has
// no repeated index in a triangle and no contracted vertex, equals a brute-force replay of the
// chosen contractions, keeps every applied contraction's parent applied, is identical for a
// second executor grain, and keeps a closed edge-manifold input closed and edge-manifold.
#include <algorithm>
#include <map>
#include <utility>
#include <vector>
#include "fuzz_common.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"
#include "infolerp/lod/vertex_contraction.hpp"
#include "infolerp/lod/view_selection.hpp"

namespace {

// Undirected edge -> number of triangles using it; false when a triangle repeats an index.
bool edge_counts(std::span<const std::uint32_t> idx, std::map<std::pair<std::uint32_t, std::uint32_t>, int>& out) {
  out.clear();
  for (std::size_t k = 0; k + 2 < idx.size(); k += 3) {
    if (idx[k] == idx[k + 1] || idx[k + 1] == idx[k + 2] || idx[k] == idx[k + 2]) return false;
    for (std::size_t j = 0; j < 3; ++j) {
      const std::uint32_t a = idx[k + j], b = idx[k + (j + 1) % 3];
      ++out[{std::min(a, b), std::max(a, b)}];
    }
  }
  return true;
}

bool closed(const std::map<std::pair<std::uint32_t, std::uint32_t>, int>& e) {
  return std::all_of(e.begin(), e.end(), [](const auto& x) { return x.second == 2; });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::reader r{data, size};
  const std::uint8_t flags = r.u8();
  const double backstop = r.unit();
  const std::uint32_t clusters = 1u + r.u8() % 4u;
  infolerp::indexed_mesh m = fuzz::read_mesh(r, 24, 40);
  std::vector<std::uint32_t> cluster(m.triangles.size());
  for (auto& c : cluster) c = r.u8() % (clusters + ((flags & 1) ? 1u : 0u));  // flag 1: ids may be out of range
  std::vector<double> w(3 * m.triangles.size() + ((flags & 2) ? 1u : 0u));   // flag 2: one weight too many
  for (auto& x : w) x = (flags & 4) ? 1.0 : r.unit() * 8.0;                   // flag 4: uniform weights
  auto h = infolerp::make_contraction_hierarchy(m, w, cluster, clusters,
                                                  {.backstop = backstop, .cluster_local_first = (flags & 8) == 0});
  fuzz::check_error(h.error());
  if (!h.ok()) return 0;
  FUZZ_CHECK(fuzz::indices_in_range(m));
  const std::size_t nv = m.positions.size(), nt = m.triangles.size();
  FUZZ_CHECK(h->triangle_count() == nt && h->removal_order.size() == nv);
  std::uint64_t total = 0;
  for (std::uint32_t c = 0; c < clusters; ++c) {
    FUZZ_CHECK(h->local_capacity(c) <= h->capacity(c));
    total += h->capacity(c);
  }
  FUZZ_CHECK(total == h->contraction_count());

  std::vector<std::uint64_t> budget(clusters);
  for (std::uint32_t c = 0; c < clusters; ++c) budget[c] = r.u8() % (h->capacity(c) + 2);  // may exceed capacity
  std::vector<std::uint32_t> stop(clusters);
  const infolerp::status s = infolerp::stop_points_from_budgets(*h, budget, stop);
  fuzz::check_error(s);
  bool over = false;
  for (std::uint32_t c = 0; c < clusters; ++c) over = over || budget[c] > h->capacity(c);
  FUZZ_CHECK(s.ok() == !over);
  if (!s.ok()) return 0;
  if (flags & 16) infolerp::match_neighbours(infolerp::make_neighbour_table(*h), stop);
  auto applied = [&](std::uint32_t i) { return i < stop[h->owner[i]]; };
  const bool matched = (flags & 16) != 0;
  if (matched)
    for (std::uint32_t i = 0; i < h->contraction_count(); ++i)
      if (applied(i) && h->parent[i] != infolerp::no_parent) FUZZ_CHECK(applied(h->parent[i]));

  infolerp::contraction_workspace w1 = infolerp::make_contraction_workspace(*h, 1 + (flags >> 5));
  infolerp::contraction_workspace w2 = infolerp::make_contraction_workspace(*h, 3);
  std::vector<std::uint32_t> out(infolerp::contracted_index_bound(*h)), out2(out.size());
  std::vector<infolerp::index_range> ranges(clusters), ranges2(clusters);
  auto n = infolerp::contract_indices(*h, stop, w1, out, ranges);
  auto n2 = infolerp::contract_indices(*h, stop, w2, out2, ranges2);
  FUZZ_CHECK(n.ok() && n2.ok() && *n == *n2 && *n % 3 == 0 && *n <= out.size());
  FUZZ_CHECK(std::equal(out.begin(), out.begin() + static_cast<long>(*n), out2.begin()));
  // Brute-force replay in global order.
  std::vector<std::uint32_t> to(nv);
  for (std::uint32_t v = 0; v < nv; ++v) to[v] = v;
  for (std::uint32_t i = 0; i < h->contraction_count(); ++i)
    if (applied(i))
      for (auto& x : to)
        if (x == h->removed[i]) x = h->target[i];
  std::vector<std::uint32_t> ref;
  for (std::size_t t = 0; t < nt; ++t) {
    const std::uint32_t a = to[h->indices[3 * t]], b = to[h->indices[3 * t + 1]], c = to[h->indices[3 * t + 2]];
    if (a != b && b != c && a != c) ref.insert(ref.end(), {a, b, c});
  }
  if (matched) {
    FUZZ_CHECK(ref.size() == *n && std::equal(ref.begin(), ref.end(), out.begin()));
  } else {  // stops not dependency-closed: triangles may be lost, never invented or reordered
    std::size_t at = 0;
    for (std::size_t k = 0; k < *n; k += 3) {
      while (at < ref.size() && !std::equal(ref.begin() + static_cast<long>(at), ref.begin() + static_cast<long>(at + 3),
                                            out.begin() + static_cast<long>(k)))
        at += 3;
      FUZZ_CHECK(at < ref.size());
      at += 3;
    }
  }
  for (std::size_t k = 0; k < *n; ++k) {
    const std::uint32_t i = h->removal_order[out[k]];
    FUZZ_CHECK(i == infolerp::invalid_id || !applied(i));
  }
  // A closed edge-manifold input stays closed and edge-manifold (at dependency-closed stops).
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> in_edges, out_edges;
  const std::span<const std::uint32_t> in_idx(h->indices);
  if (matched && edge_counts(in_idx, in_edges) && closed(in_edges)) {
    FUZZ_CHECK(edge_counts(std::span<const std::uint32_t>(out.data(), *n), out_edges));
    FUZZ_CHECK(closed(out_edges));
  }
  return 0;
}
