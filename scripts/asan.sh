#!/usr/bin/env bash
# Every test suite again under AddressSanitizer and UndefinedBehaviorSanitizer (the asan preset,
# build-asan/), halting on the first report. Arguments go to ctest. See docs/TESTING.md for what
# differs in that build.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-debian.sh
cmake --preset asan
cmake --build --preset asan
ctest --preset asan "$@"
