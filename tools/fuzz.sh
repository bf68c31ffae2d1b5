#!/usr/bin/env bash
# Builds the fuzz targets (tests/fuzz/, clang++ with libFuzzer, AddressSanitizer and
# UndefinedBehaviorSanitizer) in build-fuzz/ and runs each for SECONDS (default 60):
#   fuzz_gltf         wp::load_gltf on .gltf / .glb bytes
#   fuzz_environment  wp::load_environment on .hdr (and .exr) bytes
#   fuzz_draco, fuzz_meshopt, fuzz_webp  wp::load_gltf on a .glb around a compressed payload
#                     (tests/fuzz/fuzz_compressed.cpp)
#   fuzz_image        wp::decode_image on PNG, JPEG and WebP bytes (libpng, libjpeg-turbo, libwebp)
# Seeds: tests/fuzz/make_seeds.py's built-in ones, plus small models and cropped .hdr maps from
# ../shared/assets (WAVEPATH_ASSETS overrides) when that folder exists; for the compressed data and
# JPEGs, the main build's build/tests/make_compressed_seeds compresses a built-in quad and those
# models (Draco, meshopt, WebP: twins for fuzz_gltf, payloads for the codecs' targets). The corpus
# each run grows is kept in build-fuzz/corpus/<target>/, so later runs start where earlier ones
# stopped.
#
# Every run first replays the target's corpus, its seeds and the committed regression inputs
# (tests/fuzz/regressions/TARGET/), then fuzzes for the rest of its time.
#
# Exits non-zero when a target reports a finding (a crash, a sanitizer report, an exception other
# than wp::Error, a broken scene invariant, a hang over 10 s, a leak, over 2 GiB of memory): the
# input is saved in build-fuzz/findings/<target>/ and printed with the log's tail. Replay one with
#   build-fuzz/fuzz_gltf build-fuzz/findings/fuzz_gltf/crash-...
# (WP_FUZZ_VERBOSE=1 prints the wp::Error an input gives).
#
#   tools/fuzz.sh [SECONDS [TARGET...]]   build if needed, fuzz each target (default: all) SECONDS
#   tools/fuzz.sh --build                 only build the targets and the seeds
#   tools/fuzz.sh --run SECONDS TARGET... fuzz without building (after --build; ctest's fuzz tier
#                                         runs the targets side by side this way, tests/CMakeLists.txt)
#   tools/fuzz.sh --check                 exit 0 when clang++ can build libFuzzer targets, else 1
#                                         (silent)
set -euo pipefail
cd "$(dirname "$0")/.."

have_libfuzzer() {
  command -v clang++ >/dev/null 2>&1 || return 1
  local dir
  dir=$(mktemp -d)
  printf 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }\n' \
    >"$dir/probe.cpp"
  clang++ -fsanitize=fuzzer,address,undefined "$dir/probe.cpp" -o "$dir/probe" >/dev/null 2>&1
  local status=$?
  rm -rf "$dir"
  return $status
}

if [[ ${1:-} == --check ]]; then
  if have_libfuzzer; then exit 0; fi
  exit 1
fi
build_step=1 run_step=1
case ${1:-} in
  --build) run_step=0 && shift ;;
  --run) build_step=0 && shift ;;
