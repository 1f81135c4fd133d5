#!/usr/bin/env bash
# Fuzzing (issue 8), called by .ci/run: builds the libFuzzer targets of tests/fuzz with clang
# (ASan + UBSan, assertions on) and runs each for FUZZ_SECONDS (default 30) on a copy of its
# seed corpus (tests/fuzz/corpus/<target>/), so the repository's corpus is never modified.
# Prints executions per target; fails on the first crash, leak, sanitizer report or failed
# FUZZ_CHECK (the offending input is kept in build-fuzz/artifacts/).
# Environment: FUZZ_SECONDS (per target), INFOLERP_JOBS (build parallelism, default 2).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${FUZZ_SECONDS:-30}
jobs=${INFOLERP_JOBS:-2}

cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE= -DINFOLERP_BUILD_FUZZERS=ON \
      -DINFOLERP_BUILD_TESTS=OFF -DINFOLERP_BUILD_BENCHMARKS=OFF -DINFOLERP_BUILD_EXAMPLES=OFF >/dev/null
targets=()
for src in tests/fuzz/fuzz_*.cpp; do targets+=("$(basename "$src" .cpp)"); done
cmake --build build-fuzz -j"$jobs" --target "${targets[@]}"

mkdir -p build-fuzz/artifacts
summary=()
for t in "${targets[@]}"; do
  work=build-fuzz/corpus/$t
  rm -rf "$work" && mkdir -p "$work"
  log=build-fuzz/$t.log
  echo "fuzz: $t for ${seconds} s"
  if ! build-fuzz/tests/fuzz/"$t" -max_total_time="$seconds" -print_final_stats=1 -rss_limit_mb=2048 \
        -timeout=10 -artifact_prefix=build-fuzz/artifacts/"$t"- "$work" tests/fuzz/corpus/"$t" >"$log" 2>&1; then
    tail -n 60 "$log"
    echo "fuzz: $t FAILED (input in build-fuzz/artifacts/)"
    exit 1
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo "?")
  summary+=("$t: $runs executions, coverage $cov edges, corpus $(ls "$work" | wc -l) inputs")
done
printf 'fuzz: %s\n' "${summary[@]}"
