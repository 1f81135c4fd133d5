#pragma once
// The values progressive_refiner (refine/progressive_driver.hpp) takes and gives: its options,
// what one refine() call may do and did, a shading request, the display's incremental delta
// (Oliveira et al. §2) and the figures of Table 1 (§5).
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "infolerp/refine/criteria.hpp"
#include "infolerp/refine/subdivision_mesh.hpp"

namespace infolerp {

// What the shading callback gets for one vertex.
struct shading_point {
  std::uint32_t vertex = invalid_id;     // vertex id in the subdivision mesh
  glm::vec3 position{0.0f};              // its world position
  glm::vec3 normal{0.0f};                // unit geometric normal of `triangle`
  std::uint32_t triangle = invalid_id;   // an original triangle it lies in
  glm::vec2 barycentric{0.0f};           // Embree-style (u, v) of the position in that triangle
};

struct stage_figures {
  std::size_t triangles = 0;           // Δ: leaves shown
  std::size_t triangles_total = 0;     // Δ_total: triangles sent to the visualizer since the view was set (Table 1)
  std::size_t triangles_produced = 0;  // every triangle the hierarchy holds
  std::size_t shading_samples = 0;     // vertices shaded so far
  double seconds = 0.0;                // wall time since the run started
};

struct refinement_report {
  stage_figures stage1, stage2;
  std::size_t batches = 0;      // batches of R run in stage 2
  std::size_t selections = 0;   // triangles the criterion selected
  bool budget_reached = false;  // stage 2 stopped on the shading budget or max_batches
};

struct driver_options {
  criteria_options criteria{};                                              // which criterion and its settings
  std::size_t max_shading_samples = std::numeric_limits<std::size_t>::max();  // stop once this many vertices are shaded
  std::size_t max_batches = std::numeric_limits<std::size_t>::max();          // stop after this many batches
  std::size_t max_cached_samples = std::numeric_limits<std::size_t>::max();  // cache bound (>= 1), see progressive_driver.hpp
  std::size_t max_hierarchy_triangles = std::numeric_limits<std::size_t>::max();  // hierarchy bound (>= 1), ditto
  glm::vec3 background{0.0f};                                              // colour of pixels without a hit or shown triangle
  std::size_t grain = 4096;                                                // executor grain (pixels, vertices)
};

// What one call of refine() did.
enum class refine_progress : std::uint8_t {
  refined,     // selected and split at least one batch; new requests may be waiting
  waiting,     // requests are outstanding: deliver them first
  finished,    // the criterion selects nothing more in this view
  cache_full,  // the cache holds max_cached_samples: no further refinement in this view
};

// How much one refine() call may do (§4.1: control returns to the caller after R selections).
struct refine_budget {
  std::size_t batches = 1;                                         // batches of R selections
  std::size_t samples = std::numeric_limits<std::size_t>::max();   // shading samples to request
  double seconds = std::numeric_limits<double>::infinity();        // wall time, checked between batches
};

// The incremental protocol of §2: how the shown set changed, in the paper's order.
struct display_delta {
  std::vector<std::uint32_t> added_from_cache;  // shown now, every corner shaded before the last delta
  std::vector<std::uint32_t> deleted;           // shown at the last delta, not now
  std::vector<std::uint32_t> newly_shaded;      // shown now, a corner delivered since the last delta
  void clear() {
    added_from_cache.clear();
    deleted.clear();
    newly_shaded.clear();
  }
};

}  // namespace infolerp
