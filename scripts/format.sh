#!/usr/bin/env bash
# Formats the C++ sources as .clang-format says (clang-format 14, Debian 12's); with --check,
# changes nothing and fails naming each place that differs (CI's first stage). The GLSL, and
# shaders/shared/layouts.h which GLSL reads too, are formatted by hand (shaders/.clang-format).
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(find app engine fuzz packaging shaders tests ui \( -name '*.cpp' -o -name '*.h' \) | sort)
if [ "${1:-}" = --check ]; then
  clang-format --dry-run --Werror "${files[@]}"
  echo "format: ${#files[@]} files follow .clang-format"
else
  clang-format -i "${files[@]}"
fi
