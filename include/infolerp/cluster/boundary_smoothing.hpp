#pragma once
// Boundary smoothing (clustering paper §3.3). Placeholder until implemented: moves nothing.
#include <cstdint>
#include <span>
#include "infolerp/cluster/region_growing.hpp"

namespace infolerp {

template <class S, class M>
std::uint32_t smooth_boundaries(const S& /*state*/, const element_graph& /*g*/, const M& /*m*/,
                                std::span<const std::uint32_t> /*triangles*/, double /*threshold*/,
                                region_growing_result& /*r*/) {
  return 0;
}

}  // namespace infolerp
