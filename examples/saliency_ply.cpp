// Mesh saliency (Lee, Varshney, Jacobs 2005, as used by "Salient clustering for view-dependent
// multiresolution rendering", §III.A) of a real mesh, written as a PLY with per-vertex colours
// (heat map: blue = low, red = high saliency; square-root tone curve so mid values show).
//   saliency_ply [MESH [OUT.ply]]   default MESH: CGAL's bunny00, OUT: saliency.ply
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include "demo/stage_saliency.hpp"  // heat_colour
#include "infolerp/core/executor.hpp"
#include "infolerp/mesh/validate.hpp"
#include "infolerp/saliency/mesh_saliency.hpp"
#include "support/mesh_io.hpp"

namespace sup = infolerp::support;

int main(int argc, char** argv) {
  if (argc > 3) {
    std::fprintf(stderr, "usage: saliency_ply [MESH [OUT.ply]]\n");
    return 2;
  }
  const std::string in = argc > 1 ? argv[1] : sup::cgal_mesh("bunny00");
  const std::string out = argc > 2 ? argv[2] : "saliency.ply";
  auto mesh = in.ends_with(".off") ? sup::read_off(in) : sup::load_mesh(in);
  if (!mesh) return std::fprintf(stderr, "saliency_ply: %s\n", mesh.error().message().c_str()), 1;
  // Saliency needs indices in range and finite positions; degenerate triangles are tolerated.
  if (auto s = infolerp::validate_mesh(*mesh, {.allow_degenerate = true, .allow_non_manifold = true}); !s)
    return std::fprintf(stderr, "saliency_ply: %s: %s\n", in.c_str(), s.message().c_str()), 1;
#ifdef _OPENMP
  auto sal = infolerp::compute_saliency(*mesh, {}, infolerp::openmp_executor{});
#else
  auto sal = infolerp::compute_saliency(*mesh);
#endif
  if (!sal) return std::fprintf(stderr, "saliency_ply: %s\n", sal.error().message().c_str()), 1;
  const double top = *std::max_element(sal->saliency.begin(), sal->saliency.end());

  std::FILE* f = std::fopen(out.c_str(), "w");
  if (f == nullptr) return std::fprintf(stderr, "saliency_ply: cannot write '%s'\n", out.c_str()), 1;
  std::fprintf(f,
               "ply\nformat ascii 1.0\ncomment saliency of %s (epsilon %.6g)\nelement vertex %zu\n"
               "property float x\nproperty float y\nproperty float z\nproperty float saliency\n"
               "property uchar red\nproperty uchar green\nproperty uchar blue\n"
               "element face %zu\nproperty list uchar uint vertex_indices\nend_header\n",
               in.c_str(), sal->epsilon, mesh->positions.size(), mesh->triangles.size());
  for (std::size_t v = 0; v < mesh->positions.size(); ++v) {
    const glm::vec3 p = mesh->positions[v];
    const double s = sal->saliency[v];
    const glm::vec3 c = infolerp::demo::heat_colour(top > 0.0 ? static_cast<float>(std::sqrt(s / top)) : 0.0f);
    auto byte = [](float x) { return static_cast<unsigned>(std::lround(std::clamp(x, 0.0f, 1.0f) * 255.0f)); };
    std::fprintf(f, "%.7g %.7g %.7g %.6g %u %u %u\n", static_cast<double>(p.x), static_cast<double>(p.y),
                 static_cast<double>(p.z), s, byte(c.r), byte(c.g), byte(c.b));
  }
  for (const auto& t : mesh->triangles) std::fprintf(f, "3 %u %u %u\n", t.x, t.y, t.z);
  const bool ok = std::fclose(f) == 0;
  if (!ok) return std::fprintf(stderr, "saliency_ply: cannot write '%s'\n", out.c_str()), 1;
  std::printf("%s: %zu vertices, %zu triangles, saliency max %.4f (epsilon %.4g); wrote %s\n", in.c_str(),
              mesh->positions.size(), mesh->triangles.size(), top, sal->epsilon, out.c_str());
  return 0;
}
