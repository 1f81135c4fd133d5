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

// Neighbour matching in place; returns the sweeps run (>= 1). Preconditions: stop holds one
// entry per cluster. O(sweeps · applied cross-cluster dependencies), no allocation.
inline std::uint32_t match_neighbours(const contraction_hierarchy& h, std::span<std::uint32_t> stop) {
  std::uint32_t sweeps = 0;
  for (bool changed = true; changed;) {
    changed = false;
    ++sweeps;
    for (std::uint32_t c = 0; c < h.cluster_count; ++c)
      for (std::uint32_t k = h.cross_offsets[c]; k < h.cross_offsets[c + 1] && h.cross[k].order < stop[c]; ++k) {
        std::uint32_t& s = stop[h.cross[k].cluster];
        if (s <= h.cross[k].needs) s = h.cross[k].needs + 1, changed = true;
      }
  }
  return sweeps;
}

}  // namespace infolerp
