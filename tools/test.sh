#!/usr/bin/env bash
# Sets up (installs missing Debian packages, builds build/) and runs the whole test suite with
# ctest on the default OpenCL device (PoCL on a machine without a GPU). Extra arguments go to
# ctest, e.g. tools/test.sh -R bvh.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
cd build
exec ctest --output-on-failure --timeout 600 "$@"
