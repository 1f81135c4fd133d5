#!/usr/bin/env bash
# Sanitizer runs (issue 8), called by .ci/run:
#  1. AddressSanitizer + UndefinedBehaviorSanitizer (CMakePresets.json "asan"): every Catch2
#     test executable (tests/<area>/), run through ctest. The build-only tests
#     (header_self_contained, compile_fail_*, consumer_*) execute no library code and are left
#     to the plain build.
#  2. ThreadSanitizer ("tsan"): the tests tagged [threads] (tests/reliability/
#     test_determinism.cpp), which drive every parallel component through
#     support::thread_pool_executor with 1, 2 and 8 workers. Tests using openmp_executor are
#     excluded on purpose: Debian's libgomp is not built with TSan, so its barriers are invisible
#     to TSan and every OpenMP region is reported as a race (false positives). Embree is
#     excluded for the same reason (its task threads are not instrumented); [threads] tests use
#     support::brute_force_tracer.
# Environment: INFOLERP_JOBS (default 2) build parallelism.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${INFOLERP_JOBS:-2}
start=$SECONDS

areas=()
for d in tests/*/; do
  a=$(basename "$d")
  [[ $a =~ ^(support|consumer|compile_fail|fuzz)$ ]] && continue
  compgen -G "tests/$a/*.cpp" >/dev/null && areas+=("$a")
done
targets=("${areas[@]/#/infolerp_tests_}")
regex="^($(IFS='|'; echo "${areas[*]}"))\$"

echo "sanitizers: ASan+UBSan build of ${targets[*]}"
cmake --preset asan >/dev/null
cmake --build build-asan -j"$jobs" --target "${targets[@]}"
echo "sanitizers: ASan+UBSan build took $((SECONDS - start)) s"
t=$SECONDS
ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1} \
UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1} \
  ctest --test-dir build-asan --output-on-failure -R "$regex"
echo "sanitizers: ASan+UBSan tests took $((SECONDS - t)) s"

t=$SECONDS
echo "sanitizers: TSan build of infolerp_tests_reliability"
# Portable kernels here (no run-time dispatch), so that CI also runs them (see .ci/clang.sh).
cmake --preset tsan -DCMAKE_CXX_FLAGS="-fsanitize=thread -fno-omit-frame-pointer -DINFOLERP_NO_RUNTIME_DISPATCH" >/dev/null
cmake --build build-tsan -j"$jobs" --target infolerp_tests_reliability
TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1} \
  build-tsan/tests/infolerp_tests_reliability "[threads]"
echo "sanitizers: TSan build + run took $((SECONDS - t)) s; total $((SECONDS - start)) s"
