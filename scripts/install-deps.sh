#!/usr/bin/env bash
# Installs every Debian 12 package gdpt needs to build, render and test (run as root).
# Nothing is downloaded from anywhere but Debian's archive.
#
#   scripts/install-deps.sh                   Mesa 22.3 lavapipe from bookworm (the default)
#   scripts/install-deps.sh --mesa-backports  also enables bookworm-backports and installs its
#                                             Mesa 25 lavapipe (about 2x faster on gdpt's
#                                             kernels; see bench/RESULTS.md)
#   scripts/install-deps.sh --dry-run [...]   prints what apt-get would do, changes nothing
set -euo pipefail
backports=0
dry=0
for arg in "$@"; do
  case "$arg" in
    --mesa-backports) backports=1 ;;
    --dry-run) dry=1 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "install-deps.sh: unknown option '$arg' (try --help)" >&2; exit 2 ;;
  esac
done
packages=(
  build-essential cmake ninja-build pkg-config
  mesa-vulkan-drivers libvulkan-dev vulkan-validationlayers vulkan-tools
  glslang-tools spirv-tools
  libglm-dev libtinygltf-dev libopenexr-dev libimath-dev libstb-dev
  libcli11-dev libfmt-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libeigen3-dev
  gnuplot-nox python3 clang libclang-rt-dev clang-format-14
  assimp-testmodels
  libopenmpi-dev openmpi-bin
  libembree-dev
  ffmpeg
)
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
APT=($SUDO env DEBIAN_FRONTEND=noninteractive apt-get)
((dry)) && APT+=(-s)
if ((backports)); then
  list=/etc/apt/sources.list.d/gdpt-bookworm-backports.list
  if [ ! -f "$list" ] && ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
    if ((dry)); then
      echo "would write $list: deb http://deb.debian.org/debian bookworm-backports main"
    else
      echo "deb http://deb.debian.org/debian bookworm-backports main" | $SUDO tee "$list" > /dev/null
    fi
  fi
  ((dry)) || "${APT[@]}" update -q
  "${APT[@]}" install -y -q --no-install-recommends "${packages[@]}"
  # Backports packages are never chosen by default; ask for Mesa's (its libdrm follows).
  if ((dry)) && ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
    echo "would run: apt-get install -t bookworm-backports mesa-vulkan-drivers"
  else
    "${APT[@]}" install -y -q --no-install-recommends -t bookworm-backports mesa-vulkan-drivers
  fi
  exit 0
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  ((dry)) || "${APT[@]}" update -q
  "${APT[@]}" install -y -q --no-install-recommends "${missing[@]}"
fi
