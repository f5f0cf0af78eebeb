#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job. Until the editor lands this renders the
# built-in default scene and prints where the image is; arguments replace the default job, e.g.
#   scripts/run.sh render ../shared/scenes/living-room/scene.json --size 640x360 --spp 64
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-debian.sh
cmake --preset default
cmake --build --preset default
if [ $# -eq 0 ]; then
  set -- render default --size 640x360 --spp 64 --out build/default-scene.png
fi
exec build/bin/retile "$@"
