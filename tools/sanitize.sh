#!/usr/bin/env bash
# The sanitizer tier (docs/testing.md): configures and builds build-san/ with AddressSanitizer
# (LeakSanitizer with it) and UndefinedBehaviorSanitizer (-DWP_SANITIZE=ON, GCC, -O1 -g), only
# wavepath and the test executables the tier runs (the wp_sanitize_tier target), then runs with
# ctest, tests side by side:
#   - the unit tier's GoogleTest entries (host code: loaders, BVH, film, tonemaps, program-cache
#     key, emission, packed sizes, ...; the tier's Python scripts are left out, nothing of theirs
#     is instrumented)
#   - the command-line tests, which run the instrumented wavepath binary, rendering through PoCL
#     inside it: Cli.*, EdgeCli.*, FilmCli.*, StopResume.*, InfoCli.*
#
#   tools/sanitize.sh [CTEST_ARGS...]   e.g. tools/sanitize.sh -R Gltf (ctest keeps the tests that
#                                       are in the tier and match)
#
# Any sanitizer report fails the test it happens in, in the test process or in a wavepath it runs
# (exit status 86, the report on stderr). PoCL's compiler stack is not instrumented and keeps its
# state to the end of the process: its leaks are suppressed (tests/sanitize/lsan.supp). The
# packages are tools/setup.sh's (it is not run here). WP_TEST_JOBS sets how many tests run at once
# (default: the number of cores plus one, as tools/test.sh).
set -euo pipefail
cd "$(dirname "$0")/.."

build="build-san"
jobs=$(nproc 2>/dev/null || echo 2)

# Sanitizer options, for the build too: gtest_discover_tests runs each test executable once after
# linking it, to list its tests. GCC links two runtimes, libasan (ASan and LSan: ASAN_OPTIONS,
# LSAN_OPTIONS) and libubsan (UBSAN_OPTIONS), each with its own copy of the common flags, so the
# exit status is set in both. A user's own options come last and win.
#   exitcode=86  a status no wavepath run has (0, 1, 128 + signal), so that a report in a run a
#                test expects to fail with status 1 still fails the test
#   intercept_tls_get_addr=0  GCC 12's runtime records the TLS blocks of libraries loaded with
#                dlopen (libLLVM and libclang-cpp, which PoCL brings) for the leak check to scan, and
#                takes a block that happens to start 16 bytes into a page for glibc 2.18's layout,
#                reading a bogus range before it (google/sanitizers#1322). The leak check at exit
#                then crashed now and then: "Tracer caught signal 11: addr=0x1708", in
#                ScanRangeForPointers, 2 of the first 51 command-line tests. Those blocks hold
#                only PoCL's and LLVM's pointers, whose leaks are suppressed anyway.
#   suppressions, print_suppressions=0  tests/sanitize/lsan.supp, silently: the command-line
#                tests compare wavepath's stderr
#   print_stacktrace=1, halt_on_error=1  UBSan's report with its stack, and the process ends
supp=$PWD/tests/sanitize/lsan.supp
export ASAN_OPTIONS="exitcode=86:intercept_tls_get_addr=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export LSAN_OPTIONS="suppressions=$supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:exitcode=86${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
# As tools/test.sh: PoCL compiles each kernel once, not once more per local size.
export POCL_WORK_GROUP_SPECIALIZATION=${POCL_WORK_GROUP_SPECIALIZATION:-0}

# -O1 -g (the Debug type's flags replaced; no NDEBUG, so assert()s are checked too): on the 2-core
# machine of docs/testing.md its build took ~560 s of CPU time against RelWithDebInfo's (-O2 -g)
# ~870 s, for a tier ~20 s longer.
cmake -S . -B "$build" -DWP_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g" \
  "-DCMAKE_C_FLAGS_DEBUG=-O1 -g" >/dev/null
cmake --build "$build" -j"$jobs" --target wp_sanitize_tier

cd "$build"
# The tier's tests by their ctest numbers (ctest -I), so that CTEST_ARGS narrow it further:
# GoogleTest entries (Suite.Test) labelled unit, and the command-line suites.
list=$(mktemp)
trap 'rm -f "$list"' EXIT
numbers() { ctest -N "$@" | sed -n 's/^ *Test *#\([0-9]*\): \(.*\)$/\1 \2/p'; }
{
  numbers -L '^unit$' | awk '$2 ~ /\./ { print $1 }'
  numbers -R '^(Cli|EdgeCli|FilmCli|StopResume|InfoCli)\.' | awk '{ print $1 }'
} | sort -n -u | paste -s -d, | sed 's/^/0,0,0,/' >"$list"
if [[ $(<"$list") == 0,0,0, ]]; then
  echo "wavepath sanitize: no tests found in $build" >&2
  exit 1
fi
test_jobs=${WP_TEST_JOBS:-$((jobs + 1))}
ctest --output-on-failure --timeout 600 -j"$test_jobs" -I "$list" "$@"
