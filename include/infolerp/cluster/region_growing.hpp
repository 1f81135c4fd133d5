#pragma once
// Clustering one channel (clustering paper §3.2): seeds (§3.2.2), parallel growth from the seeds
// one ring at a time and sequential clustering of what is left (§3.2.3), merging of small
// clusters (§3.2.4). Works on any channel_state (channel.hpp) over a set of elements joined by an
// element_graph (the dual graph of a triangle set).
//
// Rules pinned down here:
//   membership   JS(t, seed) < Th, and Th = 1 accepts everything (is_similar).
//   Th = 0       every element is its own cluster (no growth, no merging).
//   Th = 1, or all rows alike   one cluster per connected component, no divergence evaluated.
//   seeds        first: the class with minimum I(x;Y); next: the class with maximum summed JS
//                to the seeds so far among those with JS > Th to every seed; stop when none.
//                With the state's mutual_information_lower_bound, MI is evaluated only where
//                the bound is within 1e-9 of the MI of the class of smallest bound.
//                Lazy: a seed's JS is evaluated (in parallel) only for the classes still
//                candidates, and during growth only where its frontier arrives, once per
//                (seed, class); with the state's surely_within, a candidate the bound puts
//                within Th of the new seed is dropped without its JS (it could not be a seed
//                any more), and growth evaluates JS exactly only where two seeds claim an
//                element in the same ring. With the state's estimate() (error e), an entry
//                the estimate puts at most Th − e − 2⁻²² is bounded as above, one it puts above
//                Th + e + 2⁻²² keeps the estimate (a float above Th) and its error in the
//                candidate's summed JS, and the rest are exact; a seed is chosen among the
//                candidates whose summed JS can still be the largest after their entries were
//                made exact, so the seeds are those of exact columns. The sequential pass
//                decides JS < Th by the estimate where it can. With the state's
//                representative(), an entry whose representative is evaluated in the same
//                batch is copied from it (bit-identical). Same result.
//   growth       all seeds grow together ring by ring; an element claimed by several seeds in
//                one ring joins the one with the smallest JS, then the smallest seed index.
//   sequential   leftover elements in index order each seed a new cluster grown breadth-first.
//   merging      clusters with fewer than min_cluster_fraction·N elements join the neighbouring
//                cluster whose seed has the smallest JS to theirs (ties: smallest id), in passes
//                (smallest first) until none can merge. Isolated small clusters stay. N is
//                fraction_of when set (cluster_mesh: the mesh's triangle count, the paper's "a
//                given fraction of the input triangles", so the floor is the same for the small
//                sets of later channels), else the set's own size M.
//   numbering    clusters are numbered by their smallest element.
// Every cluster is connected in the graph; results are identical for any executor.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numeric>
#include <span>
#include <type_traits>
#include <vector>
#include "infolerp/cluster/channel.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/mesh/topology.hpp"

