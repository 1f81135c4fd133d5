#pragma once
// Algorithm 1 of the clustering paper (§3, §3.5): hierarchical clustering over several channels.
// Each channel, in the user's order, re-clusters every cluster of the previous step as an
// independent set (ch.init(cl); ch.cluster(); ch.smoothBoundaries()), with its own threshold.
// Keyframed meshes (§3.4): cluster_keyframes repeats Algorithm 1 per keyframe, each starting
// from the previous keyframe's clusters.
//
//   auto ids = infolerp::cluster_mesh(mesh, tracer, exec, {},
//       infolerp::visibility_channel{.threshold = 0.48f, .viewpoints = 64},
//       infolerp::orientation_channel{.threshold = 0.02f},
//       infolerp::stretch_channel{.threshold = 0.10f});   // skipped (and reported) without UVs
//
// Channels that trace nothing (orientation, stretch, a visibility channel passed prepared) need
// no tracer: pass infolerp::no_tracer{} in its place.
//
//   auto ids = infolerp::cluster_mesh(mesh, infolerp::no_tracer{}, exec,
//       infolerp::orientation_channel{.threshold = 0.02f});
//
// Output: a dense cluster id per triangle (0..C−1, numbered by smallest triangle), every
// cluster edge-connected, identical for any executor and thread count. Th = 0 for any channel
// gives one cluster per triangle, Th = 1 for every channel one cluster per connected component.
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>
#include <glm/vec3.hpp>
#include "infolerp/cluster/boundary_smoothing.hpp"
#include "infolerp/cluster/channel.hpp"
#include "infolerp/cluster/orientation_channel.hpp"
#include "infolerp/cluster/region_growing.hpp"
#include "infolerp/cluster/stretch_channel.hpp"
#include "infolerp/cluster/visibility_channel.hpp"
#include "infolerp/core/detail/csr.hpp"
#include "infolerp/core/executor.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/mesh/topology.hpp"
#include "infolerp/mesh/validate.hpp"

