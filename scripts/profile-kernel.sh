#!/usr/bin/env bash
# Profiles the trace kernel as lavapipe compiled it: samples `retile bench throughput` with perf
# while it runs, copies the JIT-compiled machine code out of the running process with gdb, and
# writes it annotated with each instruction's share of the samples. perf alone sees only
# "[JIT]" addresses: lavapipe registers no symbols, and its code is gone when the process ends.
#
# What it showed on the kitchen: 14 % of the time on the first texel load of each traversal
# step (cache misses on the BVH and triangles), the subgroup ballot that ends the traversal
# loop about 9 % (a loop over the lanes on lavapipe), texel-buffer fetch functions 8 to 10 %.
#
# usage: scripts/profile-kernel.sh [--bin RETILE] [--frames N] [--warm-up SECONDS] SCENE OUTDIR
#   OUTDIR/annotated.txt   share of samples (%), offset in the kernel, instruction
#   OUTDIR/summary.txt     the hottest instructions and the share of each KiB of code
# Needs perf (linux-perf), gdb and objdump (binutils); run it as root or with
# kernel.perf_event_paranoid <= 1. Pick --frames so that the run outlasts the warm-up (scene
# load and kernel compile) by ten seconds.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bin="$here/build/bin/retile"
frames=60
warm=15
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --warm-up) warm="$2"; shift 2 ;;
    -h | --help) sed -n 2,17p "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "error: unknown option '$1'" >&2; exit 2 ;;
    *) break ;;
  esac
done
[ $# -eq 2 ] || { sed -n 11,17p "$0" | sed 's/^# \{0,1\}//'; exit 2; }
scene="$1" out="$2"
for tool in perf gdb objdump python3; do
  command -v "$tool" >/dev/null || { echo "error: $tool is not installed" >&2; exit 2; }
done
[ -x "$bin" ] || { echo "error: $bin is not an executable (build first, or pass --bin)" >&2; exit 2; }
mkdir -p "$out"

"$bin" bench throughput "$scene" --size 320x180 --frames "$frames" >"$out/bench.txt" 2>&1 &
pid=$!
trap 'kill $pid 2>/dev/null || true' EXIT
sleep "$warm"
kill -0 $pid 2>/dev/null || { echo "error: the benchmark ended within the warm-up; raise --frames" >&2; cat "$out/bench.txt" >&2; exit 1; }
perf record -q -o "$out/perf.data" -F 1999 -p $pid -- sleep 8 >/dev/null 2>&1
perf report -i "$out/perf.data" --sort sym 2>/dev/null | awk '$3 ~ /^0x/ {sub("%", "", $1); print $3, $1}' >"$out/samples.txt"

# The executable mapping that holds most samples is the trace kernel's code.
read -r start end < <(python3 - "$pid" "$out/samples.txt" <<'PY'
import sys
samples = [(int(a, 16), float(s)) for a, s in (l.split() for l in open(sys.argv[2]))]
best = (0.0, 0, 0)
for line in open(f"/proc/{sys.argv[1]}/maps"):
    fields = line.split()
    if "x" not in fields[1] or len(fields) > 5:  # executable and anonymous
        continue
    lo, hi = (int(x, 16) for x in fields[0].split("-"))
    best = max(best, (sum(s for a, s in samples if lo <= a < hi), lo, hi))
print(hex(best[1]), hex(best[2]))
PY
)
gdb -p $pid -batch -ex "dump memory $out/kernel.bin $start $end" >/dev/null 2>&1
kill $pid 2>/dev/null || true
objdump -D -b binary -m i386:x86-64 --adjust-vma="$start" "$out/kernel.bin" >"$out/kernel.asm"

python3 - "$out" "$start" <<'PY'
import sys
out, start = sys.argv[1], int(sys.argv[2], 16)
samples = {int(a, 16): float(s) for a, s in (l.split() for l in open(f"{out}/samples.txt"))}
rows = []
for line in open(f"{out}/kernel.asm"):
    parts = line.rstrip("\n").split("\t")
    head = line.split()
    try:
        address = int(head[0].rstrip(":"), 16)
    except (ValueError, IndexError):
        continue
    rows.append((samples.get(address, 0.0), address - start, parts[-1] if len(parts) > 2 else ""))
with open(f"{out}/annotated.txt", "w") as f:
    for share, offset, text in rows:
        f.write(f"{share:5.2f} {offset:6x} {text}\n")
inside = sum(share for share, _, _ in rows)
kib = {}
for share, offset, _ in rows:
    kib[offset // 1024] = kib.get(offset // 1024, 0.0) + share
with open(f"{out}/summary.txt", "w") as f:
    f.write(f"{inside:.1f} % of the samples in the kernel's {len(rows)} instructions\n\nhottest instructions:\n")
    for share, offset, text in sorted(rows, reverse=True)[:25]:
        f.write(f"{share:5.2f} {offset:6x} {text}\n")
    f.write("\nshare of each KiB of code (over 0.5 %):\n")
    for k in sorted(kib):
        if kib[k] > 0.5:
            f.write(f"{k:5d} KiB {kib[k]:5.2f}\n")
PY
echo "wrote $out/annotated.txt and $out/summary.txt"
head -1 "$out/summary.txt"
