#pragma once
// An Embree 3 tracer for infolerp, small enough to copy into an engine: one triangle mesh, single
// rays and batched occlusion. infolerp itself never includes Embree; this file is an example.
//
//   RTCDevice device = rtcNewDevice(nullptr);
//   auto tracer = example::embree_tracer::create(device, mesh);     // any infolerp mesh
//   if (!tracer) log(tracer.error().message());                      // bad index, NaN, Embree error
//   auto ids = infolerp::cluster_mesh(mesh, *tracer, exec, infolerp::visibility_channel{});
//
// Tracing is const and thread-safe after create(). Embree recommends flush-to-zero and
// denormals-are-zero on every thread that traces (_MM_SET_FLUSH_ZERO_MODE, _MM_SET_DENORMALS_ZERO_MODE).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>
#include <embree3/rtcore.h>
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/mesh/validate.hpp"

namespace example {

class embree_tracer {
 public:
  // Copies the mesh's positions and indices into buffers Embree shares, then builds the BVH.
  // Errors: what validate_mesh refuses (Embree does not check indices), an Embree failure.
  template <class M>
  static infolerp::result<embree_tracer> create(RTCDevice device, const M& mesh) {
    if (auto ok = infolerp::validate_mesh(mesh, {.allow_degenerate = true, .allow_non_manifold = true}); !ok) return ok;
    embree_tracer t;
    const std::size_t nv = infolerp::mesh_vertex_count(mesh), nt = infolerp::mesh_triangle_count(mesh);
    // Embree reads each vertex with one 16-byte load, so the last vertex needs a float after it.
    t.positions_.resize(3 * nv + 1);
    t.indices_.resize(3 * nt);
    for (std::size_t v = 0; v < nv; ++v) {
      const glm::vec3 p = infolerp::mesh_position(mesh, v);
      std::copy_n(&p.x, 3, &t.positions_[3 * v]);
    }
    for (std::size_t i = 0; i < nt; ++i) {
      const glm::uvec3 tri = infolerp::mesh_triangle(mesh, i);
      std::copy_n(&tri.x, 3, &t.indices_[3 * i]);
    }
    t.scene_ = rtcNewScene(device);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, t.positions_.data(), 0,
                               3 * sizeof(float), nv);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, t.indices_.data(), 0,
                               3 * sizeof(unsigned), nt);
    rtcCommitGeometry(g);
    rtcAttachGeometry(t.scene_, g);  // geometry id 0
    rtcReleaseGeometry(g);
    rtcCommitScene(t.scene_);
    if (const RTCError e = rtcGetDeviceError(device); e != RTC_ERROR_NONE)
      return infolerp::make_error(infolerp::errc::bad_parameter, infolerp::no_element, "embree_tracer: Embree error ",
                                  static_cast<int>(e));
    return t;
  }

  embree_tracer(embree_tracer&& o) noexcept
      : scene_(std::exchange(o.scene_, nullptr)), positions_(std::move(o.positions_)), indices_(std::move(o.indices_)) {}
  embree_tracer& operator=(embree_tracer&&) = delete;
  embree_tracer(const embree_tracer&) = delete;
  embree_tracer& operator=(const embree_tracer&) = delete;
  ~embree_tracer() {
    if (scene_ != nullptr) rtcReleaseScene(scene_);
  }

  bool occluded(const infolerp::ray& r) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay er = to_embree(r);
    rtcOccluded1(scene_, &context, &er);
    return er.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
  }

  infolerp::hit intersect(const infolerp::ray& r) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray = to_embree(r);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
    return {rh.hit.geomID, rh.hit.primID, {rh.hit.u, rh.hit.v}, rh.ray.tfar};
  }

  // Batched occlusion as an Embree ray stream, used by the library when present.
  void occluded(std::span<const infolerp::ray> rays, std::span<std::uint8_t> out) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    constexpr std::size_t chunk = 64;
    RTCRay er[chunk];
    for (std::size_t base = 0; base < rays.size(); base += chunk) {
      const std::size_t n = std::min(chunk, rays.size() - base);
      for (std::size_t i = 0; i < n; ++i) er[i] = to_embree(rays[base + i]);
      rtcOccluded1M(scene_, &context, er, static_cast<unsigned>(n), sizeof(RTCRay));
      for (std::size_t i = 0; i < n; ++i) out[base + i] = er[i].tfar < 0.0f ? 1 : 0;
    }
  }

 private:
  embree_tracer() = default;
  static RTCRay to_embree(const infolerp::ray& r) {
    RTCRay e;
    e.org_x = r.origin.x, e.org_y = r.origin.y, e.org_z = r.origin.z, e.tnear = r.tnear;
    e.dir_x = r.direction.x, e.dir_y = r.direction.y, e.dir_z = r.direction.z, e.time = 0.0f;
    e.tfar = r.tfar, e.mask = ~0u, e.id = 0, e.flags = 0;
    return e;
  }

  RTCScene scene_ = nullptr;
  std::vector<float> positions_;   // 3 per vertex + 1 float of padding
  std::vector<unsigned> indices_;  // 3 per triangle
};

static_assert(infolerp::batch_occlusion_tracer<embree_tracer>);

}  // namespace example
