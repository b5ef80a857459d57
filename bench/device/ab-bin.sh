#!/usr/bin/env bash
# A/B of two volpt binaries on the device (a host-side change, same kernels), side by side in one
# session: each scene x strategy renders with BEFORE, then AFTER, then BEFORE and AFTER again.
#   bash bundle/ab-bin.sh   -> $OUT/ab-bin.txt (one line per binary x scene x strategy x round)
# BEFORE (bin/volpt-before) and AFTER (bin/volpt) may be gzipped (.gz beside them is unpacked).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
BEFORE=${BEFORE:-$PWD/bin/volpt-before}
AFTER=${AFTER:-$PWD/bin/volpt}
for b in "$BEFORE" "$AFTER"; do
    [ -f "$b.gz" ] && gunzip -f "$b.gz"
    chmod +x "$b"
done
SPP=${SPP:-100}
TRIALS=${TRIALS:-3}
STRATEGIES=${STRATEGIES:-regeneration-sk regeneration-block-sk}  # "defaults": no --strategy, no --math
MATH=${MATH:-fast}
T=${T:-60}
"$AFTER" scene generate scenes >/dev/null
# A strategy's flags; "defaults" is no flag but --backend cuda (the schedule and math volpt picks).
flags() { [ "$1" = defaults ] || echo "--strategy $1 --math $MATH"; }
SCENES=(
    "homogeneous-cube-null:scenes/homogeneous-cube/scene.xml:-Dboundary=null"
    "homogeneous-cube:scenes/homogeneous-cube/scene.xml:"
    "cgg-logo:scenes/cgg-logo/scene.xml:"
    "smoke:scenes/smoke/scene.xml:-Ddata=$PWD/data"
    "bucky:scenes/bucky/scene.toml:-Ddata=$PWD/data"
)
{
    echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader) spp=$SPP (bucky 3x) trials=$TRIALS math=$MATH; medians"
    for entry in "${SCENES[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        spp=$SPP
        [ "$name" = bucky ] && spp=$((3 * SPP))
        for s in $STRATEGIES; do
            for round in 1 2; do
                for bin in "$BEFORE" "$AFTER"; do
                    # shellcheck disable=SC2086
                    timeout "$T" "$bin" bench "$file" $params --spp "$spp" --backend cuda $(flags "$s") --trials "$TRIALS" --json >"$OUT/tmp.json" 2>"$OUT/tmp.log" \
                        || { echo "FAIL $(basename "$bin") $name $s"; continue; }
                    python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(f\"{sys.argv[2]:<14} {sys.argv[3]:<22} {sys.argv[4]:<22} round {sys.argv[5]} {r['time_median_s']*1e3:9.2f} ms  {r['segments_per_s']/1e9:7.3f} G seg/s  {r['paths_per_s']/1e6:8.2f} M paths/s\")" \
                        "$OUT/tmp.json" "$(basename "$bin")" "$name" "$s" "$round"
                done
            done
        done
    done
} | tee "$OUT/ab-bin.txt"
rm -f "$OUT/tmp.json" "$OUT/tmp.log"
