#pragma once
// Demo stage: the results of every method the demo ran (ctx.results: the reference first) and
// the LOD stage's meshes (ctx.lod_results).
//   - prints a table: method, time, speed-up over the reference, PSNR, SSIM, evaluated fraction;
//   - DIR/summary.csv: method,seconds,speedup,psnr_db,ssim,evaluated_fraction,setting
//     (psnr_db "inf" for the reference, ssim "nan" below 11x11 pixels);
//   - DIR/tradeoff.png: PSNR against time (gnuplot; exact methods drawn at the top of the PSNR
//     axis), with tradeoff.dat and tradeoff.gp next to it;
//   - the LOD table (method, fraction, triangles, seconds, weighted distance, Hausdorff, PSNR,
//     SSIM; PSNR and SSIM against the full mesh's image, seconds those of the mesh update, so
//     no speed-up) and DIR/lod.csv:
//     method,fraction,triangles,seconds,weighted_distance,hausdorff,psnr_db,ssim.
//
//   bool stage_summary(const demo_context& ctx);
// Returns false when summary.csv or lod.csv cannot be written; a missing or failing gnuplot is
// reported and leaves tradeoff.dat/.gp (returns true).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>
#include "demo.hpp"

namespace infolerp::demo {

namespace detail {
// A string as one single-quoted shell word.
inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The LOD table and DIR/lod.csv (nothing when the LOD stage did not run); false when lod.csv
// cannot be written (reported).
inline bool lod_summary(const demo_context& ctx) {
  if (ctx.lod_results.empty()) return true;
  std::printf("\n%-16s %8s %10s %10s %12s %10s %10s %7s\n", "LOD method", "fraction", "triangles", "time (s)",
              "weighted d.", "Hausdorff", "PSNR (dB)", "SSIM");
  for (const auto& r : ctx.lod_results)
    std::printf("%-16s %7.0f%% %10zu %10.6f %12.4g %10.4g %10.2f %7.4f\n", r.method.c_str(), 100.0 * r.fraction, r.triangles,
                r.seconds, r.weighted_distance, r.hausdorff, r.psnr, r.ssim);
  std::printf("(distances to the full mesh; PSNR and SSIM against the full mesh's image of the same view; "
              "time of the per-frame step: frame(), or the peer's culling pass)\n");
  const std::string path = (ctx.options.out_dir / "lod.csv").string();
  std::ofstream csv(path);
  csv << "method,fraction,triangles,seconds,weighted_distance,hausdorff,psnr_db,ssim\n";
  char line[256];
  for (const auto& r : ctx.lod_results) {
    std::snprintf(line, sizeof line, "%s,%.4f,%zu,%.6f,%.6g,%.6g,%.4f,%.6f\n", r.method.c_str(), r.fraction, r.triangles,
                  r.seconds, r.weighted_distance, r.hausdorff, r.psnr, r.ssim);
    csv << line;
  }
  if (!csv.flush()) {
    std::fprintf(stderr, "infolerp_demo: cannot write '%s'\n", path.c_str());
    return false;
  }
  std::printf("wrote %s\n", path.c_str());
  return true;
}
}  // namespace detail

inline bool stage_summary(const demo_context& ctx) {
  if (ctx.results.empty()) return true;
  auto rows = ctx.results;  // the reference first, then by method name (ibuffer-2 before ibuffer-16)
  std::stable_sort(rows.begin() + 1, rows.end(), [](const auto& a, const auto& b) {
    return a.method.size() != b.method.size() ? a.method.size() < b.method.size() : a.method < b.method;
  });
  const double t_ref = rows.front().seconds;
  auto speedup = [&](const method_result& r) { return r.seconds > 0.0 ? t_ref / r.seconds : 0.0; };

  std::printf("\n%-16s %9s %9s %10s %7s %10s\n", "method", "time (s)", "speed-up", "PSNR (dB)", "SSIM", "evaluated");
  for (const auto& r : rows)
    std::printf("%-16s %9.3f %8.2fx %10.2f %7.4f %9.2f%%\n", r.method.c_str(), r.seconds, speedup(r), r.psnr, r.ssim,
                100.0 * r.evaluated);
  if (!detail::lod_summary(ctx)) return false;

  const auto dir = ctx.options.out_dir;
  const std::string csv_path = (dir / "summary.csv").string();
  {
    std::ofstream csv(csv_path);
    csv << "method,seconds,speedup,psnr_db,ssim,evaluated_fraction,setting\n";
    char line[256];
    for (const auto& r : rows) {
      std::snprintf(line, sizeof line, "%s,%.6f,%.4f,%.4f,%.6f,%.6f,", r.method.c_str(), r.seconds, speedup(r), r.psnr,
                    r.ssim, r.evaluated);
      csv << line << '"' << r.setting << "\"\n";
    }
    if (!csv.flush()) {
      std::fprintf(stderr, "infolerp_demo: cannot write '%s'\n", csv_path.c_str());
      return false;
    }
  }
  std::printf("wrote %s\n", csv_path.c_str());

  // The plot: one point per method, PSNR capped just above the best finite value for exact ones.
  double top = 0.0;
  for (const auto& r : rows)
    if (std::isfinite(r.psnr)) top = std::max(top, r.psnr);
  top = std::ceil(top / 5.0) * 5.0 + 5.0;
  {
    std::ofstream dat(dir / "tradeoff.dat");
    dat << "# seconds psnr_db(exact at " << top << ") method\n";
    for (const auto& r : rows)
      dat << r.seconds << ' ' << (std::isfinite(r.psnr) ? r.psnr : top) << ' ' << r.method << '\n';
    std::ofstream gp(dir / "tradeoff.gp");
    gp << "set terminal pngcairo size 900,600 noenhanced\nset output 'tradeoff.png'\n"
       << "set title 'infolerp_demo " << ctx.options.width << "x" << ctx.options.height
       << ": PSNR against frame time (reference = per-pixel evaluation, drawn at " << top << " dB)'\n"
       << "set xlabel 'frame time (s, log)'\nset ylabel 'PSNR (dB) against the reference'\nset logscale x\nset grid\n"
       << "set offsets graph 0.1, graph 0.1, 1, 1\nunset key\n"
       << "plot 'tradeoff.dat' using 1:2 with points pt 7 ps 1.5, '' using 1:2:3 with labels offset 0,1\n";
  }
  const std::string cmd = "cd " + detail::shell_quote(dir.string()) + " && gnuplot tradeoff.gp";
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "infolerp_demo: gnuplot failed; the plot data is in %s\n", (dir / "tradeoff.dat").string().c_str());
    return true;
  }
  std::printf("wrote %s\n", (dir / "tradeoff.png").string().c_str());
  return true;
}

}  // namespace infolerp::demo
