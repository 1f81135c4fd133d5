#pragma once
// Embree 3 behind infolerp's tracer concept (core/tracer.hpp), for tests, benchmarks and the
// demo. The library itself never includes Embree.
//
//   support::embree_device device;                 // RAII, move-only
//   support::embree_scene scene{device};           // RAII, move-only, keeps the device alive
//   auto id = scene.add_mesh(mesh);                // geometry id: 0, 1, 2 ... in order added
//   if (auto s = scene.commit(); !s) ...           // build the BVH; then trace from any thread
//   infolerp::hit h = scene.intersect(ray);
//
// Threads: call enable_flush_to_zero() once on every thread that traces (Embree's
// recommendation: denormals make traversal slow, and a thread without FTZ/DAZ may round
// differently from one with it, which would make renders depend on the thread count).
// Tracing (occluded/intersect, single or batched) is const and thread-safe after commit().
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>
#include <embree3/rtcore.h>
#include <glm/vec3.hpp>
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"

namespace infolerp::support {

// Sets flush-to-zero and denormals-are-zero in the calling thread's MXCSR (no-op off x86).
// Call it at the start of every worker thread (or every parallel task) that traces or shades.
void enable_flush_to_zero();

// An Embree device (RTCDevice). Move-only; the handle is released when the last owner (this or
// a scene built from it) goes away.
class embree_device {
 public:
  // `config` is Embree's device configuration string ("" = defaults, e.g. "threads=1"); the
  // environment variable INFOLERP_EMBREE_CONFIG is appended to it (CI moves runs to other ISAs).
  // Device creation failure (e.g. an unsupported CPU) is fatal: it prints Embree's error and aborts.
  explicit embree_device(const char* config = "");
  embree_device(embree_device&& other) noexcept;
  embree_device& operator=(embree_device&& other) noexcept;
  embree_device(const embree_device&) = delete;
  embree_device& operator=(const embree_device&) = delete;
  ~embree_device();

  RTCDevice handle() const { return device_; }

 private:
  RTCDevice device_ = nullptr;
};

struct embree_scene_options {
  bool robust = true;                                  // RTC_SCENE_FLAG_ROBUST: watertight, no accuracy-reducing shortcuts
  RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;  // BVH build quality (HIGH adds spatial splits: slower build)
  // Batched occlusion as one Embree ray stream (rtcOccluded1M) flagged coherent instead of
  // 16-ray packets: Embree regroups the stream itself, which pays when the caller orders its
  // rays coherently (e.g. visibility_channel::coherent). Same answers per ray.
  bool coherent_streams = false;
  // occluded() ignores hits on a triangle's back (geometric normal, counter-clockwise winding,
  // along the ray): occlusion by closed meshes seen from outside, and no self-shadowing of a
  // surface drawn just inside one (a LOD's triangles shadowed by the full mesh). intersect() is unchanged.
  bool occlude_front_faces_only = false;
};

// A scene of triangle meshes that models infolerp::tracer, batch_occlusion_tracer and
// batch_intersection_tracer. Move-only.
class embree_scene {
 public:
  explicit embree_scene(const embree_device& device, const embree_scene_options& options = {});
  embree_scene(embree_scene&& other) noexcept;
  embree_scene& operator=(embree_scene&& other) noexcept;
  embree_scene(const embree_scene&) = delete;
  embree_scene& operator=(const embree_scene&) = delete;
  ~embree_scene();

  // Adds any infolerp mesh (copied into Embree's buffers) before commit(). Returns its geometry
  // id: the number of meshes added before it. Errors (nothing is added): an empty mesh, a vertex
  // index out of range, more than 2^32 vertices or triangles, adding after commit().
  // O(V + T) time; allocates Embree buffers of V vertices and T triangles.
  template <class M>
  result<std::uint32_t> add_mesh(const M& m) {
    static_assert(check_mesh<M>());
    std::vector<glm::vec3> positions(mesh_vertex_count(m));
    std::vector<glm::uvec3> triangles(mesh_triangle_count(m));
    for (std::size_t v = 0; v < positions.size(); ++v) positions[v] = mesh_position(m, v);
    for (std::size_t t = 0; t < triangles.size(); ++t) triangles[t] = mesh_triangle(m, t);
    return add_triangles(positions, triangles);
  }
  // The same from plain arrays.
  result<std::uint32_t> add_triangles(std::span<const glm::vec3> positions, std::span<const glm::uvec3> triangles);

  // Builds the BVH. Must be called once, after the last add_mesh and before any trace.
  // An empty scene commits fine (every ray misses). Errors: Embree reports a failure.
  status commit();

  [[nodiscard]] bool committed() const { return committed_; }
  [[nodiscard]] std::uint32_t geometry_count() const { return geometry_count_; }
  RTCScene handle() const { return scene_; }

  // Tracing. Preconditions: committed(); out.size() >= rays.size() for the batch overloads.
  // Batches are traced as 16-ray packets (rtcOccluded16 / rtcIntersect16); the tail that is not
  // a multiple of 16 goes in one packet with the unused lanes masked off. With coherent_streams,
  // batched occlusion goes through rtcOccluded1M instead (chunks of 256 rays).
  bool occluded(const ray& r) const;
  hit intersect(const ray& r) const;
  void occluded(std::span<const ray> rays, std::span<std::uint8_t> out) const;
  void intersect(std::span<const ray> rays, std::span<hit> out) const;

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::uint32_t geometry_count_ = 0;
  bool committed_ = false;
  bool coherent_streams_ = false;
  bool front_faces_only_ = false;
};

static_assert(batch_occlusion_tracer<embree_scene> && batch_intersection_tracer<embree_scene>);

}  // namespace infolerp::support
