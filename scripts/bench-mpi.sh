#!/usr/bin/env bash
# What splitting a render across MPI ranks costs on this machine (docs/distributed.md): one
# process against `mpirun -n RANKS` at equal spp, for PT and G-PT, with each rank using every
# core (lavapipe's default) and pinned to cores/RANKS threads (LP_NUM_THREADS); A/B runs
# interleaved, medians of the whole command's wall time (mpirun's start-up included) and of
# gdpt's own sampling and merge times. Prints one JSON object per configuration. Not a test.
#
#   scripts/bench-mpi.sh [--scene S] [--size 256] [--spp-pt 256] [--spp-gpt 64] [--ranks 2]
#                        [--repeats 3]
set -euo pipefail
cd "$(dirname "$0")/.."
scene=scenes/cornell_box.gltf size=256 spppt=256 sppgpt=64 ranks=2 repeats=3
while (($#)); do
  case "$1" in
    --scene) scene=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --spp-pt) spppt=$2; shift 2 ;;
    --spp-gpt) sppgpt=$2; shift 2 ;;
    --ranks) ranks=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "bench-mpi.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[ -x build/gdpt ] || { echo "bench-mpi.sh: build/gdpt missing; run scripts/build.sh first" >&2; exit 1; }
command -v mpirun > /dev/null || { echo "bench-mpi.sh: no mpirun (scripts/install-deps.sh installs Open MPI)" >&2; exit 1; }
# Open MPI refuses root without these, and more ranks than cores without oversubscription.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
cores=$(nproc)
pinned=$(( cores / ranks > 0 ? cores / ranks : 1 ))
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# run NAME CMD...: appends "wall sampling merge spp" of one run to $tmp/NAME.
run() {
  local name=$1; shift
  local start end
  start=$(date +%s.%N)
  "$@" -o "$tmp/out.exr" --json "$tmp/out.json" --quiet
  end=$(date +%s.%N)
  python3 - "$tmp/out.json" "$start" "$end" >> "$tmp/$name" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
merge = j.get("distributed", {}).get("merge_s", 0.0)
print(float(sys.argv[3]) - float(sys.argv[2]), j["time_s"]["sampling"], merge, j["spp"])
PY
}

for method in pt gpt; do
  spp=$spppt; [ "$method" = gpt ] && spp=$sppgpt
  args=(render "$scene" --method "$method" --width "$size" --height "$size" --spp "$spp" --seed 1)
  for ((r = 0; r < repeats; ++r)); do
    run "$method.one" build/gdpt "${args[@]}"
    run "$method.mpi" mpirun -n "$ranks" build/gdpt "${args[@]}"
    run "$method.pinned" mpirun -n "$ranks" -x LP_NUM_THREADS="$pinned" build/gdpt "${args[@]}"
  done
  python3 - "$tmp" "$method" "$size" "$spp" "$ranks" "$pinned" "$cores" <<'PY'
import json, statistics, sys
tmp, method, size, spp, ranks, pinned, cores = sys.argv[1:]
def med(name, col):
    rows = [list(map(float, l.split())) for l in open(f"{tmp}/{method}.{name}")]
    return statistics.median(r[col] for r in rows)
one = med("one", 0)
out = {"method": method, "size": int(size), "spp": int(spp), "ranks": int(ranks), "cores": int(cores),
       "one_process_wall_s": one, "one_process_sampling_s": med("one", 1)}
for name, threads in (("mpi", "all cores per rank"), ("pinned", f"LP_NUM_THREADS={pinned} per rank")):
    out[name] = {"threads": threads, "wall_s": med(name, 0), "sampling_s": med(name, 1),
                 "merge_s": med(name, 2), "wall_over_one_process": med(name, 0) / one}
print(json.dumps(out))
PY
done
