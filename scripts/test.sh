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

# The render thread's channels and the engine facade again under ThreadSanitizer.
cmake --preset tsan
cmake --build --preset tsan --target unit_tests gpu_tests
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" build-tsan/bin/unit_tests --gtest_filter='EditQueue*:Mailbox*'
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" build-tsan/bin/gpu_tests --gtest_filter='Engine*'
