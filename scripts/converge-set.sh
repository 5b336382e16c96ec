#!/usr/bin/env bash
# Error against time for the whole benchmark scene set, in one command: runs `gdpt converge`
# on the Cornell box of ../shared/scenes/cbox (a glTF scene outside the repository with
# reference.exr, a converged render by an independent path tracer) and on each
# scene of scenes/ (against a PT reference made and cached with --make-reference), each into
# OUT/<scene>/ (results.json, results.csv, error_vs_time.png), then prints every scene's
# equal-time table with each method's gain over PT and bias. Not a test: a long benchmark (hours with
# the defaults on 2 cores).
#
# Scene `engine_sky` (skipped when the file is missing): a real asset, the Khronos sample model
# 2CylinderEngine (110,342 triangles, no lights) from Debian's assimp-testmodels
# (scripts/install-deps.sh installs it), under a constant sky of radiance 1 (`--env 1,1,1`).
#
#   scripts/converge-set.sh [-o OUT] [--times 4,8,16,32] [--repeats 3] [--reference-spp 4096]
#                           [--methods pt,gpt-wl1,gpt-l1,gpt-l2] [--size 256] [--scenes a,b,...]
set -euo pipefail
cd "$(dirname "$0")/.."
out=converge-set times=4,8,16,32 repeats=3 refspp=4096 methods=pt,gpt-wl1,gpt-l1,gpt-l2 size=256
scenes=cbox,cornell_box,glossy_cornell,small_light,indirect_gap,textured,furnace,open_scene,engine_sky
while (($#)); do
  case "$1" in
    -o) out=$2; shift 2 ;;
    --times) times=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    --reference-spp) refspp=$2; shift 2 ;;
    --methods) methods=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "converge-set.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[ -x build/gdpt ] || { echo "converge-set.sh: build/gdpt missing; run scripts/build.sh first" >&2; exit 1; }
common=(--methods "$methods" --times "$times" --repeats "$repeats" --width "$size" --height "$size")
IFS=, read -ra list <<< "$scenes"
for s in "${list[@]}"; do
  if [ "$s" = cbox ]; then
    ref=../shared/scenes/cbox/reference.exr
    [ "$size" = 256 ] || { echo "converge-set.sh: cbox's reference is 256x256; skipping it at --size $size" >&2; continue; }
    build/gdpt converge ../shared/scenes/cbox/cbox.gltf --reference "$ref" "${common[@]}" -o "$out/$s"
  elif [ "$s" = engine_sky ]; then
    engine=/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb
    [ -f "$engine" ] || { echo "converge-set.sh: $engine missing (apt-get install assimp-testmodels); skipping engine_sky" >&2; continue; }
    build/gdpt converge "$engine" --env 1,1,1 --make-reference "$refspp" "${common[@]}" -o "$out/$s"
  else
    build/gdpt converge "scenes/$s.gltf" --make-reference "$refspp" "${common[@]}" -o "$out/$s"
  fi
done
for s in "${list[@]}"; do
  [ -f "$out/$s/results.json" ] || continue
  echo "== $s"
  python3 - "$out/$s/results.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
rows = d["summary"]
methods = list(dict.fromkeys(r["method"] for r in rows))
budgets = sorted({r["budget_s"] for r in rows})
# relMSE medians per method, each other method's gain over PT (PT's error / its error), and
# each method's bias (median over repeats of the image mean minus the reference's).
others = [m for m in methods if m != "pt"] if "pt" in methods else []
print("budget_s " + " ".join(f"{m:>12}" for m in methods) + "".join(f" {m + ' gain':>12}" for m in others)
      + "".join(f" {m + ' bias':>12}" for m in methods))
for b in budgets:
    cells = {r["method"]: r for r in rows if r["budget_s"] == b}
    rel = {m: cells[m]["relmse_median"] for m in cells}
    gains = [rel.get("pt", float("nan")) / rel[m] if rel.get(m) else float("nan") for m in others]
    print(f"{b:8g} " + " ".join(f"{rel.get(m, float('nan')):12.5g}" for m in methods)
          + "".join(f" {g:11.2f}x" for g in gains)
          + "".join(f" {cells[m]['bias_median']:12.3g}" if m in cells else " " * 13 for m in methods))
PY
done
