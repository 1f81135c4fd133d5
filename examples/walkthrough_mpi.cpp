// The paper's distribution (Oliveira, Santos, Proença, §2: the renderer "launches several
// processes across a cluster of workstations"): the shading agent runs on MPI rank 0, Embree
// shading on every other rank. Rank 0 walks the walkthrough path, sends each batch of requests
// in chunks to the shading ranks round-robin and delivers the results in the order they arrive
// (MPI_ANY_SOURCE). The library knows nothing of MPI: it hands out shading_points and accepts
// (vertex, colour) pairs. At the end rank 0 walks the same path in one process, synchronously,
// and compares every frame bit for bit.
//   mpirun -np 3 walkthrough_mpi [FRAMES]   (exit 1 when a frame differs)
#include <mpi.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>
#include "infolerp/core/executor.hpp"
#include "infolerp/refine/progressive_driver.hpp"
#include "support/walkthrough_scene.hpp"

namespace sup = infolerp::support;

namespace {

constexpr std::uint32_t width = 160, height = 120;
constexpr int tag_work = 1, tag_result = 2, tag_stop = 3;
constexpr std::size_t chunk = 64;

struct shaded {
  std::uint32_t vertex;
  glm::vec3 colour;
};
static_assert(std::is_trivially_copyable_v<infolerp::shading_point> && std::is_trivially_copyable_v<shaded>);

infolerp::progressive_refiner make_agent(const sup::walkthrough_scene& sc) {
  auto sub = infolerp::subdivision_mesh::create(sc.mesh);
  if (!sub) std::fprintf(stderr, "walkthrough_mpi: %s\n", sub.error().message().c_str()), std::exit(1);
  auto r = infolerp::progressive_refiner::create(std::move(*sub), {.criteria = {.s_req = 0.05f}});
  if (!r) std::fprintf(stderr, "walkthrough_mpi: %s\n", r.error().message().c_str()), std::exit(1);
  return std::move(*r);
}

// A shading rank: shade every chunk it is sent until told to stop.
void serve(const sup::walkthrough_scene& sc) {
  std::vector<infolerp::shading_point> req;
  std::vector<shaded> out;
  sup::enable_flush_to_zero();
  for (;;) {
    MPI_Status st;
    MPI_Probe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &st);
    if (st.MPI_TAG == tag_stop) {
      MPI_Recv(nullptr, 0, MPI_BYTE, 0, tag_stop, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      return;
    }
    int bytes = 0;
    MPI_Get_count(&st, MPI_BYTE, &bytes);
    req.resize(std::size_t(bytes) / sizeof(infolerp::shading_point));
    MPI_Recv(req.data(), bytes, MPI_BYTE, 0, tag_work, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    out.resize(req.size());
    for (std::size_t i = 0; i < req.size(); ++i) out[i] = {req[i].vertex, sc.shade(req[i].position, req[i].triangle)};
    MPI_Send(out.data(), static_cast<int>(out.size() * sizeof(shaded)), MPI_BYTE, 0, tag_result, MPI_COMM_WORLD);
  }
}

// Rank 0: every outstanding request goes out in chunks; results are delivered as they arrive.
void shade_remotely(infolerp::progressive_refiner& agent, int ranks) {
  std::vector<infolerp::shading_point> req;
  agent.take_requests(req);
  int sent = 0;
  for (std::size_t begin = 0; begin < req.size(); begin += chunk, ++sent) {
    const std::size_t n = std::min(chunk, req.size() - begin);
    MPI_Send(req.data() + begin, static_cast<int>(n * sizeof(infolerp::shading_point)), MPI_BYTE, 1 + sent % (ranks - 1),
             tag_work, MPI_COMM_WORLD);
  }
  std::vector<shaded> in;
  std::vector<std::uint32_t> ids;
  std::vector<glm::vec3> colours;
  for (int r = 0; r < sent; ++r) {
    MPI_Status st;
    MPI_Probe(MPI_ANY_SOURCE, tag_result, MPI_COMM_WORLD, &st);
    int bytes = 0;
    MPI_Get_count(&st, MPI_BYTE, &bytes);
    in.resize(std::size_t(bytes) / sizeof(shaded));
    MPI_Recv(in.data(), bytes, MPI_BYTE, st.MPI_SOURCE, tag_result, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    ids.clear();
    colours.clear();
    for (const shaded& s : in) ids.push_back(s.vertex), colours.push_back(s.colour);
    if (auto ok = agent.deliver(ids, colours); !ok) std::fprintf(stderr, "deliver: %s\n", ok.message().c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const std::uint32_t frames = argc > 1 ? static_cast<std::uint32_t>(std::atoi(argv[1])) : 8u;
  auto scene = sup::make_walkthrough_scene();
  if (!scene || ranks < 2 || frames < 2 || frames > 64) {
    if (rank == 0)
      std::fprintf(stderr, "walkthrough_mpi: %s\n",
                   !scene ? scene.error().message().c_str() : "needs >= 2 ranks and FRAMES in 2-64");
    MPI_Finalize();
    return 2;
  }
  if (rank != 0) {
    serve(*scene);
    MPI_Finalize();
    return 0;
  }
  const infolerp::serial_executor exec{};
  auto agent = make_agent(*scene), local = make_agent(*scene);
  const auto shade = [&](const infolerp::shading_point& sp) { return scene->shade(sp.position, sp.triangle); };
  int mismatches = 0;
  for (std::uint32_t f = 0; f < frames; ++f) {
    const auto cam = sup::walkthrough_path(f, frames, width, height);
    if (!agent.set_view(*scene, cam, exec).ok() || !local.set_view(*scene, cam, exec).ok()) return MPI_Abort(MPI_COMM_WORLD, 1), 1;
    const std::size_t before = agent.samples_delivered();
    do shade_remotely(agent, ranks);
    while (agent.refine({}, exec) == infolerp::refine_progress::refined);
    local.shade_requests(shade, exec);
    while (local.refine(shade, {}, exec) == infolerp::refine_progress::refined) {
    }
    std::vector<glm::vec3> a(std::size_t(width) * height), b(a.size());
    agent.reconstruct(a);
    local.reconstruct(b);
    const bool same = std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
    mismatches += !same;
    std::printf("frame %u: %zu new samples shaded on %d ranks; image %s the single-process run\n", f,
                agent.samples_delivered() - before, ranks - 1, same ? "identical to" : "DIFFERS from");
  }
  for (int r = 1; r < ranks; ++r) MPI_Send(nullptr, 0, MPI_BYTE, r, tag_stop, MPI_COMM_WORLD);
  MPI_Finalize();
  return mismatches == 0 ? 0 : 1;
}
