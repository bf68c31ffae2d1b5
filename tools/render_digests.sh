#!/usr/bin/env bash
# Renders a fixed set of small images covering every kernel feature and prints the MD5 of each
# image's pixels (PFM), one line per render: a refactor that changes no behaviour leaves every line
# as it was. Usage: tools/render_digests.sh [WAVEPATH_BINARY] > digests.txt
# Models from ../shared/assets are left out (with a note on stderr) when the folder is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build/wavepath}
assets=${WAVEPATH_ASSETS:-../shared/assets}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export WAVEPATH_CACHE_DIR="$work/cache"
common=(--width 48 --height 36 --spp 8 -q)
n=0
case_() {  # name, scene, extra options...
  local name=$1 scene=$2
  shift 2
  if [[ ! -f $scene ]]; then
    echo "render_digests: $name skipped ($scene not found)" >&2
    return
  fi
  n=$((n + 1))
  "$bin" render "$scene" "${common[@]}" "$@" -o "$work/$n.pfm"
  local files=("$work/$n.pfm")
  for aov in albedo normal depth variance; do
    [[ -f $work/$n.$aov.pfm ]] && files+=("$work/$n.$aov.pfm")
  done
  echo "$(cat "${files[@]}" | md5sum | cut -c1-32)  $name"
}
f=scenes/failure
m=$assets/models
case_ cornell scenes/cornell_box.gltf
case_ cornell-split scenes/cornell_box.gltf --pipeline split
case_ cornell-bvh2 scenes/cornell_box.gltf --bvh-width 2
case_ cornell-all scenes/cornell_box.gltf --features all
case_ cornell-aov scenes/cornell_box.gltf --aov albedo,normal,depth --variance
case_ cornell-nee scenes/cornell_box.gltf --strategy nee --mis-heuristic balance
case_ cornell-bsdf scenes/cornell_box.gltf --strategy bsdf --pipeline split
case_ cornell-indep scenes/cornell_box.gltf --sampler independent --light-select uniform
case_ cornell-padded scenes/cornell_box.gltf --sampler sobol-padded --no-rr --seed 3
case_ cornell-wave scenes/cornell_box.gltf --wave-size 700 --local-size 32 --no-prefetch
case_ cornell-point scenes/cornell_box_point.gltf --max-depth 4 --rr-depth 1 --rr-threshold 1
for s in caustics closed_box degenerate glossy_floor lambert_quad opening_room punctual \
         small_light_room veach_mis scale_1e-3; do
  case_ "$s" "$f/$s.gltf"
done
case_ env_sun "$f/env_sun.gltf" --env "$f/env_sun.hdr" --env-rotation 30 --env-intensity 0.7
case_ env_sun-split "$f/env_sun.gltf" --env "$f/env_sun.hdr" --pipeline split --aov albedo,normal
case_ helmet "$m/DamagedHelmet/DamagedHelmet.glb" --env "$assets/env/studio_small_03_1k.hdr"
case_ helmet-split "$m/DamagedHelmet/DamagedHelmet.glb" --env "$assets/env/studio_small_03_1k.hdr" --pipeline split --bvh-width 2
case_ flight "$m/FlightHelmet/FlightHelmet.gltf" --env-color 1,1,1 --aov albedo,normal,depth
case_ transmission "$m/TransmissionTest/TransmissionTest.glb" --env-color 0.8,0.9,1
case_ trans-rough "$m/TransmissionRoughnessTest/TransmissionRoughnessTest.glb" --env-color 1,1,1 --pipeline split
case_ attenuation "$m/AttenuationTest/AttenuationTest.glb" --env-color 1,1,1
case_ alpha "$m/AlphaBlendModeTest/AlphaBlendModeTest.glb" --env-color 1,1,1 --pipeline split
case_ lamp "$m/LightsPunctualLamp/LightsPunctualLamp.gltf"
case_ spot "$m/ShadowsSpot/shadows-spot.gltf"
case_ lowpoly "$m/LowPoly/low-poly.gltf" --aov albedo
case_ vertexcolor "$m/VertexColorTest/VertexColorTest.glb" --env-color 1,1,1
case_ textransform "$m/TextureTransformMultiTest/TextureTransformMultiTest.glb" --env-color 1,1,1
case_ emissive "$m/EmissiveStrengthTest/EmissiveStrengthTest.glb"
case_ cornellbox-glb "$m/CornellBox/CornellBox.glb" --pipeline split
case_ spheres "$m/MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.glb" --env "$assets/env/venice_sunset_1k.hdr"
# The material extensions (fused and split give the same MD5s).
case_ clearcoat "$m/ClearCoatCarPaint/ClearCoatCarPaint.glb" --env-color 1,1,1
case_ sheen-specular "$m/GlamVelvetSofa/GlamVelvetSofa.glb" --env-color 1,1,1 --pipeline split
case_ anisotropy "$m/AnisotropyRotationTest/AnisotropyRotationTest.glb" --env-color 1,1,1
case_ iridescence "$m/IridescenceSuzanne/IridescenceSuzanne.glb" --pipeline split
case_ variant "$m/MaterialsVariantsShoe/MaterialsVariantsShoe.gltf" --variant street --env-color 1,1,1
# Thin lens, the nearest environment lookup, full-resolution textures and instances.
case_ cornell-lens scenes/cornell_box.gltf --aperture 0.05 --focus-distance 3
case_ env_sun-nearest "$f/env_sun.gltf" --env "$f/env_sun.hdr" --env-filter nearest
case_ helmet-nomip "$m/DamagedHelmet/DamagedHelmet.glb" --env "$assets/env/studio_small_03_1k.hdr" --mipmaps off
case_ instancing "$m/SimpleInstancing/SimpleInstancing.glb" --env-color 1,1,1
# Dispersion and diffuse transmission: the Cornell box with its white material made dispersive
# glass, or half diffusely transmitting (written here from scenes/cornell_box.gltf).
derive() {  # out, extension JSON for material 0 ("white")
  python3 - "$1" "$2" <<'PY'
import json, sys
out, extensions = sys.argv[1], json.loads(sys.argv[2])
doc = json.load(open("scenes/cornell_box.gltf"))
doc["materials"][0].setdefault("extensions", {}).update(extensions)
doc["extensionsUsed"] = sorted(set(doc.get("extensionsUsed", [])) | set(extensions))
json.dump(doc, open(out, "w"))
PY
}
derive "$work/dispersion.gltf" '{"KHR_materials_transmission":{"transmissionFactor":1},
  "KHR_materials_volume":{"thicknessFactor":1},"KHR_materials_ior":{"ior":1.6},
  "KHR_materials_dispersion":{"dispersion":2}}'
case_ dispersion "$work/dispersion.gltf"
derive "$work/diffuse_transmission.gltf" '{"KHR_materials_diffuse_transmission":
  {"diffuseTransmissionFactor":0.5,"diffuseTransmissionColorFactor":[1,0.5,0.25]}}'
case_ diffuse-transmission "$work/diffuse_transmission.gltf" --pipeline split
