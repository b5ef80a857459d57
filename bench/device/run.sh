#!/usr/bin/env bash
# The GPU check-and-benchmark, run on the device machine from the bundle that
# `cargo xtask device-bundle` builds (it has no Rust: everything here is prebuilt).
#
#   bash bundle/run.sh            # writes everything under $OUT (default: ./out)
#   QUICK=1 bash bundle/run.sh    # correctness only, no benchmark
#
# 1. device and driver, and `ptxas -v` (registers, spills, stack) for every kernel;
# 2. per scene: the CPU and each GPU strategy render the same seed; naive-sk must be bit-identical
#    to the CPU (same paths, same summation order), regeneration-sk equal up to summation order;
# 3. compute-sanitizer memcheck on one small render per strategy;
# 4. `volpt bench` of every scene x strategy (first trial discarded), as JSON.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
DATA=$PWD/data
TRIALS=${TRIALS:-5}
STRATEGIES=(naive-sk regeneration-sk)
failures=0
log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
check() { # check NAME CMD...: run, record, count failures
    local name=$1; shift
    if "$@" >"$OUT/$name.log" 2>&1; then log "PASS $name: $(tail -n 1 "$OUT/$name.log")"
    else log "FAIL $name: $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1)); fi
}

log "date $(date -u +%Y-%m-%dT%H:%MZ)"
nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv,noheader | tee "$OUT/device.txt"
nvcc --version | tail -n 2 >>"$OUT/device.txt"
ARCH=sm_$(nvidia-smi --query-gpu=compute_cap --format=csv,noheader | head -n 1 | tr -d '.')
gunzip -kf volpt_kernels.ptx.gz
ptxas -arch="$ARCH" -v volpt_kernels.ptx -o /dev/null >"$OUT/ptxas-$ARCH.txt" 2>&1
log "ptxas -arch=$ARCH: $(grep -c 'Used' "$OUT/ptxas-$ARCH.txt") kernels reported"

"$VOLPT" scene generate scenes >"$OUT/generate.log" 2>&1 || { log "FAIL generate"; failures=$((failures + 1)); }

# name : scene file : extra parameters (the benchmark uses each scene's own spp: 100, bucky 300)
# envmap-cube's sky.exr comes from `volpt scene generate`, like the grids.
SCENES=(
    "homogeneous-cube:scenes/homogeneous-cube/scene.xml:-Dspp=100"
    "homogeneous-cube-null:scenes/homogeneous-cube/scene.xml:-Dspp=100 -Dboundary=null"
    "cgg-logo:scenes/cgg-logo/scene.xml:"
    "ad:scenes/ad/scene.xml:"
    "smoke:scenes/smoke/scene.xml:-Ddata=$DATA"
    "bucky:scenes/bucky/scene.toml:-Ddata=$DATA"
    "envmap-cube:scenes/envmap-cube/scene.xml:-Dspp=100 -Dresolution=400"
)

for entry in "${SCENES[@]}"; do
    IFS=: read -r name file params <<<"$entry"
    [ -f "$file" ] || { log "SKIP $name: $file not in this bundle"; continue; }
    # shellcheck disable=SC2086
    "$VOLPT" render "$file" $params --spp 4 --seed 7 -o "$OUT/$name-cpu.exr" >"$OUT/$name-cpu.log" 2>&1 \
        || { log "FAIL $name cpu render"; failures=$((failures + 1)); continue; }
    for s in "${STRATEGIES[@]}"; do
        # shellcheck disable=SC2086
        if "$VOLPT" render "$file" $params --spp 4 --seed 7 --backend cuda --math exact --strategy "$s" \
            -o "$OUT/$name-$s.exr" >"$OUT/$name-$s.log" 2>&1; then
            if [ "$s" = naive-sk ]; then
                check "$name-cpu-vs-$s" "$VOLPT" compare "$OUT/$name-cpu.exr" "$OUT/$name-$s.exr" --identical
            else
                check "$name-cpu-vs-$s" "$VOLPT" compare "$OUT/$name-cpu.exr" "$OUT/$name-$s.exr" --max-relative 1e-6
            fi
        else
            log "FAIL $name $s render: $(tail -n 2 "$OUT/$name-$s.log" | tr '\n' ' ')"; failures=$((failures + 1))
        fi
    done
done

# A library user's own medium (examples/smooth-ball) through its own kernels crate: the GPU's
# naive-sk image equals the CPU's bit for bit, regeneration-sk up to the order of its sums.
SB="bin/smooth-ball --spp 8"
if $SB "$OUT/smooth-ball-cpu.exr" >"$OUT/smooth-ball-cpu.log" 2>&1; then
    for s in "${STRATEGIES[@]}"; do
        if $SB "$OUT/smooth-ball-$s.exr" --cuda --strategy "$s" --ptx smooth_ball_kernels.ptx \
            >"$OUT/smooth-ball-$s.log" 2>&1; then
            if [ "$s" = naive-sk ]; then tol=--identical; else tol="--max-relative 1e-6"; fi
            # shellcheck disable=SC2086
            check "smooth-ball-cpu-vs-$s" "$VOLPT" compare "$OUT/smooth-ball-cpu.exr" "$OUT/smooth-ball-$s.exr" $tol
        else
            log "FAIL smooth-ball $s: $(tail -n 2 "$OUT/smooth-ball-$s.log" | tr '\n' ' ')"; failures=$((failures + 1))
        fi
    done
