#!/usr/bin/env bash
# Compares the samples/s of two retile binaries on one scene, in rounds that run both, and prints
# each round and the mean of the per-round ratio B/A with its standard error.
#
# Why rounds: this machine's speed drifts by 10 % and more over minutes, so two figures taken
# minutes apart do not compare; the two runs of a round see nearly the same machine. The order
# alternates (AB, BA, AB, ...) so that a drift within a round does not favour one binary. The
# standard error assumes rounds independent, which the drift makes only roughly true: take
# differences under about three standard errors as noise.
#
# --side-by-side runs A and B at once, each on one core with one lavapipe thread, so that both
# see the same moment of the machine; the cores swap each round, and since one core has been
# seen 5 to 30 % faster than the other, the figure is the geometric mean of each pair of rounds
# (one on each core), with its standard error over the pairs. On this shared machine that
# separated a 5 % difference the sequential rounds could not (their per-round ratios spread
# 0.8 to 1.2). It needs two cores and taskset.
#
# Each round also prints both binaries' loop iterations per path: they do not depend on the
# machine's moment, so a ratio that moves with them is a change in work, and one that moves
# without them a change in the cost of each step (or noise).
#
# usage: scripts/ab-throughput.sh [--side-by-side] BIN_A BIN_B ROUNDS SCENE [retile bench throughput options]
# e.g.   scripts/ab-throughput.sh /tmp/retile-before build/bin/retile 8 \
#          ../shared/scenes/spaceship/scene.json --size 320x180 --frames 16
set -euo pipefail
side=0
if [ "${1:-}" = --side-by-side ]; then
  side=1
  shift
fi
if [ $# -lt 4 ]; then
  sed -n 2,24p "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
a="$1" b="$2" rounds="$3"
shift 3
for bin in "$a" "$b"; do
  [ -x "$bin" ] || { echo "error: $bin is not an executable" >&2; exit 2; }
done
case "$rounds" in '' | *[!0-9]* | 0) echo "error: ROUNDS must be a positive integer, not '$rounds'" >&2; exit 2 ;; esac

# samples/s (M) and loop iterations per path of one run.
measure() {
  local out rate iter
  out="$("$1" bench throughput "${@:2}" 2>&1)" || { echo "error: $1 bench throughput failed:" >&2; echo "$out" >&2; return 1; }
  rate="$(echo "$out" | awk '$1 == "samples/s" {print $2}')"
  iter="$(echo "$out" | awk '$1 == "paths" {print $2}')"
  [ -n "$rate" ] || { echo "error: no samples/s from $1:" >&2; echo "$out" >&2; return 1; }
  echo "$rate ${iter:-?}"
}

if ((side)); then
  command -v taskset >/dev/null || { echo "error: --side-by-side needs taskset (util-linux)" >&2; exit 2; }
  printf '%5s %6s %10s %10s %8s   %s\n' round "A core" "A M/s" "B M/s" "B/A" "loop iterations per path (A, B)"
  results=""
  for ((i = 1; i <= rounds; i++)); do
    ca=$(((i + 1) % 2)) cb=$((i % 2))
    outa="$(mktemp)" outb="$(mktemp)"
    LP_NUM_THREADS=1 taskset -c "$ca" bash -c "$(declare -f measure); measure \"\$@\"" _ "$a" "$@" >"$outa" &
    pa=$!
    LP_NUM_THREADS=1 taskset -c "$cb" bash -c "$(declare -f measure); measure \"\$@\"" _ "$b" "$@" >"$outb" &
    pb=$!
    wait "$pa" && wait "$pb" || { rm -f "$outa" "$outb"; exit 1; }
    read -r ra ia <"$outa"
    read -r rb ib <"$outb"
    rm -f "$outa" "$outb"
    printf '%5d %6d %10s %10s %8.4f   %s, %s\n' "$i" "$ca" "$ra" "$rb" "$(awk -v x="$ra" -v y="$rb" 'BEGIN {print y / x}')" "$ia" "$ib"
    results+="$ra $rb"$'\n'
  done
  echo "$results" | awk 'NF == 2 {r[++n] = $2 / $1}
    END {
      pairs = int(n / 2)
      if (pairs < 1) { print "one round: run an even number of rounds for a figure"; exit }
      for (k = 1; k <= pairs; k++) { g = sqrt(r[2 * k - 1] * r[2 * k]); s += g; ss += g * g }
      m = s / pairs; v = pairs > 1 ? (ss - pairs * m * m) / (pairs - 1) : 0; if (v < 0) v = 0
      printf "B/A %.4f, standard error %.4f over %d pairs of rounds (the geometric mean of each pair, one round on each core)\n", m, sqrt(v / pairs), pairs
    }'
  exit 0
fi

printf '%5s %10s %10s %8s   %s\n' round "A M/s" "B M/s" "B/A" "loop iterations per path (A, B)"
results=""
for ((i = 1; i <= rounds; i++)); do
  # Command substitution, not a pipe into read, so that a failed run stops the script (set -e).
  if ((i % 2)); then
    ma="$(measure "$a" "$@")"
    mb="$(measure "$b" "$@")"
  else
    mb="$(measure "$b" "$@")"
    ma="$(measure "$a" "$@")"
  fi
  read -r ra ia <<<"$ma"
  read -r rb ib <<<"$mb"
  printf '%5d %10s %10s %8.4f   %s, %s\n' "$i" "$ra" "$rb" "$(awk -v x="$ra" -v y="$rb" 'BEGIN {print y / x}')" "$ia" "$ib"
  results+="$ra $rb"$'\n'
done
echo "$results" | awk 'NF == 2 {r = $2 / $1; s += r; ss += r * r; sa += $1; sb += $2; n++}
  END {
    m = s / n; v = n > 1 ? (ss - n * m * m) / (n - 1) : 0; if (v < 0) v = 0
    printf "means: A %.3f M, B %.3f M samples/s; B/A %.4f, standard error %.4f over %d rounds\n", sa / n, sb / n, m, sqrt(v / n), n
  }'
