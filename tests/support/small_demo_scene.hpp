#pragma once
// The demo scene at test size (a coarser sphere and torus), for the upsampler's tests. Each
// test file builds and keeps its own copy: test_frame_reuse.cpp moves its scene's camera, and a
// shared one would let that leak into another file's frames.
#include <utility>
#include <catch2/catch.hpp>
#include "support/demo_scene.hpp"

namespace infolerp::support {

inline demo_scene make_small_demo_scene(const embree_device& device) {
  demo_scene_options small;
  small.sphere_slices = 24;
  small.sphere_stacks = 12;
  small.torus_major = 24;
  small.torus_minor = 8;
  auto built = make_demo_scene(device, small);
  REQUIRE(built.ok());
  return std::move(*built);
}

}  // namespace infolerp::support
