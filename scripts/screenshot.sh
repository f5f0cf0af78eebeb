#!/usr/bin/env bash
# Regenerates docs/editor.png, the README's screenshot: the editor on the built-in scene under
# Xvfb, the cup just moved, the priority overlay showing the pass in progress.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-docs/editor.png}"
RETILE_NO_PROMPTS=1 RETILE_SCREENSHOT="$out" RETILE_SCREENSHOT_FRAMES=30 RETILE_SCREENSHOT_SELECT=Cup \
  xvfb-run -a -s "-screen 0 1400x900x24" build/bin/retile
echo "wrote $out"
