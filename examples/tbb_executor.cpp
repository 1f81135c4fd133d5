// oneTBB as infolerp's job system (examples/tbb_executor.hpp): clusters a real mesh (fandisk,
// orientation channel, and visibility through Embree) and upsamples the demo scene with the
// serial, OpenMP and oneTBB executors on 1 and 2 threads, and exits non-zero unless every
// result is the same bit for bit.
#include <cstdio>
#include <cstring>
#include <span>
#include <string>
#include <vector>
#include "infolerp/cluster/cluster_mesh.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "support/demo_clusters.hpp"
#include "support/demo_upsample.hpp"
#include "support/mesh_io.hpp"
#include "tbb_executor.hpp"

namespace sup = infolerp::support;

namespace {

template <class E>
infolerp::result<infolerp::mesh_clustering> cluster(const infolerp::indexed_mesh& m, const sup::embree_scene& tracer, E&& exec) {
  return infolerp::cluster_mesh(m, tracer, exec, infolerp::visibility_channel{.threshold = 0.48, .viewpoints = 16},
                                infolerp::orientation_channel{.threshold = 0.05, .bins = 256});
}

// Every thread that traces rounds alike (Embree's flush-to-zero; embree_tracer.hpp).
template <class E>
struct flush_to_zero_executor {
  E inner;
  template <class F>
  void parallel_for(std::size_t n, std::size_t grain, F&& fn) const {
    inner.parallel_for(n, grain, [&](std::size_t begin, std::size_t end) {
      sup::enable_flush_to_zero();
      fn(begin, end);
    });
  }
};

template <class S, class E>
std::vector<glm::vec3> upsample(const S& src, std::uint32_t w, std::uint32_t h, E exec) {
  std::vector<glm::vec3> out(std::size_t{w} * h);
  auto up = infolerp::upsampler<sup::demo_sample>::create(w, h, {.passes = 4, .max_passes = 4});
  if (!up || !up->render(src, std::span<glm::vec3>(out), flush_to_zero_executor<E>{exec})) out.clear();
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mesh_path = argc > 1 ? argv[1] : sup::cgal_mesh("fandisk");
  auto m = sup::load_mesh(mesh_path);
  if (!m) {
    std::fprintf(stderr, "tbb_executor: %s\n", m.error().message().c_str());
    return 1;
  }
  const sup::embree_device device;
  sup::embree_scene tracer(device);
  if (!tracer.add_mesh(*m) || !tracer.commit()) {
    std::fprintf(stderr, "tbb_executor: Embree rejected %s\n", mesh_path.c_str());
    return 1;
  }
  int failures = 0;
  const auto serial = cluster(*m, tracer, infolerp::serial_executor{});
  if (!serial) {
    std::fprintf(stderr, "tbb_executor: %s\n", serial.error().message().c_str());
    return 1;
  }
  const auto same_clusters = [&](const char* name, const auto& r) {
    const bool same = r && r->cluster_of == serial->cluster_of && r->cluster_count == serial->cluster_count;
    std::printf("clustering %-10s %s (%u clusters)\n", name, same ? "same as serial" : "DIFFERS", r ? r->cluster_count : 0u);
    failures += same ? 0 : 1;
  };
  same_clusters("openmp 2", cluster(*m, tracer, infolerp::openmp_executor{2}));
  same_clusters("tbb 1", cluster(*m, tracer, examples::tbb_executor{1}));
  same_clusters("tbb 2", cluster(*m, tracer, examples::tbb_executor{2}));

  auto scene = sup::make_demo_scene(device);
  if (!scene) {
    std::fprintf(stderr, "tbb_executor: %s\n", scene.error().message().c_str());
    return 1;
  }
  constexpr std::uint32_t w = 160, h = 120;
  const sup::reference_shader shader(*scene, {.ao_rays = 16, .soft_shadow_rays = 4});
  const auto ids = sup::split_at_texture_seams(*scene, sup::cluster_by_normal(*scene, 2));
  if (!ids) return 1;
  auto src = sup::make_demo_ray_cast_source(shader, *ids, w, h);
  if (!src) return 1;
  const auto reference = upsample(*src, w, h, infolerp::serial_executor{});
  const auto same_frame = [&](const char* name, const std::vector<glm::vec3>& f) {
    const bool same = !f.empty() && f.size() == reference.size() &&
                      std::memcmp(f.data(), reference.data(), f.size() * sizeof(glm::vec3)) == 0;
    std::printf("upsampling %-10s %s\n", name, same ? "same as serial" : "DIFFERS");
    failures += same ? 0 : 1;
  };
  same_frame("openmp 2", upsample(*src, w, h, infolerp::openmp_executor{2}));
  same_frame("tbb 1", upsample(*src, w, h, examples::tbb_executor{1}));
  same_frame("tbb 2", upsample(*src, w, h, examples::tbb_executor{2}));
  return failures == 0 ? 0 : 1;
}
