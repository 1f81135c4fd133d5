#pragma once
// A wrapper around a prepared channel whose states forward every member of the channel's state,
// estimate() only when Estimate, and count the divergences evaluated (divergence() calls and
// divergences() entries; serial executor only): the clustering with and without the JS
// estimate, for the equivalence test (tests/cluster/test_clustering.cpp) and the benchmark
// baseline (benchmarks/bench_clustering.cpp).
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include "infolerp/cluster/channel.hpp"

namespace infolerp::support {

template <class S, bool Estimate>
struct counting_state {
  S s;
  std::size_t* divergences_evaluated;
  std::size_t element_count() const { return s.element_count(); }
  std::size_t class_count() const { return s.class_count(); }
  std::uint32_t class_of(std::uint32_t i) const { return s.class_of(i); }
  double mutual_information(std::uint32_t a) const { return s.mutual_information(a); }
  double divergence(std::uint32_t a, std::uint32_t b) const {
    ++*divergences_evaluated;  // the serial executor only
    return s.divergence(a, b);
  }
  double estimate(std::uint32_t a, std::uint32_t b) const requires Estimate { return s.estimate(a, b); }
  double estimate_error() const requires Estimate { return s.estimate_error(); }
  bool all_alike() const requires requires(const S& x) { x.all_alike(); } { return s.all_alike(); }
  bool surely_within(std::uint32_t a, std::uint32_t b, double th) const
    requires requires(const S& x) { x.surely_within(a, b, th); } { return s.surely_within(a, b, th); }
  double mutual_information_lower_bound(std::uint32_t a) const
    requires requires(const S& x) { x.mutual_information_lower_bound(a); } { return s.mutual_information_lower_bound(a); }
  std::uint32_t representative(std::uint32_t a) const
    requires requires(const S& x) { x.representative(a); } { return s.representative(a); }
  void prefetch(std::uint32_t a) const requires requires(const S& x) { x.prefetch(a); } { s.prefetch(a); }
  void divergences(std::uint32_t a, std::uint32_t first, std::span<float> out) const
    requires requires(const S& x) { x.divergences(a, first, out); } {
    *divergences_evaluated += out.size();
    s.divergences(a, first, out);
  }
};
template <class P, bool Estimate>
struct counting_channel {
  const P* p;
  double threshold;
  std::size_t* divergences_evaluated;
  const char* skip_reason() const requires requires(const P& x) { x.skip_reason(); } { return p->skip_reason(); }
  auto init(std::span<const std::uint32_t> tris) const -> result<counting_state<channel_state_of<P>, Estimate>> {
    auto st = p->init(tris);
    if (!st) return st.error();
    return counting_state<channel_state_of<P>, Estimate>{std::move(*st), divergences_evaluated};
  }
};

}  // namespace infolerp::support
