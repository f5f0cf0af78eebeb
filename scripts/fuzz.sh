#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, in the asan preset's tree: clang with ASan and UBSan, the
# same build scripts/asan.sh runs the suites in, so CI compiles the engine once for both), seeds each from
# ../shared (scenes, corpus), resources/scripts and scenes the command line converts to native
# files, and fuzzes each for SECONDS (default 30). Usage: scripts/fuzz.sh [SECONDS] [TARGET...]
# Inputs found to add coverage stay in build-asan/fuzz/corpus/TARGET (runs build on them); an input
# that crashes, breaks an invariant, leaks, times out or runs out of memory is written to
# build-asan/fuzz/artifacts/TARGET/ and the script fails. Prints how many executions each target ran.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-30}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_json fuzz_obj fuzz_scenario fuzz_native fuzz_tungsten fuzz_assimp)
shared=${RETILE_SHARED_DIR:-../shared}

cmake --preset asan >/dev/null
cmake --build --preset asan --target fuzzers
# The native seeds are scenes saved by the command line (the ci build's, built if missing).
[ -x build-ci/bin/retile ] || { cmake --preset ci >/dev/null && cmake --build --preset ci --target retile retile-import-worker; }

seeds=build-asan/fuzz/seeds
rm -rf "$seeds"
mkdir -p "$seeds"/{fuzz_json,fuzz_obj,fuzz_scenario,fuzz_native,fuzz_tungsten,fuzz_assimp}
small() { find "$@" -type f -size -64k 2>/dev/null; }
n=0
# Copies the files listed on stdin (one a line: names may hold spaces) into TARGET's seeds.
seed() { while IFS= read -r f; do cp "$f" "$seeds/$1/$((n++))$2"; done; }
seed fuzz_json .json < <(small "$shared/scenes" "$shared/corpus" \( -name '*.json' -o -name '*.gltf' \); printf '%s\n' resources/scripts/*.json)
seed fuzz_tungsten .json < <(printf '%s\n' "$shared"/scenes/*/scene.json; small "$shared/corpus" -name '*.json')
seed fuzz_obj .obj < <(small "$shared/scenes" "$shared/corpus" -iname '*.obj')
seed fuzz_scenario .json < <(printf '%s\n' resources/scripts/*.json)
while IFS= read -r f; do
  build-ci/bin/retile import "$f" --save "$seeds/fuzz_native/$((n++)).retile" >/dev/null 2>&1 || true
done < <(printf '%s\n' default "$shared"/scenes/cornell-box/scene.json; small "$shared/corpus/valid" -name '*.gltf' | head -8)
# The conversion's first byte picks the format (the order of kExtensions in fuzz_assimp.cpp).
exts=(obj gltf glb ply stl dae fbx off)
for i in "${!exts[@]}"; do
  while IFS= read -r f; do
    { printf "\\x$(printf %02x "$i")"; cat "$f"; } >"$seeds/fuzz_assimp/$((n++))"
  done < <(small "$shared/corpus" -iname "*.${exts[$i]}")
done

# Leaks inside libraries (listed with their reasons) are not findings.
export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
# Fuzzes target $1 and prints its summary; fails on a finding of ours.
fuzz_one() {
  local t=$1 status=0
  corpus=build-asan/fuzz/corpus/$t
  artifacts=build-asan/fuzz/artifacts/$t
  mkdir -p "$corpus" "$artifacts"
  log=build-asan/fuzz/$t.log
  extra=()
  # Assimp is not instrumented and crashes on hostile files inside its own parsers, which is why
  # the editor runs it in a child process: keep fuzzing past such crashes (in forked jobs) and sort
  # them out afterwards.
  [ "$t" = fuzz_assimp ] && extra=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
  # Readers print a warning per problem they repair: stderr goes to the log, of which the end
  # (the sanitizer's or libFuzzer's report) is shown when the run fails.
  set +e
  "build-asan/bin/$t" "$corpus" "$seeds/$t" -max_total_time="$seconds" -max_len=65536 -timeout=20 \
    -rss_limit_mb=3072 -print_final_stats=1 -artifact_prefix="$artifacts/" "${extra[@]}" >"$log" 2>&1
  rc=$?
  set -e
  execs=$(grep -a 'stat::number_of_executed_units' "$log" | tail -1 | awk '{print $2}' || true)
  # Forked jobs report "#EXECS: cov: ..." lines instead of final stats.
  [ -n "$execs" ] || execs=$(grep -a -o '^#[0-9]*: cov' "$log" | tail -1 | tr -dc 0-9 || true)
  cov=$(grep -a -o 'cov: [0-9]*' "$log" | tail -1 | awk '{print $2}' || true)
  summary="$t: ${execs:-?} executions in ${seconds} s, coverage ${cov:-?} edges, $(ls "$corpus" | wc -l) inputs kept"
  if [ "$t" = fuzz_assimp ]; then
    # A finding is Assimp's when its stack reaches none of our functions but the call of Assimp's
    # ReadFile in convertWithAssimp (its leaks in zlib have no frame of ours at all).
    ours=0 theirs=0
    mkdir -p "$artifacts/in-assimp"
    for a in "$artifacts"/crash-* "$artifacts"/leak-* "$artifacts"/oom-* "$artifacts"/timeout-*; do
      [ -e "$a" ] || continue
      report=$(timeout 300 "build-asan/bin/$t" -rss_limit_mb=3072 -timeout=20 "$a" 2>&1 || true)
      first=$(grep -a -m1 -o ' in retile::[^ ]*' <<<"$report" || true)
      if [ -z "$first" ] || [[ "$first" == *convertWithAssimp* ]]; then
        theirs=$((theirs + 1)); mv "$a" "$artifacts/in-assimp/"
      else
        ours=$((ours + 1)); echo "fuzz: $t: a finding in our code ($first): $a"; tail -n 40 <<<"$report"
      fi
    done
    echo "fuzz: $summary; crashes, leaks, timeouts and out-of-memory inside Assimp (the worker process and its limits contain them): $theirs; in our code: $ours"
    # Forked jobs end with an error status when a job found something; with every finding sorted
    # as Assimp's, only a run that found nothing at all may still have failed.
    if [ $ours -ne 0 ] || { [ $rc -ne 0 ] && [ $theirs -eq 0 ]; }; then
      status=1
      [ $ours -ne 0 ] || tail -n 40 "$log"
    fi
  elif [ $rc -eq 0 ]; then
    echo "fuzz: $summary, nothing found"
  else
    echo "fuzz: $t FAILED (exit $rc) after ${execs:-?} executions; artifacts in $artifacts:"
    ls "$artifacts"
    tail -n 60 "$log"
    status=1
  fi
  return $status
}

# Two targets at a time, one a core: each runs for SECONDS as it would alone. Their reports are
# shown in order once all are done.
status=0
pids=()
for t in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge 2 ]; do wait -n || true; done
  fuzz_one "$t" >"build-asan/fuzz/$t.report" 2>&1 &
  pids+=($!)
done
for i in "${!targets[@]}"; do
  wait "${pids[$i]}" || status=1
  cat "build-asan/fuzz/${targets[$i]}.report"
done
exit $status
