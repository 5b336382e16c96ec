#!/usr/bin/env bash
# Builds the libFuzzer harnesses with clang (+ASan/UBSan) into build-fuzz and runs each for
# SECONDS (default 60) on a copy of its seed corpus. Exits non-zero if a harness finds a
# crash; the reproducer is left in build-fuzz/artifacts/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGDPT_FUZZ=ON > /dev/null
cmake --build build-fuzz -j"$(nproc)" --target fuzz_gltf fuzz_exr
mkdir -p build-fuzz/artifacts
for target in gltf exr; do
  work=build-fuzz/corpus-$target
  mkdir -p "$work"
  cp -n tests/fuzz/corpus/$target/* "$work"/ 2>/dev/null || true
  echo "fuzz_$target: ${seconds}s"
  ASAN_OPTIONS=detect_leaks=0 build-fuzz/tests/fuzz/fuzz_$target "$work" -max_total_time="$seconds" \
    -max_len=65536 -timeout=10 -rss_limit_mb=4096 -artifact_prefix=build-fuzz/artifacts/ -print_final_stats=1 \
    2>&1 | tail -n 12
done
