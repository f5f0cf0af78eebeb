#!/usr/bin/env bash
# Writes docs/RESULTS.md and its pictures (docs/results/) from `retile eval` runs made now: the
# built-in scene under the whole protocol, the living room at 160x90, and the stability suite.
# The page's tables and every figure in its text are read from the runs' CSV files; only what a
# scenario or case is, and why a method can fail it, is fixed text.
#
# usage: scripts/results.sh [--bin RETILE] [--runs DIR] [--reuse] [--out FILE]
#   --runs DIR  where the eval output directories go (default out/results); their cached
#               references make a second run shorter
#   --reuse     write the page from the runs already in DIR without running anything
# About 45 minutes on 2 cores with lavapipe; needs python3 and oiiotool (openimageio-tools).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bin="$here/build/bin/retile"
runs="$here/out/results"
out="$here/docs/RESULTS.md"
reuse=0
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --reuse) reuse=1; shift ;;
    --out) out="$2"; shift 2 ;;
    -h | --help) sed -n 2,11p "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "error: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
command -v python3 >/dev/null || { echo "error: python3 is needed to write the page" >&2; exit 2; }
command -v oiiotool >/dev/null || { echo "error: oiiotool (openimageio-tools) is needed to scale the strips" >&2; exit 2; }
living="$here/../shared/scenes/living-room/scene.json"
mkdir -p "$runs"

# One eval run, its wall time kept beside its report for the page.
run() {
  local name=$1; shift
  local start; start=$(date +%s)
  echo "== $name: retile eval $*" >&2
  "$bin" eval "$@" --out-dir "$runs/$name" >"$runs/$name.log" 2>&1 || { tail -20 "$runs/$name.log" >&2; exit 1; }
  echo $(($(date +%s) - start)) >"$runs/$name.seconds"
}
if [ "$reuse" = 0 ]; then
  [ -x "$bin" ] || { echo "error: $bin is not an executable (build first, or pass --bin)" >&2; exit 2; }
  [ -f "$living" ] || { echo "error: $living not found (../shared beside the repository)" >&2; exit 2; }
  run default default
  run living-room "$living" --size 160x90
  run stability default --stability --quick
fi

