#!/usr/bin/env bash
# The README's performance table from one run: each benchmark beside the reference it is compared
# with, all in one infolerp_bench process, repetitions in random interleaved order, min and median
# of the repetitions. Prints Markdown (CPU, load and date first) on stdout.
#
#   benchmarks/report.sh [BUILD_DIR] [REPETITIONS]     defaults: build, 3
#
# Needs infolerp_bench built (cmake --build BUILD_DIR --target infolerp_bench), python3, and
# CGAL's meshes in ~/.cache/infolerp/meshes (cmake/install-deps.sh). A few minutes on 2 cores.
set -euo pipefail
build=${1:-build}
reps=${2:-3}
bench="$build/benchmarks/infolerp_bench"
[[ -x "$bench" ]] || { echo "report.sh: $bench not found; build the infolerp_bench target first" >&2; exit 1; }

# Rows: benchmark, then its reference (same run).
filter='^(BM_JensenShannon/1048576|BM_JensenShannon_Naive/1048576'
filter+='|BM_JensenShannon_Column_Float/64/[01]'
filter+='|BM_Topology_RefinedElephant|BM_Topology_RefinedElephant_Memcpy'
filter+='|BM_Embree_Occluded_Single|BM_Embree_Occluded_Packet16'
filter+='|BM_VisibilityChannel_Total/iterations:2|BM_VisibilityChannel_RaysOnly/iterations:2/manual_time'
filter+='|BM_Clustering_RefinedElephant|BM_Clustering_RefinedElephant_Ordered|BM_Clustering_RefinedElephant_Counted/0'
filter+='|BM_Clustering_KnownAnswer'
filter+='|BM_Saliency_Exact/2/iterations:1/real_time|BM_Saliency_StrayVertex/[01]/real_time'
filter+='|BM_SalientClustering/real_time|BM_Subdivision_Uniform'
filter+='|BM_UpsampleInterpolatedPixel<cheap_source>/4|BM_UpsamplePlainEvaluation'
filter+='|BM_IBufferFrame_vs_PerPixel/4/1/iterations:1|BM_IBufferFrame_vs_PerPixel/6/0/iterations:1)$'

out=$(mktemp --suffix=.json)
trap 'rm -f "$out"' EXIT
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
"$bench" --benchmark_filter="$filter" --benchmark_repetitions="$reps" \
  --benchmark_enable_random_interleaving=true --benchmark_out="$out" --benchmark_out_format=json \
  >/dev/null
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
cpu=$(lscpu | sed -n 's/^Model name: *//p' | head -1)
flags=$(grep -m1 -o -w -E 'avx512f|avx2' /proc/cpuinfo | sort -u | tr '\n' ' ')

python3 - "$out" "$cpu" "$flags" "$(nproc)" "$load_before" "$load_after" "$reps" <<'PY'
import json, statistics, sys
path, cpu, flags, ncpu, load0, load1, reps = sys.argv[1:]
runs = {}
for b in json.load(open(path))["benchmarks"]:
    if b.get("run_type") == "iteration" and not b.get("error_occurred"):
        runs.setdefault(b["run_name"], []).append(b)

def get(name, key="real_time"):
    rs = runs.get(name)
    if not rs:
        return None
    v = sorted(r[key] for r in rs)
    return v[0], statistics.median(v), v[-1]

def fmt(x, digits=3):
    if x is None:
        return "n/a"
    return f"{x:.0f}" if abs(x) >= 10 ** (digits - 1) else f"{x:.{digits}g}"

def mm(t, unit, digits=3, largest=False):
    if t is None:
        return "n/a"
    best = t[2] if largest else t[0]
    return f"{fmt(best, digits)} / {fmt(t[1], digits)} {unit}"

def ratio(a, b, largest=False):
    if a is None or b is None:
        return "n/a"
    i = 2 if largest else 0
    return f"{a[i] / b[i]:.2f}× (median {a[1] / b[1]:.2f}×)"

rows = []
def row(what, value, reference, ratio_text, goal):
    rows.append(f"| {what} | {value} | {reference} | {ratio_text} | {goal} |")

M = 1e-6
def rate_row(what, name, ref_label, ref_name, counter, goal, ref_over_value=False, suffix=""):
    a, b = get(name, counter), get(ref_name, counter)
    mega = lambda t: t and tuple(x * M for x in t)
    r = ratio(b, a, largest=True) if ref_over_value else ratio(a, b, largest=True)
    row(what, mm(mega(a), "M", largest=True), ref_label + ": " + mm(mega(b), "M", largest=True), r + suffix, goal)

rate_row("Jensen–Shannon, double, 2^20 bins, one core (bins/s)", "BM_JensenShannon/1048576",
         "naive `std::log2` per bin", "BM_JensenShannon_Naive/1048576", "bins_per_second", "≥ 2× the naive loop")
G = 1e9  # counters with kInvert are in seconds
def ns(t):
    return t and tuple(x * G for x in t)
est = ns(get("BM_JensenShannon_Column_Float/64/1", "ns_per_pair"))
exa = ns(get("BM_JensenShannon_Column_Float/64/0", "ns_per_pair"))
row("JS estimate, 64 float bins, one row against 4096 (ns per pair)", mm(est, "ns"),
    "exact kernel: " + mm(exa, "ns"), ratio(exa, est) + " faster", "screens most comparisons")
