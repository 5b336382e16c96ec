#!/usr/bin/env bash
# Animations at equal time: PT, per-frame G-PT and temporal G-PT (docs/animation.md; `tgpt` with
# its default motion shift, `tgpt-replay` and `tgpt-reconnect` with --temporal-shift replay and
# reconnect) render the same frames
# of each animated scene with the same --time for the whole sequence (`tgpt-gammaG` and
# `tgpt-betaB`, `tgpt-reconR`: tgpt with --gamma G, --beta B or --recon R), and each sequence is
# compared with a PT reference sequence of REFSPP samples per pixel by `gdpt diff-sequence`:
# the mean per-frame relMSE and the mean temporal relMSE (the error of the frame-to-frame
# change: flicker), at the same pixel and along the motion (each pixel paired with the pixel of
# the frame before its content came from, by the motion layer of a tgpt render, `--motion`).
# The reference is rendered twice (seeds 1001, 2002) and the two are compared with each other:
# their relMSE is twice the reference's noise floor.
# Writes OUT/<scene>/<method>/f_*.exr (+ .json summaries, .diff.json metrics), OUT/results.csv,
# OUT/results.json and OUT/temporal.png (gnuplot); the table goes to stdout. Not a test: about
# 15 minutes on 2 cores with the defaults.
#
#   scripts/bench-temporal.sh [-o OUT] [--scenes moving_box,camera_move] [--frames 0:15]
#                             [--size 96] [--seconds-per-frame 1] [--reference-spp 1024]
#                             [--methods pt,gpt,tgpt,tgpt-replay] [--repeats 1] [--fps 24]
set -euo pipefail
cd "$(dirname "$0")/.."
out=bench-temporal scenes=moving_box,camera_move frames=0:15 size=96 perframe=1 refspp=1024
methods=pt,gpt,tgpt,tgpt-replay repeats=1 fps=24
while (($#)); do
  case "$1" in
    -o) out=$2; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --seconds-per-frame) perframe=$2; shift 2 ;;
    --reference-spp) refspp=$2; shift 2 ;;
    --methods) methods=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    --fps) fps=$2; shift 2 ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    *) echo "bench-temporal.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[ -x build/gdpt ] || { echo "bench-temporal.sh: build/gdpt missing; run scripts/build.sh first" >&2; exit 1; }
first=${frames%%:*} last=${frames##*:}
count=$((last - first + 1))
budget=$(python3 -c "print($perframe * $count)")
mkdir -p "$out"
common=(--frames "$frames" --fps "$fps" --width "$size" --height "$size" --no-video --quiet)
rows=()
for scene in ${scenes//,/ }; do
  file=scenes/$scene.gltf
  dir=$out/$scene
  for seed in 1001 2002; do
    ref=$dir/reference_$seed
    [ -f "$ref/f_$(printf %04d "$last").exr" ] ||
      build/gdpt render "$file" --method pt --spp "$refspp" --seed "$seed" -o "$ref/f_%04d.exr" "${common[@]}"
  done
  # The motion layer of a tgpt render of this sequence (the same for every seed) pairs each pixel
  # with its source in the frame before: the temporal error along the motion as well.
  motion=()
  if [[ ",$methods," == *,tgpt,* ]]; then
    motion=(--motion "$dir/motion/f_%04d.exr")
    [ -f "$dir/motion/f_$(printf %04d "$last").exr" ] ||
      build/gdpt render "$file" --method tgpt --spp 2 -o "$dir/motion/f_%04d.exr" "${common[@]}"
  fi
  build/gdpt diff-sequence "$dir/reference_2002/f_%04d.exr" "$dir/reference_1001/f_%04d.exr" --frames "$frames" \
    --json "$dir/reference.diff.json" "${motion[@]}" > /dev/null
  for ((r = 1; r <= repeats; r++)); do
    for m in ${methods//,/ }; do  # interleaved: one sequence of each method per round
      run=$dir/${m}_$r
      method=(--method "$m")
      case "$m" in
        tgpt-replay) method=(--method tgpt --temporal-shift replay) ;;
        tgpt-reconnect) method=(--method tgpt --temporal-shift reconnect) ;;
        tgpt-gamma*) method=(--method tgpt --gamma "${m#tgpt-gamma}") ;;  # e.g. tgpt-gamma1
        tgpt-beta*) method=(--method tgpt --beta "${m#tgpt-beta}") ;;
        tgpt-recon*) method=(--method tgpt --recon "${m#tgpt-recon}") ;;  # e.g. tgpt-reconwl1
      esac
      build/gdpt render "$file" "${method[@]}" --time "$budget" --seed "$((r * 7))" -o "$run/f_%04d.exr" \
        --json "$run.json" "${common[@]}"
      build/gdpt diff-sequence "$run/f_%04d.exr" "$dir/reference_1001/f_%04d.exr" --frames "$frames" \
        --json "$run.diff.json" "${motion[@]}" > /dev/null
      rows+=("$scene,$m,$r,$run")
    done
  done
