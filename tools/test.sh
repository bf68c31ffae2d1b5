#!/usr/bin/env bash
# Sets up (installs missing Debian packages, builds build/) and runs the whole test suite: first,
# when clang++ with libFuzzer is there, a short fuzz run of the loaders (tools/fuzz.sh,
# WP_FUZZ_SECONDS per target, default 60; 0 skips it), then ctest on the default OpenCL device
# (PoCL on a machine without a GPU). Extra arguments go to ctest, e.g. tools/test.sh -R bvh.
# Either failing fails the script; ctest runs last, so its summary closes the output.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh

fuzz_status=0
fuzz_seconds=${WP_FUZZ_SECONDS:-60}
if ((fuzz_seconds == 0)); then
  echo "wavepath: fuzzing skipped (WP_FUZZ_SECONDS=0)"
elif tools/fuzz.sh --check; then
  tools/fuzz.sh "$fuzz_seconds" || fuzz_status=$?
else
  echo "wavepath: fuzzing skipped (no clang++ with libFuzzer; tools/setup.sh installs it)"
fi
if ((fuzz_status != 0)); then
  echo "wavepath: fuzzing found a problem (exit status $fuzz_status; see above)" >&2
fi

ctest_status=0
(cd build && ctest --output-on-failure --timeout 600 "$@") || ctest_status=$?
if ((ctest_status != 0)); then exit "$ctest_status"; fi
exit "$fuzz_status"
