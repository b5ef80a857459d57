#!/usr/bin/env bash
# Several GPUs in one render (`--gpus`), on a machine of two or more GPUs, from a bundle
# (bin/volpt with the PTX embedded, scenes/, data/); everything it writes goes under $OUT.
#
#   bash multigpu.sh
#
# 1. Equality: naive-sk (one GPU adds every sample in order, as the CPU does) on one GPU and on two;
#    the two films' sums compared (film_diff.py: the largest relative difference, f64 rounding only).
# 2. Speed-up: each included scene at a production sample count, $RESOLUTION (default 800x800),
#    regeneration-sk (fixed,
#    so that no `auto` calibration enters the timing), one GPU against `--gpus all`; after a short
#    warm-up render on both GPUs (the driver's JIT cache). The time is the render's own ("in X s":
#    one GPU, its kernels; several, the wall time of the shared queue from the first batch to the
#    last film added, grid copies and film transfers of every batch included) and the process's
#    wall time (scene loading, GPU contexts and the JIT cache too). The several-GPU render logs
#    its batches (device, samples, start, duration: `RUST_LOG=volpt=debug`) in NAME-all.log.
# 3. Processes: two `volpt render --samples` processes, one per GPU, and `volpt merge`, against
#    the one-GPU image.
# 4. `auto` on two GPUs: one calibration (the second GPU, of the same model, finds it cached).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
DATA=$PWD/data
RESOLUTION=${RESOLUTION:-800x800}
failures=0
log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
now() { date +%s.%N; }
calc() { awk "BEGIN { printf \"%.3f\", $1 }"; }
# The render's own time from its summary line ("... in 1.234 s: ...").
render_seconds() { sed -n 's/.* in \([0-9.]*\) s: .*/\1/p' "$1" | tail -n 1; }

log "date $(date -u +%Y-%m-%dT%H:%MZ)"
nvidia-smi --query-gpu=index,name,driver_version,memory.total,clocks.max.sm --format=csv,noheader \
    | tee "$OUT/device.txt"
nvidia-smi topo -m >>"$OUT/device.txt" 2>&1
"$VOLPT" scene generate scenes >"$OUT/generate.log" 2>&1 || { log "FAIL generate"; failures=$((failures + 1)); }

# 1. Equality, from the films themselves.
EQ="scenes/cgg-logo/scene.xml"
for gpus in 0 all; do
    "$VOLPT" render "$EQ" --spp 256 --seed 3 --backend cuda --strategy naive-sk --gpus "$gpus" \
        --film "$OUT/eq-$gpus.vfilm" -o "$OUT/eq-$gpus.exr" >"$OUT/eq-$gpus.log" 2>&1 \
        || { log "FAIL equality render --gpus $gpus: $(tail -n 2 "$OUT/eq-$gpus.log" | tr '\n' ' ')"; failures=$((failures + 1)); }
done
if python3 film_diff.py "$OUT/eq-0.vfilm" "$OUT/eq-all.vfilm" >"$OUT/eq-diff.txt" 2>&1; then
    log "PASS equality (cgg-logo, naive-sk, 256 spp, 1 GPU vs 2): $(tail -n 1 "$OUT/eq-diff.txt")"
else
    log "FAIL equality: $(tail -n 2 "$OUT/eq-diff.txt" | tr '\n' ' ')"; failures=$((failures + 1))
fi
rm -f "$OUT"/eq-*.vfilm