else
    log "FAIL smooth-ball cpu render"; failures=$((failures + 1))
fi

# Checkpoints on the GPU: naive-sk resumed from a checkpoint equals its uninterrupted render bit for
# bit. And a film too large for the card is a clear error (60000^2 pixels of f64 RGB: 86 GB).
CK="scenes/cgg-logo/scene.xml -Dresolution=64 --seed 3 --backend cuda --math exact --strategy naive-sk"
# shellcheck disable=SC2086
if "$VOLPT" render $CK --spp 6 -o "$OUT/ck-whole.exr" >"$OUT/ck-whole.log" 2>&1 \
    && "$VOLPT" render $CK --spp 2 --checkpoint "$OUT/ck.ckpt" -o "$OUT/ck-part.exr" >"$OUT/ck-part.log" 2>&1 \
    && "$VOLPT" render $CK --spp 6 --resume "$OUT/ck.ckpt" -o "$OUT/ck-resumed.exr" >"$OUT/ck-resumed.log" 2>&1; then
    check "checkpoint-resume-naive-sk" "$VOLPT" compare "$OUT/ck-whole.exr" "$OUT/ck-resumed.exr" --identical
else
    log "FAIL checkpoint renders: $(tail -n 2 "$OUT/ck-resumed.log" | tr '\n' ' ')"; failures=$((failures + 1))
fi
rm -f "$OUT/ck.ckpt"
"$VOLPT" render scenes/example/cube.xml --resolution 60000x60000 --spp 1 --backend cuda -o "$OUT/oom.exr" \
    >"$OUT/oom.log" 2>&1
code=$?
if [ $code -ne 0 ] && [ $code -lt 128 ] && ! grep -q panicked "$OUT/oom.log"; then
    log "PASS device out of memory is an error: $(grep -m1 -i 'error' "$OUT/oom.log")"
else
    log "FAIL device out of memory (exit $code): $(tail -n 3 "$OUT/oom.log" | tr '\n' ' ')"; failures=$((failures + 1))
fi

# What specialisation saves (docs/effects.md): each scene specialised and with --general, GPU and CPU.
if [ -n "${EFFECTS:-}" ]; then
    for entry in "${SCENES[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        for variant in specialised general; do
            flag=""; [ "$variant" = general ] && flag=--general
            # shellcheck disable=SC2086
            "$VOLPT" bench "$file" $params $flag --backend cuda --trials 3 --json \
                >"$OUT/effects-$name-$variant-gpu.json" 2>/dev/null || { log "FAIL effects $name $variant gpu"; failures=$((failures + 1)); }
            # shellcheck disable=SC2086
            "$VOLPT" bench "$file" $params $flag --resolution 100x100 --spp 8 --trials 2 --json \
                >"$OUT/effects-$name-$variant-cpu.json" 2>/dev/null || { log "FAIL effects $name $variant cpu"; failures=$((failures + 1)); }
            log "effects $name $variant: gpu $(grep -E '"(variant|time_median_s)"' "$OUT/effects-$name-$variant-gpu.json" | tr -d ' \n') cpu $(grep -E '"time_median_s"' "$OUT/effects-$name-$variant-cpu.json" | tr -d ' \n')"
        done
    done
    (cd "$OUT" && tar czf effects.tar.gz ./effects-*.json && rm -f ./effects-*.json)
fi

for s in "${STRATEGIES[@]}"; do
    check "memcheck-$s" compute-sanitizer --tool memcheck --error-exitcode 1 \
        "$VOLPT" render scenes/cgg-logo/scene.xml -Dresolution=64 --spp 2 --backend cuda --strategy "$s" \
        -o "$OUT/memcheck-$s.exr"
done

if [ -z "${QUICK:-}" ]; then
    for entry in "${SCENES[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        [ -f "$file" ] || continue
        # The device's CPU, in the same units, at fewer samples per pixel.
        # shellcheck disable=SC2086
        if "$VOLPT" bench "$file" $params --spp 8 --trials 2 --json \
            >"$OUT/bench-$name-cpu.json" 2>"$OUT/bench-$name-cpu.log"; then
            log "bench $name cpu: $(grep -E '"(time_mean_s|segments_per_s)"' "$OUT/bench-$name-cpu.json" | tr -d ' \n')"
        else
            log "FAIL bench $name cpu"; failures=$((failures + 1))
        fi
        for s in "${STRATEGIES[@]}"; do
            # shellcheck disable=SC2086
            if "$VOLPT" bench "$file" $params --backend cuda --strategy "$s" --trials "$TRIALS" --json \
                >"$OUT/bench-$name-$s.json" 2>"$OUT/bench-$name-$s.log"; then
                log "bench $name $s: $(grep -E '"(time_mean_s|segments_per_s)"' "$OUT/bench-$name-$s.json" | tr -d ' \n')"
            else
                log "FAIL bench $name $s"; failures=$((failures + 1))
            fi
        done
    done
fi
# Few files come back from the device: pack images and logs.
(cd "$OUT" && tar czf images.tar.gz ./*.exr ./*.png && rm -f ./*.exr ./*.png)
(cd "$OUT" && tar czf logs.tar.gz ./*.log && rm -f ./*.log)
(cd "$OUT" && tar czf bench.tar.gz ./bench-*.json && rm -f ./bench-*.json)
log "failures: $failures"
exit $((failures > 0))
