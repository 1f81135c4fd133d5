#!/usr/bin/env bash
# Installs what infolerp's tests, benchmarks and examples need on Debian 12, and unpacks the
# few CGAL meshes they use. Idempotent: installs only missing packages, unpacks data once.
# The library itself needs only GLM. Run as root (apt-get).
set -euo pipefail

packages=(cmake make g++ clang libclang-rt-14-dev libglm-dev catch2 libembree-dev libbenchmark-dev libstb-dev
          libassimp-dev gnuplot-nox libmeshoptimizer-dev libmetis-dev libtbb-dev openmpi-bin libopenmpi-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# CGAL's data archive ships in libcgal-demo, which depends on all of CGAL: download the .deb
# alone and take just the meshes we use out of it.
meshes=(bunny00 armadillo fandisk refined_elephant)
data_dir="${XDG_CACHE_HOME:-$HOME/.cache}/infolerp/meshes"
need=0
for m in "${meshes[@]}"; do [ -s "$data_dir/$m.off" ] || need=1; done
if ((need)); then
  echo "install-deps: unpacking CGAL meshes into $data_dir"
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  (cd "$tmp" && apt-get download libcgal-demo >/dev/null 2>&1) || {
    apt-get update -qq && (cd "$tmp" && apt-get download libcgal-demo >/dev/null); }
  dpkg -x "$tmp"/libcgal-demo_*.deb "$tmp/deb"
  mkdir -p "$data_dir"
  tar xzf "$tmp/deb/usr/share/doc/libcgal-dev/data.tar.gz" -C "$tmp" \
      $(printf 'data/meshes/%s.off ' "${meshes[@]}")
  for m in "${meshes[@]}"; do cp "$tmp/data/meshes/$m.off" "$data_dir/"; done
fi
echo "install-deps: ready (meshes in $data_dir)"
