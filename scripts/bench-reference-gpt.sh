#!/usr/bin/env bash
# gdpt's default G-PT side by side with the reference G-PT implementation (Kettunen et al. 2015:
# Mitsuba 0.5's `gpt` integrator, L1 reconstruction), at equal wall time, on gdpt's scene set:
#   per scene, scripts/export-mitsuba.py writes it as a Mitsuba scene; per Mitsuba sample count
#   SPP and repeat, `mitsuba -p 2 -D integrator=gpt_L1 -D spp=SPP` is timed (process start to
#   its -final.exr), then `gdpt render --time <that wall time>` (seed = repeat) renders the same
#   scene; both images go through `gdpt diff` against the scene's reference.
# References: --reference SCENE=FILE, else OUT/<scene>/reference.exr, else a gdpt PT render of
# --reference-spp samples (seed 1001) made once into it. Scenes whose metals the export can
# only approximate (glossy_cornell) are judged against each renderer's own reference instead:
# Mitsuba's `path` at the same sample count is rendered once into OUT/<scene>/mitsuba_reference.exr.
# The furnace is judged by its image mean (exactly 1).
# Prints a table (relMSE medians over the repeats, reference / gdpt: > 1 = gdpt better, and
# each image's mean against the reference's) and writes OUT/results.csv. Not a test: the
# Mitsuba build (../shared/reference-gpt/ or any build of mmanzi/gradientdomain-mitsuba) is a
# benchmark baseline only, never a dependency.
#
#   scripts/bench-reference-gpt.sh --mitsuba DIST [-o OUT] [--scenes a,b,...] [--spp 16,32]
#        [--repeats 2] [--size 256] [--reference-spp 2048] [--reference SCENE=FILE ...]
set -euo pipefail
cd "$(dirname "$0")/.."
out=bench-reference-gpt scenes=cornell_box,small_light,indirect_gap,open_scene,furnace,glossy_cornell
spps=16,32 repeats=2 size=256 refspp=2048 dist=${MITSUBA_DIST:-}
declare -A refs=()
while (($#)); do
  case "$1" in
    -o) out=$2; shift 2 ;;
    --mitsuba) dist=$2; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
    --spp) spps=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --reference-spp) refspp=$2; shift 2 ;;
    --reference) refs[${2%%=*}]=${2#*=}; shift 2 ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "bench-reference-gpt.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[ -x build/gdpt ] || { echo "bench-reference-gpt.sh: build/gdpt missing; run scripts/build.sh first" >&2; exit 1; }
[ -n "$dist" ] && [ -x "$dist/mitsuba" ] ||
  { echo "bench-reference-gpt.sh: no Mitsuba build; pass --mitsuba DIST (the folder with mitsuba, plugins/)" >&2; exit 2; }
dist=$(cd "$dist" && pwd)
export LD_LIBRARY_PATH="$dist${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
mkdir -p "$out"
out=$(cd "$out" && pwd)
# Mitsuba writes its log (mitsuba.HOST.log) into the working directory: run it in OUT.
mitsuba() { (cd "$out" && "$dist/mitsuba" "$@"); }
csv=$out/results.csv
echo "scene,mitsuba_spp,repeat,wall_s,renderer,spp,relmse,mean,reference_mean" > "$csv"

# diff TEST REF -> "relmse mean reference_mean" (means of the three channels)
diffline() {
  build/gdpt diff "$1" "$2" --json - | python3 -c "
import json, sys
d = json.load(sys.stdin)
print(d['relmse'], sum(d['mean_test']) / 3, sum(d['mean_reference']) / 3)"
}

IFS=, read -r -a scene_list <<< "$scenes"
IFS=, read -r -a spp_list <<< "$spps"
for s in "${scene_list[@]}"; do
  gltf=scenes/$s.gltf
  [ -f "$gltf" ] || { echo "bench-reference-gpt.sh: no scene $gltf" >&2; exit 2; }
  dir=$out/$s
  mkdir -p "$dir"
  export_note=$(scripts/export-mitsuba.py "$gltf" "$dir/mitsuba")
  echo "$export_note"
  own=0
  [[ $export_note == *approximate* ]] && own=1
  ref=${refs[$s]:-$dir/reference.exr}
  if [ ! -f "$ref" ]; then
    echo "== $s: gdpt PT reference, $refspp spp"
    build/gdpt render "$gltf" --method pt --spp "$refspp" --seed 1001 --width "$size" --height "$size" \
      --quiet -o "$ref"
  fi
  mref=$ref
  if [ "$own" = 1 ]; then
    mref=$dir/mitsuba_reference.exr
    if [ ! -f "$mref" ]; then
      echo "== $s: Mitsuba path reference, $refspp spp"
      mitsuba -q -p 2 -D integrator=path -D spp="$refspp" -D width="$size" -D height="$size" \
        -o "$mref" "$dir/mitsuba/scene.xml" > "$dir/mitsuba_reference.log"
    fi
  fi
  for spp in "${spp_list[@]}"; do
    for ((r = 1; r <= repeats; ++r)); do
      base=$dir/mitsuba_${spp}_$r
      t0=$(date +%s.%N)
      mitsuba -q -p 2 -D integrator=gpt_L1 -D spp="$spp" -D width="$size" -D height="$size" \
        -o "$base" "$dir/mitsuba/scene.xml" > "$base.log"
      wall=$(python3 -c "print(round($(date +%s.%N) - $t0, 3))")
      echo "$s,$spp,$r,$wall,mitsuba,$spp,$(diffline "$base-final.exr" "$mref" | tr ' ' ',')" >> "$csv"
      g=$dir/gdpt_${spp}_$r.exr
      build/gdpt render "$gltf" --time "$wall" --seed "$r" --width "$size" --height "$size" --quiet \
        -o "$g" --json "$g.json"
      gspp=$(python3 -c "import json; print(json.load(open('$g.json'))['spp'])")
      echo "$s,$spp,$r,$wall,gdpt,$gspp,$(diffline "$g" "$ref" | tr ' ' ',')" >> "$csv"
      echo "   $s mitsuba $spp spp in ${wall}s; gdpt $gspp spp"
    done
  done
done

python3 - "$csv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("\n| scene | Mitsuba spp | wall s | Mitsuba G-PT relMSE | gdpt G-PT relMSE (spp) | Mitsuba / gdpt | Mitsuba mean | gdpt mean | reference mean |")
print("|---|---|---|---|---|---|---|---|---|")
keys = list(dict.fromkeys((r["scene"], r["mitsuba_spp"]) for r in rows))
for scene, spp in keys:
    sel = [r for r in rows if r["scene"] == scene and r["mitsuba_spp"] == spp]
    med = lambda who, f: statistics.median(float(r[f]) for r in sel if r["renderer"] == who)
    wall = statistics.median(float(r["wall_s"]) for r in sel if r["renderer"] == "mitsuba")
    gspp = statistics.median(float(r["spp"]) for r in sel if r["renderer"] == "gdpt")
    m, g = med("mitsuba", "relmse"), med("gdpt", "relmse")
    ref = med("gdpt", "reference_mean")
    if scene == "furnace":  # judged by its mean, exactly 1
        print(f"| {scene} | {spp} | {wall:.2f} | – | – ({gspp:.0f}) | – | {med('mitsuba', 'mean'):.4f} | {med('gdpt', 'mean'):.4f} | 1 (exact) |")
        continue
    print(f"| {scene} | {spp} | {wall:.2f} | {m:.4g} | {g:.4g} ({gspp:.0f}) | {m / g:.2f} | "
          f"{med('mitsuba', 'mean'):.4f} | {med('gdpt', 'mean'):.4f} | {ref:.4f} |")
PY
