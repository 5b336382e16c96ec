#!/usr/bin/env bash
# Builds with AddressSanitizer + UndefinedBehaviorSanitizer into build-asan and runs the
# CPU test suite (label unit) there. (GPU tests run lavapipe's JIT code, which the
# sanitizers do not instrument; they run in the normal build.)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGDPT_SANITIZE=ON > /dev/null
cmake --build build-asan -j"$(nproc)" --target gdpt_unit_util gdpt_unit_scene gdpt_unit_bvh gdpt_unit_image \
  gdpt_unit_sampling gdpt_unit_poisson gdpt_unit_shift gdpt_unit_stats gdpt_unit_distributed gdpt_unit_mlt
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan -L unit --output-on-failure -j"$(nproc)"
