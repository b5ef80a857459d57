#!/usr/bin/env bash
# `--strategy auto` against every fixed choice it could make, per scene (issue: auto within 5% of
# the best fixed choice on every scene). From the bundle, on the device:
#   bash bundle/auto-check.sh   -> $OUT/auto-check.txt
# Each scene: volpt bench (SPP, bucky 3x; TRIALS after a warm-up) with regeneration-sk,
# regeneration-block-sk and streaming-sk, regeneration-sk under register caps CAPS, and auto with
# an empty cache (its calibration runs in the warm-up trial, so the timed trials use its choice).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
SPP=${SPP:-100}
TRIALS=${TRIALS:-3}
MATH=${MATH:-fast}
CAPS=${CAPS:-64 48 40}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/auto-check.XXXXXX")
"$VOLPT" scene generate scenes >/dev/null
SCENES=(
    "homogeneous-cube-null:scenes/homogeneous-cube/scene.xml:-Dboundary=null"
    "homogeneous-cube:scenes/homogeneous-cube/scene.xml:"
    "cgg-logo:scenes/cgg-logo/scene.xml:"
    "smoke:scenes/smoke/scene.xml:-Ddata=$PWD/data"
    "bucky:scenes/bucky/scene.toml:-Ddata=$PWD/data"
)
bench() { # bench NAME FILE PARAMS SPP LABEL ARGS...: prints "LABEL median_ms"
    local name=$1 file=$2 params=$3 spp=$4 label=$5
    shift 5
    # shellcheck disable=SC2086
    if VOLPT_CACHE_DIR=$WORK/cache-$name timeout 90 "$VOLPT" bench "$file" $params --spp "$spp" --backend cuda \
        --math "$MATH" --trials "$TRIALS" --json "$@" >"$WORK/r.json" 2>"$WORK/$name-${label//\//-}.log"; then
        python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(sys.argv[2], r['time_median_s']*1e3)" \
            "$WORK/r.json" "$label"
    else
        echo "$label FAIL"
    fi
}
{
    echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader) spp=$SPP (bucky 3x) trials=$TRIALS math=$MATH; medians in ms"
    for entry in "${SCENES[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        spp=$SPP
        [ "$name" = bucky ] && spp=$((3 * SPP))
        rows=$WORK/$name.rows
        : >"$rows"
        for s in regeneration-sk regeneration-block-sk streaming-sk; do
            bench "$name" "$file" "$params" "$spp" "$s" --strategy "$s" >>"$rows"
        done
        for cap in $CAPS; do
            bench "$name" "$file" "$params" "$spp" "regeneration-sk/max-registers-$cap" \
                --strategy regeneration-sk --max-registers "$cap" >>"$rows"
        done
        bench "$name" "$file" "$params" "$spp" auto --strategy auto >>"$rows"
        choice=$(grep -h -m 1 "^auto: .* with " "$WORK/$name-auto.log" | head -c 160)
        python3 - "$rows" "$name" "$choice" <<'PY'
import sys
rows, name, choice = sys.argv[1], sys.argv[2], sys.argv[3]
times = {}
for line in open(rows):
    label, value = line.split()
    if value != "FAIL":
        times[label] = float(value)
fixed = {k: v for k, v in times.items() if k != "auto"}
print(f"## {name}: " + ", ".join(f"{k} {v:.2f}" for k, v in times.items()))
if fixed and "auto" in times:
    best = min(fixed, key=fixed.get)
    ratio = times["auto"] / fixed[best]
    verdict = "PASS" if ratio <= 1.05 else "MISS"
    print(f"{verdict} {name}: auto {times['auto']:.2f} ms / best fixed ({best}) {fixed[best]:.2f} ms = {ratio:.3f}; {choice}")
PY
    done
} | tee "$OUT/auto-check.txt"
