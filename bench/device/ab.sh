#!/usr/bin/env bash
# A/B of kernel builds on the device: the same volpt binary runs each PTX in bundle/ab/*.ptx
# (through VOLPT_PTX) on the same scenes, one after the other in one session.
#   bash bundle/ab.sh   -> $OUT/ab.txt (one line per ptx x scene x strategy) and ptxas reports
# The PTX files may hold only the kernels the scenes use (bench/ab/merge-regression.sh cuts them
# down), which keeps the bundle small and ptxas fast; ptxas runs beside the benchmarks.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
SPP=${SPP:-100}
TRIALS=${TRIALS:-3}
STRATEGIES=${STRATEGIES:-regeneration-sk}
T=${T:-60}
ARCH=sm_$(nvidia-smi --query-gpu=compute_cap --format=csv,noheader | head -n 1 | tr -d '.')
"$VOLPT" scene generate scenes >/dev/null
for ptx in ab/*.ptx; do
    ptxas -arch="$ARCH" -v "$ptx" -o /dev/null >"$OUT/ptxas-$(basename "$ptx" .ptx).txt" 2>&1 &
done
SCENES=(
    "homogeneous-cube-null:scenes/homogeneous-cube/scene.xml:-Dboundary=null"
    "homogeneous-cube:scenes/homogeneous-cube/scene.xml:"
    "cgg-logo:scenes/cgg-logo/scene.xml:"
    "smoke:scenes/smoke/scene.xml:-Ddata=$PWD/data"
    "bucky:scenes/bucky/scene.toml:-Ddata=$PWD/data"
)
{
    echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader) spp=$SPP (bucky 3x) trials=$TRIALS"
    for entry in "${SCENES[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        spp=$SPP
        [ "$name" = bucky ] && spp=$((3 * SPP))
        for ptx in ab/*.ptx; do
            for s in $STRATEGIES; do
                # shellcheck disable=SC2086
                VOLPT_PTX=$ptx timeout "$T" "$VOLPT" bench "$file" $params --spp "$spp" --backend cuda --strategy "$s" \
                    --trials "$TRIALS" --json >"$OUT/tmp.json" 2>"$OUT/tmp.log" || { echo "FAIL $ptx $name $s"; continue; }
                python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(f\"{sys.argv[2]:<24} {sys.argv[3]:<22} {sys.argv[4]:<16} {r['time_median_s']*1e3:9.2f} ms +- {r['time_std_s']*1e3:6.2f}  {r['segments_per_s']/1e9:7.3f} G seg/s  {r['tracking_steps']/r['paths']:7.1f} steps/path\")" \
                    "$OUT/tmp.json" "$(basename "$ptx" .ptx)" "$name" "$s"
            done
        done
    done
} | tee "$OUT/ab.txt"
wait
rm -f "$OUT/tmp.json" "$OUT/tmp.log"