done
python3 - "$out" "$budget" "${rows[@]}" <<'PY'
import json, statistics, sys
out, budget, rows = sys.argv[1], float(sys.argv[2]), sys.argv[3:]
results = []
for row in rows:
    scene, method, rep, run = row.split(",")
    d = json.load(open(run + ".diff.json"))
    s = json.load(open(run + ".json"))
    spp = statistics.mean(f["spp"] for f in s["frame_summaries"])
    results.append({"scene": scene, "method": method, "repeat": int(rep), "budget_s": budget,
                    "time_s": s["time_s"], "spp_per_frame": spp, "relmse": d["mean_relmse"],
                    "temporal_relmse": d["mean_temporal_relmse"],
                    "temporal_along_motion": d.get("mean_temporal_relmse_along_motion", float("nan")),
                    "per_frame": d["per_frame"]})
floors = {}
for scene in dict.fromkeys(r["scene"] for r in results):
    f = json.load(open(f"{out}/{scene}/reference.diff.json"))
    floors[scene] = (f["mean_relmse"] / 2, f["mean_temporal_relmse"] / 2,
                     f.get("mean_temporal_relmse_along_motion", float("nan")) / 2)
json.dump({"results": results, "reference_noise_floor": floors}, open(out + "/results.json", "w"), indent=1)
with open(out + "/results.csv", "w") as csv:
    csv.write("scene,method,repeat,budget_s,time_s,spp_per_frame,relmse,temporal_relmse,temporal_along_motion\n")
    for r in results:
        csv.write(f"{r['scene']},{r['method']},{r['repeat']},{r['budget_s']:g},{r['time_s']:.2f},"
                  f"{r['spp_per_frame']:.1f},{r['relmse']:.6g},{r['temporal_relmse']:.6g},"
                  f"{r['temporal_along_motion']:.6g}\n")
keys = ("time_s", "spp_per_frame", "relmse", "temporal_relmse", "temporal_along_motion")
print(f"{'scene':12} {'method':11} {'time s':>7} {'spp/frame':>9} {'relMSE':>10} {'temporal':>10} "
      f"{'along mot.':>10} {'relMSE÷gpt':>10} {'temp.÷gpt':>10} {'along÷gpt':>10}")
for scene in dict.fromkeys(r["scene"] for r in results):
    med = {}
    for m in dict.fromkeys(r["method"] for r in results if r["scene"] == scene):
        rs = [r for r in results if r["scene"] == scene and r["method"] == m]
        med[m] = {k: statistics.median(r[k] for r in rs) for k in keys}
    for m, v in med.items():
        g = med.get("gpt")
        ratio = lambda k: v[k] / g[k] if g else float("nan")
        print(f"{scene:12} {m:11} {v['time_s']:7.1f} {v['spp_per_frame']:9.1f} {v['relmse']:10.4g} "
              f"{v['temporal_relmse']:10.4g} {v['temporal_along_motion']:10.4g} {ratio('relmse'):10.3f} "
              f"{ratio('temporal_relmse'):10.3f} {ratio('temporal_along_motion'):10.3f}")
    fr, ft, fa = floors[scene]
    print(f"{scene:12} reference noise floor: relMSE {fr:.3g}, temporal {ft:.3g}, along the motion {fa:.3g}")
# Per-frame curves of the first repeat: relMSE and temporal relMSE against the frame.
with open(out + "/per_frame.dat", "w") as dat:
    for r in results:
        if r["repeat"] != 1:
            continue
        dat.write(f"{r['scene']}/{r['method']} relMSE temporal\n")
        for f in r["per_frame"]:
            dat.write(f"{f['frame']} {f['relmse']:.6g} {f.get('temporal_relmse', float('nan')):.6g}\n")
        dat.write("\n\n")
PY
if command -v gnuplot > /dev/null; then
  gnuplot -e "set terminal pngcairo size 1000,420 noenhanced; set output '$out/temporal.png'; \
    set multiplot layout 1,2; set logscale y; set key outside bottom center horizontal; \
    set xlabel 'frame'; set title 'relMSE per frame'; \
    plot for [i=0:*] '$out/per_frame.dat' index i using 1:2 with lines title columnheader(1); \
    set title 'temporal relMSE (change from the frame before)'; \
    plot for [i=0:*] '$out/per_frame.dat' index i using 1:3 with lines title columnheader(1); unset multiplot" \
    2> /dev/null || echo "bench-temporal.sh: gnuplot could not draw $out/temporal.png" >&2
fi
