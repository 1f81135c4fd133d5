#!/usr/bin/env python3
"""Writes the seed corpus (tests/fuzz/corpus/<target>/*) in the byte formats the targets read
(see fuzz_common.hpp and the comment at the top of each target). Run from anywhere; the files
are committed, so this only needs re-running when a format changes."""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def c(v):  # a coordinate on the 1/16 grid
    return bytes([int(round(v * 16)) + 127])


def mesh(vertices, triangles, scale=0):
    out = bytes([len(vertices), len(triangles), scale & 0xFF])
    for p in vertices:
        out += b"".join(c(x) for x in p)
    for t in triangles:
        out += bytes(t)
    return out


OCTA_V = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
OCTA_T = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
G = 1.625  # golden ratio on the 1/16 grid
ICO_V = [(-1, G, 0), (1, G, 0), (-1, -G, 0), (1, -G, 0), (0, -1, G), (0, 1, G), (0, -1, -G), (0, 1, -G),
         (G, 0, -1), (G, 0, 1), (-G, 0, -1), (-G, 0, 1)]
ICO_T = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]


def write(target, name, data):
    d = os.path.join(HERE, "corpus", target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


# fuzz_mesh: [flags][mesh]
write("fuzz_mesh", "octahedron", bytes([0]) + mesh(OCTA_V, OCTA_T))
write("fuzz_mesh", "icosahedron_stride20", bytes([0x20]) + mesh(ICO_V, ICO_T))
write("fuzz_mesh", "non_manifold", bytes([0]) + mesh(OCTA_V + [(2, 2, 2)], OCTA_T + [(0, 2, 6)]))
write("fuzz_mesh", "nan_vertex", bytes([4]) + mesh(OCTA_V, OCTA_T)[:3 + 3] + b"\xff" + struct.pack("<f", float("nan"))
      + mesh(OCTA_V, OCTA_T)[3 + 3 + 1:])
write("fuzz_mesh", "degenerate_allowed", bytes([1]) + mesh(OCTA_V, OCTA_T[:-1] + [(0, 0, 5)]))
write("fuzz_mesh", "huge_scale", bytes([0]) + mesh(OCTA_V, OCTA_T, scale=100))

# fuzz_jensen_shannon: [mode][weight][bins u16][entries]
write("fuzz_jensen_shannon", "equal_sizes", bytes([1, 127]) + struct.pack("<H", 8) +
      bytes([64, 80, 0, 200, 100, 65, 0, 9]) + bytes([100, 0, 70, 70, 250, 64, 3, 90]) + bytes([127] * 8))
write("fuzz_jensen_shannon", "subnormal_huge", bytes([7, 60]) + struct.pack("<H", 4) +
      bytes([253, 5, 252, 3, 64, 253, 1]) + bytes([70, 252, 9, 253, 7, 80]) + bytes([100] * 20))
write("fuzz_jensen_shannon", "mismatch", bytes([0, 127]) + struct.pack("<H", 3) + struct.pack("<H", 2) +
      bytes([64, 65, 66, 67, 68]))

# fuzz_saliency: [flags][epsilon][scale count][scales][unused][clusters][seed][mesh][pool][iterations]
# [camera][capacities][target u16][lambda]
sal_head = bytes([0, 64, 2, 85, 127, 180, 3, 1])
write("fuzz_saliency", "icosahedron_exact", sal_head + mesh(ICO_V, ICO_T) + bytes([60, 4]) + c(3) + c(0) + c(0) +
      bytes([10] * 3) + struct.pack("<H", 20) + bytes([10]))
write("fuzz_saliency", "octahedron_one_scale", bytes([0, 40, 1, 127, 100, 2, 9]) + mesh(OCTA_V, OCTA_T) + bytes([254, 1]))

# fuzz_subdivision: [flags][bisect][depth][mesh unless flags & 1] then operations
# op code % 5: 0 split id (u16, depth u8), 1 newest (back u8), 2 selection (count u8, u16 ids),
# 3 locate (original u8, u, v), 4 tessellate (limit, max level); bits 5-7 all set also check conformity.
ops = bytes([0x82, 3, 0, 1, 0x83, 0, 0x84, 3, 0, 0, 1, 0, 2, 0, 0x80, 1, 50, 80, 0x81, 40, 3, 0x83, 0, 0x83, 0,
             0x82, 7, 0, 0, 0x02, 2, 1, 0, 0xE8, 0x03])
write("fuzz_subdivision", "grid_ops", bytes([1 | (2 << 1), 127, 1]) + ops)
write("fuzz_subdivision", "octahedron_ops", bytes([0, 64, 2]) + mesh(OCTA_V, OCTA_T) + ops)
write("fuzz_subdivision", "deep_chain", bytes([1, 127, 1]) + bytes([0x83, 3] * 300) + bytes([0x80, 0, 20, 30]))

# fuzz_upsampler: [w u16][h u16][passes][max passes][rows][flags][cell][id count][ids] then ops, controller
up = struct.pack("<HH", 61, 47) + bytes([4, 4, 2, 3, 6, 4, 0, 1, 255, 2])
write("fuzz_upsampler", "basic", up + bytes([0, 3, 2, 1]) + struct.pack("<HH", 33, 20) + bytes([2]) +
      bytes([20, 40, 4, 2, 127, 3, 100]) + bytes([30, 60, 90, 120, 60, 30, 10]))
write("fuzz_upsampler", "one_pixel", struct.pack("<HH", 1, 1) + bytes([16, 16, 1, 1, 1, 1, 7]))
write("fuzz_upsampler", "plain", struct.pack("<HH", 17, 9) + bytes([1, 1, 8, 0, 3, 2, 254]) + struct.pack("<I", 0xfffffffe) + bytes([5]))

# fuzz_cluster: [flags][th vis][th ori][th str][viewpoints][samples][ori bins][str bins][min fraction][mesh][uvs]
UV = b"".join(c(u) + c(v) for u, v in [(0, 0), (1, 0), (0, 1)] * 20)
write("fuzz_cluster", "icosahedron_uv", bytes([5, 76, 10, 25, 6, 1, 16, 8, 2]) + mesh(ICO_V, ICO_T) + UV)
write("fuzz_cluster", "octahedron_exact_rows", bytes([2, 127, 5, 25, 4, 2, 0, 0, 0]) + mesh(OCTA_V, OCTA_T))
write("fuzz_cluster", "two_pieces", bytes([4, 40, 60, 25, 3, 1, 9, 0, 10]) +
      mesh(OCTA_V + [(3, 3, 3), (4, 3, 3), (3, 4, 3)], OCTA_T + [(6, 7, 8)]))

# fuzz_lod: [flags][backstop][cluster count - 1][mesh][cluster id per triangle][weight per corner][budgets]
# flags: 1 ids may be out of range, 2 one weight too many, 4 uniform weights (none read), 8 no
# cluster-local phase, 16 neighbour matching, bits 5-7 chunk grain - 1.
PLANE_V = [(x * 0.5, y * 0.5, 0) for y in range(4) for x in range(4)]
PLANE_T = [t for y in range(3) for x in range(3)
           for t in [(y * 4 + x, y * 4 + x + 1, y * 4 + x + 5), (y * 4 + x, y * 4 + x + 5, y * 4 + x + 4)]]
write("fuzz_lod", "icosahedron_matched", bytes([16, 0, 2]) + mesh(ICO_V, ICO_T) + bytes([t % 3 for t in range(20)]) +
      bytes([(7 * k) % 254 for k in range(60)]) + bytes([5, 2, 9]))
write("fuzz_lod", "octahedron_uniform_global", bytes([4 | 8 | 16 | 0x40, 0, 1]) + mesh(OCTA_V, OCTA_T) +
      bytes([0, 1] * 4) + bytes([3, 4]))
write("fuzz_lod", "plane_boundary", bytes([4, 0, 1]) + mesh(PLANE_V, PLANE_T) + bytes([t // 9 for t in range(18)]) +
      bytes([6, 7]))

# Options targets: option values through reader::real() (byte s: (s - 64) / 32; 254 + k: the k-th
# extreme; 255 + 8 bytes: raw double) and reader::count<T>() (byte s: s; 254: the type's largest).
def r(v):  # a real option on the 1/32 grid
    return bytes([int(round(v * 32)) + 64])


EXTREME_NAN, EXTREME_INF, EXTREME_MAX = bytes([254, 0]), bytes([254, 1]), bytes([254, 3])
COUNT_MAX = bytes([254])

# fuzz_options_cluster: [flags][min fraction][grain][vis: threshold viewpoints samples radius grain
# probes resolution min-pixels][ori: threshold bins exact][str: threshold bins exact theta][mesh][uvs]
write("fuzz_options_cluster", "visibility_orientation", bytes([0x05]) + r(0) + bytes([32]) +
      r(0.5) + bytes([8, 2]) + r(1) + bytes([64, 0, 16]) + r(4) + r(0.03) + bytes([64, 0]) + r(0.1) + bytes([32, 0]) +
      r(1) + mesh(OCTA_V, OCTA_T))
write("fuzz_options_cluster", "stretch_uv", bytes([0xC1]) + r(0.01) + bytes([3]) + r(0.5) + bytes([8, 2]) + r(1) +
      bytes([64, 0, 16]) + r(4) + r(0.03) + bytes([0, 1]) + r(0.1) + bytes([16, 1]) + r(1) + mesh(ICO_V, ICO_T) + UV)
write("fuzz_options_cluster", "extremes", bytes([0x25]) + r(0) + COUNT_MAX + r(0.5) + COUNT_MAX + bytes([2]) + r(1) +
      COUNT_MAX + COUNT_MAX + COUNT_MAX + EXTREME_INF + r(0.03) + COUNT_MAX + bytes([0]) + r(0.1) + COUNT_MAX +
      bytes([0]) + EXTREME_MAX + mesh(OCTA_V, OCTA_T))

# fuzz_options_saliency: [flags][epsilon][flat threshold][grain][scale count][scales][clusters][pool]
# [normal weight][seed][iterations][camera x3][lambda][target][mesh][capacities]
write("fuzz_options_saliency", "defaults_icosahedron", bytes([1]) + r(0.1) + r(0) + bytes([1, 0]) + bytes([3]) +
      r(5) + r(1) + bytes([1, 50]) + r(0.5) + r(0.5) + r(4) + r(0.03) + bytes([20]) + mesh(ICO_V, ICO_T) +
      bytes([9, 9, 9]))
write("fuzz_options_saliency", "own_scales", bytes([2]) + r(0.25) + r(0.01) + bytes([3, 2]) + r(1) + r(2) +
      bytes([2]) + r(2) + r(1) + bytes([7, 3]) + r(0) + r(0) + r(3) + r(1) + bytes([5]) + mesh(OCTA_V, OCTA_T) +
      bytes([4, 4]))
write("fuzz_options_saliency", "extremes", bytes([1]) + EXTREME_NAN + r(0) + COUNT_MAX + bytes([0]) + COUNT_MAX +
      EXTREME_MAX + EXTREME_INF + COUNT_MAX + COUNT_MAX + EXTREME_MAX + r(0) + r(4) + bytes([254, 5]) + COUNT_MAX +
      mesh(ICO_V, ICO_T) + bytes([200] * 4))

# fuzz_options_lod: [flags][epsilon][smoothing][percentile / 20][amplification][grain][backstop]
# [boundary weight][min normal cos][lambda][grain][camera x3][contractions][clusters - 1][mesh]
# [saliency per vertex][cluster per triangle]
write("fuzz_options_lod", "icosahedron_two_clusters", bytes([1]) + r(0.1) + r(3) + r(1.5) + r(1) + bytes([1]) +
      r(0) + r(2) + r(0) + r(0.03) + bytes([3]) + r(0.5) + r(-1) + r(5) + bytes([6, 1]) + mesh(ICO_V, ICO_T) +
      bytes([(37 * k) % 254 for k in range(12)]) + bytes([t % 2 for t in range(20)]))
write("fuzz_options_lod", "extremes", bytes([3]) + EXTREME_MAX + EXTREME_MAX + r(5) + EXTREME_MAX + COUNT_MAX +
      r(1) + EXTREME_INF + r(0.99) + r(1) + COUNT_MAX + EXTREME_MAX + r(0) + r(0) + COUNT_MAX + bytes([0]) +
      mesh(OCTA_V, OCTA_T) + EXTREME_MAX * 6 + bytes([0] * 8))

# fuzz_options_refine: [flags][bisect][depth][criterion][s_req][min pixels][always][batch][rnd fraction]
# [nld_is fraction][random share][seed][max samples][max batches][max cached][background][grain]
# [eye x3][target x3][up x3][fov if flags & 1][width][height][hit: geometry triangle u v distance][mesh]
refine_head = (bytes([0]) + r(0.5) + bytes([1, 0]) + r(0.05) + r(2) + r(0.03) + bytes([16, 127]) + r(1) + r(0) +
               bytes([1]) + COUNT_MAX + bytes([6]) + COUNT_MAX + r(0) + bytes([64]))
camera_part = r(0.2) + r(-0.3) + r(-0.5) + r(0) + r(0) + r(0) + r(0) + r(1) + r(0) + bytes([12, 10])
write("fuzz_options_refine", "nld_os_plane", refine_head + camera_part + bytes([0, 0]) + r(0.25) + r(0.25) + r(1) +
      mesh(PLANE_V, PLANE_T))
write("fuzz_options_refine", "wild_hits", bytes([2]) + refine_head[1:] + camera_part + bytes([0, 3]) +
      bytes([255]) + struct.pack("<d", 1e38) + bytes([255]) + struct.pack("<d", -1e38) + r(1) + mesh(PLANE_V, PLANE_T))
write("fuzz_options_refine", "far_camera", bytes([1]) + refine_head[1:] + bytes([255]) + struct.pack("<d", 3e19) +
      r(0) + r(0) + r(0) + r(0) + r(0) + r(0) + r(1) + r(0) + EXTREME_MAX + bytes([8, 8, 0, 0]) + r(0.2) + r(0.2) +
      r(1) + mesh(PLANE_V, PLANE_T))

# fuzz_options_upsample: [flags][w][h][passes][max passes][rows][min sources][controller: min max
# max-passes initial smoothing settle forget][8 frame times][ao rays][ao radius][offset][lights if 4]
# [soft points if 8][soft normal x3][view origin x3][view forward x3][tolerance][hit: triangle u v
# distance][mesh][normals if 32][texcoords if 64]
up_head = (bytes([24, 23, 3, 3, 2, 2]) + r(0.5) + r(1) + bytes([4, 1]) + r(0.25) + bytes([2, 30]) +
           b"".join(r(v) for v in [0.25, 0.5, 2, 1.5, 0.1, 0.1, 1, 0]))
rc_tail = (bytes([8]) + r(1.5) + r(0.01) + r(0) + r(0) + r(-1) + r(0) + r(0) + r(0) + r(0) + r(0) + r(-1) + EXTREME_INF +
           bytes([5]) + r(0.2) + r(0.2) + r(1))
write("fuzz_options_upsample", "icosahedron", bytes([0x01]) + up_head + rc_tail + mesh(ICO_V, ICO_T))
write("fuzz_options_upsample", "normals_uvs", bytes([0x61]) + up_head + rc_tail + mesh(OCTA_V, OCTA_T) +
      b"".join(r(x) for p in OCTA_V for x in p) + bytes([0]) + r(0.5) * 48)
write("fuzz_options_upsample", "extremes", bytes([0x8E]) + COUNT_MAX + COUNT_MAX + COUNT_MAX + COUNT_MAX +
      COUNT_MAX + COUNT_MAX + EXTREME_NAN + EXTREME_MAX + COUNT_MAX + COUNT_MAX + EXTREME_INF + COUNT_MAX +
      COUNT_MAX + EXTREME_MAX * 8 + COUNT_MAX + EXTREME_MAX + EXTREME_INF + r(1) * 12 + r(0) * 9 + EXTREME_NAN +
      bytes([1]) + bytes([255]) + struct.pack("<d", 1e38) + bytes([255]) + struct.pack("<d", -1e38) + r(1) +
      mesh(OCTA_V, OCTA_T))
