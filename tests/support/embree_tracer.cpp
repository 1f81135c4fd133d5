#include "support/embree_tracer.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#if defined(__SSE__) || defined(_M_X64)
#include <pmmintrin.h>
#include <xmmintrin.h>
#endif

namespace infolerp::support {

void enable_flush_to_zero() {
#if defined(__SSE__) || defined(_M_X64)
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#endif
}

namespace {

void report_embree_error(void* /*user*/, RTCError code, const char* message) {
  std::fprintf(stderr, "embree error %d: %s\n", static_cast<int>(code), message ? message : "");
}

constexpr unsigned packet = 16;

void to_embree(const ray& r, RTCRay& out) {
  out.org_x = r.origin.x;
  out.org_y = r.origin.y;
  out.org_z = r.origin.z;
  out.tnear = r.tnear;
  out.dir_x = r.direction.x;
  out.dir_y = r.direction.y;
  out.dir_z = r.direction.z;
  out.time = 0.0f;
  out.tfar = r.tfar;
  out.mask = ~0u;
  out.id = 0;
  out.flags = 0;
}

// Lane i of a 16-wide packet (RTCRay16 and RTCRayHit16::ray share this layout).
void to_embree(const ray& r, RTCRay16& out, unsigned i) {
  out.org_x[i] = r.origin.x;
  out.org_y[i] = r.origin.y;
  out.org_z[i] = r.origin.z;
  out.tnear[i] = r.tnear;
  out.dir_x[i] = r.direction.x;
  out.dir_y[i] = r.direction.y;
  out.dir_z[i] = r.direction.z;
  out.time[i] = 0.0f;
  out.tfar[i] = r.tfar;
  out.mask[i] = ~0u;
  out.id[i] = i;
  out.flags[i] = 0;
}

// Embree valid mask: lanes [0, n) active (-1), the rest off (0).
void set_valid(int (&valid)[packet], std::size_t n) {
  for (unsigned i = 0; i < packet; ++i) valid[i] = i < n ? -1 : 0;
}

}  // namespace

// ---- device ---------------------------------------------------------------------------------

namespace {
// The caller's configuration followed by INFOLERP_EMBREE_CONFIG's (Embree reads the last value of
// a key), so that a whole test run can be moved to other kernels, e.g. "max_isa=sse4.2".
std::string device_config(const char* config) {
  std::string s = config ? config : "";
  if (const char* env = std::getenv("INFOLERP_EMBREE_CONFIG"); env && *env) {
    if (!s.empty()) s.push_back(',');
    s.append(env);
  }
  return s;
}
}  // namespace

embree_device::embree_device(const char* config) : device_(rtcNewDevice(device_config(config).c_str())) {
  if (device_ == nullptr) {
    std::fprintf(stderr, "infolerp: cannot create an Embree device (error %d)\n",
                 static_cast<int>(rtcGetDeviceError(nullptr)));
    std::abort();
  }
  rtcSetDeviceErrorFunction(device_, report_embree_error, nullptr);
}

embree_device::embree_device(embree_device&& other) noexcept : device_(std::exchange(other.device_, nullptr)) {}

embree_device& embree_device::operator=(embree_device&& other) noexcept {
  if (this != &other) {
    if (device_) rtcReleaseDevice(device_);
    device_ = std::exchange(other.device_, nullptr);
  }
  return *this;
}

embree_device::~embree_device() {
  if (device_) rtcReleaseDevice(device_);
}

// ---- scene ----------------------------------------------------------------------------------

namespace {
// Occlusion filter of embree_scene_options::occlude_front_faces_only: Embree's geometric normal
// is the counter-clockwise one; a hit whose normal points along the ray is a back face.
void reject_back_faces(const RTCFilterFunctionNArguments* args) {
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const float d = RTCHitN_Ng_x(args->hit, args->N, i) * RTCRayN_dir_x(args->ray, args->N, i) +
                    RTCHitN_Ng_y(args->hit, args->N, i) * RTCRayN_dir_y(args->ray, args->N, i) +
                    RTCHitN_Ng_z(args->hit, args->N, i) * RTCRayN_dir_z(args->ray, args->N, i);
    if (d > 0.0f) args->valid[i] = 0;
  }
}
}  // namespace

