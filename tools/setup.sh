#!/usr/bin/env bash
# Installs wavepath's build dependencies (Debian 12 packages only) when they are missing, then
# configures and builds a Release build in build/. Used by tools/run.sh and tools/test.sh.
#
#   tools/setup.sh             the build
#   tools/setup.sh --tests     also the fuzz targets (tools/fuzz.sh --build: build-fuzz/, clang++
#                              with libFuzzer and the sanitizers) when clang++ can build them and
#                              WP_FUZZ_SECONDS is not 0; tools/test.sh builds with this, so that
#                              the suite's time is the tests' own
#   tools/setup.sh --denoise   also Intel Open Image Denoise for `wavepath render --denoise`: not
#                              in Debian 12, so PyPI's pyoidn wheel (which ships the library with
#                              the TBB it needs) is pip-installed into the venv build/oidn-venv,
#                              where build/wavepath finds it by itself (docs/denoise.md); prints
#                              the library's folder, for WAVEPATH_OIDN elsewhere
#
# As root it runs apt-get itself; otherwise it prints the exact apt-get line to run and stops.
set -euo pipefail
cd "$(dirname "$0")/.."

denoise=0 tests=0
for arg in "$@"; do
  case $arg in
    --denoise) denoise=1 ;;
    --tests) tests=1 ;;
    *) echo "usage: tools/setup.sh [--denoise] [--tests]" >&2; exit 2 ;;
  esac
done

PACKAGES=(
  build-essential cmake pkg-config python3 python3-numpy python3-matplotlib
  opencl-headers opencl-clhpp-headers ocl-icd-opencl-dev pocl-opencl-icd
  libembree-dev libtinygltf-dev libglm-dev libopenexr-dev libstb-dev libcli11-dev
  libdraco-dev libmeshoptimizer-dev libwebp-dev libpng-dev libjpeg62-turbo-dev zlib1g-dev
  libgtest-dev libbenchmark-dev oclgrind
  clang libclang-rt-14-dev libclc-14 nlohmann-json3-dev
  libopenmpi-dev openmpi-bin
)
# The venv for Open Image Denoise: Debian's python3 with its venv module (and so pip).
if ((denoise)); then PACKAGES+=(python3-venv); fi

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
if ((tests)) && [[ ${WP_FUZZ_SECONDS:-3} != 0 ]] && tools/fuzz.sh --check; then
  echo "wavepath: building the fuzz targets (build-fuzz/)" >&2
  tools/fuzz.sh --build
fi

if ((denoise)); then
  # The version the figures of docs/denoise.md were measured with. --no-deps: only the library is
  # used (pyoidn's Python side would pull in numpy and cffi).
  PYOIDN=pyoidn==2.5.1.0
  venv=build/oidn-venv
  find_lib() {
    compgen -G "$venv/lib/python3.*/site-packages/pyoidn/oidn/lib/libOpenImageDenoise.so.2" |
      tail -n 1
  }
  if [[ -z $(find_lib) ]]; then
    echo "wavepath: installing Open Image Denoise ($PYOIDN from PyPI) into $venv" >&2
    /usr/bin/python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet --disable-pip-version-check --no-deps "$PYOIDN"
  fi
  lib=$(find_lib)
  [[ -n $lib ]] || { echo "wavepath: $PYOIDN installed no libOpenImageDenoise.so.2" >&2; exit 1; }
  echo "wavepath: Open Image Denoise: $(cd "$(dirname "$lib")" && pwd)"
  echo "  (build/wavepath finds it there; for another binary: export WAVEPATH_OIDN=<that folder>)"
fi
