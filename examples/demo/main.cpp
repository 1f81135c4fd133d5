// infolerp_demo: renders the built-in demo scene (plus any --mesh assets, textured) with the full
// per-pixel reference shader (DIR/reference.png), then runs the stages on the same context:
// saliency (saliency.png), the I-Buffer upsampler (ibuffer.png, rie.png, error.png), frames
// along a camera path with reuse across frames (path.png), the
// view-dependent LOD of the mesh (lod.png) and the summary (a printed table, summary.csv,
// tradeoff.png). Every stage prints its wall time ("time: STAGE  S s") and the run ends with
// the list of stages, longest first; a stage past about 2 s shows progress on stderr. Any error
// gives one line on stderr and a non-zero exit: 2 for a bad option, 1 for anything else (an
// unreadable or malformed mesh, an unwritable output directory).
#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>
#include "demo.hpp"
#include "stage_clusters.hpp"
#include "stage_lod.hpp"
#include "stage_saliency.hpp"
#include "stage_summary.hpp"
#include "stage_upsample.hpp"
#include "stage_path.hpp"

namespace demo = infolerp::demo;
namespace support = infolerp::support;

namespace {

constexpr const char* usage =
    "usage: infolerp_demo [options]\n"
    "  --mesh FILE     add an asset to the built-in scene (repeatable): OBJ+MTL, glTF/GLB, PLY, OFF\n"
    "                  (via assimp); one object per material, shaded with its diffuse texture;\n"
    "                  each file (or group) is scaled to the same size and placed in a row\n"
    "  --group NAME    the --mesh files after this, up to the next --group, belong together: they\n"
    "                  keep their relative placement and scale (e.g. a car body and its wheels)\n"
    "  --up y|z        the assets' up axis (default y; z for Z-up files, as many game assets)\n"
    "  --size W H      image size in pixels (default 1025 1025)\n"
    "  --tessellate SHARE\n"
    "                  split the scene's triangles 1:4 until none covers more than SHARE (0-1) of\n"
    "                  the image (clustering paper 4.1; default 0: off)\n"
    "  --passes K|auto I-Buffer passes of ibuffer.png (1-16, default 4); auto: the pass controller\n"
    "                  (frame-time bounds 1/60-1/30 s, at most 4 passes)\n"
    "  --threshold CHANNEL=VALUE\n"
    "                  Jensen-Shannon threshold in [0, 1] of a clustering channel: visibility,\n"
    "                  orientation or stretch (repeatable)\n"
    "  --threads N     worker threads of every stage (default: all cores)\n"
    "  --ao N          ambient-occlusion rays per pixel (default 64)\n"
    "  --soft N        soft-shadow rays per pixel toward the area light (default 16)\n"
    "  --packets       trace each pixel's AO and soft-shadow rays as 16-ray packets\n"
    "  --out DIR       output directory (default infolerp-out)\n"
    "  --help          this text\n";

// CHANNEL=VALUE with a known channel and a value in [0, 1]; else an error message.
std::optional<std::string> parse_threshold(std::string_view text, demo::demo_options& o) {
  const auto eq = text.find('=');
  if (eq == std::string_view::npos) return "--threshold needs CHANNEL=VALUE, e.g. visibility=0.48";
  const std::string channel(text.substr(0, eq));
  if (channel != "visibility" && channel != "orientation" && channel != "stretch")
    return "--threshold: unknown channel '" + channel + "' (visibility, orientation or stretch)";
  const std::string_view number = text.substr(eq + 1);
  float value = 0.0f;
  const auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), value);
  if (number.empty() || ec != std::errc{} || end != number.data() + number.size() || !(value >= 0.0f && value <= 1.0f))
    return "--threshold: " + channel + " value '" + std::string(number) + "' is not a number in [0, 1]";
  o.thresholds[channel] = value;
  return std::nullopt;
}

bool parse_int(std::string_view text, int lo, int hi, int& out) {
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() || value < lo || value > hi) return false;
  out = value;
  return true;
}