namespace infolerp {

// Adjacency over local element ids (CSR).
struct element_graph {
  std::vector<std::uint32_t> offsets{0};
  std::vector<std::uint32_t> neighbours;
  std::size_t size() const { return offsets.size() - 1; }
  std::span<const std::uint32_t> neighbours_of(std::size_t i) const {
    return {neighbours.data() + offsets[i], neighbours.data() + offsets[i + 1]};
  }
};

// The dual graph restricted to `triangles` (local id = position in the span).
// `scratch` must hold topo.triangle_count() entries equal to invalid_id; it is restored.
// Preconditions: ids distinct and in range. O(M), allocation O(M).
inline element_graph subset_graph(const mesh_topology& topo, std::span<const std::uint32_t> triangles,
                                  std::vector<std::uint32_t>& scratch) {
  for (std::size_t i = 0; i < triangles.size(); ++i) scratch[triangles[i]] = static_cast<std::uint32_t>(i);
  element_graph g;
  g.offsets.resize(triangles.size() + 1);
  g.neighbours.reserve(3 * triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    for (std::uint32_t n : topo.neighbours_of(triangles[i]))
      if (scratch[n] != invalid_id) g.neighbours.push_back(scratch[n]);
    g.offsets[i + 1] = static_cast<std::uint32_t>(g.neighbours.size());
  }
  for (std::uint32_t t : triangles) scratch[t] = invalid_id;
  return g;
}

struct region_growing_options {
  double threshold = 0.1;               // JS threshold Th in [0,1]
  double min_cluster_fraction = 0.001;  // §3.2.4: smaller clusters merge into a neighbour (0 = never)
  std::size_t grain = 32;               // classes per parallel task when evaluating JS columns
  std::size_t fraction_of = 0;          // N of the merging floor fraction·N; 0 = the set's size
};

struct region_growing_result {
  std::vector<std::uint32_t> cluster_of;  // per element, 0..cluster_count()-1
  std::vector<std::uint32_t> seeds;       // per cluster: its seed element
  std::uint32_t parallel_seeds = 0;       // seeds chosen by §3.2.2
  std::uint32_t sequential_seeds = 0;     // clusters started by the sequential pass
  std::uint32_t merged = 0;               // clusters merged away by §3.2.4
  bool all_alike = false;                 // every row was alike: no work done
  std::uint32_t cluster_count() const { return static_cast<std::uint32_t>(seeds.size()); }
};

// What one entry of a seed's JS column holds.
enum class js_state : std::uint8_t {
  unknown,  // not evaluated (yet)
  value,    // js[c] is JS (or, with estimates, an estimate above Th: see js_entries)
  bounded,  // JS <= Th − 2⁻²² by surely_within or the estimate, not evaluated (the float of
            // the value would also be < Th: a bounded entry decides as the exact one would)
  pending,  // transient inside one js_entries call (and growth's batch): to evaluate
  copy,     // transient inside one js_entries call: to copy from the class's representative
};

// One seed's JS to every class: the values and, in its own array, what each entry holds.
struct js_column {
  std::vector<float> js;
  std::vector<js_state> state;
  explicit js_column(std::size_t classes) : js(classes, 0.0f), state(classes, js_state::unknown) {}
};

namespace detail {

template <class S>
concept has_mutual_information_lower_bound = requires(const S& s, std::uint32_t a) {
  { s.mutual_information_lower_bound(a) } -> std::convertible_to<double>;
};

template <class S>
concept has_representative = requires(const S& s, std::uint32_t a) {
  { s.representative(a) } -> std::convertible_to<std::uint32_t>;
};

template <class S>
concept has_prefetch = requires(const S& s, std::uint32_t a) { s.prefetch(a); };

template <class S>
concept has_surely_within = requires(const S& s, std::uint32_t a, double th) {
  { s.surely_within(a, a, th) } -> std::convertible_to<bool>;
};

template <class S>
concept has_estimate = requires(const S& s, std::uint32_t a) {
  { s.estimate(a, a) } -> std::convertible_to<double>;
  { s.estimate_error() } -> std::convertible_to<double>;
};

// The state's estimate error, +inf without estimate() (then nothing is decided by it).
template <class S>
double estimate_error_of(const S& s) {
  if constexpr (has_estimate<S>) {
    const double e = s.estimate_error();
    return e >= 0.0 ? e : std::numeric_limits<double>::infinity();  // also NaN: unusable
  } else {
    return std::numeric_limits<double>::infinity();
  }
}

// How the estimate places divergence(a, b) against th: +1 surely JS > th + 2⁻²² (so the float
// of JS is > th too), -1 surely JS <= th − 2⁻²² (the float < th), 0 undecided.
template <class S>
int estimate_side(const S& s, std::uint32_t a, std::uint32_t b, double th, double err, double& e) {
  if constexpr (has_estimate<S>) {
    e = s.estimate(a, b);
    if (e + err <= th - 0x1p-22) return -1;
    if (e - err > th + 0x1p-22) return 1;
  }
  (void)s, (void)a, (void)b, (void)th, (void)err, (void)e;
  return 0;
}

// is_similar(float(divergence(a, b)), th), by the estimate where it decides.
template <class S>
bool similar(const S& s, std::uint32_t a, std::uint32_t b, double th, double err) {
  double e = 0.0;
  if (err < std::numeric_limits<double>::infinity() && th < 1.0)
    if (const int side = estimate_side(s, a, b, th, err, e)) return side < 0;
  return is_similar(static_cast<float>(s.divergence(a, b)), th);
}

// col[c] = JS(a, c) for the classes c listed in `which` (ascending, distinct), in parallel chunks
// (each slot independent). With a threshold (>= 0), bounded where the state's
// surely_within(a, c, threshold) holds, or, with the state's estimate(), where the estimate
// puts JS at most threshold − err − 2⁻²²; where it puts JS above threshold + err + 2⁻²² the
// entry is the estimate (a float above threshold, within err + 2⁻²⁴ of the exact entry) and
// approx[c] (when given) is 1, else 0. Runs of consecutive classes go through the state's batch
// divergences() when it has one.
template <class S, class E>
void js_entries(const S& s, std::uint32_t a, std::span<const std::uint32_t> which, js_column& col, std::size_t grain,
                E& exec, double threshold = -1.0, std::span<std::uint8_t> approx = {}) {
  const double err = threshold >= 0.0 && threshold < 1.0 ? estimate_error_of(s) : std::numeric_limits<double>::infinity();
  if (!approx.empty())
    for (std::uint32_t c : which) approx[c] = 0;
  // With the state's representative(): a class whose representative is also listed (and is
  // neither a nor the class itself) is marked copy and copies its entry afterwards
  // (bit-identical: same row). Representatives are never copies.
  if constexpr (has_representative<S>) {
    for (std::uint32_t c : which) col.state[c] = js_state::pending;
    for (std::uint32_t c : which) {
      const std::uint32_t r = s.representative(c);
      if (r != c && r != a && c != a && col.state[r] == js_state::pending) col.state[c] = js_state::copy;
    }
  }
  const auto set = [&](std::uint32_t c, float js) {
    col.js[c] = js;
    col.state[c] = js_state::value;
  };
  for_each_chunk(exec, which.size(), grain, [&](std::size_t, std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e;) {
      const std::uint32_t c = which[i];
      if constexpr (has_prefetch<S>) {
        constexpr std::size_t ahead = 4;  // about one memory latency of divergences
        if (i + ahead < e) s.prefetch(which[i + ahead]);
      }
      if (col.state[c] == js_state::copy) {
        ++i;
        continue;
      }
      if (err < std::numeric_limits<double>::infinity()) {
        double est = 0.0;
        const int side = estimate_side(s, a, c, threshold, err, est);
        if (side < 0)
          col.state[c] = js_state::bounded;
        else
          set(c, side > 0 ? static_cast<float>(est) : static_cast<float>(s.divergence(a, c)));
        if (side > 0 && !approx.empty()) approx[c] = 1;
        ++i;
        continue;
      }
      if constexpr (has_surely_within<S>) {
        if (threshold >= 0.0 && s.surely_within(a, c, threshold))
          col.state[c] = js_state::bounded;
        else
          set(c, static_cast<float>(s.divergence(a, c)));
        ++i;
      } else if constexpr (requires { s.divergences(a, c, std::span<float>(col.js).subspan(c, 1)); }) {
        std::size_t j = i + 1;
        while (j < e && which[j] == which[j - 1] + 1) ++j;
        s.divergences(a, c, std::span<float>(col.js).subspan(c, j - i));
        std::fill(col.state.begin() + c, col.state.begin() + c + static_cast<std::ptrdiff_t>(j - i), js_state::value);
        i = j;
      } else {
        set(c, static_cast<float>(s.divergence(a, c)));
        ++i;
      }
    }
  });
  if constexpr (has_representative<S>)
    for (std::uint32_t c : which)
      if (col.state[c] == js_state::copy) {
        const std::uint32_t r = s.representative(c);
        col.js[c] = col.js[r];
        col.state[c] = col.state[r];
        if (!approx.empty()) approx[c] = approx[r];
      }
}

// Renumbers clusters by their smallest element and drops empty ids; seeds follow.
inline void canonical_numbering(std::vector<std::uint32_t>& label, std::vector<std::uint32_t>& seeds) {
  std::vector<std::uint32_t> map(seeds.size(), invalid_id), new_seeds;
  for (auto& l : label) {
    if (map[l] == invalid_id) {
      map[l] = static_cast<std::uint32_t>(new_seeds.size());
      new_seeds.push_back(seeds[l]);
    }
    l = map[l];
  }
  seeds = std::move(new_seeds);
}

// One cluster per connected component, seeded at its smallest element.
inline void component_clusters(const element_graph& g, region_growing_result& r) {
  r.cluster_of.assign(g.size(), invalid_id);
  label_unlabelled_components(
      r.cluster_of, 0, [&](std::uint32_t e) { return g.neighbours_of(e); }, [&](std::uint32_t e) { r.seeds.push_back(e); });
}

}  // namespace detail

