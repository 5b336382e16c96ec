#!/usr/bin/env bash
# gdpt's BVH build and ray throughput against Embree 3 on the same triangles and rays, in one
# run (`gdpt bench --embree`, interleaved, medians): builds gdpt with -DGDPT_EMBREE=ON in
# ./build-embree, then runs the benchmark. Needs libembree-dev (scripts/install-deps.sh).
#
#   scripts/bench-embree.sh [-o OUT.json] [gdpt bench options...]
#   e.g. scripts/bench-embree.sh -o embree.json --scenes cbox,10k,100k,1m --repeats 5
set -euo pipefail
cd "$(dirname "$0")/.."
case "${1:-}" in -h|--help) sed -n '2,7p' "$0"; exit 0 ;; esac
cmake -S . -B build-embree -G Ninja -DCMAKE_BUILD_TYPE=Release -DGDPT_EMBREE=ON > /dev/null
cmake --build build-embree -j"$(nproc)" --target gdpt
build-embree/gdpt bench --embree "$@"
