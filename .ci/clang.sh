#!/usr/bin/env bash
# The clang++ 14 build: every target (library header checks, tests, benchmarks, examples) in a
# build directory of its own, warnings as errors (-Werror comes from infolerp_strict in
# cmake/InfolerpDevelopment.cmake), then the whole test suite. Called from .ci/run.
# The vector kernels are chosen at run time (saliency: AVX-512, AVX2 or portable; JS: AVX2 or
# SSE2). The g++ stage tests the widest this machine has; this stage caps saliency at AVX2
# (INFOLERP_NO_AVX512) so that the AVX2 kernel also meets the brute-force references on an
# AVX-512 machine, and the TSan stage (.ci/sanitizers.sh) runs the portable kernels.
#   .ci/clang.sh [BUILD_DIR]   (default build-clang)
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${1:-build-clang}"
CXX="${CXX_CLANG:-clang++-14}"
command -v "$CXX" > /dev/null || CXX=clang++
"$CXX" --version | head -1
CXX="$CXX" cmake -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER="$CXX" -DCMAKE_CXX_FLAGS=-DINFOLERP_NO_AVX512
cmake --build "$build_dir" -j2
ctest --test-dir "$build_dir" --output-on-failure