esac
usage() {
  echo "usage: tools/fuzz.sh [SECONDS [TARGET...]] | --build | --run SECONDS TARGET... | --check" >&2
  exit 2
}
seconds=60
all_targets=(fuzz_gltf fuzz_environment fuzz_draco fuzz_meshopt fuzz_webp fuzz_image)
targets=("${all_targets[@]}")
if ((run_step)); then
  seconds=${1:-60}
  if ! [[ $seconds =~ ^[0-9]+$ ]] || ((seconds == 0)); then usage; fi
  (($# > 1)) && targets=("${@:2}")
  ((build_step || $# > 1)) || usage
  for t in "${targets[@]}"; do
    [[ " ${all_targets[*]} " == *" $t "* ]] || usage
  done
elif (($# > 0)); then
  usage
fi
build=build-fuzz
assets=${WAVEPATH_ASSETS:-../shared/assets}
if ((build_step)); then
  if ! have_libfuzzer; then
    echo "wavepath fuzz: clang++ with libFuzzer is missing (apt-get install clang libclang-rt-14-dev)" >&2
    exit 1
  fi
  jobs=$(nproc 2>/dev/null || echo 2)
  cmake -S tests/fuzz -B "$build" -DCMAKE_CXX_COMPILER=clang++ >/dev/null
  cmake --build "$build" -j"$jobs" >/dev/null
  rm -rf "$build/seeds"
  python3 tests/fuzz/make_seeds.py "$build/seeds" "$assets"
  # The compressed and JPEG seeds, by a tool of the main build (build/, tools/setup.sh).
  if [[ ! -d build ]]; then
    echo "wavepath fuzz: build/ missing (tools/setup.sh builds it; the seed maker is there)" >&2
    exit 1
  fi
  cmake --build build -j"$jobs" --target make_compressed_seeds >/dev/null
  build/tests/make_compressed_seeds "$build/seeds" "$assets"
fi
((run_step)) || exit 0
for t in "${targets[@]}"; do
  if [[ ! -x $build/$t || ! -d $build/seeds ]]; then
    echo "wavepath fuzz: $build/$t or its seeds missing (tools/fuzz.sh --build)" >&2
    exit 1
  fi
done

# Each input is written to a file for the loaders; on tmpfs when possible, removed at the end.
scratch=$(mktemp -d "$([[ -d /dev/shm ]] && echo /dev/shm || echo /tmp)/wavepath-fuzz.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
export WP_FUZZ_SCRATCH=$scratch

# fuzz TARGET SEEDS DICT MAX_LEN: one run; returns libFuzzer's status (0: no finding).
fuzz() {
  local target=$1 seeds=$2 dict=$3 max_len=$4
  local corpus="$build/corpus/$target" findings="$build/findings/$target"
  local log="$build/logs/$target.log"
  mkdir -p "$corpus" "$findings" "$build/logs"
  echo "wavepath fuzz: $target for ${seconds}s (log: $log)"
  local status=0
  local dict_arg=() regressions=()
  [[ $dict != - ]] && dict_arg=(-dict="tests/fuzz/$dict")
  # Inputs that once failed the target, committed once fixed (tests/fuzz/regressions/README.md):
  # read with the seeds before any new input (libFuzzer writes only to the first folder).
  [[ -d tests/fuzz/regressions/$target ]] && regressions=("tests/fuzz/regressions/$target")
  "$build/$target" "$corpus" "$build/seeds/$seeds" "${regressions[@]}" "${dict_arg[@]}" \
    -max_len="$max_len" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -detect_leaks=1 -artifact_prefix="$findings/" -print_final_stats=1 >"$log" 2>&1 ||
    status=$?
  grep -E '^stat::(number_of_executed_units|peak_rss_mb)|^Done [0-9]+ runs' "$log" |
    sed 's/^/  /' || true
  if ((status != 0)); then
    echo "wavepath fuzz: $target FOUND A PROBLEM (exit status $status); the log's tail:" >&2
    grep -v '^#[0-9]' "$log" | tail -n 40 >&2
    grep -E 'Test unit written to|^artifact_prefix' "$log" | sed 's/^/  /' >&2 || true
  fi
  return $status
}

# Each target's seed folder, dictionary and largest input.
# The codecs' and the image decoders' targets take no dictionary (their inputs are binary).
declare -A spec=([fuzz_gltf]="gltf gltf.dict 65536" [fuzz_environment]="environment environment.dict 16384"
  [fuzz_draco]="draco - 65536" [fuzz_meshopt]="meshopt - 65536" [fuzz_webp]="webp - 65536"
  [fuzz_image]="image - 65536")
failed=0
for t in "${targets[@]}"; do
  # shellcheck disable=SC2086 # the spec is three words
  fuzz "$t" ${spec[$t]} || failed=1
done
if ((failed)); then
  echo "wavepath fuzz: findings saved under $build/findings/" >&2
  exit 1
fi
echo "wavepath fuzz: no findings"
