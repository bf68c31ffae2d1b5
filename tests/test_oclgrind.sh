#!/usr/bin/env bash
# Kernel memory safety: tiny renders of several scenes under Oclgrind (Debian's `oclgrind`, an
# OpenCL device simulator that checks every memory access), with its out-of-bounds check (always
# on), --data-races, --uninitialized and --check-api. A case fails when wavepath exits non-zero or
# when Oclgrind reports anything at all: every message it logs is a diagnostic (invalid read or
# write, data race, uninitialised value, OpenCL API error, fatal error, ...). The cases cover both
# BVH layouts, `--features all`, several waves and work-groups, scenes split over several device
# buffers, an environment map, transmission, punctual lights, degenerate triangles, the packet
# kernels (--force-packets) and, from the shared assets, textures, alpha (MASK and BLEND) and
# transmission models; an asset case is skipped (with a message) when its file is absent. A
# canary renders with one kernel made to read past the counter buffer and must be reported, so
# that the test cannot pass because Oclgrind checked nothing.
#
# Usage: test_oclgrind.sh WAVEPATH SOURCE_DIR [ASSETS_DIR [CASE...]]
#        test_oclgrind.sh --list
#   ASSETS_DIR defaults to $WAVEPATH_ASSETS, else SOURCE_DIR/../shared/assets. With CASE names,
#   only those cases run (ctest runs each case as its own test, oclgrind_NAME, side by side:
#   Oclgrind simulates on one thread); --list prints every case's name, one a line.
#
# Oclgrind 21.10 notes: it cannot run the kernels built with LLVM's optimisations (a fatal
# "Undefined external function: llvm.experimental.noalias.scope.decl"), hence -cl-opt-disable
# through its own --build-options. It is the only OpenCL platform the program sees under
# `oclgrind`, and reports itself as a GPU, so the BVH layout is chosen per case explicitly.
set -uo pipefail

# The cases, in the order they run; case_table prints "NAME" lines for --list, or runs the
# selected ones through check (and canary).
case_table() {
  local scenes=$src/scenes models=$assets/models
  # In the repository: both BVH layouts, all features, several waves of several work-groups (and
  # a partial last group), an environment map, glass and mirrors, punctual lights, degenerate
  # triangles, scenes split over several scene buffers (3 each, --json's scene_buffers), AOVs,
  # waves of several samples, the split stage kernels (the fused shade kernel is the default) and
  # the independent sampler.
  check cornell_bvh2 "$scenes/cornell_box.gltf" --bvh-width 2
  check cornell_bvh8_all "$scenes/cornell_box.gltf" --bvh-width 8 --features all --local-size 16 \
    --pipeline split
  check point_waves "$scenes/cornell_box_point.gltf" --bvh-width 8 --spp 2 --wave-size 20 \
    --local-size 16
  check cornell_samples_per_wave "$scenes/cornell_box.gltf" --bvh-width 8 --spp 3 --wave-size 100 \
    --pipeline split
  check cornell_split "$scenes/cornell_box.gltf" --bvh-width 8 --scene-buffer-kib 4
  check env_sun_split "$scenes/failure/env_sun.gltf" --env "$scenes/failure/env_sun.hdr" \
    --bvh-width 2 --scene-buffer-kib 2048
  check caustics "$scenes/failure/caustics.gltf" --bvh-width 8 --aov albedo,normal,depth
  check caustics_split "$scenes/failure/caustics.gltf" --bvh-width 2 --aov albedo,normal,depth \
    --pipeline split
  check punctual "$scenes/failure/punctual.gltf" --bvh-width 8 --features all --pipeline split
  check punctual_fused "$scenes/failure/punctual.gltf" --bvh-width 2 --features all \
    --pipeline fused --sampler independent
  check degenerate "$scenes/failure/degenerate.gltf" --bvh-width 2 --local-size 16
  # The eight-lane packet kernels, which only PoCL's CPU devices build by default (--force-packets):
  # ray packets from the second wave on (the first one traces single rays, to time them), shading
  # and camera rays in packets where every surface is Lambertian, a triangle light's samples in
  # lanes (lambert_quad), point and spot lights lane by lane and the independent sampler
  # (punctual), waves whose last packet is short (20 paths) and glossy surfaces shaded singly
  # between ray packets (cornell).
  check packets_lambert_quad "$scenes/failure/lambert_quad.gltf" --bvh-width 8 --force-packets \
    --spp 3 --wave-size 48
  check packets_punctual "$scenes/failure/punctual.gltf" --bvh-width 8 --force-packets --spp 3 \
    --wave-size 48 --local-size 16 --sampler independent
  check packets_cornell "$scenes/cornell_box.gltf" --bvh-width 8 --force-packets --spp 3 \
    --wave-size 20

  # Shared assets (small ones; see ../shared/assets/README.md for what each exercises).
  check textures_alpha_mask "$models/TextureEncodingTest/TextureEncodingTest.glb" --bvh-width 8
  check alpha_blend_spot "$models/ShadowsSpot/shadows-spot.gltf" --bvh-width 2
  check transmission_volume "$models/AttenuationTest/AttenuationTest.glb" --bvh-width 2 \
    --features all
  check glass_alpha_normal_maps "$models/GlassBrokenWindow/GlassBrokenWindow.glb" --bvh-width 8
  check texture_samplers "$models/TextureSettingsTest/TextureSettingsTest.glb" --bvh-width 2
  # The material extensions, in the split pipeline (their path-state fields) and fused.
  check clearcoat_split "$models/ClearCoatTest/ClearCoatTest.glb" --bvh-width 8 --pipeline split
  check anisotropy_split "$models/AnisotropyStrengthTest/AnisotropyStrengthTest.glb" \
    --bvh-width 2 --pipeline split
  check iridescence_split "$models/IridescenceSuzanne/IridescenceSuzanne.glb" --bvh-width 8 \
    --pipeline split
  check sheen_specular "$models/GlamVelvetSofa/GlamVelvetSofa.glb" --bvh-width 2
  # (check skips a case whose scene, or environment map from the assets, is absent.)
  check env_map_textured "$models/BoxTextured/BoxTextured.glb" \
    --env "$assets/env/studio_small_03_1k.hdr" --bvh-width 8

  canary
}

