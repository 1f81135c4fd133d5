#!/usr/bin/env bash
# Runs each libFuzzer target of tests/fuzz (built with clang, ASan + UBSan, assertions on, in
# the given build tree: .ci/sanitizers.sh passes build-asan) for FUZZ_SECONDS (default 30) on a
# copy of its seed corpus (tests/fuzz/corpus/<target>/), so the repository's corpus is never
# modified. Prints executions per target; fails on the first crash, leak, sanitizer report or
# failed FUZZ_CHECK (the offending input is kept in <tree>/fuzz-artifacts/).
#   .ci/fuzz.sh [BUILD_DIR]   (default build-asan; configured with cmake --preset asan if missing)
set -euo pipefail
cd "$(dirname "$0")/.."
tree=${1:-build-asan}
seconds=${FUZZ_SECONDS:-30}
jobs=${INFOLERP_JOBS:-2}

[ -f "$tree/CMakeCache.txt" ] || cmake --preset asan >/dev/null
targets=()
for src in tests/fuzz/fuzz_*.cpp; do targets+=("$(basename "$src" .cpp)"); done
cmake --build "$tree" -j"$jobs" --target "${targets[@]}"

mkdir -p "$tree/fuzz-artifacts"
summary=()
for t in "${targets[@]}"; do
  work=$tree/fuzz-corpus/$t
  rm -rf "$work" && mkdir -p "$work"
  log=$tree/$t.log
  echo "fuzz: $t for ${seconds} s"
  if ! LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp:print_suppressions=0" "$tree"/tests/fuzz/"$t" -max_total_time="$seconds" -print_final_stats=1 -rss_limit_mb=2048 \
        -timeout=10 -artifact_prefix="$tree/fuzz-artifacts/$t-" "$work" tests/fuzz/corpus/"$t" >"$log" 2>&1; then
    tail -n 60 "$log"
    echo "fuzz: $t FAILED (input in $tree/fuzz-artifacts/)"
    exit 1
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo "?")
  summary+=("$t: $runs executions, coverage $cov edges, corpus $(ls "$work" | wc -l) inputs")
done
printf 'fuzz: %s\n' "${summary[@]}"
