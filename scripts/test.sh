#!/usr/bin/env bash
# Builds and runs the default test suite (labels unit and gpu; `slow` is excluded) on the
# default Vulkan device (lavapipe), with validation layers on in every GPU test.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh "$@"
ctest --test-dir build -LE slow --output-on-failure -j"$(nproc)" --timeout 900
