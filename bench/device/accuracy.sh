#!/usr/bin/env bash
# Error against time on the GPU (docs/accuracy.md), from the device bundle
# (`cargo xtask device-bundle`, with this script copied beside run.sh):
#
#   bash bundle/accuracy.sh     # writes $OUT/accuracy/<scene>-<strategy>-<knob>/ (default OUT: ./out)
#
# For cgg-logo, smoke and bucky at 400x400: one reference per scene (4096 spp on the GPU, cached and
# shared by all runs of the scene), then `volpt converge` per GPU strategy over Russian roulette
# (rr_depth 1, 5, off) and max_depth (2, 4, 8, 16, unlimited), TIME seconds per setting.
# Each run directory holds converge.csv, rmse.svg, rel-mse.svg and table.md; copy them to
# docs/accuracy/gpu/ and add the tables to docs/accuracy.md.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
VOLPT=$PWD/bin/volpt
DATA=$PWD/data
TIME=${TIME:-2}
RES=${RES:-400x400}
mkdir -p "$OUT/accuracy"
"$VOLPT" scene generate scenes >/dev/null
SCENES=(
    "cgg-logo:scenes/cgg-logo/scene.xml:"
    "smoke:scenes/smoke/scene.xml:-Ddata=$DATA"
    "bucky:scenes/bucky/scene.toml:-Ddata=$DATA"
)
for entry in "${SCENES[@]}"; do
    IFS=: read -r name file params <<<"$entry"
    ref="$OUT/accuracy/$name-reference"
    mkdir -p "$ref"
    for strategy in naive-sk regeneration-sk; do
        for knob in "rr_depth=1,5,-1" "max_depth=2,4,8,16,-1"; do
            dir="$OUT/accuracy/$name-$strategy-${knob%%=*}"
            mkdir -p "$dir"
            # The reference is rendered into the first run's directory; later runs reuse it.
            cp "$ref"/reference-* "$dir"/ 2>/dev/null
            # shellcheck disable=SC2086
            "$VOLPT" converge "$file" $params --resolution "$RES" --backend cuda --strategy "$strategy" \
                --reference-spp 4096 --setting "$knob" --time "$TIME" -o "$dir" >"$dir/log.txt" 2>&1 \
                || echo "FAIL $name $strategy $knob: $(tail -n 2 "$dir/log.txt")"
            cp "$dir"/reference-* "$ref"/ 2>/dev/null
            echo "== $name $strategy $knob"; cat "$dir/table.md" 2>/dev/null
        done
    done
done | tee "$OUT/accuracy/summary.md"
