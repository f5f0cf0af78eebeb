#!/usr/bin/env bash
# Regenerates docs/denoise-4spp.png: at 4 spp, the raw image, the denoised one and a 1024-spp
# render, for the built-in scene, the Cornell box and the living room (../shared/scenes), at
# 320x180 each. About ten minutes on lavapipe, most of it the living room's 1024 spp.
set -euo pipefail
cd "$(dirname "$0")/.."
retile="${RETILE:-build/bin/retile}"
out="${1:-docs/denoise-4spp.png}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
panels=()
for scene in default ../shared/scenes/cornell-box/scene.json ../shared/scenes/living-room/scene.json; do
  name="$(basename "$(dirname "$scene")")-$(basename "$scene")"
  "$retile" render "$scene" --size 320x180 --spp 4 --seed 1 --out "$tmp/$name-raw.png" >/dev/null
  "$retile" render "$scene" --size 320x180 --spp 4 --seed 1 --denoise --out "$tmp/$name-denoised.png" >/dev/null
  "$retile" render "$scene" --size 320x180 --spp 1024 --seed 2 --out "$tmp/$name-reference.png" >/dev/null
  panels+=("$tmp/$name-raw.png" "$tmp/$name-denoised.png" "$tmp/$name-reference.png")
done
oiiotool "${panels[@]}" --mosaic:pad=4 3x3 --ch R,G,B -o "$out"  # RGB: the padding black, not transparent
echo "wrote $out"
