// A walkthrough with asynchronous shading (Oliveira, Santos, Proença, §2): the agent walks the
// walkthrough scene's path (street -> temple -> street), keeps its hierarchy and shading cache
// across frames, and hands its shading requests to worker threads that shade them in chunks and
// deliver the results in whatever order they finish. The display is kept by replaying the
// agent's add/delete deltas into a set. At the end the frames are written as a contact sheet
// with the refined wireframe, and every frame is compared bit for bit with a synchronous,
// single-threaded walk of the same path.
//   walkthrough [OUT_DIR] [FRAMES]  ->  OUT_DIR/walkthrough_sheet.png ; exit 1 when a frame differs
#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <vector>
#include "infolerp/core/executor.hpp"
#include "infolerp/refine/progressive_driver.hpp"
#include "support/image.hpp"
#include "support/walkthrough_scene.hpp"

namespace sup = infolerp::support;

namespace {

constexpr std::uint32_t width = 240, height = 180;

infolerp::progressive_refiner make_agent(const sup::walkthrough_scene& sc) {
  auto sub = infolerp::subdivision_mesh::create(sc.mesh);
  if (!sub) std::fprintf(stderr, "walkthrough: %s\n", sub.error().message().c_str()), std::exit(1);
  auto r = infolerp::progressive_refiner::create(std::move(*sub), {.criteria = {.s_req = 0.05f}});
  if (!r) std::fprintf(stderr, "walkthrough: %s\n", r.error().message().c_str()), std::exit(1);
  return std::move(*r);
}

// The visualizer's side of the incremental protocol: apply one delta in the paper's order.
void follow(infolerp::progressive_refiner& agent, std::set<std::uint32_t>& shown) {
  infolerp::display_delta d;
  agent.take_delta(d);
  for (std::uint32_t t : d.added_from_cache) shown.insert(t);
  for (std::uint32_t t : d.deleted) shown.erase(t);
  for (std::uint32_t t : d.newly_shaded) shown.insert(t);
}

// Shades every outstanding request on `workers` threads, each delivering its chunk when done
// (the order differs from run to run); deliveries are serialised by a mutex, as the agent
// requires. The visualizer's set follows every delta.
void shade_on_threads(infolerp::progressive_refiner& agent, const sup::walkthrough_scene& sc, unsigned workers,
                      std::set<std::uint32_t>& shown) {
  std::vector<infolerp::shading_point> req;
  agent.take_requests(req);
  std::mutex m;
  std::vector<std::thread> pool;
  for (unsigned w = 0; w < workers; ++w)
    pool.emplace_back([&, w] {
      std::vector<std::uint32_t> ids;
      std::vector<glm::vec3> colours;
      for (std::size_t i = w; i < req.size(); i += workers) {
        ids.push_back(req[i].vertex);
        colours.push_back(sc.shade(req[i].position, req[i].triangle));
        if (ids.size() == 32 || i + workers >= req.size()) {
          const std::lock_guard<std::mutex> lock(m);
          if (auto st = agent.deliver(ids, colours); !st) std::fprintf(stderr, "deliver: %s\n", st.message().c_str());
          follow(agent, shown);
          ids.clear();
          colours.clear();
        }
      }
    });
  for (auto& t : pool) t.join();
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path dir = argc > 1 ? argv[1] : ".";
  std::uint32_t frames = 12;
  if (argc > 2) {
    const std::string_view s(argv[2]);
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), frames);
    if (ec != std::errc{} || end != s.data() + s.size() || frames < 2 || frames > 64) {
      std::fprintf(stderr, "usage: walkthrough [OUT_DIR] [FRAMES (2-64)]\n");
      return 2;
    }
  }
  std::error_code fs_error;
  std::filesystem::create_directories(dir, fs_error);
  auto scene = sup::make_walkthrough_scene();
  if (!scene) return std::fprintf(stderr, "walkthrough: %s\n", scene.error().message().c_str()), 1;
  const sup::walkthrough_scene& sc = *scene;
  const infolerp::serial_executor exec{};

  auto agent = make_agent(sc), sync = make_agent(sc);
  const auto shade = [&](const infolerp::shading_point& sp) { return sc.shade(sp.position, sp.triangle); };
  const unsigned columns = 4, rows = (frames + columns - 1) / columns;
  sup::image sheet(static_cast<int>(columns * width), static_cast<int>(rows * height));
  std::set<std::uint32_t> shown;  // the visualizer's triangles, fed by deltas only
  int mismatches = 0;
  for (std::uint32_t f = 0; f < frames; ++f) {
    const auto cam = sup::walkthrough_path(f, frames, width, height);
    if (auto st = agent.set_view(sc, cam, exec); !st) return std::fprintf(stderr, "walkthrough: %s\n", st.message().c_str()), 1;
    follow(agent, shown);
    const std::size_t before = agent.samples_delivered();
    for (bool more = true; more;) {
      shade_on_threads(agent, sc, 4, shown);
      more = agent.refine({}, exec) == infolerp::refine_progress::refined;
      follow(agent, shown);
    }
    // The synchronous single-threaded walk of the same path.
    if (auto st = sync.set_view(sc, cam, exec); !st) return 1;
    sync.shade_requests(shade, exec);
    while (sync.refine(shade, {}, exec) == infolerp::refine_progress::refined) {
    }
    std::vector<glm::vec3> a(std::size_t(width) * height), b(a.size());
    agent.reconstruct(a);
    sync.reconstruct(b);
    const bool same = std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
    const auto visible = agent.visible_leaves();
    const bool replay_ok = std::equal(shown.begin(), shown.end(), visible.begin(), visible.end());
    mismatches += !same + !replay_ok;
    std::printf("frame %2u: %5zu new samples, %5zu leaves shown, threads vs serial %s, delta replay %s\n", f,
                agent.samples_delivered() - before, visible.size(), same ? "identical" : "DIFFERENT",
                replay_ok ? "matches" : "DIFFERS");
    const sup::image tile = sup::leaf_wireframe(agent, width, height);
    for (std::uint32_t y = 0; y < height; ++y)
      for (std::uint32_t x = 0; x < width; ++x)
        sheet.at(static_cast<int>((f % columns) * width + x), static_cast<int>((f / columns) * height + y)) =
            tile.at(static_cast<int>(x), static_cast<int>(y));
  }
  const std::string path = (dir / "walkthrough_sheet.png").string();
  if (auto st = sup::write_png(sheet, path); !st) return std::fprintf(stderr, "walkthrough: %s\n", st.message().c_str()), 1;
  std::printf("samples: %zu over the walk; wrote %s\n", agent.samples_delivered(), path.c_str());
  return mismatches == 0 ? 0 : 1;
}
