#!/usr/bin/env bash
# Metropolis light transport against PT and G-PT at equal time (docs/mlt.md), in one command:
#   1. the door scene (scenes/indirect_gap.gltf, lit only through a gap) at 256², against a PT
#      reference of REFSPP samples per pixel (rendered once into OUT/, seed 99, in --reference-shards
#      parts that are kept as they finish, so an interrupted run resumes where it stopped, then
#      merged (docs/distributed.md); or given with --reference, then of --reference-spp samples);
#      its noise floor is printed (about 0.065 in relMSE at the default 65,536 spp, 0.26 at 16,384);
#   2. the Cornell box of ../shared/scenes/cbox against its independent reference;
#   3. the throughput: mutations per second of gmlt and pssmlt against camera samples per
#      second of G-PT and PT (the same scene and size, --json samples_per_s, 3 interleaved rounds,
#      medians).
# Each converge run writes OUT/<scene>/results.{json,csv} and error_vs_time.png; the tables go
# to stdout. Not a test: about 30 minutes on 2 cores with the defaults, plus the reference
# (about an hour at 65,536 spp, once).
#
#   scripts/bench-mlt.sh [-o OUT] [--times 16,64] [--repeats 2] [--reference-spp 65536]
#                        [--reference-shards 8] [--methods pt,gpt,pssmlt,gmlt] [--reference DOOR_REF.exr]
set -euo pipefail
cd "$(dirname "$0")/.."
out=bench-mlt times=16,64 repeats=2 refspp=65536 shards=8 methods=pt,gpt,pssmlt,gmlt doorref=
while (($#)); do
  case "$1" in
    -o) out=$2; shift 2 ;;
    --times) times=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    --reference-spp) refspp=$2; shift 2 ;;
    --reference-shards) shards=$2; shift 2 ;;
    --methods) methods=$2; shift 2 ;;
    --reference) doorref=$2; shift 2 ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "bench-mlt.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[ -x build/gdpt ] || { echo "bench-mlt.sh: build/gdpt missing; run scripts/build.sh first" >&2; exit 1; }
mkdir -p "$out"
door=scenes/indirect_gap.gltf
if [ -z "$doorref" ]; then
  doorref=$out/indirect_gap_pt_${refspp}spp.exr
  if [ ! -f "$doorref" ]; then
    parts=()
    for ((i = 0; i < shards; i++)); do
      part=$out/indirect_gap_pt_${refspp}spp_part_${i}of${shards}.exr
      [ -f "$part" ] || build/gdpt render "$door" --method pt --spp "$refspp" --seed 99 --shard "$i/$shards" -o "$part"
      parts+=("$part")
    done
    build/gdpt merge "${parts[@]}" -o "$doorref"
  fi
fi
common=(--methods "$methods" --times "$times" --repeats "$repeats")
build/gdpt converge "$door" --reference "$doorref" "${common[@]}" -o "$out/indirect_gap"
if [ -f ../shared/scenes/cbox/cbox.gltf ]; then
  build/gdpt converge ../shared/scenes/cbox/cbox.gltf --reference ../shared/scenes/cbox/reference.exr \
    --methods "$methods" --times "${times%%,*}" --repeats "$repeats" -o "$out/cbox"
fi
for s in indirect_gap cbox; do
  [ -f "$out/$s/results.json" ] || continue
  echo "== $s (relMSE medians; gain = PT's relMSE / the method's)"
  python3 - "$out/$s/results.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
rows = d["summary"]
methods = list(dict.fromkeys(r["method"] for r in rows))
budgets = sorted({r["budget_s"] for r in rows})
print("budget_s " + " ".join(f"{m:>10}" for m in methods) + "".join(f" {m + ' gain':>12}" for m in methods if m != "pt"))
for b in budgets:
    cells = {r["method"]: r["relmse_median"] for r in rows if r["budget_s"] == b}
    gains = [cells["pt"] / cells[m] if cells.get("pt") and cells.get(m) else float("nan") for m in methods if m != "pt"]
    print(f"{b:8g} " + " ".join(f"{cells.get(m, float('nan')):10.4g}" for m in methods) + "".join(f" {g:11.2f}x" for g in gains))
PY
done
echo "== throughput on $door at 256x256 (medians of 3 rounds; samples_per_s: camera samples or mutations)"
for round in 1 2 3; do
  for m in pt gpt pssmlt gmlt; do
    build/gdpt render "$door" --method "$m" --spp 16 --quiet -o "$out/throughput_$m.exr" --json - |
      python3 -c "import json,sys; j=json.load(sys.stdin); print('$m', j['samples_per_s'], j['time_s']['sampling'])"
  done
done | python3 -c "
import sys, statistics
rows = {}
for line in sys.stdin:
    m, rate, t = line.split(); rows.setdefault(m, []).append(float(rate))
med = {m: statistics.median(v) for m, v in rows.items()}
for m, v in med.items():
    print(f'{m:8s} {v:12.0f} per s   {v / med[\"gpt\"]:.2f}x G-PT')
"
# The reference's own noise, from PT's error at the largest budget: PT's relMSE falls as 1/spp,
# so a PT reference of REFSPP samples sits about relMSE · spp / REFSPP from the truth, and every
# relMSE against it carries that much on top.
python3 - "$out/indirect_gap/results.json" "$refspp" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
pt = [r for r in d["summary"] if r["method"] == "pt"]
if pt:
    last = max(pt, key=lambda r: r["budget_s"])
    floor = last["relmse_median"] * last["spp_median"] / float(sys.argv[2])
    print(f"door reference ({sys.argv[2]} spp): noise floor about {floor:.3g} in relMSE")
PY