embree_scene::embree_scene(const embree_device& device, const embree_scene_options& options)
    : device_(device.handle()) {
  INFOLERP_ASSERT(device_ != nullptr && "embree_scene built from a moved-from device");
  rtcRetainDevice(device_);
  scene_ = rtcNewScene(device_);
  rtcSetSceneFlags(scene_, options.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
  rtcSetSceneBuildQuality(scene_, options.quality);
  coherent_streams_ = options.coherent_streams;
  front_faces_only_ = options.occlude_front_faces_only;
}

embree_scene::embree_scene(embree_scene&& other) noexcept
    : device_(std::exchange(other.device_, nullptr)),
      scene_(std::exchange(other.scene_, nullptr)),
      geometry_count_(std::exchange(other.geometry_count_, 0)),
      committed_(std::exchange(other.committed_, false)),
      coherent_streams_(other.coherent_streams_),
      front_faces_only_(other.front_faces_only_) {}

embree_scene& embree_scene::operator=(embree_scene&& other) noexcept {
  if (this != &other) {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
    device_ = std::exchange(other.device_, nullptr);
    scene_ = std::exchange(other.scene_, nullptr);
    geometry_count_ = std::exchange(other.geometry_count_, 0);
    committed_ = std::exchange(other.committed_, false);
    coherent_streams_ = other.coherent_streams_;
    front_faces_only_ = other.front_faces_only_;
  }
  return *this;
}

embree_scene::~embree_scene() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

result<std::uint32_t> embree_scene::add_triangles(std::span<const glm::vec3> positions,
                                                  std::span<const glm::uvec3> triangles) {
  if (committed_)
    return make_error(errc::unsupported, no_element, "embree_scene: add_mesh after commit()");
  if (positions.empty() || triangles.empty())
    return make_error(errc::empty_input, no_element, "embree_scene: mesh ", geometry_count_, " has ",
                      positions.size(), " vertices and ", triangles.size(), " triangles");
  constexpr std::size_t max_count = std::numeric_limits<std::uint32_t>::max();
  if (positions.size() > max_count || triangles.size() > max_count)
    return make_error(errc::bad_parameter, no_element, "embree_scene: mesh ", geometry_count_,
                      " has more than 2^32 vertices or triangles");
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const glm::uvec3 tri = triangles[t];
    if (std::max({tri.x, tri.y, tri.z}) >= positions.size())
      return make_error(errc::index_out_of_range, t, "embree_scene: mesh ", geometry_count_, " triangle ", t,
                        ": vertex index ", std::max({tri.x, tri.y, tri.z}), " >= vertex count ", positions.size());
  }

  RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), positions.size()));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), triangles.size()));
  if (vertices == nullptr || indices == nullptr) {
    rtcReleaseGeometry(geometry);
    return make_error(errc::bad_parameter, no_element, "embree_scene: Embree could not allocate mesh ",
                      geometry_count_, " (error ", static_cast<int>(rtcGetDeviceError(device_)), ")");
  }
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float) && sizeof(glm::uvec3) == 3 * sizeof(unsigned));
  std::memcpy(vertices, positions.data(), positions.size_bytes());
  std::memcpy(indices, triangles.data(), triangles.size_bytes());
  if (front_faces_only_) rtcSetGeometryOccludedFilterFunction(geometry, reject_back_faces);
  rtcCommitGeometry(geometry);
  rtcAttachGeometryByID(scene_, geometry, geometry_count_);
  rtcReleaseGeometry(geometry);  // the scene holds it now
  return geometry_count_++;
}

status embree_scene::commit() {
  if (committed_) return make_error(errc::unsupported, no_element, "embree_scene: commit() called twice");
  rtcCommitScene(scene_);
  if (const RTCError e = rtcGetDeviceError(device_); e != RTC_ERROR_NONE)
    return make_error(errc::bad_parameter, no_element, "embree_scene: commit failed with Embree error ",
                      static_cast<int>(e));
  committed_ = true;
  return {};
}

bool embree_scene::occluded(const ray& r) const {
  INFOLERP_ASSERT(committed_);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay er;
  to_embree(r, er);
  rtcOccluded1(scene_, &context, &er);
  return er.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

hit embree_scene::intersect(const ray& r) const {
  INFOLERP_ASSERT(committed_);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  to_embree(r, rh.ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
  return {rh.hit.geomID, rh.hit.primID, {rh.hit.u, rh.hit.v}, rh.ray.tfar};
}

void embree_scene::occluded(std::span<const ray> rays, std::span<std::uint8_t> out) const {
  INFOLERP_ASSERT(committed_ && out.size() >= rays.size());
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  if (coherent_streams_) {
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    constexpr std::size_t stream = 256;
    RTCRay er[stream];
    for (std::size_t base = 0; base < rays.size(); base += stream) {
      const std::size_t n = std::min(stream, rays.size() - base);
      for (std::size_t i = 0; i < n; ++i) to_embree(rays[base + i], er[i]);
      rtcOccluded1M(scene_, &context, er, static_cast<unsigned>(n), sizeof(RTCRay));
      for (std::size_t i = 0; i < n; ++i) out[base + i] = er[i].tfar < 0.0f ? 1 : 0;
    }
    return;
  }
  alignas(64) int valid[packet];
  alignas(64) RTCRay16 er;
  for (std::size_t base = 0; base < rays.size(); base += packet) {
    const std::size_t n = std::min<std::size_t>(packet, rays.size() - base);
    set_valid(valid, n);
    for (unsigned i = 0; i < packet; ++i) to_embree(i < n ? rays[base + i] : ray{}, er, i);
    rtcOccluded16(valid, scene_, &context, &er);
    for (unsigned i = 0; i < n; ++i) out[base + i] = er.tfar[i] < 0.0f ? 1 : 0;
  }
}

void embree_scene::intersect(std::span<const ray> rays, std::span<hit> out) const {
  INFOLERP_ASSERT(committed_ && out.size() >= rays.size());
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  alignas(64) int valid[packet];
  alignas(64) RTCRayHit16 rh;
  for (std::size_t base = 0; base < rays.size(); base += packet) {
    const std::size_t n = std::min<std::size_t>(packet, rays.size() - base);
    set_valid(valid, n);
    for (unsigned i = 0; i < packet; ++i) {
      to_embree(i < n ? rays[base + i] : ray{}, rh.ray, i);
      rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.primID[i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, scene_, &context, &rh);
    for (unsigned i = 0; i < n; ++i) {
      out[base + i] = rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID
                          ? hit{}
                          : hit{rh.hit.geomID[i], rh.hit.primID[i], {rh.hit.u[i], rh.hit.v[i]}, rh.ray.tfar[i]};
    }
  }
}

}  // namespace infolerp::support
