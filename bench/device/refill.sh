#!/usr/bin/env bash
# regeneration-sk's refill threshold (`--refill-at N`: a warp's idle lanes take new paths once N of
# them are idle) against time, on volpt's scenes and the thesis's cgg_logo with its roulette.
#   bash bundle/refill.sh   -> $OUT/refill.txt
# Knobs: VALUES (1 4 8 16 24 32), SPP (100; bucky 3x), TRIALS (3), MATH (fast).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
VALUES=${VALUES:-1 4 8 16 24 32}
SPP=${SPP:-100}
TRIALS=${TRIALS:-3}
MATH=${MATH:-fast}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/refill.XXXXXX")
"$VOLPT" scene generate scenes >/dev/null
SCENES=(
    "homogeneous-cube-null:scenes/homogeneous-cube/scene.xml:-Dboundary=null"
    "homogeneous-cube:scenes/homogeneous-cube/scene.xml:"
    "cgg-logo:scenes/cgg-logo/scene.xml:"
    "smoke:scenes/smoke/scene.xml:-Ddata=$PWD/data"
    "bucky:scenes/bucky/scene.toml:-Ddata=$PWD/data"
)
if [ -f thesis/gen_scenes.py ] && python3 thesis/gen_scenes.py "$WORK/scenes" >/dev/null 2>&1; then
    SCENES+=("thesis-cgg-rr:$WORK/scenes/cgg_logo/volpath_bsdf.xml:--roulette throughput --rr-depth 0")
fi
{
    echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader) regeneration-sk spp=$SPP (bucky 3x) trials=$TRIALS math=$MATH; medians"
    for entry in "${SCENES[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        spp=$SPP
        [ "$name" = bucky ] && spp=$((3 * SPP))
        for n in $VALUES; do
            # shellcheck disable=SC2086
            timeout 60 "$VOLPT" bench "$file" $params --spp "$spp" --backend cuda --strategy regeneration-sk \
                --refill-at "$n" --math "$MATH" --trials "$TRIALS" --json >"$WORK/r.json" 2>"$WORK/r.log" \
                || { echo "FAIL $name refill-at $n: $(tail -n 2 "$WORK/r.log" | tr '\n' ' ')"; continue; }
            python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(f\"{sys.argv[2]:<22} refill-at {sys.argv[3]:>2} {r['time_median_s']*1e3:9.2f} ms  {r['segments_per_s']/1e9:7.3f} G seg/s  {r['paths_per_s']/1e6:8.2f} M paths/s\")" \
                "$WORK/r.json" "$name" "$n"
        done
    done
} | tee "$OUT/refill.txt"
# The same paths as the CPU with any threshold: exact math, 4 spp, within 1e-6 (the film's sums
# are added in another order).
for entry in "${SCENES[@]:0:3}"; do
    IFS=: read -r name file params <<<"$entry"
    # shellcheck disable=SC2086
    "$VOLPT" render "$file" $params --spp 4 --seed 7 -o "$WORK/$name-cpu.exr" >/dev/null 2>&1
    for n in 8 32; do
        # shellcheck disable=SC2086
        timeout 60 "$VOLPT" render "$file" $params --spp 4 --seed 7 --backend cuda --math exact --strategy regeneration-sk \
            --refill-at "$n" -o "$WORK/$name-$n.exr" >/dev/null 2>&1 \
            && "$VOLPT" compare "$WORK/$name-cpu.exr" "$WORK/$name-$n.exr" --max-relative 1e-6 >"$WORK/c.txt" 2>&1 \
            && echo "PASS $name refill-at $n: the CPU's image within 1e-6" \
            || echo "FAIL $name refill-at $n: $(tail -n 2 "$WORK/c.txt" 2>/dev/null | tr '\n' ' ')"
    done
done | tee -a "$OUT/refill.txt"
