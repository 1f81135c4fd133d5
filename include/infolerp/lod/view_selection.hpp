#pragma once
// Per-view contraction selection (salient-clustering paper §IV.A): per-cluster budgets (eq. 9
// over A_est·I_est, cluster_importance.hpp) become stop points in the global contraction order,
// and neighbour matching raises stop points until no selected contraction runs before one it
// depends on.
//
// A cluster with budget b performs its first b owned contractions (in global order): its stop
// point is one past the order of the b-th, and contraction i is applied iff i < stop[owner(i)].
// Neighbour matching (§IV.A): the paper takes, per cluster, the largest parent order D among its
// applied contractions and raises every neighbouring cluster's stop point to D. With one global
// order that drags each neighbour to about the same place in the order as the most refined
// cluster around it (on a mesh of ten clusters, to nearly every contraction), so this raises
// per dependency instead: for each applied contraction with a dependency j owned by another
// cluster c' (the latest such j per c', recorded at build time), stop[c'] becomes at least
// j + 1. Raising a stop point applies more contractions with dependencies of their own, so the
// sweep repeats until nothing changes. At that fixed point every applied contraction's
// dependencies are applied (those in its own cluster come earlier in the same prefix), which
// keeps shared boundaries gap-free. Matching only adds contractions: each cluster performs at
// least its budget.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>
#include "infolerp/core/status.hpp"
#include "infolerp/lod/contraction_hierarchy.hpp"

namespace infolerp {

// Stop points from per-cluster budgets (no matching). Errors: spans not one per cluster
// (bad_size), a budget above the cluster's capacity (bad_parameter, names the cluster).
// O(clusters), no allocation unless an error is returned.
inline status stop_points_from_budgets(const contraction_hierarchy& h, std::span<const std::uint64_t> budget,
                                       std::span<std::uint32_t> stop) {
  if (budget.size() != h.cluster_count || stop.size() != h.cluster_count)
    return make_error(errc::bad_size, budget.size(), "budget and stop hold ", budget.size(), " and ", stop.size(),
                      " entries for ", h.cluster_count, " clusters");
  for (std::uint32_t c = 0; c < h.cluster_count; ++c) {
    if (budget[c] > h.capacity(c))
      return make_error(errc::bad_parameter, c, "cluster ", c, ": budget ", budget[c], " exceeds its capacity ",
                        h.capacity(c));
    stop[c] = budget[c] == 0 ? 0 : h.cluster_contractions[h.cluster_offsets[c] + budget[c] - 1] + 1;
  }
  return {};
}

// Contractions cluster c applies at stop point s. O(log capacity).
inline std::uint32_t applied_count(const contraction_hierarchy& h, std::uint32_t c, std::uint32_t s) {
  const auto b = h.cluster_contractions.begin() + h.cluster_offsets[c];
  const auto e = h.cluster_contractions.begin() + h.cluster_offsets[c + 1];
  return static_cast<std::uint32_t>(std::lower_bound(b, e, s) - b);
}

// Contractions all clusters apply at their stop points. O(C log capacity).
inline std::uint64_t applied_total(const contraction_hierarchy& h, std::span<const std::uint32_t> stop) {
  std::uint64_t n = 0;
  for (std::uint32_t c = 0; c < h.cluster_count; ++c) n += applied_count(h, c, stop[c]);
  return n;
}

// Per cluster c and each other cluster c' it depends on: c's cross dependencies on c' by
// ascending order with the running maximum of `needs`, so that matching reads the raise each
// stop point implies by one binary search instead of one step per dependency. `active` lists the
// clusters that hold triangles (ascending): the selection's per-frame loops visit those only, so
// that a frame's cost follows them, not the cluster ids a caller allocated.
struct neighbour_table {
  std::vector<std::uint32_t> pair_offsets;  // per cluster, pairs + 1 (CSR)
  std::vector<std::uint32_t> pair_cluster;  // per pair: c'
  std::vector<std::uint32_t> pair_begin;    // per pair, entries + 1
  std::vector<std::uint32_t> order, needs_max;
  std::vector<std::uint32_t> active;
};

// O(C + D log D) for D cross-cluster dependencies, allocation: the result.
inline neighbour_table make_neighbour_table(const contraction_hierarchy& h) {
  neighbour_table t;
  t.pair_offsets.push_back(0);
  t.pair_begin.push_back(0);
  std::vector<cross_dependency> mine;
  for (std::uint32_t c = 0; c < h.cluster_count; ++c) {
    if (h.triangle_offsets[c + 1] > h.triangle_offsets[c]) t.active.push_back(c);
    mine.assign(h.cross.begin() + h.cross_offsets[c], h.cross.begin() + h.cross_offsets[c + 1]);
    std::stable_sort(mine.begin(), mine.end(), [](const cross_dependency& a, const cross_dependency& b) {
      return a.cluster < b.cluster;  // stable: each cluster's entries keep their ascending order
    });
    for (std::size_t k = 0; k < mine.size(); ++k) {
      const bool first = k == 0 || mine[k].cluster != mine[k - 1].cluster;
      if (first && k > 0) t.pair_begin.push_back(static_cast<std::uint32_t>(t.order.size()));
      if (first) t.pair_cluster.push_back(mine[k].cluster);
      const std::uint32_t m = first ? mine[k].needs : std::max(t.needs_max.back(), mine[k].needs);
      t.order.push_back(mine[k].order), t.needs_max.push_back(m);
    }
    if (!mine.empty()) t.pair_begin.push_back(static_cast<std::uint32_t>(t.order.size()));
    t.pair_offsets.push_back(static_cast<std::uint32_t>(t.pair_cluster.size()));
  }
  return t;
}

// Neighbour matching in place: every applied cross dependency of cluster c on cluster c' raises
// the stop point of c' past the contraction it needs; sweeps until none changes. Returns the sweeps run
// (>= 1). Preconditions: t = make_neighbour_table(h), stop one entry per cluster.
// O(sweeps · (active clusters + pairs · log dependencies)), no allocation.
inline std::uint32_t match_neighbours(const neighbour_table& t, std::span<std::uint32_t> stop) {
  std::uint32_t sweeps = 0;
  for (bool changed = true; changed;) {
    changed = false;
    ++sweeps;
    for (std::uint32_t c : t.active)  // c' != c: stop[c] holds during c's pairs
      for (std::uint32_t p = t.pair_offsets[c]; p < t.pair_offsets[c + 1]; ++p) {
        const auto b = t.order.begin() + t.pair_begin[p], e = t.order.begin() + t.pair_begin[p + 1];
        const auto n = std::lower_bound(b, e, stop[c]) - b;  // the applied ones
        if (n == 0) continue;
        const std::uint32_t need = t.needs_max[t.pair_begin[p] + static_cast<std::size_t>(n) - 1];
        std::uint32_t& s = stop[t.pair_cluster[p]];
        if (s <= need) s = need + 1, changed = true;
      }
  }
  return sweeps;
}

}  // namespace infolerp
