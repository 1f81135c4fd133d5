#!/usr/bin/env bash
# The clang++ 14 build: every target (library header checks, tests, benchmarks, examples) in a
# build directory of its own, warnings as errors (-Werror comes from infolerp_strict in
# cmake/InfolerpDevelopment.cmake), then the whole test suite. Called from .ci/run.
#   .ci/clang.sh [BUILD_DIR]   (default build-clang)
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${1:-build-clang}"
CXX="${CXX_CLANG:-clang++-14}"
command -v "$CXX" > /dev/null || CXX=clang++
"$CXX" --version | head -1
CXX="$CXX" cmake -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER="$CXX"
cmake --build "$build_dir" -j2
ctest --test-dir "$build_dir" --output-on-failure
