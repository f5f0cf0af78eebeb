#!/usr/bin/env bash
# Installs every Debian 12 package Retile needs to build, test and run. Idempotent: packages
# already present are skipped, so running it twice costs one dpkg query.
set -euo pipefail

# zlib1g-dev: Debian's Assimp CMake package names libz.so in its link interface, but libassimp-dev
# does not depend on zlib1g-dev, so a fresh machine fails at the link step without it.
# file, dpkg-dev: CPack's Debian generator finds the executables with file and their library
# dependencies with dpkg-shlibdeps (the `package` target).
# locales: the locale sources that localedef compiles, for the tests that run under a comma-decimal
# locale (de_DE) as an artist in much of Europe does.
# libcli11-dev: the command line's parser (header-only): options, ranges and --help of every command.
# clang, libclang-rt-14-dev: the fuzz targets (libFuzzer's runtime is only recommended by clang).
# clang-format: the sources' format, checked by scripts/format.sh --check.
packages=(
  build-essential cmake ninja-build pkg-config git file dpkg-dev
  qt6-base-dev qt6-base-dev-tools qt6-charts-dev qt6-svg-dev libqt6opengl6-dev libgl-dev
  libvulkan-dev vulkan-tools mesa-vulkan-drivers vulkan-validationlayers
  glslang-dev glslang-tools spirv-tools
  libassimp-dev zlib1g-dev
  libopenimageio-dev openimageio-tools
  libopencolorio-dev
  libgtest-dev libgmock-dev
  libcli11-dev
  clang libclang-rt-14-dev clang-format
  locales time
  xvfb xauth libxkbcommon-x11-0 libxcb-cursor0 libxcb-icccm4 libxcb-image0 libxcb-keysyms1
  libxcb-randr0 libxcb-render-util0 libxcb-shape0 libxcb-xinerama0 libxcb-xkb1 fonts-dejavu-core
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

echo "setup: installing ${#missing[@]} packages: ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