namespace infolerp {

struct cluster_options {
  // §3.2.4: clusters smaller than this fraction of the mesh's triangles merge into a neighbour,
  // in every channel (the paper's "fraction of the input triangles"; 0 = never).
  double min_cluster_fraction = 0.001;
  bool smooth_boundaries = true;        // §3.3 boundary smoothing after each channel
  std::size_t grain = 32;               // classes per parallel task when evaluating JS columns
};

// What one channel did.
struct channel_report {
  const char* skipped = nullptr;       // why the channel was skipped; nullptr when it ran
  std::uint32_t clusters_after = 0;    // clusters after this channel
  std::uint32_t seeds = 0;             // §3.2.2 seeds over all sets
  std::uint32_t sequential_seeds = 0;  // clusters started by the sequential pass
  std::uint32_t merged = 0;            // clusters merged away (§3.2.4)
  std::uint32_t all_alike_sets = 0;    // sets whose rows were all alike (no work done)
  std::uint32_t smoothed_triangles = 0;  // triangles moved by boundary smoothing
  // Wall time of each stage over all sets, in seconds (steady clock), so an engine can see
  // what a channel costs: prepare (whole mesh; 0 for a channel passed prepared), init (rows
  // per set), growth (dual graph, seeds, growth, merging), smoothing.
  double prepare_seconds = 0, init_seconds = 0, growth_seconds = 0, smoothing_seconds = 0;
};

struct mesh_clustering {
  std::vector<std::uint32_t> cluster_of;  // per triangle, 0..cluster_count-1
  std::uint32_t cluster_count = 0;
  std::vector<channel_report> channels;   // one per channel, in order (the last keyframe's for cluster_keyframes)
};

// Stands in for the tracer when no channel traces rays. A visibility_channel (which prepares by
// tracing) with no_tracer is refused at compile time with a message saying so.
struct no_tracer {};

// A channel Algorithm 1 accepts: a prepared channel, or one with prepare(mesh, topo, tracer, exec).
template <class C, class M, class T, class E>
concept clustering_channel =
    channel<C> || requires(const C& c, const M& m, const mesh_topology& topo, const T& t, E& e) {
      { c.threshold } -> std::convertible_to<double>;
      c.prepare(m, topo, t, e);
    };

namespace detail {

// check_tracer, with no_tracer accepted. Compile time only.
template <class T>
constexpr bool check_cluster_tracer() {
  if constexpr (std::is_same_v<T, no_tracer>) return true;
  else return check_tracer<T>();
}

// Seconds on the steady clock since `since`, which is then moved to now.
inline double lap(std::chrono::steady_clock::time_point& since) {
  const auto now = std::chrono::steady_clock::now();
  return std::chrono::duration<double>(now - std::exchange(since, now)).count();
}

// Runs one prepared channel over every current cluster (Algorithm 1's inner loop).
template <class P, class M, class E>
status run_channel(const P& ch, const M& m, const mesh_topology& topo, const cluster_options& o, E& exec,
                   std::vector<std::uint32_t>& label, std::uint32_t& count, channel_report& rep) {
  if constexpr (requires { { ch.skip_reason() } -> std::convertible_to<const char*>; }) {
    if (const char* why = ch.skip_reason()) {
      rep.skipped = why;
      rep.clusters_after = count;
      return {};
    }
  }
  const std::size_t nt = label.size();
  // Triangles of each cluster, ascending.
  std::vector<std::uint32_t> offsets, tris;
  detail::group_by_key(
      count, nt, [&](std::size_t t) { return label[t]; }, [](std::size_t t) { return static_cast<std::uint32_t>(t); },
      offsets, tris);
  std::vector<std::uint32_t> scratch(nt, invalid_id), next(nt);
  std::uint32_t next_count = 0;
  const region_growing_options go{static_cast<double>(ch.threshold), o.min_cluster_fraction, o.grain, nt};
  for (std::uint32_t k = 0; k < count; ++k) {
    const std::span<const std::uint32_t> set(tris.data() + offsets[k], offsets[k + 1] - offsets[k]);
    auto clock = std::chrono::steady_clock::now();
    auto state = ch.init(set);
    if (!state) return state.error();
    rep.init_seconds += lap(clock);
    const element_graph g = subset_graph(topo, set, scratch);
    auto r = grow_regions(*state, g, go, exec);
    if (!r) return r.error();
    rep.growth_seconds += lap(clock);
    if (o.smooth_boundaries) rep.smoothed_triangles += smooth_boundaries(*state, g, m, set, go.threshold, *r);
    rep.smoothing_seconds += lap(clock);
    for (std::size_t i = 0; i < set.size(); ++i) next[set[i]] = next_count + r->cluster_of[i];
    next_count += r->cluster_count();
    rep.seeds += r->parallel_seeds;
    rep.sequential_seeds += r->sequential_seeds;
    rep.merged += r->merged;
    rep.all_alike_sets += r->all_alike ? 1u : 0u;
  }
  label = std::move(next);
  count = next_count;
  rep.clusters_after = count;
  return {};
}

template <class C, class M, class T, class E>
status apply_channel(const C& c, const M& m, const mesh_topology& topo, const T& tracer, const cluster_options& o,
                     E& exec, std::vector<std::uint32_t>& label, std::uint32_t& count, channel_report& rep) {
  if constexpr (requires { c.prepare(m, topo, tracer, exec); }) {
    auto clock = std::chrono::steady_clock::now();
    auto p = c.prepare(m, topo, tracer, exec);
    if (!p) return p.error();
    rep.prepare_seconds = lap(clock);
    return run_channel(*p, m, topo, o, exec, label, count, rep);
  } else {
    return run_channel(c, m, topo, o, exec, label, count, rep);
  }
}

// Algorithm 1 starting from `label` (count clusters).
template <class M, class T, class E, class... C>
status algorithm1(const M& m, const mesh_topology& topo, const T& tracer, E& exec, const cluster_options& o,
                  mesh_clustering& out, const C&... channels) {
  out.channels.assign(sizeof...(C), channel_report{});
  status st;
  std::size_t i = 0;
  auto step = [&](const auto& c) {
    if (st.ok()) st = apply_channel(c, m, topo, tracer, o, exec, out.cluster_of, out.cluster_count, out.channels[i]);
    ++i;
  };
  (step(channels), ...);
  if (!st.ok()) return st;
  std::vector<std::uint32_t> seeds(out.cluster_count, 0);
  canonical_numbering(out.cluster_of, seeds);
  out.cluster_count = static_cast<std::uint32_t>(seeds.size());
  return {};
}

template <class M, class E, class... C>
status check_inputs(const M& m, const cluster_options& o, const C&... channels) {
  if (mesh_triangle_count(m) == 0) return make_error(errc::empty_input, no_element, "cluster_mesh: mesh has no triangles");
  if (!(o.min_cluster_fraction >= 0.0 && o.min_cluster_fraction <= 1.0))
    return make_error(errc::bad_parameter, no_element, "cluster_mesh: min_cluster_fraction ", o.min_cluster_fraction,
                      " outside [0, 1]");
  status st;
  std::size_t i = 0;
  auto check = [&](const auto& c) {
    if (st.ok() && !(c.threshold >= 0.0 && c.threshold <= 1.0))
      st = make_error(errc::bad_parameter, i, "cluster_mesh: channel ", i, ": threshold ", static_cast<double>(c.threshold),
                      " outside [0, 1] (or NaN)");
    ++i;
  };
  (check(channels), ...);
  if (!st.ok()) return st;
  // Indices and finite positions; degenerate triangles and non-manifold edges are accepted
  // (their rows are defined, see the channels).
  return validate_mesh(m, {.allow_degenerate = true, .allow_non_manifold = true});
}

}  // namespace detail

// Algorithm 1 over `channels` (at least one), in the order given.
// Errors: empty mesh, index out of range, non-finite positions (names the triangle and vertex),
// a threshold outside [0,1] or NaN (names the channel), bad options, a channel's own errors.
// Complexity: the channels' prepare (visibility: T·N·n² rays) plus, per channel and set of M
// triangles, the seeds' JS columns (O(U²) for binned direct channels, O(M·N) per seed for
// visibility) and O(M) growth. Allocation O(T) plus the channels' (visibility: T·N bytes).
// Thread-safety: the tracer and channel states are used from the executor's threads.
template <class M, class T, class E, class... C>
result<mesh_clustering> cluster_mesh(const M& m, const T& tracer, E&& exec, const cluster_options& opts,
                                     const C&... channels) {
  static_assert(check_mesh<M>());
  static_assert(detail::check_cluster_tracer<T>());
  static_assert(check_executor<std::remove_cvref_t<E>>());
  static_assert(sizeof...(C) >= 1, "infolerp: cluster_mesh needs at least one channel");
  static_assert((clustering_channel<C, M, T, std::remove_cvref_t<E>> && ...),
                "infolerp: each channel needs a `threshold` and init(span<const uint32_t>) -> result<channel_state>, "
                "or prepare(mesh, topology, tracer, executor) (see cluster/channel.hpp)");
  constexpr bool traces_without_tracer =
      std::is_same_v<T, no_tracer> && (std::is_same_v<C, visibility_channel> || ...);
  static_assert(!traces_without_tracer,
                "infolerp: visibility_channel traces rays: pass a tracer instead of no_tracer (or the channel prepared)");
  if constexpr (traces_without_tracer) {
    return make_error(errc::bad_parameter, no_element, "cluster_mesh: visibility_channel without a tracer");
  } else {
    if (status st = detail::check_inputs<M, E>(m, opts, channels...); !st) return st;
    auto topo = make_topology(m);
    if (!topo) return topo.error();
    mesh_clustering out;
    out.cluster_of.assign(mesh_triangle_count(m), 0);
    out.cluster_count = 1;
    if (status st = detail::algorithm1(m, *topo, tracer, exec, opts, out, channels...); !st) return st;
    return out;
  }
}

// The same with default options.
template <class M, class T, class E, class C0, class... C>
  requires(!std::is_same_v<std::remove_cvref_t<C0>, cluster_options>)
result<mesh_clustering> cluster_mesh(const M& m, const T& tracer, E&& exec, const C0& first, const C&... rest) {
  return cluster_mesh(m, tracer, std::forward<E>(exec), cluster_options{}, first, rest...);
}

// A keyframe of a keyframed mesh seen as a plain mesh (positions from keyframe k).
template <class M>
struct keyframe_view {
  const M* mesh = nullptr;
  std::size_t keyframe = 0;
  std::size_t vertex_count() const { return mesh_vertex_count(*mesh); }
  std::size_t triangle_count() const { return mesh_triangle_count(*mesh); }
  glm::vec3 position(std::size_t v) const { return mesh_traits<M>::keyframe_position(*mesh, keyframe, v); }
  glm::uvec3 triangle(std::size_t t) const { return mesh_triangle(*mesh, t); }
  bool has_texcoords() const { return mesh_has_texcoords(*mesh); }
  glm::vec2 texcoord(std::size_t t, unsigned c) const requires textured_mesh<M> { return mesh_traits<M>::texcoord(*mesh, t, c); }
};

// §3.4: Algorithm 1 for keyframe 0, then for each later keyframe starting from the previous
// keyframe's clusters (so clusters only ever split and stay consistent over the animation).
// tracer_of(k) returns the tracer of keyframe k's geometry (called once per keyframe).
// Errors: as cluster_mesh, a mesh without keyframes (empty_input), a keyframe whose position
// count differs from the vertex count (bad_size, naming the keyframe; checked before any
// position is read, where the mesh type offers keyframe_vertex_count), non-finite positions.
// Complexity: keyframe_count × cluster_mesh.
template <class M, class F, class E, class... C>
result<mesh_clustering> cluster_keyframes(const M& m, F&& tracer_of, E&& exec, const cluster_options& opts,
                                          const C&... channels) {
  static_assert(check_mesh<M>());
  static_assert(keyframed_mesh<M>, "infolerp: cluster_keyframes needs keyframe_count() and keyframe_position(k, v)");
  static_assert(check_executor<std::remove_cvref_t<E>>());
  const std::size_t nk = mesh_keyframe_count(m);
  if (nk == 0) return make_error(errc::empty_input, no_element, "cluster_keyframes: mesh has no keyframes");
  for (std::size_t k = 0; k < nk; ++k)
    if (const std::size_t n = mesh_keyframe_vertex_count(m, k); n != mesh_vertex_count(m))
      return make_error(errc::bad_size, k, "cluster_keyframes: keyframe ", k, " has ", n, " positions for ",
                        mesh_vertex_count(m), " vertices");
  auto topo = make_topology(m);
  if (!topo) return topo.error();
  mesh_clustering out;
  out.cluster_of.assign(mesh_triangle_count(m), 0);
  out.cluster_count = 1;
  for (std::size_t k = 0; k < nk; ++k) {
    const keyframe_view<M> view{&m, k};
    if (status st = detail::check_inputs<keyframe_view<M>, E>(view, opts, channels...); !st) return st;
    const auto& tracer = tracer_of(k);
    static_assert(check_tracer<std::remove_cvref_t<decltype(tracer)>>());
    if (status st = detail::algorithm1(view, *topo, tracer, exec, opts, out, channels...); !st) return st;
  }
  return out;
}

}  // namespace infolerp
