#!/usr/bin/env bash
# Regenerates every chart, CSV and table of docs/accuracy.md from scratch: all failure-mode
# scenes of scenes/failure/manifest.json, every configuration, 1..256 samples per pixel at
# 128 x 96, references of 4096 samples per pixel rendered anew (a fresh cache, removed
# afterwards). About 25 minutes on a 2-core machine with PoCL. Needs numpy and matplotlib (Debian: python3-numpy,
# python3-matplotlib).
#
#   tools/accuracy.sh                  # builds build/ first when there is no build/wavepath
#   WAVEPATH=build-x/wavepath tools/accuracy.sh --scene veach_mis   # extra arguments go to
#                                                                   # tools/convergence.py
set -euo pipefail
cd "$(dirname "$0")/.."
wavepath=${WAVEPATH:-build/wavepath}
if [[ ! -x $wavepath ]]; then
  tools/setup.sh
fi
cache=$(mktemp -d "${TMPDIR:-/tmp}/wavepath-accuracy.XXXXXX")
trap 'rm -rf "$cache"' EXIT
args=("$@")
if [[ ${#args[@]} -eq 0 ]]; then
  args=(--all)
fi
python3 tools/convergence.py --wavepath "$wavepath" --cache "$cache" --out docs/accuracy \
  --doc docs/accuracy.md --size 128x96 --spp 1:256 --ref-spp 4096 --crop-spp 16 "${args[@]}"