// Parses argv; on error prints one line and returns nothing. --help prints usage and exits 0.
std::optional<demo::demo_options> parse_options(int argc, char** argv) {
  demo::demo_options o;
  std::string group;  // the current --group ("" before the first)
  auto fail = [](const std::string& message) {
    std::fprintf(stderr, "infolerp_demo: %s (try --help)\n", message.c_str());
    return std::nullopt;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    auto value = [&](int k) -> const char* { return i + k < argc ? argv[i + k] : nullptr; };
    // An option's value is there and is not the next option.
    auto need = [&](int k) {
      for (int j = 1; j <= k; ++j)
        if (value(j) == nullptr || std::string_view(value(j)).starts_with("--")) return false;
      return true;
    };
    if (arg == "--help" || arg == "-h") {
      std::fputs(usage, stdout);
      std::exit(0);
    } else if (arg == "--mesh") {
      if (!need(1)) return fail("--mesh needs a file name");
      o.mesh_paths.emplace_back(argv[++i]);
      o.mesh_groups.push_back(group);
    } else if (arg == "--group") {
      if (!need(1)) return fail("--group needs a name");
      group = argv[++i];
    } else if (arg == "--up") {
      if (!need(1) || (std::string_view(argv[i + 1]) != "y" && std::string_view(argv[i + 1]) != "z"))
        return fail("--up needs y or z");
      o.z_up = std::string_view(argv[++i]) == "z";
    } else if (arg == "--size") {
      if (!need(2) || !parse_int(argv[i + 1], 1, 16384, o.width) || !parse_int(argv[i + 2], 1, 16384, o.height))
        return fail("--size needs two integers W H in [1, 16384]");
      i += 2;
    } else if (arg == "--tessellate") {
      const std::string_view text = need(1) ? argv[i + 1] : "";
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), o.tessellate);
      if (text.empty() || ec != std::errc{} || end != text.data() + text.size() || !(o.tessellate >= 0.0f && o.tessellate <= 1.0f))
        return fail("--tessellate needs a share of the image in [0, 1]");
      ++i;
    } else if (arg == "--threads") {
      if (!need(1) || !parse_int(argv[++i], 1, 1024, o.threads)) return fail("--threads needs an integer in [1, 1024]");
    } else if (arg == "--ao" || arg == "--soft") {
      int n = 0;
      if (!need(1) || !parse_int(argv[++i], 0, 4096, n))
        return fail(std::string(arg) + " needs an integer in [0, 4096]");
      (arg == "--ao" ? o.shader.ao_rays : o.shader.soft_shadow_rays) = static_cast<unsigned>(n);
    } else if (arg == "--passes") {
      int k = 0;
      if (!need(1)) return fail("--passes needs K (1-16) or auto");
      if (std::string_view(argv[++i]) == "auto") {
        o.passes = 0;
      } else if (parse_int(argv[i], 1, 16, k)) {
        o.passes = static_cast<std::uint32_t>(k);
      } else {
        return fail("--passes needs K (1-16) or auto, not '" + std::string(argv[i]) + "'");
      }
    } else if (arg == "--threshold") {
      if (!need(1)) return fail("--threshold needs CHANNEL=VALUE");
      if (auto error = parse_threshold(argv[++i], o)) return fail(*error);
    } else if (arg == "--packets") {
      o.shader.packets = true;
    } else if (arg == "--out") {
      if (!need(1)) return fail("--out needs a directory");
      o.out_dir = argv[++i];
    } else {
      return fail("unknown option '" + std::string(arg) + "'");
    }
  }
  return o;
}

// Stage 1: the full per-pixel reference (every pixel evaluated and shaded).
bool stage_reference(demo::demo_context& ctx) {
  const auto& o = ctx.options;
  std::printf("reference: %dx%d, AO %u rays, soft shadow %u rays, hard-shadow sun, textures, %s\n", o.width,
              o.height, o.shader.ao_rays, o.shader.soft_shadow_rays, o.shader.packets ? "16-ray packets" : "single rays");
  demo::progress_line line("reference");
  auto stats = support::render_reference(ctx.shader, o.width, o.height, ctx.reference, o.threads,
                                         [&](int done, int total) { line(static_cast<std::size_t>(done), static_cast<std::size_t>(total)); });
  line.finish();
  if (!stats) {
    demo::report(stats.error());
    return false;
  }
  ctx.reference_stats = *stats;
  demo::record_time(ctx, "reference", stats->seconds);
  std::printf("reference: %.3f s, %llu rays, %.2f Mrays/s\n", stats->seconds,
              static_cast<unsigned long long>(stats->rays), stats->rays_per_second() * 1e-6);
  demo::add_result(ctx, "reference",
                   "per-pixel evaluation, AO " + std::to_string(o.shader.ao_rays) + ", soft shadow " +
                       std::to_string(o.shader.soft_shadow_rays) + " rays",
                   stats->seconds, 1.0, ctx.reference);
  return demo::save_png(ctx, ctx.reference, "reference.png");
}

