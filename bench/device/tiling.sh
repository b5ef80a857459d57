#!/usr/bin/env bash
# Image tiling (`--tiles C,R`: each tile rendered by its own launches, one tile after another), the
# thesis's tiling table: cgg-logo at RES x RES (1920), SPP samples, tiles 1x1 ... 64x64, with
# naive-sk and regeneration-sk (fast math). Then checks: naive-sk tiled equals naive-sk whole bit
# for bit, regeneration-sk tiled equals the CPU within 1e-6.
#   bash bundle/tiling.sh   -> $OUT/tiling.txt
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
RES=${RES:-1920}
SPP=${SPP:-16}
TRIALS=${TRIALS:-3}
TILES=${TILES:-1 2 4 8 16 32 64}
STRATEGIES=${STRATEGIES:-regeneration-sk naive-sk}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/tiling.XXXXXX")
"$VOLPT" scene generate scenes >/dev/null
SCENE=scenes/cgg-logo/scene.xml
{
    echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader) cgg-logo ${RES}x$RES $SPP spp, fast math, medians of $TRIALS"
    for s in $STRATEGIES; do
        for t in $TILES; do
            if timeout 120 "$VOLPT" bench "$SCENE" --resolution "${RES}x$RES" --spp "$SPP" --backend cuda --strategy "$s" \
                --math fast --tiles "$t,$t" --trials "$TRIALS" --json >"$WORK/r.json" 2>"$WORK/r.log"; then
                python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(f\"{sys.argv[2]:<16} tiles {sys.argv[3]:>2}x{sys.argv[3]:<2} {r['time_median_s']*1e3:9.2f} ms  {r['segments_per_s']/1e9:7.3f} G seg/s  {r['paths_per_s']/1e6:8.2f} M paths/s\")" \
                    "$WORK/r.json" "$s" "$t"
            else
                echo "FAIL $s tiles $t: $(tail -n 2 "$WORK/r.log" | tr '\n' ' ')"
            fi
        done
    done
    small=(--resolution 97x61 --spp 4 --seed 7)
    "$VOLPT" render "$SCENE" "${small[@]}" -o "$WORK/cpu.exr" >/dev/null 2>&1
    "$VOLPT" render "$SCENE" "${small[@]}" --backend cuda --math exact --strategy naive-sk -o "$WORK/naive.exr" >/dev/null 2>&1
    for t in 2,3 7,5; do
        "$VOLPT" render "$SCENE" "${small[@]}" --backend cuda --math exact --strategy naive-sk --tiles "$t" -o "$WORK/naive-$t.exr" >/dev/null 2>&1 \
            && "$VOLPT" compare "$WORK/naive.exr" "$WORK/naive-$t.exr" --identical >/dev/null 2>&1 \
            && echo "PASS naive-sk tiles $t: bit-identical to the whole film (and to the CPU: $("$VOLPT" compare "$WORK/cpu.exr" "$WORK/naive-$t.exr" --identical >/dev/null 2>&1 && echo yes || echo no))" \
            || echo "FAIL naive-sk tiles $t"
        for s in regeneration-sk regeneration-block-sk streaming-sk; do
            "$VOLPT" render "$SCENE" "${small[@]}" --backend cuda --math exact --strategy "$s" --tiles "$t" -o "$WORK/$s-$t.exr" >/dev/null 2>&1 \
                && "$VOLPT" compare "$WORK/cpu.exr" "$WORK/$s-$t.exr" --max-relative 1e-6 >/dev/null 2>&1 \
                && echo "PASS $s tiles $t: the CPU's image within 1e-6" \
                || echo "FAIL $s tiles $t"
        done
    done
} | tee "$OUT/tiling.txt"
