#!/usr/bin/env bash
# Achieved occupancy and warp execution efficiency of every strategy (issue: ncu for the best
# strategies), from Nsight Compute with unlocked clocks, one render (warm-up excluded: the last
# launch of `volpt bench --trials 1` is profiled). From the bundle, on the device:
#   bash bundle/occupancy.sh   -> $OUT/occupancy.txt
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
SPP=${SPP:-100}
MATH=${MATH:-fast}
STRATEGIES=${STRATEGIES:-regeneration-sk regeneration-block-sk streaming-sk}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/occupancy.XXXXXX")
"$VOLPT" scene generate scenes >/dev/null
SCENES=(
    "homogeneous-cube-null:scenes/homogeneous-cube/scene.xml:-Dboundary=null"
    "cgg-logo:scenes/cgg-logo/scene.xml:"
    "smoke:scenes/smoke/scene.xml:-Ddata=$PWD/data"
    "bucky:scenes/bucky/scene.toml:-Ddata=$PWD/data"
)
METRICS=gpu__time_duration.sum,launch__registers_per_thread,sm__maximum_warps_per_active_cycle_pct,sm__warps_active.avg.pct_of_peak_sustained_active,smsp__thread_inst_executed_per_inst_executed.ratio,sm__inst_issued.avg.pct_of_peak_sustained_active
{
    echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader) spp=$SPP (bucky 3x) math=$MATH; kernel time summed over the render's launches, the rest the launch-weighted mean"
    printf "%-22s %-22s %9s %5s %11s %10s %12s %10s\n" scene strategy "ms" regs "theor. occ" "achieved" "warp eff." "issue busy"
    for entry in "${SCENES[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        spp=$SPP
        [ "$name" = bucky ] && spp=$((3 * SPP))
        for s in $STRATEGIES; do
            # shellcheck disable=SC2086
            timeout 120 ncu --clock-control none --metrics "$METRICS" --csv \
                "$VOLPT" render "$file" $params --spp "$spp" --backend cuda --strategy "$s" --math "$MATH" \
                -o "$WORK/i.exr" >"$WORK/r.csv" 2>"$WORK/r.err" || { echo "FAIL $name $s"; continue; }
            python3 - "$WORK/r.csv" "$name" "$s" <<'PY'
import csv, sys
rows = [r for r in csv.reader(open(sys.argv[1], errors="replace")) if len(r) > 10]
head = rows[0]
i = {k: head.index(k) for k in ("ID", "Metric Name", "Metric Unit", "Metric Value")}
launches = {}
for r in rows[1:]:
    launches.setdefault(r[i["ID"]], {})[r[i["Metric Name"]]] = (r[i["Metric Unit"]], float(r[i["Metric Value"]].replace(",", "")))
scale = {"ns": 1e-6, "nsecond": 1e-6, "us": 1e-3, "usecond": 1e-3, "ms": 1.0, "msecond": 1.0, "s": 1e3, "second": 1e3}
ms = [scale[m["gpu__time_duration.sum"][0]] * m["gpu__time_duration.sum"][1] for m in launches.values()]
def mean(key):
    return sum(w * m[key][1] for w, m in zip(ms, launches.values())) / sum(ms)
print(f"{sys.argv[2]:<22} {sys.argv[3]:<22} {sum(ms):9.2f} {mean('launch__registers_per_thread'):5.0f} "
      f"{mean('sm__maximum_warps_per_active_cycle_pct'):10.1f}% {mean('sm__warps_active.avg.pct_of_peak_sustained_active'):9.1f}% "
      f"{100 * mean('smsp__thread_inst_executed_per_inst_executed.ratio') / 32:11.1f}% {mean('sm__inst_issued.avg.pct_of_peak_sustained_active'):9.1f}%")
PY
        done
    done
} | tee "$OUT/occupancy.txt"
