#!/usr/bin/env bash
# Sets up (installs missing Debian packages, builds build/) and renders the default scene, the
# project's Cornell box, to render.exr and render.png. Extra arguments go to `wavepath render`,
# e.g. tools/run.sh --spp 256 --width 800 --height 800.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
exec build/wavepath render scenes/cornell_box.gltf "$@"
