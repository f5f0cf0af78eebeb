#!/usr/bin/env bash
# Writes docs/PERFORMANCE.md: today's figures, measured now on this machine. Throughput of each
# shared scene against Tungsten's on the same machine (the figures ../shared/refs/README.md
# records), peak memory, bytes per triangle of the synthetic room, and, given the log of a
# `bash .ci/run` (which prints its stages' times), CI's time by stage.
#
# usage: scripts/performance.sh [--bin RETILE] [--ci-log FILE] [--out FILE]
# About five minutes; the scenes are read from ../shared beside the repository.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bin="$here/build/bin/retile"
ci_log=""
out="$here/docs/PERFORMANCE.md"
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --ci-log) ci_log="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h | --help) sed -n 2,8p "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "error: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -x "$bin" ] || { echo "error: $bin is not an executable (build first, or pass --bin)" >&2; exit 2; }
shared="$here/../shared"
[ -d "$shared/scenes" ] || { echo "error: $shared/scenes not found (../shared beside the repository)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Tungsten's samples/s on this machine, from ../shared/refs/README.md (two threads, scene loading
# excluded; the kitchen's is the middle of its range).
declare -A tungsten=([cornell-box]=0.80 [living-room]=0.21 [spaceship]=0.82 [kitchen]=0.2325)
declare -A size=([cornell-box]=256x256 [living-room]=320x180 [spaceship]=320x180 [kitchen]=320x180)

# Samples/s of an offline render (the reference's size, 64 spp, the scene's bounces) and the
# process's peak memory.
render() {
  local name=$1
  /usr/bin/time -f '%M' -o "$work/$name.rss" "$bin" render "$shared/scenes/$name/scene.json" --size "${size[$name]}" \
    --spp 64 --seed 1 --out "$work/$name.exr" 2>/dev/null | grep -o '[0-9.]* M samples/s' | cut -d' ' -f1
}

# A row of the path-cost table: `bench throughput`'s figures of one scene, read by field position
# (a change to those lines' wording must change this too).
pathCost() {
  local label=$1 scene=$2
  shift 2
  [ -f "$scene" ] || return 0
  "$bin" bench throughput "$scene" --size 320x180 --frames 4 "$@" 2>/dev/null | awk -v label="$label" '
    $1 == "scene" && $2 != "upload" { tris = $3; sub(/^\(/, "", tris) }
    $1 == "samples/s" { rate = $2 }
    $1 == "rays/sample" { rays = $2 }
    $1 == "paths" { perPath = $2; perRay = $11; ns = $14 }
    $1 == "path" && $2 == "ends" { left = $3; emitter = $8; limit = $17; roulette = $23; other = $27 }
    END {
      if (label == "synthetic room") label = label " (" tris " triangles)"
      printf "| %s | %s | %s | %s | %s | %s | %s %% | %s %% | %s %% | %s %% | %s %% |\n", label, rate, rays, perPath, perRay, ns, left, emitter, limit, roulette, other
    }'
}

# The device as retile sets it up (its vector width is retile's choice: core/process.h), not as
# another Vulkan program sees it.
device() {
  "$bin" render default --size 8x8 --spp 1 --out "$work/device.png" 2>&1 | sed -n 's/^device: //p' | grep . || echo 'the Vulkan device found'
}

{
  echo "# Performance"
  echo
  echo "Today's figures, written by \`scripts/performance.sh\` on $(nproc) cores with $(device)."
  echo "Regenerate them rather than editing this page."
  echo
  echo "## Throughput against Tungsten"
  echo
  echo "\`retile render SCENE --size WxH --spp 64\` against Tungsten's samples/s on the same machine"
  echo "(../shared/refs/README.md). Peak memory is the whole process's."
  echo
  echo "| scene | size | Retile M samples/s | Tungsten | ratio | peak memory |"
  echo "|---|---|---|---|---|---|"
  for name in cornell-box living-room spaceship kitchen; do
    [ -f "$shared/scenes/$name/scene.json" ] || continue
    rate=$(render "$name")
    rss=$(cat "$work/$name.rss")
    printf '| %s | %s | %s | %s | %s | %d MB |\n' "$name" "${size[$name]}" "$rate" "${tungsten[$name]}" \
      "$(awk -v a="$rate" -v b="${tungsten[$name]}" 'BEGIN { printf "%.2fx", a / b }')" $((rss / 1024))
  done
  echo
  echo "## Memory and throughput against scene size"
  echo
  echo "\`retile bench room --triangles 100k,1M\`: a synthetic furnished room."
  echo
  echo '```'
  "$bin" bench room --triangles 100k,1M 2>/dev/null
  echo '```'
  echo
  echo "## What a path costs"
  echo
  echo "\`retile bench throughput SCENE --size 320x180 --frames 4\`: the kitchen at its 16 bounces"
  echo "(\`--max-bounces 15\`) against the synthetic room of 1 M triangles written by \`retile bench room"
  echo "--triangles 1M --roulette low_throughput --write-scene\` (the kitchen's roulette), at the same"
  echo "bounces; and \`scenes/glass-ice/scene.json\` at its 32 against itself with every dielectric made"
  echo "lambert. That scene is ours, in Tungsten's format: a glass of water holding two ice cubes, a"
  echo "third on an aluminium floor, each with an air bubble, in a closed white room (each surface's"
  echo "\`ior\` the ratio of its two sides: glass 1.5, water in glass 0.8867, ice in water 0.985, bubble in"
  echo "ice 0.7634, ice in air 1.31). Tungsten's samples/s on it are not measured here (no Tungsten on"
  echo "this machine). Where paths end: the share that left the scene, met an emitter that does not"
  echo "reflect, reached the bounce limit, ended by roulette, or otherwise (absorbed, cut short). One run"
  echo "each: samples/s and ns an iteration move by 10 % and more from run to run on this machine, the"
  echo "rays and loop iterations do not (\`scripts/ab-throughput.sh\` compares two binaries' speed)."
  echo
  echo "| scene | M samples/s | rays a sample | loop iterations a path | a ray | ns an iteration | left | at a null emitter | at the limit | roulette | otherwise |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|"
  "$bin" bench room --triangles 1M --frames 1 --roulette low_throughput --write-scene "$work/room.retile" >/dev/null 2>&1
  sed -E 's/"type"[[:space:]]*:[[:space:]]*"dielectric"/"type": "lambert"/' "$here/scenes/glass-ice/scene.json" >"$work/glass-ice-lambert.json"
  if grep -q '"dielectric"' "$work/glass-ice-lambert.json"; then
    echo "error: the lambert twin of scenes/glass-ice/scene.json still has a dielectric" >&2
    exit 1
  fi
  pathCost kitchen "$shared/scenes/kitchen/scene.json" --max-bounces 15
  pathCost "synthetic room" "$work/room.retile" --max-bounces 15
  pathCost "glass and ice" "$here/scenes/glass-ice/scene.json"
  pathCost "glass and ice, lambert" "$work/glass-ice-lambert.json"
  if [ -n "$ci_log" ]; then
    echo
    echo "## CI by stage"
    echo
    echo "From a clean clone's \`bash .ci/run\` (its \`stage\` lines):"
    echo
    echo "| stage | seconds |"
    echo "|---|---|"
    grep -a '^stage ' "$ci_log" | sed -E 's/^stage ([^:]*): ([0-9]+) s$/| \1 | \2 |/'
  fi
} >"$out.tmp"
mv "$out.tmp" "$out"
echo "wrote $out"
