#!/usr/bin/env bash
# Sets up (installs missing Debian packages, builds build/) and runs the test suite with ctest on
# the default OpenCL device (PoCL on a machine without a GPU), tests side by side (ctest -j), tiers
# and timings in docs/testing.md:
#   tools/test.sh [CTEST_ARGS...]          everything: unit, kernel, sampling, energy, scene, bench,
#                                          oclgrind, gpu and fuzz (WP_FUZZ_SECONDS per fuzz
#                                          target, default 60; 0 skips them)
#   tools/test.sh --quick [CTEST_ARGS...]  the developer loop: no fuzz, oclgrind, gpu or bench, and
#                                          of scene only what is not also labelled slow (the
#                                          accuracy_* scenes)
# Extra arguments go to ctest, e.g. tools/test.sh -R bvh, tools/test.sh -L kernel. WP_TEST_JOBS
# sets how many tests run at once (default: the number of cores plus one; see docs/testing.md).
#
# Most of the suite's time is PoCL compiling kernel programs (a few seconds each, ~100 distinct
# ones). PoCL compiles each kernel once more for every local size it is launched with
# (work-group specialization: faster kernels, slower builds); the tests' kernels are tiny, so
# this script turns that off unless POCL_WORK_GROUP_SPECIALIZATION is set (a quarter less CPU time
# for the suite; the images are the same bit for bit, docs/testing.md).
# A failing test (a fuzz finding included) fails the script; ctest runs last, so its summary
# closes the output.
set -euo pipefail
cd "$(dirname "$0")/.."

quick=0
if [[ ${1:-} == --quick ]]; then
  quick=1
  shift
fi
tools/setup.sh

export POCL_WORK_GROUP_SPECIALIZATION=${POCL_WORK_GROUP_SPECIALIZATION:-0}
jobs=${WP_TEST_JOBS:-$(($(nproc 2>/dev/null || echo 2) + 1))}
args=(--output-on-failure --timeout 600 -j"$jobs")
if ((quick)); then
  args+=(-LE 'fuzz|oclgrind|gpu|bench|slow')
else
  fuzz_seconds=${WP_FUZZ_SECONDS:-60}
  if [[ $fuzz_seconds == 0 ]]; then
    echo "wavepath: fuzzing skipped (WP_FUZZ_SECONDS=0)"
  elif ! tools/fuzz.sh --check; then
    echo "wavepath: fuzzing skipped (no clang++ with libFuzzer; tools/setup.sh installs it)"
  fi
fi
cd build
exec ctest "${args[@]}" "$@"