// The closing list of stage times, longest first, each with its share of the whole run.
void print_times(const demo::demo_context& ctx, double total) {
  std::vector<demo::stage_time> times = ctx.times;
  double listed = 0.0;
  for (const auto& t : times) listed += t.seconds;
  times.push_back({"the rest (start-up, images, LOD frames, orbit)", total - listed});
  std::stable_sort(times.begin(), times.end(), [](const auto& a, const auto& b) { return a.seconds > b.seconds; });
  std::printf("where the time went (%.3f s in all):\n", total);
  for (const auto& t : times) std::printf("  %-40s %9.3f s  %5.1f%%\n", t.stage.c_str(), t.seconds, 100.0 * t.seconds / total);
}

}  // namespace

int main(int argc, char** argv) {
  const demo::stopwatch run;
  const auto options = parse_options(argc, argv);
  if (!options) return 2;
  std::error_code ec;
  std::filesystem::create_directories(options->out_dir, ec);
  if (ec) {
    std::fprintf(stderr, "infolerp_demo: cannot create output directory '%s': %s\n",
                 options->out_dir.string().c_str(), ec.message().c_str());
    return 1;
  }

  support::enable_flush_to_zero();
  const std::string embree_config = options->threads > 0 ? "threads=" + std::to_string(options->threads) : "";
  const support::embree_device device(embree_config.c_str());
  auto scene = support::make_demo_scene(device, {.mesh_paths = options->mesh_paths,
                                                 .mesh_groups = options->mesh_groups,
                                                 .z_up = options->z_up,
                                                 .tessellate = options->tessellate});
  if (!scene) {
    demo::report(scene.error());
    return 1;
  }
  std::size_t triangles = 0;
  for (const auto& object : scene->objects) triangles += object.mesh.triangle_count();
  std::printf("scene: %zu objects, %zu triangles\n", scene->objects.size(), triangles);
  for (const auto& object : scene->objects) {
    const auto& image = object.mat.image;
    if (image)
      std::printf("  %s: %zu triangles, texture %dx%d (%zu mip levels)\n", object.name.c_str(), object.mesh.triangle_count(),
                  image->width(), image->height(), image->level_count());
    else if (!object.note.empty())
      std::printf("  %s: %zu triangles, %s\n", object.name.c_str(), object.mesh.triangle_count(), object.note.c_str());
  }

  support::shader_options shading = options->shader;
  shading.pixel_angle = support::pixel_angle(scene->view, options->height);  // mip levels from the footprint
  const support::reference_shader shader(*scene, shading);
  if (!options->thresholds.empty()) {
    std::printf("thresholds:");
    for (const auto& [channel, value] : options->thresholds) std::printf(" %s=%g", channel.c_str(), static_cast<double>(value));
    std::printf(" (for the clusters stage)\n");
  }
  demo::demo_context ctx{*options, *scene, shader, {}, {}, {}, {}, {}};
  demo::record_time(ctx, "load", scene->load_seconds);
  demo::record_time(ctx, "BVH", scene->bvh_seconds);
  if (!stage_reference(ctx)) return 1;
  support::scene_clustering clusters;
  if (!demo::stage_clusters(ctx, clusters)) return 1;
  if (!demo::stage_saliency(ctx)) return 1;
  if (!demo::stage_upsample(ctx, &clusters)) return 1;
  if (!demo::stage_path(ctx, clusters)) return 1;
  if (!demo::stage_lod(ctx)) return 1;
  if (!demo::stage_summary(ctx)) return 1;
  print_times(ctx, run.seconds());
  return 0;
}