// §3.2.2 seed selection. Returns the seed classes in order; `columns[k]` receives seed k's JS to
// every class that was still a candidate (JS > Th to seeds 0..k-1) when seed k was chosen; the
// other entries are unknown. Lazy: a class with JS <= Th to some seed can never become a
// seed, and its summed JS no longer matters, so it is not evaluated against later seeds (the
// seeds are the same as with full columns). With the state's surely_within, entries the bound
// decides (JS <= Th) are bounded and need no divergence: those classes are dropped anyway.
// Preconditions: 0 < threshold < 1, class_count() >= 1.
// Complexity: U MI evaluations + one divergence (or estimate) per (seed, class still a
// candidate), at most U per seed, plus with estimates one divergence per estimated entry of a
// class that came within its error bound of the largest sum. Allocation U floats and U
// bytes (a js_column) per seed, and U bytes more per seed with estimates.
template <class S, class E>
std::vector<std::uint32_t> select_seeds(const S& s, double threshold, std::size_t grain, E& exec,
                                        std::vector<js_column>& columns) {
  static_assert(channel_state<S>);
  const std::size_t u = s.class_count();
  std::vector<double> mi(u);
  if constexpr (detail::has_mutual_information_lower_bound<S>) {
    // MI only where the bound allows it to reach the MI of the class of smallest bound (all
    // classes of minimum MI among them); the others get +inf, which cannot be the minimum.
    for_each_chunk(exec, u, grain, [&](std::size_t, std::size_t b, std::size_t e) {
      for (std::size_t c = b; c < e; ++c) mi[c] = s.mutual_information_lower_bound(static_cast<std::uint32_t>(c));
    });
    const auto lowest = static_cast<std::uint32_t>(std::min_element(mi.begin(), mi.end()) - mi.begin());
    const double reach = s.mutual_information(lowest) + 1e-9;
    for_each_chunk(exec, u, grain, [&](std::size_t, std::size_t b, std::size_t e) {
      for (std::size_t c = b; c < e; ++c)
        mi[c] = mi[c] <= reach ? s.mutual_information(static_cast<std::uint32_t>(c)) : std::numeric_limits<double>::infinity();
    });
  } else {
    for_each_chunk(exec, u, grain, [&](std::size_t, std::size_t b, std::size_t e) {
      for (std::size_t c = b; c < e; ++c) mi[c] = s.mutual_information(static_cast<std::uint32_t>(c));
    });
  }
  std::uint32_t next = 0;
  for (std::uint32_t c = 1; c < u; ++c)
    if (mi[c] < mi[next]) next = c;
  std::vector<std::uint32_t> seeds;
  std::vector<double> sum(u, 0.0);
  std::vector<std::uint32_t> candidates(u);  // ascending
  std::iota(candidates.begin(), candidates.end(), 0u);
  columns.clear();
  // With an estimate: slack[c] bounds |sum[c] − its exact value| (err + 2⁻²⁴ per estimated entry).
  const double err = threshold < 1.0 ? detail::estimate_error_of(s) : std::numeric_limits<double>::infinity();
  const bool estimated = err < std::numeric_limits<double>::infinity();
  std::vector<double> slack(estimated ? u : 0, 0.0);
  std::vector<std::vector<std::uint8_t>> approx;  // per seed: 1 where its entry is an estimate
  // The estimated entries of c made exact (copied from its representative, a candidate too, made
  // exact first); the sum recomputed in the same order (the same bits as if every entry had
  // been exact from the start).
  auto make_exact = [&](std::uint32_t c, auto& self) -> void {
    std::uint32_t r = c;
    if constexpr (detail::has_representative<S>) r = s.representative(c);
    if (r != c && slack[r] > 0.0) self(r, self);
    sum[c] = 0.0;
    for (std::size_t k = 0; k < seeds.size(); ++k) {
      float& js = columns[k].js[c];
      if (approx[k][c]) {
        js = r != c ? columns[k].js[r] : static_cast<float>(s.divergence(seeds[k], c));
        approx[k][c] = 0;
      }
      sum[c] += js;
    }
    slack[c] = 0.0;
  };
  for (;;) {
    seeds.push_back(next);
    columns.emplace_back(u);
    auto& col = columns.back();
    if (estimated) approx.emplace_back(u, 0);
    detail::js_entries(s, next, candidates, col, grain, exec, threshold,
                       estimated ? std::span<std::uint8_t>(approx.back()) : std::span<std::uint8_t>());
    std::uint32_t best = invalid_id;
    std::size_t kept = 0;
    for (std::uint32_t c : candidates) {
      sum[c] += col.js[c];  // a bounded entry's 0 adds to a sum no longer looked at
      if (col.state[c] != js_state::value || !(static_cast<double>(col.js[c]) > threshold)) continue;
      if (estimated && approx.back()[c]) slack[c] += err + 0x1p-24;
      candidates[kept++] = c;
      if (best == invalid_id || sum[c] > sum[best]) best = c;
    }
    candidates.resize(kept);
    if (best == invalid_id) break;
    if (estimated) {
      // Every candidate whose sum can reach best's lowest possible sum is made exact; the others
      // are then strictly below best's exact sum, so the exact maximum (first on ties) is among
      // the exact ones.
      const double low = sum[best] - slack[best];
      bool changed = false;
      for (std::uint32_t c : candidates)
        if (slack[c] > 0.0 && sum[c] + slack[c] >= low) {
          make_exact(c, make_exact);
          changed = true;
        }
      if (changed) {
        best = invalid_id;
        for (std::uint32_t c : candidates)
          if (slack[c] == 0.0 && (best == invalid_id || sum[c] > sum[best])) best = c;
      }
    }
    next = best;
  }
  return seeds;
}