pictures="$(dirname "$out")/results"
mkdir -p "$pictures"
rm -f "$pictures"/*.png "$pictures"/*.jpg
# Named by run, not by the report's scene name (the living room's is its file's: living-room-scene).
for run in default living-room; do
  [ -d "$runs/$run" ] || continue
  for kind in fig6-affected fig6-tradeoff material-affected light-affected drag-affected; do
    chart=$(ls "$runs/$run"/charts/*-"$kind".png 2>/dev/null || true)
    [ -z "$chart" ] || cp "$chart" "$pictures/$run-$kind.png"
  done
  oiiotool "$(ls "$runs/$run"/strips/*-fig6.png)" --resize 50% -o "$pictures/$run-fig6-strip.jpg"
done

python3 - "$runs" "$out" "$(nproc)" "$(vulkaninfo --summary 2>/dev/null | grep -m1 deviceName | sed 's/.*= //')" <<'EOF'
import csv, datetime, os, sys

runs, out, cores, device = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4] or "the Vulkan device found"
pictures = os.path.join(os.path.dirname(out), "results")

def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))

def seconds(name):
    p = os.path.join(runs, name + ".seconds")
    return int(open(p).read()) if os.path.exists(p) else None

def minutes(s):
    return "not timed" if s is None else f"{s // 60} min {s % 60:02d} s"

def f2(v):
    return "" if v in ("", None) else f"{float(v):.2f}"

def target(r):
    return f"{r['frames_to_target']}, {float(r['ms_to_target']):.0f}" if r["frames_to_target"] else "not reached"

def val(r, key):
    return float(r[key]) if r.get(key) not in ("", None) else None

page = []
w = page.append
today = datetime.date.today().isoformat()
w("# Results: speed against accuracy for every method, and where methods fail\n")
w(f"What `retile eval` measured on {today}, on {cores} cores with {device}. Written by")
w("`scripts/results.sh`, which makes the runs and writes this page and its pictures from their CSV")
w("files (`bash scripts/results.sh`, about 45 minutes here): regenerate it rather than editing it.")
w("Each run's own report (`index.html`, `metrics.csv`,")
w("`summary.csv`, every chart as PNG and SVG, the frame strips) is the full record.\n")
w("| run | command | time |")
w("|---|---|---|")
w(f"| built-in scene | `retile eval default` | {minutes(seconds('default'))} |")
w(f"| living room | `retile eval ../shared/scenes/living-room/scene.json --size 160x90` | {minutes(seconds('living-room'))} |")
w(f"| stability suite | `retile eval default --stability --quick` | {minutes(seconds('stability'))} |")
w("")
w("The protocol at its defaults: 320x180; converged references of 1024 spp, cached beside the")
w("report; every method traces exactly W x H samples a frame; the Fig. 6 scenario (the object nearest")
w("the image centre moves by 0.005 a frame for 100 frames, then rests 100) converges 1024 spp first,")
w("the material, light, camera and drag scenarios 256. PSNR compares display-referred images (the sRGB")
w("view, clamped) at frames 1, 10, 100 and 200, over the whole image and over the affected region (where")
w("the scenario's references differ from the start beyond their noise); \"to 2 %\" is the time from")
w("frame 1 until the relative RMSE of the affected region (linear luminance, 4x4 blocks) stays at or")
w("below 2 %. METHOD.md explains the methods; `global` is the restart every other is measured against.\n")

def scene_section(name, title):
    path = os.path.join(runs, name, "summary.csv")
    if not os.path.exists(path):
        return
    data = rows(path)
    fig6 = [r for r in data if r["scenario"] == "fig6"]
    other = [r for r in data if r["scenario"] != "fig6"]
    w(f"## {title}: the Fig. 6 protocol\n")
    w("| method | PSNR @1 | @10 | @100 | @200 | affected @1 | @10 | @100 | @200 | to 2 % (frames, ms) |")
    w("|---|---|---|---|---|---|---|---|---|---|")
    for r in fig6:
        cells = [f2(r[f"psnr_{f}"]) for f in (1, 10, 100, 200)] + [f2(r[f"psnr_affected_{f}"]) for f in (1, 10, 100, 200)]
        w(f"| {r['method']} | " + " | ".join(cells) + f" | {target(r)} |")
    w("")
    for chart in ("fig6-affected", "fig6-tradeoff"):
        if os.path.exists(os.path.join(pictures, f"{name}-{chart}.png")):
            w(f"![{chart}](results/{name}-{chart}.png)")
    w(f"![Fig. 6 strip](results/{name}-fig6-strip.jpg)\n")
    w("The strip: frames of every method with the overlays (tiles traced that frame outlined, queue")
    w("priority as a heat map, the point of change and focus marked, denoised regions framed).\n")
    by = {r["method"]: r for r in fig6}
    notes = []
    g = by.get("global")
    raw = [m for m in by if m != "global" and "denoise" not in m]
    if g and raw:
        leads = [val(by[m], "psnr_affected_1") - val(g, "psnr_affected_1") for m in raw if val(by[m], "psnr_affected_1") is not None]
        if leads:
            notes.append(f"At frame 1 of the move the other raw methods show {min(leads):+.1f} to {max(leads):+.1f} dB against the"
                         f" global restart in the affected region ({val(g, 'psnr_affected_1'):.1f} dB): the restart is at 1 spp"
                         " a frame for as long as edits come, the incremental methods keep the converged rest.")
        s = by.get("spiral")
        if s and val(s, "psnr_affected_100") is not None:
            notes.append(f"The spiral's lead shrinks as the move goes on ({val(s, 'psnr_affected_1'):.1f} dB in the affected region"
                         f" at frame 1, {val(s, 'psnr_affected_100'):.1f} at frame 100): a frame refreshes W x H samples while"
                         " the moving object and what it changes cover more, so the image lags behind the object"
                         " (the ghosting of the stability suite).")
    ind, s = by.get("indirection"), by.get("spiral")
    first = [r for r in rows(os.path.join(runs, name, "metrics.csv"))
             if r["scenario"] == "fig6" and r["method"] == "indirection" and r["frame"] == "1"]
    if ind and s and first and val(ind, "psnr_affected_100") is not None and val(s, "psnr_affected_100") is not None:
        q, tiles = first[0]["quality"], first[0]["served_tiles"]
        notes.append(f"Indirection takes Q = {q} (automatic: the largest at which its high tiles fit one frame) and serves"
                     f" those {tiles} tiles every frame while the object moves: fresh, but at {q} spp. In the affected region"
                     f" that gives {val(ind, 'psnr_affected_1'):.1f} dB at frame 1 and {val(ind, 'psnr_affected_100'):.1f}"
                     f" at frame 100, against the spiral's converged but lagging tiles at {val(s, 'psnr_affected_1'):.1f}"
                     f" and {val(s, 'psnr_affected_100'):.1f}: while the object has moved little, the old image is nearer"
                     " than a fresh noisy one. Once it stops, its last pass serves every tile at that Q, the rest of"
                     " the image too (the strip's third column, ten frames after the move).")
    gd = by.get("global+denoise")
    if g and gd and val(g, "psnr_1") is not None and val(g, "psnr_200") is not None:
        notes.append(f"The denoiser adds {val(gd, 'psnr_1') - val(g, 'psnr_1'):+.1f} dB to the global restart at frame 1 and"
                     f" {val(gd, 'psnr_200') - val(g, 'psnr_200'):+.1f} dB at frame 200, 100 frames at rest.")
    reached = sorted((int(r["frames_to_target"]), r["method"]) for r in fig6 if r["frames_to_target"])
    if reached:
        missed = len(fig6) - len(reached)
        notes.append("The affected region comes within 2 % under " + ", ".join(f"{m} (frame {n})" for n, m in reached) +
                     (f"; not within the run under the other {missed}." if missed else "."))
    else:
        notes.append("No method brings the affected region within 2 % within the run.")
    sp, su = by.get("spiral"), by.get("spiral+reuse")
    if sp and su and val(sp, "psnr_200") is not None:
        notes.append(f"Verified reuse keeps the tiles the move did not change: spiral+reuse {val(su, 'psnr_200'):.1f} dB over the"
                     f" image at frame 200 against the spiral's {val(sp, 'psnr_200'):.1f}.")
    if notes:
        w("What it says:")
        for n in notes:
            w(f"- {n}")
        w("")
    if not other:
        return
    w(f"## {title}: the other scenarios\n")
    what = {"material": "the object's material takes a new roughness and albedo",
            "light": "a light turns warmer and 1.5 times as strong",
            "camera": "the camera orbits its target by 0.5 degrees a frame for 20 frames",
            "drag": "the object slides sideways by a fiftieth of its size a frame for 50 frames"}
    played = list(dict.fromkeys(r["scenario"] for r in other))
    w(" ".join(f"{p.capitalize()}: {what.get(p, 'see the report')}." for p in played) + " Each then rests 100 frames.\n")
    w("| scenario | method | PSNR @1 | @10 | @100 | affected @1 | @10 | @100 | to 2 % (frames, ms) |")
    w("|---|---|---|---|---|---|---|---|---|")
    for r in other:
        cells = [f2(r[f"psnr_{f}"]) for f in (1, 10, 100)] + [f2(r[f"psnr_affected_{f}"]) for f in (1, 10, 100)]
        w(f"| {r['scenario']} | {r['method']} | " + " | ".join(cells) + f" | {target(r)} |")
    w("")
    for scenario in ("material", "light", "drag"):
        if os.path.exists(os.path.join(pictures, f"{name}-{scenario}-affected.png")):
            w(f"![{scenario}](results/{name}-{scenario}-affected.png)")
    w("")

scene_section("default", "Built-in scene")
scene_section("living-room", "Living room (160x90)")

# What each stability case plays, and the mechanism METHOD.md gives for a method failing it.
cases = {
    "camera-mid-pass": ("the camera moves while a pass is under way", ""),
    "resize-mid-pass": ("the image is resized while a pass is under way", ""),
    "burst": ("an edit every frame for 100 frames; the detail counts the changed tiles never traced during it",
              "each edit restarts the spiral at the new point of change, so its far tiles starve"),
    "ghosting": ("a drag at Q=512 of the object by its own size over 10 frames, scored 20 frames later",
                 "at Q=512 a frame refreshes a few pixels, so the object stays at its old positions"),
    "off-screen": ("the edited object is outside the view", ""),
    "behind-camera": ("the edited object is behind the camera", ""),
    "fill-screen": ("the edited object fills the view", ""),
    "light-global": ("a light edit that changes every lit pixel", "the stale light stays on the tiles not reached yet"),
    "mirror-only": ("a sphere behind the camera, seen only in a mirror, changes material",
                    "the object projects nowhere on screen, so the spiral's order has nothing to do with the mirror"),
    "offscreen-shadow": ("a sphere above the frame moves; only its shadow is seen", ""),
}
stab_path = os.path.join(runs, "stability", "stability.csv")
if os.path.exists(stab_path):
    data = rows(stab_path)
    broken = [r for r in data if r["broken"]]
    figures = [r for r in data if r["case"] != "extreme" and r["method"]]
    methods = list(dict.fromkeys(r["method"] for r in figures))
    w("## Stability suite\n")
    w("Each case plays a short edit under every method at 96x54 and takes one figure: the relative RMSE")
    w("of the affected region (linear luminance, 4x4 blocks) at the case's frame against a converged")
    w("reference of what that frame should show. A method passes at up to 1.5 times the global method's")
    w("figure: a restart shows nothing stale, so its noise is the yardstick. `ctest -L stability` runs")
    w("the same cases and asserts the invariants (exactly W x H samples every frame, finite pixels, no")
    w("error; a camera move or resize mid-pass as good as a restart; every method converging after the")
    w(f"burst). In this run {len(broken)} of {len(data)} rows broke an invariant.\n")
    w("| case (limit) | " + " | ".join(methods) + " |")
    w("|---|" + "---|" * len(methods))
    order = list(dict.fromkeys(r["case"] for r in figures))
    fails = {}
    for c in order:
        cell = {r["method"]: r for r in figures if r["case"] == c}
        limit = next(float(r["threshold"]) for r in cell.values() if r["threshold"])
        line = []
        for m in methods:
            r = cell.get(m)
            if not r or not r["figure"]:
                line.append("")
                continue
            text = f"{float(r['figure']):.3f}"
            if r["pass"] != "1":
                text += " **fail**"
                fails.setdefault(c, []).append(m)
            if c == "burst" and r["detail"]:
                text += f" ({r['detail'].split()[0]} starved)"
            line.append(text)
        w(f"| {c} ({limit:.3f}) | " + " | ".join(line) + " |")
    passed = sum(1 for r in figures if r["pass"] == "1")
    w(f"\n{passed} of {len(figures)} figures pass. The cases:\n")
    for c in order:
        what, why = cases.get(c, ("", ""))
        failed = fails.get(c, [])
        if c in ("off-screen", "behind-camera") and "change" in failed:
            why = "change's probe frame traces a frame's budget it does not keep, a cost the others do not pay"
        verdict = "every method passes" if not failed else "fails: " + ", ".join(failed) + (f"; {why}" if why else "")
        w(f"- **{c}**: {what}; {verdict}.")
    extreme = [r for r in data if r["case"] == "extreme"]
    if extreme:
        w("\nExtreme settings (the spiral unless named): the share of frames with exactly W x H samples, and")
        w("the tiles traced after the edit.\n")
        w("| variant | frames with exactly W x H samples | tiles traced after the edit |")
        w("|---|---|---|")
        for r in extreme:
            w(f"| {r['method']} | {float(r['figure']):.2f} | {r['detail'].split()[0] if r['detail'] else ''} |")
    w("")

with open(out + ".tmp", "w") as f:
    f.write("\n".join(page).rstrip("\n") + "\n")
os.replace(out + ".tmp", out)
print(f"wrote {out}")
EOF
