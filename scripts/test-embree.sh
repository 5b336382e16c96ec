#!/usr/bin/env bash
# Builds gdpt bench's Embree baseline (-DGDPT_EMBREE=ON, in ./build-embree) and runs its tests:
# Embree and gdpt's traversal find the same closest hits and trace the same bench paths.
# Extra arguments go to CMake's configure. Needs libembree-dev (scripts/install-deps.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-embree -G Ninja -DCMAKE_BUILD_TYPE=Release -DGDPT_EMBREE=ON -DGDPT_BUILD_TESTS=ON "$@" > /dev/null
cmake --build build-embree -j"$(nproc)" --target gdpt_unit_baseline
build-embree/tests/unit/gdpt_unit_baseline
