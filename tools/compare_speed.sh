#!/usr/bin/env bash
# Samples per second of two wavepath binaries on one render, alternated run by run (this machine's
# noise hits both alike), after one unmeasured run each (kernel and BVH caches); prints each
# binary's runs and their median. Usage:
#   tools/compare_speed.sh OLD_BINARY NEW_BINARY RUNS SCENE [render options...]
set -euo pipefail
old=$1 new=$2 runs=$3
shift 3
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for b in "$old" "$new"; do "$b" render "$@" -q -o "$out/x.exr" > /dev/null; done
for ((i = 0; i < runs; i++)); do
  for b in old new; do
    bin=$old
    [[ $b == new ]] && bin=$new
    "$bin" render "$@" --json -q -o "$out/x.exr" | tail -1 |
      python3 -c "import json, sys; print(json.load(sys.stdin)['samples_per_second'])" >> "$out/$b"
  done
done
for b in old new; do
  python3 - "$out/$b" "$b" <<'PY'
import statistics, sys
v = [float(x) for x in open(sys.argv[1])]
print(f"{sys.argv[2]}: median {statistics.median(v):.4g} samples/s of", " ".join(f"{x:.3g}" for x in v))
PY
done
