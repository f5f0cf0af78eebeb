#!/usr/bin/env bash
# Installs what is missing, builds, and opens the editor on the built-in scene. Without a display
# (no $DISPLAY or $WAYLAND_DISPLAY) it renders the built-in scene instead and prints where the
# image is. Arguments are passed to retile, e.g.
#   scripts/run.sh ../shared/scenes/living-room/scene.json         (the editor on a file)
#   scripts/run.sh render default --size 640x360 --out room.png     (the command line)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-debian.sh
cmake --preset default
cmake --build --preset default
if [ $# -eq 0 ] && [ -z "${DISPLAY:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ]; then
  echo "no display: rendering the built-in scene instead of opening the editor"
  set -- render default --size 640x360 --spp 64 --out build/default-scene.png
fi
exec build/bin/retile "$@"
