#!/usr/bin/env bash
# The test suites again under AddressSanitizer and UndefinedBehaviorSanitizer (the asan preset,
# build-asan/: clang, which also builds the fuzz targets there for scripts/fuzz.sh), halting on the first report. Arguments go to ctest; without any, every suite but
# image and stability: those two spend 6.5 of the 11 minutes all suites took under ASan rendering
# on lavapipe, which the sanitizers do not instrument, while the code of ours they drive runs
# under ASan in unit_tests (every policy and the planner, extreme Q and image sizes) and gpu_tests
# (the renderer and the render thread). `bash scripts/asan.sh -L image` runs one of them.
# See docs/TESTING.md for what differs in that build.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-debian.sh
cmake --preset asan
cmake --build --preset asan
if [ $# -eq 0 ]; then set -- -LE '^(image|stability)$'; fi
ctest --preset asan "$@"
