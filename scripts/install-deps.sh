#!/usr/bin/env bash
# Installs every Debian 12 package gdpt needs to build, render and test (run as root).
# Nothing is downloaded from anywhere but Debian's archive.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config
  mesa-vulkan-drivers libvulkan-dev vulkan-validationlayers vulkan-tools
  glslang-tools spirv-tools
  libglm-dev libtinygltf-dev libopenexr-dev libimath-dev libstb-dev
  libcli11-dev libfmt-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libeigen3-dev
  gnuplot-nox python3 clang libclang-rt-dev
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
