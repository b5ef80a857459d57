#!/usr/bin/env bash
# Majorant grid and next-event estimation on the GPU (issue 10, docs/heterogeneous.md), run on the
# device machine from the bundle (`cargo xtask device-bundle`), like run.sh:
#
#   bash bundle/heterogeneous.sh        # writes under $OUT (default: ./out)
#   ROOT=. BACKEND=cpu VOLPT=$PWD/target/release/volpt DATA=../shared/data SIZE=100x100 SPP=16 \
#       bash bench/device/heterogeneous.sh   # the same on the CPU backend (docs/heterogeneous.md)
#
# 1. naive-sk vs CPU bit-identity (4 spp, 64x64) for the grid and the nee variants, and for today's
#    algorithm (--tracking global --estimator pt);
# 2. `volpt bench --json` (regeneration-sk) at 400x400, 100 spp (bucky 300): smoke, bucky, ad and
#    cgg-logo with global majorant vs majorant grids of 8, 16, 32, 64 cells (path tracing), pt vs
#    nee with a grid of 32, the factory's default majorants (global or a grid, by the rule that
#    `volpt info` prints), and pt vs nee on envmap-cube with an index-matched boundary;
#    summary.csv has time, tracking steps and segments per path. Efficiency (1 / (MSE x time)) of
#    nee vs pt: `volpt converge --backend cuda --setting estimator=pt,nee` (docs/heterogeneous.md).
set -uo pipefail
cd "${ROOT:-$(dirname "$0")}"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=${VOLPT:-$PWD/bin/volpt}
DATA=${DATA:-$PWD/data}
TRIALS=${TRIALS:-3}
BACKEND=${BACKEND:-cuda}
RESOLUTIONS=${RESOLUTIONS:-8 16 32 64}
SIZE=${SIZE:-400x400}
SPP=${SPP:-100}          # bucky renders 3x this
failures=0
log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
if [ "$BACKEND" = cuda ]; then
    GPU=(--backend cuda --math exact)
    BENCH=(--backend cuda --strategy regeneration-sk)
else
    GPU=()
    BENCH=()
fi

log "date $(date -u +%Y-%m-%dT%H:%MZ) backend $BACKEND"
"$VOLPT" scene generate scenes >"$OUT/generate.log" 2>&1 || { log "FAIL generate"; failures=$((failures + 1)); }

# name : scene file : extra parameters
SCENES=(
    "smoke:scenes/smoke/scene.xml:-Ddata=$DATA"
    "bucky:scenes/bucky/scene.toml:-Ddata=$DATA"
    "ad:scenes/ad/scene.xml:"
    "cgg-logo:scenes/cgg-logo/scene.xml:"
)
# The variants of the identity check: name : flags
VARIANTS=(
    "global-pt:--tracking global --estimator pt"
    "grid-pt:--tracking grid --estimator pt"
    "grid-nee:--tracking grid --estimator nee"
    "global-nee:--tracking global --estimator nee"
)

for entry in "${SCENES[@]}" "envmap-cube:scenes/envmap-cube/index-matched.xml:"; do
    IFS=: read -r name file params <<<"$entry"
    [ -f "$file" ] || { log "SKIP $name: $file not in this bundle"; continue; }
    for v in "${VARIANTS[@]}"; do
        IFS=: read -r vname flags <<<"$v"
        base="$OUT/id-$name-$vname"
        # shellcheck disable=SC2086
        "$VOLPT" render "$file" $params $flags --resolution 64x64 --spp 4 --seed 7 -o "$base-cpu.exr" >"$base-cpu.log" 2>&1 \
            || { log "FAIL identity $name $vname: cpu render"; failures=$((failures + 1)); continue; }
        if [ "$BACKEND" = cuda ]; then
            # shellcheck disable=SC2086
            "$VOLPT" render "$file" $params $flags --resolution 64x64 --spp 4 --seed 7 "${GPU[@]}" --strategy naive-sk \
                -o "$base-gpu.exr" >"$base-gpu.log" 2>&1 \
                || { log "FAIL identity $name $vname: gpu render"; failures=$((failures + 1)); continue; }
            if r=$("$VOLPT" compare "$base-cpu.exr" "$base-gpu.exr" --identical 2>&1); then
                log "PASS identity $name $vname: $(echo "$r" | tail -n 1)"
            else
                log "FAIL identity $name $vname: $(echo "$r" | tail -n 1)"; failures=$((failures + 1))
            fi
        fi
    done
done
rm -f "$OUT"/id-*.exr "$OUT"/id-*.png

echo "scene,config,time_mean_s,time_std_s,tracking_steps_per_path,segments_per_path,paths_per_s,image_mean_r" >"$OUT/summary.csv"
bench() { # bench SCENE CONFIG FILE PARAMS FLAGS...
    local name=$1 config=$2 file=$3 params=$4; shift 4
    local json="$OUT/bench-$name-$config.json"
    # shellcheck disable=SC2086
    if "$VOLPT" bench "$file" $params "$@" --resolution "$SIZE" --trials "$TRIALS" "${BENCH[@]}" --json >"$json" 2>"$OUT/bench-$name-$config.log"; then
        python3 - "$json" "$name" "$config" >>"$OUT/summary.csv" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
p = d["paths"]
print(f'{sys.argv[2]},{sys.argv[3]},{d["time_mean_s"]:.4f},{d["time_std_s"]:.4f},'
      f'{d["tracking_steps"] / p:.2f},{d["segments"] / p:.3f},{d["paths_per_s"]:.4g},{d["image_mean"][0]:.6f}')
PY
        log "bench $name $config: $(tail -n 1 "$OUT/summary.csv")"
    else
        log "FAIL bench $name $config"; failures=$((failures + 1))
    fi
}
for entry in "${SCENES[@]}"; do
    IFS=: read -r name file params <<<"$entry"
    [ -f "$file" ] || continue
    spp=$SPP
    [ "$name" = bucky ] && spp=$((3 * SPP))
    bench "$name" global-pt "$file" "$params" --spp $spp --tracking global --estimator pt
    for r in $RESOLUTIONS; do
        bench "$name" "grid$r-pt" "$file" "$params" --spp $spp --majorant-resolution "$r" --estimator pt
    done
    bench "$name" grid-nee "$file" "$params" --spp $spp --tracking grid --estimator nee
    # The factory's own choice (`volpt info`'s "default:" line says which and why).
    bench "$name" default-pt "$file" "$params" --spp $spp --estimator pt
    # shellcheck disable=SC2086
    "$VOLPT" info "$file" $params 2>/dev/null | grep -A1 '^tracking' >>"$OUT/summary.txt"
done
# NEE where its default applies: envmap-cube's sun through an index-matched boundary.
file=scenes/envmap-cube/index-matched.xml
if [ -f "$file" ]; then
    bench envmap-cube-index-matched pt "$file" "" --spp "$SPP" --estimator pt
    bench envmap-cube-index-matched nee "$file" "" --spp "$SPP" --estimator nee
fi

log "failures $failures"
# Few files come back from the device: the summaries, and one archive of the JSON and logs.
(cd "$OUT" && tar -czf heterogeneous-details.tar.gz -- *.json *.log 2>/dev/null && rm -f -- *.json *.log)
exit $((failures > 0))
