// Refinement on the walkthrough scene (Oliveira, Santos, Proença, "Refinement criteria for
// high-fidelity interactive walkthroughs"): the coarse street scene is shaded at its vertices
// (stage 1), then refined with the NLD_OS criterion until the rule stops it (stage 2, §5).
// Writes the reconstructed image with the shown leaf triangles drawn over it, for both stages:
//   refine_wireframe [OUT_DIR] [WIDTH HEIGHT]  ->  OUT_DIR/refine_stage1.png, OUT_DIR/refine_wireframe.png
// The wireframe is where neighbouring pixels show different leaves, so it follows what the
// camera sees (hidden edges are not drawn).
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include "infolerp/core/executor.hpp"
#include "infolerp/refine/progressive_driver.hpp"
#include "support/image.hpp"
#include "support/walkthrough_scene.hpp"

namespace sup = infolerp::support;

namespace {

bool parse(const char* text, std::uint32_t& out) {
  const std::string_view s(text);
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc{} && end == s.data() + s.size() && out >= 8 && out <= 8192;
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path dir = argc > 1 ? argv[1] : ".";
  std::uint32_t width = 640, height = 480;
  if (argc == 3 || argc > 4 || (argc == 4 && (!parse(argv[2], width) || !parse(argv[3], height)))) {
    std::fprintf(stderr, "usage: refine_wireframe [OUT_DIR] [WIDTH HEIGHT (8-8192)]\n");
    return 2;
  }
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  auto scene = sup::make_walkthrough_scene();
  if (!scene) return std::fprintf(stderr, "refine_wireframe: %s\n", scene.error().message().c_str()), 1;
  auto sub = infolerp::subdivision_mesh::create(scene->mesh);
  if (!sub) return std::fprintf(stderr, "refine_wireframe: %s\n", sub.error().message().c_str()), 1;
  infolerp::driver_options o;
  o.criteria.criterion = infolerp::refinement_criterion::nld_os;
  o.criteria.s_req = 0.05f;  // as infolerp_pareto refine
  auto refiner = infolerp::progressive_refiner::create(std::move(*sub), o);
  if (!refiner) return std::fprintf(stderr, "refine_wireframe: %s\n", refiner.error().message().c_str()), 1;

  const auto cam = sup::walkthrough_camera(width, height);
  const auto shade = [&](const infolerp::shading_point& sp) { return scene->shade(sp.position, sp.triangle); };
#ifdef _OPENMP
  const infolerp::openmp_executor exec{};
#else
  const infolerp::serial_executor exec{};
#endif
  if (auto s = refiner->start(*scene, cam, shade, exec); !s)
    return std::fprintf(stderr, "refine_wireframe: %s\n", s.message().c_str()), 1;
  const sup::image stage1 = sup::leaf_wireframe(*refiner, width, height);
  while (refiner->refine_batch(shade, exec)) {
  }
  const sup::image stage2 = sup::leaf_wireframe(*refiner, width, height);

  const auto& rep = refiner->report();
  std::printf("stage 1: %zu triangles shown, %zu shading samples, %.3f s\n", rep.stage1.triangles,
              rep.stage1.shading_samples, rep.stage1.seconds);
  std::printf("stage 2 (NLD_OS): %zu triangles shown, %zu shading samples, %zu batches, %.3f s\n", rep.stage2.triangles,
              rep.stage2.shading_samples, rep.batches, rep.stage2.seconds);
  for (const auto& [img, name] : {std::pair{&stage1, "refine_stage1.png"}, std::pair{&stage2, "refine_wireframe.png"}}) {
    const std::string path = (dir / name).string();
    if (auto s = sup::write_png(*img, path); !s) return std::fprintf(stderr, "refine_wireframe: %s\n", s.message().c_str()), 1;
    std::printf("wrote %s\n", path.c_str());
  }
  return 0;
}
