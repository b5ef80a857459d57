#!/usr/bin/env bash
# Grids read through 3D textures (`--lookup texture|texture-f16`, issue 10; docs/heterogeneous.md)
# against dense f32 grids with software trilinear lookups (`--lookup trilinear`, the default):
# 1. `volpt selftest`: the GPU's texture lookups against the CPU's filter;
# 2. the same estimate: GPU texture renders against CPU texture renders and against GPU trilinear
#    renders, each of its own seed, `volpt compare --independent` (a significant mean difference
#    fails);
# 3. time: `volpt bench`, regeneration-sk, SPP (bucky 3x), TRIALS after a warm-up, MATH;
# 4. accuracy against time: `volpt converge --setting lookup=trilinear,texture,texture-f16`, TIME
#    seconds per setting against a REFSPP reference (which uses the scene's trilinear lookups);
# 5. registers: `ptxas -v` of the regeneration-sk kernels of the texture and dense media, if the
#    bundle has the PTX.
#   bash bundle/texture.sh   -> $OUT/texture.txt, $OUT/converge-*.md
# Knobs: SPP (100), TRIALS (5), MATH (fast), TIME (1.0), REFSPP (2048), ONLY (a scene regex),
# PARTS (the parts to run, default "1 2 3 4 5").
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
SPP=${SPP:-100}
TRIALS=${TRIALS:-5}
MATH=${MATH:-fast}
TIME=${TIME:-1.0}
REFSPP=${REFSPP:-2048}
ONLY=${ONLY:-.}
PARTS=${PARTS:-1 2 3 4 5}
part() { [[ " $PARTS " == *" $1 "* ]]; }
WORK=$(mktemp -d "${TMPDIR:-/tmp}/texture.XXXXXX")
export RUST_BACKTRACE=0 RUST_LIB_BACKTRACE=0
# The first error line of a log, on one line.
first_error() { grep -m 2 -E "^Error|panicked|error" "$1" | tr '\n' ' '; }
"$VOLPT" scene generate scenes >/dev/null
SCENES=(
    "smoke:scenes/smoke/scene.xml:-Ddata=$PWD/data"
    "bucky:scenes/bucky/scene.toml:-Ddata=$PWD/data"
    "cgg-logo:scenes/cgg-logo/scene.xml:"
    "ad:scenes/ad/scene.xml:"
)
if [ -f thesis/gen_scenes.py ] && python3 thesis/gen_scenes.py "$WORK/scenes" >/dev/null 2>&1; then
    SCENES+=("thesis-cgg:$WORK/scenes/cgg_logo/volpath_bsdf.xml:")
fi
selected=()
for entry in "${SCENES[@]}"; do
    [[ ${entry%%:*} =~ $ONLY ]] && selected+=("$entry")
done
LOOKUPS="trilinear texture texture-f16"
{
    echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv,noheader)"
    part 1 && {
    echo "## 1. selftest"
    "$VOLPT" selftest >"$WORK/selftest.txt" 2>&1 || echo "FAIL selftest: $(first_error "$WORK/selftest.txt")"
    grep -iE "texture|difference|passed|FAIL" "$WORK/selftest.txt"
    }
    part 2 && {
    echo "## 2. the same estimate (64x64, 256 spp, exact math, naive-sk on the GPU)"
    for entry in "${selected[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        common=(--resolution 64x64 --spp 256)
        # shellcheck disable=SC2086
        "$VOLPT" render "$file" $params "${common[@]}" --lookup texture --seed 1 -o "$WORK/$name-cpu.exr" >/dev/null 2>&1
        seed=1
        for lookup in texture texture-f16 trilinear; do
            seed=$((seed + 1))
            # shellcheck disable=SC2086
            timeout 120 "$VOLPT" render "$file" $params "${common[@]}" --lookup "$lookup" --seed "$seed" \
                --backend cuda --strategy naive-sk --math exact -o "$WORK/$name-$lookup.exr" >/dev/null 2>"$WORK/r.log" \
                || { echo "FAIL $name $lookup: $(first_error "$WORK/r.log")"; continue; }
        done
        for pair in "cpu texture" "texture texture-f16" "texture trilinear"; do
            read -r a b <<<"$pair"
            if "$VOLPT" compare "$WORK/$name-$a.exr" "$WORK/$name-$b.exr" --independent >"$WORK/c.txt" 2>&1; then
                echo "PASS $name: $a vs GPU $b: $(tail -n 1 "$WORK/c.txt")"
            else
                echo "FAIL $name: $a vs GPU $b: $(tail -n 2 "$WORK/c.txt" | tr '\n' ' ')"
            fi
        done
    done
    }
    part 3 && {
    echo "## 3. time (regeneration-sk, $SPP spp (bucky 3x), $TRIALS trials, math $MATH; medians)"
    for entry in "${selected[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        spp=$SPP
        [ "$name" = bucky ] && spp=$((3 * SPP))
        for lookup in $LOOKUPS; do
            # shellcheck disable=SC2086
            timeout 120 "$VOLPT" bench "$file" $params --spp "$spp" --backend cuda --strategy regeneration-sk \
                --lookup "$lookup" --math "$MATH" --trials "$TRIALS" --json >"$WORK/b.json" 2>"$WORK/b.log" \
                || { echo "FAIL $name $lookup: $(first_error "$WORK/b.log")"; continue; }
            python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(f\"{sys.argv[2]:<12} {sys.argv[3]:<12} {r['time_median_s']*1e3:9.2f} ms  {r['segments_per_s']/1e9:7.3f} G seg/s  {r['paths_per_s']/1e6:8.2f} M paths/s\")" \
                "$WORK/b.json" "$name" "$lookup"
        done
    done
    }
} 2>&1 | tee "$OUT/texture.txt"
{
    part 4 && {
    echo "## 4. accuracy against time (converge, $TIME s per setting, reference $REFSPP spp)"
    for entry in "${selected[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        [ "$name" = thesis-cgg ] && continue
        # shellcheck disable=SC2086
        if timeout 240 "$VOLPT" converge "$file" $params --resolution 400x400 --backend cuda \
            --reference-spp "$REFSPP" --setting lookup=trilinear,texture,texture-f16 \
            --setting math="$MATH" --time "$TIME" -o "$WORK/conv-$name" >"$WORK/conv.log" 2>&1; then
            echo "== $name"
            cat "$WORK/conv-$name/table.md"
            cp "$WORK/conv-$name/table.md" "$OUT/converge-$name.md"
        else
            echo "FAIL converge $name: $(first_error "$WORK/conv.log")"
        fi
    done
    }
    part 5 && {
    echo "## 5. registers (ptxas -v, sm_90)"
    ptx=volpt_kernels_fast.ptx
    [ "$MATH" = exact ] && ptx=volpt_kernels.ptx
    if [ -f "$ptx" ] && command -v ptxas >/dev/null; then
        python3 ptx_cut.py "$ptx" "$WORK/cut.ptx" \
            '^regeneration_sk__grid_density__(grid_albedo__texture_trilinear|constant_albedo__dense_trilinear|grid_albedo__dense_trilinear)__(index_matched|rough_dielectric)__(isotropic|henyey_greenstein)__constant$'
        ptxas -arch=sm_90 -v "$WORK/cut.ptx" -o /dev/null 2>&1 \
            | grep -E "Compiling entry|registers" | paste - - \
            | sed -E "s/.*entry function '([^']*)'.*Used ([0-9]+) registers.*/\1 \2 registers/"
    else
        echo "(no $ptx in the bundle)"
    fi
    }
} 2>&1 | tee -a "$OUT/texture.txt"
