#!/usr/bin/env bash
# Installs what is missing, builds with warnings as errors and runs every test suite (unit, corpus,
# gpu, image) on the Vulkan device the machine has (lavapipe without a GPU); then the threading
# tests again under ThreadSanitizer. Arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-debian.sh
cmake --preset ci
cmake --build --preset ci
ctest --preset ci "$@"

# The Debian package builds, and an installed tree works without the source tree: resources from
# share/retile, the import worker from libexec/retile (a PLY goes through it).
cmake --build --preset ci --target package
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
cmake --install build-ci --prefix "$stage" >/dev/null
test -f "$stage/share/retile/ocio/config.ocio" && test -x "$stage/libexec/retile/retile-import-worker"
"$stage/bin/retile" --version
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >"$stage/triangle.ply"
"$stage/bin/retile" render "$stage/triangle.ply" --size 16x16 --spp 1 --out "$stage/triangle.png" 2>/dev/null
test -s "$stage/triangle.png"

# The render thread's channels and the engine facade again under ThreadSanitizer.
cmake --preset tsan
cmake --build --preset tsan --target thread_tests
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" build-tsan/bin/thread_tests --gtest_filter='EditQueue*:Mailbox*:Engine*'
