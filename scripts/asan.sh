#!/usr/bin/env bash
# The test suites again under AddressSanitizer and UndefinedBehaviorSanitizer (the asan preset,
# build-asan/: clang, which also builds the fuzz targets there for scripts/fuzz.sh), halting on
# the first report. Arguments go to ctest; without any, every suite but
# image and stability: those two spend most of their time rendering on lavapipe, which the
# sanitizers do not instrument, while the code of ours they drive runs
# under ASan in unit_tests (every policy and the planner, extreme Q and image sizes) and gpu_tests
# (the renderer and the render thread). `bash scripts/asan.sh -L image` runs one of them. The
# Bsdfs tests of gpu_tests are left out too (the asan test preset's GTEST_FILTER): they hold the
# kernel's BSDF code, which runs on lavapipe, to its definitions, and the only code of ours they
# run on the host is packMaterial, which every rendering test runs. The build is a unity build
# (16 sources to a compilation): 304 s instead of 529 here.
# See docs/TESTING.md for what differs in that build.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-debian.sh
cmake --preset asan
if [ $# -eq 0 ]; then
  # The suites run here and the fuzz targets scripts/fuzz.sh runs next, not the two left out.
  cmake --build --preset asan --target unit_tests corpus_tests gpu_tests gui_tests gui_vulkan_tests fuzzers
  set -- -LE '^(image|stability)$'
else
  cmake --build --preset asan
fi
ctest --preset asan "$@"
