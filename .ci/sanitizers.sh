#!/usr/bin/env bash
# The clang++ 14 and sanitizer stage of CI, called by .ci/run:
#  1. One clang tree (CMakePresets.json "asan", build-asan/) with AddressSanitizer +
#     UndefinedBehaviorSanitizer at -O0 and assertions on. It is also the clang build with warnings
#     as errors (-Werror comes from infolerp_strict), so every target is built in it: header
#     checks, tests, benchmarks, examples and the libFuzzer targets. Then its whole ctest suite.
#     -O0 because building this tree is the longest step of CI: it compiles in under half the time
#     of -O1, more than the tests lose by running slower; the fuzz targets keep -O1 for their rate.
#     The saliency kernels are capped at AVX2 here (INFOLERP_NO_AVX512), so that the AVX2 kernel
#     also meets the brute-force references on an AVX-512 machine; the g++ stage tests the widest
#     the machine has and the TSan run below the portable kernels. Embree runs its SSE4.2
#     kernels here (INFOLERP_EMBREE_CONFIG), a third set of the tracer's rounding.
#  2. ThreadSanitizer ("tsan" preset): infolerp_tests_threads, the [threads] tests
#     (tests/reliability/test_determinism.cpp), which drive every parallel component through
#     support::thread_pool_executor with 1, 2 and 8 workers. Tests using openmp_executor are
#     excluded on purpose: Debian's libgomp is not built with TSan, so every OpenMP region would
#     be reported as a race; Embree likewise (its task threads are not instrumented).
#  3. .ci/fuzz.sh build-asan: each fuzz target for FUZZ_SECONDS on a copy of its seed corpus.
# Environment: INFOLERP_JOBS (default 2) build and test parallelism, FUZZ_SECONDS.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${INFOLERP_JOBS:-2}
start=$SECONDS
clang++ --version | head -1

cmake --preset asan >/dev/null
cmake --build build-asan -j"$jobs"
echo "sanitizers: clang ASan+UBSan build of every target took $((SECONDS - start)) s"
t=$SECONDS
ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1} \
UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1} \
INFOLERP_EMBREE_CONFIG=max_isa=sse4.2 \
  ctest --test-dir build-asan -j"$jobs" --output-on-failure
echo "sanitizers: clang ASan+UBSan tests took $((SECONDS - t)) s"

t=$SECONDS
cmake --preset tsan >/dev/null
cmake --build build-tsan -j"$jobs" --target infolerp_tests_threads
TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1} \
  build-tsan/tests/infolerp_tests_threads "[threads]"
echo "sanitizers: TSan build + run took $((SECONDS - t)) s"

t=$SECONDS
FUZZ_SECONDS=${FUZZ_SECONDS:-15} bash .ci/fuzz.sh build-asan
echo "sanitizers: fuzzing took $((SECONDS - t)) s; stage total $((SECONDS - start)) s"
