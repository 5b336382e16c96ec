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
# Memory limits per harness: the glTF loader must refuse anything large before allocating it
# (its harness sets a 64 MiB budget), so one allocation over 256 MiB or 1 GiB resident is a
# finding; an EXR header may declare a large data window that OpenEXR allocates first.
declare -A limits=([gltf]="-rss_limit_mb=1024 -malloc_limit_mb=256 -dict=tests/fuzz/gltf.dict"
                   [exr]="-rss_limit_mb=4096")
for target in gltf exr; do
  work=build-fuzz/corpus-$target
  mkdir -p "$work"
  cp -n tests/fuzz/corpus/$target/* "$work"/ 2>/dev/null || true
  echo "fuzz_$target: ${seconds}s"
  # shellcheck disable=SC2086  # the limits are separate arguments
  ASAN_OPTIONS=detect_leaks=0 build-fuzz/tests/fuzz/fuzz_$target "$work" -max_total_time="$seconds" \
    -max_len=65536 -timeout=10 ${limits[$target]} -artifact_prefix=build-fuzz/artifacts/ -print_final_stats=1 \
    2>&1 | tail -n 12
done