rate_row("topology build, refined_elephant, one core (triangles/s)", "BM_Topology_RefinedElephant",
         "memcpy of the index buffer", "BM_Topology_RefinedElephant_Memcpy", "triangles_per_second", "regression figure",
         ref_over_value=True, suffix=" slower than the copy")
rate_row("Embree occlusion rays, bunny00, incoherent, 16-ray packets (rays/s)", "BM_Embree_Occluded_Packet16",
         "single rays", "BM_Embree_Occluded_Single", "rays_per_second", "—")
vt = get("BM_VisibilityChannel_Total/iterations:2")
vr = get("BM_VisibilityChannel_RaysOnly/iterations:2/manual_time")
row("visibility channel, refined_elephant, 64 viewpoints, one core, wall (ms)", mm(vt, "ms"),
    "its own rays alone, same tracer: " + mm(vr, "ms"), ratio(vt, vr), "≤ 1.3×")
cl = get("BM_Clustering_RefinedElephant", "cpu_time")
co = get("BM_Clustering_RefinedElephant_Ordered", "cpu_time")
# The regression's reference shares neither the rays nor the region growing: the same three
# channels and options on a cube whose clusters are known from geometry (its 6 faces), scored by
# the adjusted Rand index. Beside it, the elephant's clusters against the same clustering with the
# exact JS kernel in this run (a hash recorded on one CPU would not hold on another: Embree's rays).
ari = runs.get("BM_Clustering_KnownAnswer", [{}])[0].get("ari_vs_faces")
fnv = runs.get("BM_Clustering_RefinedElephant", [{}])[0].get("cluster_of_fnv24")
fnv_exact = runs.get("BM_Clustering_RefinedElephant_Counted/0", [{}])[0].get("cluster_of_fnv24")
same = "same" if fnv is not None and fnv == fnv_exact else "DIFFERENT"
known = "n/a" if ari is None else f"{ari:.4f}" + ("" if ari >= 0.999 else " (FAILED)")
row("three-channel clustering, refined_elephant, rays precomputed, one core, CPU (ms)", mm(cl, "ms"),
    "the same mesh in Morton order: " + mm(co, "ms"), ratio(cl, co),
    f"regression: ARI ≥ 0.999 against a cube's 6 faces (known answer): {known}; clusters {same} as with the exact JS kernel")
se = get("BM_Saliency_Exact/2/iterations:1/real_time")
row("saliency, refined_elephant subdivided (178k vertices), 2 threads, wall (ms)", mm(se, "ms"), "—", "—",
    "regression figure")
ss = get("BM_Saliency_StrayVertex/1/real_time")
sb = get("BM_Saliency_StrayVertex/0/real_time")
row("saliency, bunny00 + one vertex 10⁶ diagonals away (σ kept), 2 threads, wall (ms)", mm(ss, "ms"),
    "bunny00 alone: " + mm(sb, "ms"), ratio(ss, sb), "≈ 1×")
sc = get("BM_SalientClustering/real_time", "cpu_time")
row("salient clustering, bunny00, C = 10, CPU (ms)", mm(sc, "ms"), "—", "—", "regression figure (paper: 30 s)")
sd = get("BM_Subdivision_Uniform", "children_per_second")
row("subdivision, fandisk, 3 levels (children/s)", mm(sd and tuple(x * M for x in sd), "M", largest=True),
    "—", "—", "regression figure")
ui = ns(get("BM_UpsampleInterpolatedPixel<cheap_source>/4", "ns_per_pixel"))
ii = ns(get("BM_UpsampleInterpolatedPixel<cheap_source>/4", "ns_per_interpolated"))
up = ns(get("BM_UpsamplePlainEvaluation", "ns_per_pixel"))
row("upsampler's own work, 1025², 4 passes, cheap source, one core (ns per pixel)",
    mm(ui, "ns") + f" ({fmt(ii and ii[1])} ns per interpolated pixel, median)",
    "plain per-pixel evaluation of the same source: " + mm(up, "ns"), ratio(ui, up),
    "regression figure")

for args, what, goal in (("4/1", "default options (4 passes, a probe per pixel)", "—"),
                         ("6/0", "6 passes, probes only where sources or their normals (5°) differ", "≥ 24× single rays at ≥ 40 dB")):
    name = f"BM_IBufferFrame_vs_PerPixel/{args}/iterations:1"
    ib, pp, db = get(name, "ibuffer_ms"), get(name, "per_pixel_ms"), get(name, "psnr_db")
    pk = get(name, "per_pixel_packets_ms")
    row(f"I-Buffer frame, demo scene 1025², {what}, 2 threads, wall (ms)",
        mm(ib, "ms") + (f" at {db[0]:.1f} dB" if db else ""),
        "per-pixel evaluation, same source, single rays: " + mm(pp, "ms") + "; with 16-ray packets: " + mm(pk, "ms"),
        ratio(pp, ib) + " faster than single rays; " + ratio(pk, ib) + " faster than packets", goal)

print(f"CPU: {cpu} ({ncpu} cores{', ' + flags.strip() if flags.strip() else ''}); "
      f"load average {load0} before, {load1} after; {reps} repetitions, interleaved. "
      "Figures: best / median of the repetitions (rates: highest, times: lowest); "
      "one-core rates and times are CPU time, rows marked wall are wall time.")
print()
print("| what | measured | reference, same run | ratio (best, median) | goal |")
print("|---|---|---|---|---|")
print("\n".join(rows))
PY
