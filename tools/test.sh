#!/usr/bin/env bash
# Sets up (installs missing Debian packages, builds build/) and runs the test suite with ctest on
# the default OpenCL device (PoCL on a machine without a GPU), tests side by side (ctest -j), tiers
# and timings in docs/testing.md:
#   tools/test.sh [CTEST_ARGS...]          the default suite: unit, kernel, sampling, energy, scene,
#                                          bench, oclgrind, gpu (two representative variants) and
#                                          fuzz (WP_FUZZ_SECONDS per target, default 3; 0 skips
#                                          them), without the tests also labelled slow
#   tools/test.sh --quick [CTEST_ARGS...]  the developer loop: the unit, kernel and sampling tiers
#                                          (host code, every kernel against its host reference,
#                                          every sampling routine's chi-square test), not slow
#   tools/test.sh --all [CTEST_ARGS...]    everything: the default suite and the slow tier (the
#                                          accuracy_* scenes, every GPU variant); what CI runs
# Extra arguments go to ctest, e.g. tools/test.sh -R bvh, tools/test.sh -L kernel. WP_TEST_JOBS
# sets how many tests run at once (default: the number of cores plus one; see docs/testing.md).
# Hours of fuzzing are a command of their own: tools/fuzz.sh 3600.
#
# Most of the suite's time is PoCL compiling kernel programs (a few seconds each, ~100 distinct
# ones). PoCL compiles each kernel once more for every local size it is launched with
# (work-group specialization: faster kernels, slower builds); the tests' kernels are tiny, so
# this script turns that off unless POCL_WORK_GROUP_SPECIALIZATION is set (a quarter less CPU time
# for the suite; the images are the same bit for bit, docs/testing.md).
# A failing test (a fuzz finding included) fails the script. ctest's summary closes the output,
# then one line naming the tests that were skipped and what would run them.
set -euo pipefail
cd "$(dirname "$0")/.."

tier=default
case ${1:-} in
  --quick | --all) tier=${1#--} && shift ;;
esac
tools/setup.sh --tests

export POCL_WORK_GROUP_SPECIALIZATION=${POCL_WORK_GROUP_SPECIALIZATION:-0}
jobs=${WP_TEST_JOBS:-$(($(nproc 2>/dev/null || echo 2) + 1))}
args=(--output-on-failure --timeout 600 -j"$jobs")
if [[ $tier == quick ]]; then
  args+=(-L 'unit|kernel|sampling' -LE slow)
else
  [[ $tier == default ]] && args+=(-LE slow)
  fuzz_seconds=${WP_FUZZ_SECONDS:-3}
  if [[ $fuzz_seconds == 0 ]]; then
    echo "wavepath: fuzzing skipped (WP_FUZZ_SECONDS=0)"
  elif ! tools/fuzz.sh --check; then
    echo "wavepath: fuzzing skipped (no clang++ with libFuzzer; tools/setup.sh installs it)"
  fi
fi
cd build
log=$(mktemp)
trap 'rm -f "$log"' EXIT
set +e
ctest "${args[@]}" "$@" | tee "$log"
status=${PIPESTATUS[0]}
set -e

# One closing line naming the tests that skipped and what enables them (ctest lists them as
# "(Skipped)" under "The following tests did not run:").
skipped=$(sed -n 's/^[[:space:]]*[0-9]* - \(.*\) (Skipped)$/\1/p' "$log")
if [[ -z $skipped ]]; then
  echo "wavepath: no test skipped"
else
  declare -A groups=()
  while IFS= read -r name; do
    case $name in
      Denoise*) why="Open Image Denoise: tools/setup.sh --denoise" ;;
      fuzz_*) why="clang++ with libFuzzer: tools/setup.sh, and WP_FUZZ_SECONDS not 0" ;;
      gpu_compile) why="clang's GPU targets, libclc and the CUDA toolkit's ptxas" ;;
      Mpi.*) why="Open MPI: tools/setup.sh" ;;
      KernelSources.EachStageBuildsWithClang*) why="clang: tools/setup.sh" ;;
      vectorization_py | simd_probe_py) why="PoCL as the default OpenCL device" ;;
      *) why="the shared models: ../shared/assets or WAVEPATH_ASSETS" ;;
    esac
    groups[$why]+="${groups[$why]:+, }$name"
  done <<<"$skipped"
  line="wavepath: $(wc -l <<<"$skipped") tests skipped:"
  sep=" "
  for why in "${!groups[@]}"; do
    line+="$sep${groups[$why]} (to run them: $why)"
    sep="; "
  done
  echo "$line"
fi
exit "$status"
