#!/usr/bin/env bash
# Installs what is missing, builds with warnings as errors and runs every test suite (unit, corpus,
# gpu, image) on the Vulkan device the machine has (lavapipe without a GPU); then the threading
# tests again under ThreadSanitizer. Arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
stage() { local name=$1 start=$SECONDS; shift; "$@"; echo "stage $name: $((SECONDS - start)) s"; }
stage set-up bash scripts/setup-debian.sh
stage format bash scripts/format.sh --check
cmake --preset ci
stage build cmake --build --preset ci
stage suites ctest --preset ci "$@"

# The Debian package builds, and an installed tree works without the source tree: resources from
# share/retile, the import worker from libexec/retile (a PLY goes through it).
package() {
  cmake --build --preset ci --target package
  local tree
  tree=$(mktemp -d)
  cmake --install build-ci --prefix "$tree" >/dev/null
  test -f "$tree/share/retile/ocio/config.ocio" && test -x "$tree/libexec/retile/retile-import-worker"
  "$tree/bin/retile" --version
  printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >"$tree/triangle.ply"
  "$tree/bin/retile" render "$tree/triangle.ply" --size 16x16 --spp 1 --out "$tree/triangle.png" 2>/dev/null
  test -s "$tree/triangle.png"
  rm -rf "$tree"
}
stage package package

# The render thread's channels and the engine facade again under ThreadSanitizer.
tsan() {
  cmake --preset tsan
  cmake --build --preset tsan --target thread_tests
  TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" build-tsan/bin/thread_tests --gtest_filter='EditQueue*:Mailbox*:Engine*'
}
stage TSan tsan