if [[ ${1:-} == --list ]]; then
  check() { echo "$1"; }
  canary() { echo canary; }
  src=. assets=.
  case_table
  exit 0
fi
if (($# < 2)); then
  echo "usage: $0 WAVEPATH SOURCE_DIR [ASSETS_DIR [CASE...]] | --list" >&2
  exit 2
fi
wavepath=$1
src=$2
assets=${3:-${WAVEPATH_ASSETS:-$src/../shared/assets}}
selected=("${@:4}")

# selected NAME: whether case NAME runs (every case when none is named).
is_selected() {
  ((${#selected[@]} == 0)) && return 0
  local s
  for s in "${selected[@]}"; do [[ $s == "$1" ]] && return 0; done
  return 1
}

if ! command -v oclgrind >/dev/null; then
  echo "FAIL: oclgrind not found (tools/setup.sh installs Debian's oclgrind package)" >&2
  exit 1
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/wavepath-oclgrind.XXXXXX")
trap 'rm -rf "$work"' EXIT

failures=0
ran=0
skipped=0

# Counts of the messages in an Oclgrind log, by kind (the formats of Oclgrind 21.10's plugins).
summarise() {
  local log=$1
  printf '    invalid read/write: %s, data race: %s, uninitialised: %s, API error: %s, fatal: %s\n' \
    "$(grep -c -E '^Invalid (read|write)' "$log")" "$(grep -c -i 'data race' "$log")" \
    "$(grep -c -i 'uninitiali[sz]ed' "$log")" "$(grep -c 'OpenCL runtime error' "$log")" \
    "$(grep -c 'OCLGRIND FATAL ERROR' "$log")"
}

# run_case NAME SCENE [wavepath render options...]: one 8x6 render under Oclgrind, 1 spp in one
# wave of its 48 paths unless the options say otherwise. Sets case_log, case_out and case_rc;
# prints nothing. (The default wave, sized for large images, holds ~260,000 paths: Oclgrind then
# tracks ~60 MB of path state that 48 paths never touch, 10x the time and 3 GB of
# memory for nothing, and an index past the live paths would still land inside the buffers.)
run_case() {
  local name=$1 scene=$2
  shift 2
  case_log=$work/$name.log
  case_out=$work/$name.out
  rm -f "$case_log"
  local spp=(--spp 1) wave=(--wave-size 48) uninit=(--uninitialized) arg
  for arg in "$@"; do
    [[ $arg == --spp ]] && spp=() && wave=()
    [[ $arg == --wave-size ]] && wave=()
    # Oclgrind 21.10's uninitialised-value plugin crashes (SIGSEGV in
    # Uninitialized::instructionExecuted) on every packet kernel; their bounds, data-race and API
    # checks still run.
    [[ $arg == --force-packets ]] && uninit=()
  done
  timeout -k 10 300 oclgrind --build-options -cl-opt-disable --check-api --data-races "${uninit[@]}" \
    --max-errors 50 --log "$case_log" \
    "$wavepath" render "$scene" --device Oclgrind --width 8 --height 6 "${spp[@]}" "${wave[@]}" \
    --no-bvh-cache --json -o "$work/$name.pfm" "$@" >"$case_out" 2>&1
  case_rc=$?
}

# check NAME SCENE [options...]: a case that must run cleanly.
check() {
  local name=$1 scene=$2 arg
  is_selected "$name" || return 0
  matched=$((matched + 1))
  if [[ ! -f $scene ]]; then
    echo "SKIP $name: $scene not found"
    skipped=$((skipped + 1))
    return
  fi
  local previous=""
  for arg in "$@"; do  # an environment map from the shared assets may be absent too
    if [[ $previous == --env && $arg == "$assets"/* && ! -f $arg ]]; then
      echo "SKIP $name: $arg not found"
      skipped=$((skipped + 1))
      return
    fi
    previous=$arg
  done
  local start=$SECONDS
  run_case "$@"
  local seconds=$((SECONDS - start)) problem=""
  ran=$((ran + 1))
  if ((case_rc != 0)); then
    problem="wavepath exited with $case_rc"
  elif [[ ! -f $case_log ]]; then
    problem="Oclgrind wrote no log (did it run?)"
  elif grep -q '[^[:space:]]' "$case_log"; then
    problem="Oclgrind reported errors"
  elif ! tail -n 1 "$case_out" | grep -q '"device":"Oclgrind'; then
    problem="the render did not run on the Oclgrind device"
  fi
  if [[ -z $problem ]]; then
    echo "ok   $name (${seconds} s)"
    return
  fi
  failures=$((failures + 1))
  echo "FAIL $name (${seconds} s): $problem"
  echo "    oclgrind ... $wavepath render ${*:2}"
  if [[ -f $case_log ]]; then
    summarise "$case_log"
    sed -n '1,60p' "$case_log" | sed 's/^/    | /'
  fi
  tail -n 20 "$case_out" | sed 's/^/    > /'
}

# The canary: queue_get also reads a word past the end of the counter buffer. Oclgrind must report
# an invalid read, or the clean results above mean nothing. The word read is multiplied by 0: what
# lies past the buffer must not steer the kernel (a garbage queue length once sent traversal into
# garbage slots for minutes).
canary() {
  is_selected canary || return 0
  matched=$((matched + 1))
  local dir=$work/canary_kernels
  mkdir -p "$dir/integrator"
  sed 's/if (index >= qs\.counters\[q\]) return false;/if (index >= qs.counters[q] + 0u * qs.counters[q + WP_COUNTER_COUNT]) return false;/' \
    "$src/kernels/integrator/queues.h" >"$dir/integrator/queues.h"
  ran=$((ran + 1))
  if ! grep -q 'qs.counters\[q + WP_COUNTER_COUNT\]' "$dir/integrator/queues.h"; then
    failures=$((failures + 1))
    echo "FAIL canary: could not plant the out-of-bounds read (queue_get in kernels/integrator/queues.h changed;"
    echo "     update the sed pattern in $0)"
    return
  fi
  local start=$SECONDS
  WAVEPATH_KERNEL_DIR=$dir run_case canary "$src/scenes/cornell_box.gltf" --bvh-width 2
  local seconds=$((SECONDS - start))
  if [[ -f $case_log ]] && grep -q '^Invalid read of size 4 at global memory address' "$case_log"; then
    echo "ok   canary (${seconds} s): Oclgrind reported the planted out-of-bounds read"
  else
    failures=$((failures + 1))
    echo "FAIL canary (${seconds} s): Oclgrind did not report the planted out-of-bounds read"
    [[ -f $case_log ]] && sed -n '1,30p' "$case_log" | sed 's/^/    | /'
    tail -n 20 "$case_out" | sed 's/^/    > /'
  fi
}

matched=0
case_table
if ((matched != ${#selected[@]} && ${#selected[@]} > 0)); then
  echo "FAIL: no such case among ${selected[*]} (test_oclgrind.sh --list names them)"
  failures=$((failures + 1))
fi

echo "oclgrind: $ran run, $skipped skipped, $failures failed"
((failures == 0))
