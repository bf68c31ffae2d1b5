#!/usr/bin/env bash
# ctest's fuzz tier (tests/CMakeLists.txt): `ctest_fuzz.sh --build` builds the fuzz targets
# (tools/fuzz.sh --build), `ctest_fuzz.sh TARGET` runs one for $WP_FUZZ_SECONDS (default 3;
# tools/fuzz.sh --run). Exits 77, ctest's skip, when WP_FUZZ_SECONDS is 0 or clang++ cannot build
# libFuzzer targets.
set -uo pipefail
cd "$(dirname "$0")/../.."
seconds=${WP_FUZZ_SECONDS:-3}
if ! [[ $seconds =~ ^[0-9]+$ ]]; then
  echo "wavepath fuzz: WP_FUZZ_SECONDS must be a whole number of seconds, not '$seconds'" >&2
  exit 2
fi
if ((seconds == 0)); then
  echo "wavepath fuzz: skipped (WP_FUZZ_SECONDS=0)"
  exit 77
fi
if ! tools/fuzz.sh --check; then
  echo "wavepath fuzz: skipped (no clang++ with libFuzzer; tools/setup.sh installs it)"
  exit 77
fi
if [[ ${1:-} == --build ]]; then
  exec tools/fuzz.sh --build
fi
exec tools/fuzz.sh --run "$seconds" "$@"