# 2. Speed-up. name : scene file : parameters : spp
SCENES=(
    "homogeneous-cube:scenes/homogeneous-cube/scene.xml::4096"
    "cgg-logo:scenes/cgg-logo/scene.xml::4096"
    "bucky:scenes/bucky/scene.toml:-Ddata=$DATA:4096"
    "smoke:scenes/smoke/scene.xml:-Ddata=$DATA:2048"
    "ad:scenes/ad/scene.xml::2048"
)
echo "scene,spp,one_gpu_render_s,two_gpu_render_s,render_speedup,one_gpu_process_s,two_gpu_process_s,process_speedup,max_relative" >"$OUT/speedup.csv"
for entry in "${SCENES[@]}"; do
    IFS=: read -r name file params spp <<<"$entry"
    common=(--resolution "$RESOLUTION" --seed 1 --backend cuda --strategy regeneration-sk)
    # shellcheck disable=SC2086
    "$VOLPT" render "$file" $params "${common[@]}" --spp 4 --gpus all -o /dev/null >/dev/null 2>&1
    for gpus in 0 all; do
        start=$(now)
        # shellcheck disable=SC2086
        RUST_LOG=info,volpt=debug "$VOLPT" render "$file" $params "${common[@]}" --spp "$spp" --gpus "$gpus" \
            -o "$OUT/$name-$gpus.exr" >"$OUT/$name-$gpus.log" 2>&1 \
            || { log "FAIL $name --gpus $gpus: $(tail -n 2 "$OUT/$name-$gpus.log" | tr '\n' ' ')"; failures=$((failures + 1)); }
        calc "$(now) - $start" >"$OUT/$name-$gpus.wall"
    done
    one=$(render_seconds "$OUT/$name-0.log"); two=$(render_seconds "$OUT/$name-all.log")
    w1=$(cat "$OUT/$name-0.wall"); w2=$(cat "$OUT/$name-all.wall")
    cmp=$("$VOLPT" compare "$OUT/$name-0.exr" "$OUT/$name-all.exr" --max-relative 1e-5 2>&1 | tail -n 1)
    "$VOLPT" compare "$OUT/$name-0.exr" "$OUT/$name-all.exr" --max-relative 1e-5 >/dev/null 2>&1 \
        || { log "FAIL $name images differ: $cmp"; failures=$((failures + 1)); }
    line="$name,$spp,$one,$two,$(calc "$one / $two"),$w1,$w2,$(calc "$w1 / $w2"),\"$cmp\""
    echo "$line" >>"$OUT/speedup.csv"
    log "$line"
    rm -f "$OUT/$name-0.exr" "$OUT/$name-all.exr" "$OUT"/*.png
done

# 3. Two processes, one GPU each, then merge.
M="scenes/cgg-logo/scene.xml"
"$VOLPT" render "$M" --resolution 400x400 --seed 2 --spp 1024 --backend cuda --strategy regeneration-sk \
    --gpus 0 -o "$OUT/proc-one.exr" >"$OUT/proc-one.log" 2>&1
start=$(now)
"$VOLPT" render "$M" --resolution 400x400 --seed 2 --samples 0..512 --backend cuda \
    --strategy regeneration-sk --gpus 0 --film "$OUT/a.vfilm" >"$OUT/proc-a.log" 2>&1 &
"$VOLPT" render "$M" --resolution 400x400 --seed 2 --samples 512..1024 --backend cuda \
    --strategy regeneration-sk --gpus 1 --film "$OUT/b.vfilm" >"$OUT/proc-b.log" 2>&1 &
wait
"$VOLPT" merge "$OUT/b.vfilm" "$OUT/a.vfilm" --spp 1024 -o "$OUT/proc-merged.exr" >"$OUT/proc-merge.log" 2>&1
wall=$(calc "$(now) - $start")
if "$VOLPT" compare "$OUT/proc-one.exr" "$OUT/proc-merged.exr" --max-relative 1e-5 >"$OUT/proc-compare.txt" 2>&1; then
    log "PASS two processes (--samples on GPU 0 and 1) merged = one GPU: $(tail -n 1 "$OUT/proc-compare.txt"); $wall s wall against $(render_seconds "$OUT/proc-one.log") s"
else
    log "FAIL two processes merged: $(tail -n 2 "$OUT/proc-compare.txt" "$OUT/proc-merge.log" | tr '\n' ' ')"; failures=$((failures + 1))
fi
rm -f "$OUT"/*.vfilm "$OUT"/proc-*.exr "$OUT"/*.png

# 4. auto on two GPUs.
if timeout 120 "$VOLPT" render scenes/homogeneous-cube/scene.xml --spp 4096 --backend cuda --strategy auto \
    --gpus all -o /dev/null >"$OUT/auto.log" 2>&1; then
    log "PASS auto on two GPUs: $(grep -c 'calibrating' "$OUT/auto.log") calibration(s), $(tail -n 1 "$OUT/auto.log")"
else
    log "FAIL auto on two GPUs: $(tail -n 2 "$OUT/auto.log" | tr '\n' ' ')"; failures=$((failures + 1))
fi

log "failures $failures"
# Logs in one archive ($OUT brings back few files).
tar czf "$OUT/logs.tgz" -C "$OUT" --exclude logs.tgz --exclude summary.txt --exclude speedup.csv . 2>/dev/null
find "$OUT" -mindepth 1 -maxdepth 1 ! -name logs.tgz ! -name summary.txt ! -name speedup.csv ! -name device.txt -exec rm -rf {} +
exit "$failures"
