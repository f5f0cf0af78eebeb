#!/usr/bin/env bash
# Installs what is missing, builds with warnings as errors and runs every test suite (unit, corpus,
# gpu, image) on the Vulkan device the machine has (lavapipe without a GPU).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-debian.sh
cmake --preset ci
cmake --build --preset ci
ctest --preset ci "$@"