namespace detail {

// Validates grow_regions' input; see there for the errors.
template <class S>
status check_region_growing(const S& s, const element_graph& g, const region_growing_options& o) {
  if (status st = check_threshold(o.threshold, "region growing"); !st) return st;
  if (!(o.min_cluster_fraction >= 0.0 && o.min_cluster_fraction <= 1.0))
    return make_error(errc::bad_parameter, no_element, "region growing: min_cluster_fraction ", o.min_cluster_fraction,
                      " outside [0, 1]");
  const std::size_t m = s.element_count();
  if (m == 0) return make_error(errc::empty_input, no_element, "region growing: empty element set");
  if (g.size() != m)
    return make_error(errc::bad_size, no_element, "region growing: graph has ", g.size(), " elements, channel ", m);
  return {};
}

// The cases that need no divergence: Th = 0 (one cluster per element), Th = 1 or all rows alike
// (one cluster per connected component). Returns false, leaving r empty, for the others.
template <class S>
bool trivial_clusters(const S& s, const element_graph& g, double th, region_growing_result& r) {
  const std::size_t m = s.element_count();
  if (th == 0.0) {
    r.cluster_of.resize(m);
    std::iota(r.cluster_of.begin(), r.cluster_of.end(), 0u);
    r.seeds = r.cluster_of;
    r.sequential_seeds = static_cast<std::uint32_t>(m);
    return true;
  }
  bool alike = s.class_count() <= 1;
  if constexpr (requires { { s.all_alike() } -> std::convertible_to<bool>; }) alike = alike || s.all_alike();
  if (!alike && th < 1.0) return false;
  r.all_alike = alike;
  component_clusters(g, r);
  return true;
}

// §3.2.3, parallel: every seed class's first element grows one ring at a time; an element
// claimed by several seeds in one ring joins the one with the smallest JS, then the smallest
// seed index. `columns` are select_seeds' (entries filled in where the frontiers arrive).
// Sets r.cluster_of (invalid_id where no seed arrived), r.seeds, r.parallel_seeds.
template <class S, class E>
void grow_rings(const S& s, const element_graph& g, std::span<const std::uint32_t> cls,
                std::span<const std::uint32_t> seed_classes, std::vector<js_column>& columns, double th,
                std::size_t grain, E& exec, region_growing_result& r) {
  const std::size_t m = cls.size(), k0 = seed_classes.size();
  r.parallel_seeds = static_cast<std::uint32_t>(k0);
  std::vector<std::uint32_t> first_of(s.class_count(), invalid_id);
  for (std::uint32_t e = 0; e < m; ++e)
    if (first_of[cls[e]] == invalid_id) first_of[cls[e]] = e;
  std::vector<std::uint32_t>& label = r.cluster_of;
  label.assign(m, invalid_id);
  std::vector<std::vector<std::uint32_t>> frontier(k0);
  for (std::uint32_t k = 0; k < k0; ++k) {
    const std::uint32_t e = first_of[seed_classes[k]];
    r.seeds.push_back(e);
    label[e] = k;
    frontier[k].push_back(e);
  }
  std::vector<float> best_js(m, std::numeric_limits<float>::infinity());
  std::vector<std::uint32_t> best_k(m, invalid_id), touched;
  std::vector<std::vector<std::uint32_t>> missing(k0);  // column entries this ring needs
  for (bool any = true; any;) {
    touched.clear();
    for (std::uint32_t k = 0; k < k0; ++k) {
      missing[k].clear();
      for (std::uint32_t f : frontier[k])
        for (std::uint32_t n : g.neighbours_of(f))
          if (label[n] == invalid_id && columns[k].state[cls[n]] == js_state::unknown) {
            columns[k].state[cls[n]] = js_state::pending;
            missing[k].push_back(cls[n]);
          }
      std::sort(missing[k].begin(), missing[k].end());
      js_entries(s, seed_classes[k], missing[k], columns[k], grain, exec, th);
    }
    // A bounded entry is similar; its value is needed only when a second seed claims the
    // same element in this ring (then both values are made exact, in this fixed order).
    auto exact = [&](std::uint32_t k, std::uint32_t c) {
      js_column& col = columns[k];
      if (col.state[c] == js_state::bounded) {
        col.js[c] = static_cast<float>(s.divergence(seed_classes[k], c));
        col.state[c] = js_state::value;
      }
      return col.js[c];
    };
    for (std::uint32_t k = 0; k < k0; ++k)
      for (std::uint32_t f : frontier[k])
        for (std::uint32_t n : g.neighbours_of(f)) {
          if (label[n] != invalid_id) continue;
          float js = columns[k].js[cls[n]];
          if (columns[k].state[cls[n]] != js_state::bounded && !is_similar(js, th)) continue;
          if (best_k[n] == invalid_id) {
            touched.push_back(n);
          } else if (best_k[n] != k) {
            js = exact(k, cls[n]);
            best_js[n] = exact(best_k[n], cls[n]);
          }
          if (best_k[n] == invalid_id || js < best_js[n] || (js == best_js[n] && k < best_k[n])) {
            best_js[n] = js;
            best_k[n] = k;
          }
        }
    for (auto& f : frontier) f.clear();
    for (std::uint32_t n : touched) {
      label[n] = best_k[n];
      frontier[best_k[n]].push_back(n);
      best_k[n] = invalid_id;
      best_js[n] = std::numeric_limits<float>::infinity();
    }
    any = !touched.empty();
  }
}

// §3.2.3, sequential: each element no seed reached, in index order, seeds a new cluster grown
// breadth-first over elements with JS < Th to it ("JS < Th" memoised per class, stamped by
// cluster; decided by the state's estimate where it can).
template <class S>
void grow_leftovers(const S& s, const element_graph& g, std::span<const std::uint32_t> cls, double th,
                    region_growing_result& r) {
  std::vector<std::uint32_t>& label = r.cluster_of;
  const double err = estimate_error_of(s);
  std::vector<std::uint8_t> memo(s.class_count());
  std::vector<std::uint32_t> stamp(s.class_count(), invalid_id), queue;
  for (std::uint32_t e = 0; e < cls.size(); ++e) {
    if (label[e] != invalid_id) continue;
    const auto k = static_cast<std::uint32_t>(r.seeds.size());
    r.seeds.push_back(e);
    ++r.sequential_seeds;
    label[e] = k;
    queue.assign(1, e);
    const std::uint32_t sc = cls[e];
    for (std::size_t q = 0; q < queue.size(); ++q) {
      if constexpr (has_prefetch<S>)  // the rows tested next, a hint (far apart in memory)
        if (q + 1 < queue.size())
          for (std::uint32_t n : g.neighbours_of(queue[q + 1]))
            if (label[n] == invalid_id) s.prefetch(cls[n]);
      for (std::uint32_t n : g.neighbours_of(queue[q])) {
        if (label[n] != invalid_id) continue;
        if (stamp[cls[n]] != k) {
          stamp[cls[n]] = k;
          memo[cls[n]] = similar(s, sc, cls[n], th, err) ? 1 : 0;
        }
        if (!memo[cls[n]]) continue;
        label[n] = k;
        queue.push_back(n);
      }
    }
  }
}

// One §3.2.4 pass: every cluster under min_size, smallest first, joins the neighbouring
// cluster whose seed has the smallest JS to its seed (ties: smallest id). Returns whether any
// merged; renumbers canonically.
template <class S>
bool merge_pass(const S& s, const element_graph& g, std::span<const std::uint32_t> cls, double min_size,
                region_growing_result& r) {
  std::vector<std::uint32_t>& label = r.cluster_of;
  const std::size_t kc = r.seeds.size();
  std::vector<double> size(kc, 0.0);
  for (std::uint32_t l : label) size[l] += 1.0;
  std::vector<std::uint32_t> small;
  for (std::uint32_t k = 0; k < kc; ++k)
    if (size[k] < min_size) small.push_back(k);
  if (small.empty()) return false;
  // Neighbouring clusters of each small cluster.
  std::vector<std::uint32_t> is_small(kc, invalid_id);
  for (std::uint32_t i = 0; i < small.size(); ++i) is_small[small[i]] = i;
  std::vector<std::vector<std::uint32_t>> adj(small.size());
  for (std::uint32_t e = 0; e < label.size(); ++e) {
    const std::uint32_t si = is_small[label[e]];
    if (si == invalid_id) continue;
    for (std::uint32_t n : g.neighbours_of(e))
      if (label[n] != label[e]) adj[si].push_back(label[n]);
  }
  for (auto& a : adj) {  // one divergence per neighbouring cluster (the choice is order-free)
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  std::vector<std::uint32_t> parent(kc);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::vector<std::uint32_t> order(small.begin(), small.end());
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return size[a] < size[b]; });
  bool changed = false;
  for (std::uint32_t a : order) {
    if (find(a) != a || size[a] >= min_size) continue;
    std::uint32_t best = invalid_id;
    double best_d = 0.0;
    for (std::uint32_t nb : adj[is_small[a]]) {
      const std::uint32_t b = find(nb);
      if (b == a) continue;
      const double d = s.divergence(cls[r.seeds[a]], cls[r.seeds[b]]);
      if (best == invalid_id || d < best_d || (d == best_d && b < best)) {
        best = b;
        best_d = d;
      }
    }
    if (best == invalid_id) continue;
    parent[a] = best;
    size[best] += size[a];
    ++r.merged;
    changed = true;
  }
  for (auto& l : label) l = find(l);
  canonical_numbering(label, r.seeds);
  return changed;
}

