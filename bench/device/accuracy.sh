#!/usr/bin/env bash
# Error against time on the GPU (docs/accuracy.md), from the device bundle
# (`cargo xtask device-bundle`, with this script copied beside run.sh):
#
#   bash bundle/accuracy.sh     # writes $OUT/accuracy.tar.gz and $OUT/accuracy-summary.md
#
# For cgg-logo, smoke and bucky at RES (400x400): one reference per scene (4096 spp on the GPU,
# cached and shared by all runs of the scene), then one `volpt converge` per knob, each comparing
# both GPU strategies (`--setting strategy=...`) over: Russian roulette (rr_depth 1, 5, off),
# max_depth (2, 4, 8, 16, unlimited), grid lookup (trilinear, nearest) and, once the renderer has
# it, GPU math (exact, fast); TIME seconds per configuration.
#
# Only what is small comes back: the tarball holds each run's converge.csv, table.md, log.txt and
# its SVG and PNG plots (about 50 files, a few MB); the references (EXR, ~2 MB each) stay in WORK.
# Unpack it into docs/accuracy/gpu/ and add the tables to docs/accuracy.md. If the plots did not
# come back, `volpt plot DIR` draws them again from a run's converge.csv.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
WORK=${WORK:-${TMPDIR:-/tmp}/volpt-accuracy}
VOLPT=$PWD/bin/volpt
DATA=$PWD/data
TIME=${TIME:-2}
RES=${RES:-400x400}
STRATEGIES=${STRATEGIES-naive-sk,regeneration-sk}
REFSPP=${REFSPP:-4096}
# BACKEND=cpu STRATEGIES= tries the script without a GPU (the math knob then reports itself skipped
# or refused, and the CPU has no strategies).
BACKEND=${BACKEND:-cuda}
# ONLY (a regex of scene names, default all) renders some of the scenes.
ONLY=${ONLY:-.}
strategies=()
[ -n "$STRATEGIES" ] && strategies=(--setting "strategy=$STRATEGIES")
mkdir -p "$OUT" "$WORK/runs" "$WORK/references"
"$VOLPT" scene generate scenes >/dev/null
SCENES=(
    "cgg-logo:scenes/cgg-logo/scene.xml:"
    "smoke:scenes/smoke/scene.xml:-Ddata=$DATA"
    "bucky:scenes/bucky/scene.toml:-Ddata=$DATA"
)
KNOBS=(
    "roulette:rr_depth=1,5,-1"
    "depth:max_depth=2,4,8,16,-1"
    "lookup:lookup=trilinear,nearest"
    "math:math=exact,fast"
)
for entry in "${SCENES[@]}"; do
    IFS=: read -r name file params <<<"$entry"
    [[ $name =~ $ONLY ]] || continue
    ref="$WORK/references/$name"
    mkdir -p "$ref"
    for knob in "${KNOBS[@]}"; do
        IFS=: read -r label setting <<<"$knob"
        dir="$WORK/runs/$name-$label"
        mkdir -p "$dir"
        # The reference is rendered into the first run's directory; later runs reuse it.
        cp "$ref"/reference-* "$dir"/ 2>/dev/null
        # shellcheck disable=SC2086
        "$VOLPT" converge "$file" $params --resolution "$RES" --backend "$BACKEND" \
            --reference-spp "$REFSPP" "${strategies[@]}" --setting "$setting" \
            --time "$TIME" -o "$dir" >"$dir/log.txt" 2>&1
        status=$?
        mv "$dir"/reference-* "$ref"/ 2>/dev/null
        echo "== $name $setting"
        if [ $status -ne 0 ] && grep -q "unknown setting" "$dir/log.txt"; then
            echo "(skipped: this volpt has no ${setting%%=*} setting)"
        elif [ $status -ne 0 ]; then
            echo "FAIL: $(tail -n 3 "$dir/log.txt")"
        else
            cat "$dir/table.md"
        fi
    done
done | tee "$OUT/accuracy-summary.md"
(cd "$WORK/runs" && tar czf "$OUT/accuracy.tar.gz" --exclude='reference-*' --exclude='*.exr' .)
ls -l "$OUT/accuracy.tar.gz"
