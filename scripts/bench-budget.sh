#!/usr/bin/env bash
# How well `gdpt render --time T` holds its budget: each scene at each budget, on an idle
# machine and beside busy processes (each a shell loop that keeps one processor busy), with
# warm caches and with cold ones (an empty Mesa shader cache, so lavapipe compiles every
# kernel again, and an empty gdpt cache, so the reconstruction is calibrated again). Runs of
# the conditions are interleaved. Prints one JSON line per render (its --json "budget"
# object, with the condition), then per condition the median and largest overrun (total /
# budget - 1) and how many renders said their fixed costs alone exceeded the budget. Not a
# test: a benchmark (about 15 minutes with the defaults on 2 cores).
#
#   scripts/bench-budget.sh [--times 4,8] [--scenes cornell_box,open_scene,...] [--busy 0,2]
#                           [--caches warm,cold] [--repeats 3] [--size 256] [--method gpt]
set -euo pipefail
cd "$(dirname "$0")/.."
times=4,8 scenes=cornell_box,glossy_cornell,indirect_gap,open_scene busy=0,2 caches=warm,cold repeats=3
size=256 method=gpt
while (($#)); do
  case "$1" in
    --times) times=$2; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
    --busy) busy=$2; shift 2 ;;
    --caches) caches=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --method) method=$2; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) echo "bench-budget.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[ -x build/gdpt ] || { echo "bench-budget.sh: build/gdpt missing; run scripts/build.sh first" >&2; exit 1; }
work=$(mktemp -d)
hogs=()
stop_hogs() { for p in "${hogs[@]}"; do kill "$p" 2>/dev/null || true; done; hogs=(); }
trap 'stop_hogs; rm -rf "$work"' EXIT
IFS=, read -ra scene_list <<< "$scenes"
IFS=, read -ra time_list <<< "$times"
IFS=, read -ra busy_list <<< "$busy"
IFS=, read -ra cache_list <<< "$caches"
warm_gdpt="$work/gdpt-warm"
lines="$work/lines.jsonl"
: > "$lines"
# Warm caches: one untimed render of each scene and one timed render per budget first.
for s in "${scene_list[@]}"; do
  for t in "${time_list[@]}"; do
    GDPT_CACHE_DIR="$warm_gdpt" build/gdpt render "scenes/$s.gltf" --method "$method" --time "$t" \
      --width "$size" --height "$size" -o "$work/warm.exr" --quiet
  done
done
for ((r = 0; r < repeats; ++r)); do
  for s in "${scene_list[@]}"; do
    for t in "${time_list[@]}"; do
      for b in "${busy_list[@]}"; do
        for c in "${cache_list[@]}"; do
          env=(GDPT_CACHE_DIR="$warm_gdpt")
          if [ "$c" = cold ]; then
            rm -rf "$work/gdpt-cold" "$work/mesa-cold"
            env=(GDPT_CACHE_DIR="$work/gdpt-cold" MESA_SHADER_CACHE_DIR="$work/mesa-cold")
          fi
          for ((i = 0; i < b; ++i)); do (while :; do :; done) & hogs+=($!); done
          env "${env[@]}" build/gdpt render "scenes/$s.gltf" --method "$method" --time "$t" \
            --width "$size" --height "$size" -o "$work/out.exr" --quiet --json "$work/out.json"
          stop_hogs
          python3 - "$work/out.json" "$s" "$t" "$b" "$c" "$r" >> "$lines" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
row = {"scene": sys.argv[2], "budget_s": float(sys.argv[3]), "busy": int(sys.argv[4]),
       "cache": sys.argv[5], "repeat": int(sys.argv[6]), "spp": d["spp"]}
row.update(d["budget"])
print(json.dumps(row, sort_keys=True))
PY
          tail -n 1 "$lines"
        done
      done
    done
  done
done
python3 - "$lines" <<'PY'
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
print("busy cache budget_s renders overrun_median overrun_max fixed_exceeded")
for key in sorted({(r["busy"], r["cache"], r["budget_s"]) for r in rows}):
    sel = [r for r in rows if (r["busy"], r["cache"], r["budget_s"]) == key]
    over = [r["overrun"] for r in sel]
    print(f"{key[0]:4d} {key[1]:>5} {key[2]:8g} {len(sel):7d} {statistics.median(over):+14.3f} "
          f"{max(over):+11.3f} {sum(r['fixed_exceeded'] for r in sel):14d}")
PY