// §3.2.4: merging passes until none merges (nothing when min_size <= 1).
template <class S>
void merge_small_clusters(const S& s, const element_graph& g, std::span<const std::uint32_t> cls, double min_size,
                          region_growing_result& r) {
  if (min_size > 1.0)
    while (merge_pass(s, g, cls, min_size, r)) {
    }
}

}  // namespace detail

// §3.2 for one channel on one set: seeds, parallel growth, sequential pass, merging.
// Errors: threshold or min_cluster_fraction outside [0,1] or NaN, graph/state size mismatch,
// empty set. Complexity: dominated by the seeds' divergences (see select_seeds; growth adds at
// most one per (seed, class) its frontier reaches), plus
// O(M·degree) for growth and O(M·degree) per merging pass. Allocation O(M + seeds·U).
// Thread-safety: the state's const members are called from the executor's threads.
template <class S, class E>
result<region_growing_result> grow_regions(const S& s, const element_graph& g, const region_growing_options& o,
                                           E&& exec) {
  static_assert(channel_state<S>, "infolerp: grow_regions needs a channel_state (see cluster/channel.hpp)");
  static_assert(check_executor<std::remove_cvref_t<E>>());
  if (status st = detail::check_region_growing(s, g, o); !st) return st;
  region_growing_result r;
  if (detail::trivial_clusters(s, g, o.threshold, r)) return r;
  const std::size_t m = s.element_count();
  std::vector<std::uint32_t> cls(m);
  for (std::uint32_t e = 0; e < m; ++e) cls[e] = s.class_of(e);
  std::vector<js_column> columns;
  const std::vector<std::uint32_t> seed_classes = select_seeds(s, o.threshold, o.grain, exec, columns);  // §3.2.2
  detail::grow_rings(s, g, cls, seed_classes, columns, o.threshold, o.grain, exec, r);                 // §3.2.3
  columns = {};
  detail::grow_leftovers(s, g, cls, o.threshold, r);
  const double min_size = o.min_cluster_fraction * static_cast<double>(o.fraction_of ? o.fraction_of : m);
  detail::merge_small_clusters(s, g, cls, min_size, r);  // §3.2.4
  detail::canonical_numbering(r.cluster_of, r.seeds);
  return r;
}

}  // namespace infolerp
