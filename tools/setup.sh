#!/usr/bin/env bash
# Installs wavepath's build dependencies (Debian 12 packages only) when they are missing, then
# configures and builds a Release build in build/. Used by tools/run.sh and tools/test.sh.
#
# As root it runs apt-get itself; otherwise it prints the exact apt-get line to run and stops.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake pkg-config python3 python3-numpy python3-matplotlib
  opencl-headers opencl-clhpp-headers ocl-icd-opencl-dev pocl-opencl-icd
  libembree-dev libtinygltf-dev libglm-dev libopenexr-dev libstb-dev libcli11-dev
  libgtest-dev libbenchmark-dev oclgrind
  clang libclang-rt-14-dev libclc-14 nlohmann-json3-dev
  libopenmpi-dev openmpi-bin
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  if [[ $(id -u) -eq 0 ]]; then
    echo "wavepath: installing ${missing[*]}" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  else
    echo "wavepath: missing packages; run:" >&2
    echo "  sudo apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
fi

jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs"
