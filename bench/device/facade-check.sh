#!/usr/bin/env bash
# The GPU through the library facade (`volpt` crate), on the device machine from the bundle:
#
#   bash bundle/facade-check.sh      # results under $OUT (default ./out)
#
# 1. `volpt selftest` with the exact and the fast kernels;
# 2. run.sh's correctness half (QUICK=1): every scene on the CPU and with naive-sk (bit-identical)
#    and regeneration-sk, the library user's own medium, a naive-sk checkpoint resumed, a film
#    too large for the card;
# 3. what the facade adds on the GPU: a render cut into chunks (a checkpoint every millisecond) and
#    a regeneration-sk render interrupted and resumed both equal the render in one go bit for bit;
#    `--strategy auto` calibrates once, then takes its choice from the cache.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
export VOLPT_CACHE_DIR=$OUT/cache
failures=0
log() { echo "== $*" | tee -a "$OUT/facade.txt"; }
check() { # check NAME CMD...: run, record, count failures
    local name=$1; shift
    if "$@" >"$OUT/$name.log" 2>&1; then log "PASS $name: $(tail -n 1 "$OUT/$name.log")"
    else log "FAIL $name: $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1)); fi
}

log "date $(date -u +%Y-%m-%dT%H:%MZ), $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -n 1)"
check selftest-exact "$VOLPT" selftest --math exact
check selftest-fast "$VOLPT" selftest --math fast
QUICK=1 OUT=$OUT/run bash run.sh >"$OUT/run.log" 2>&1 || failures=$((failures + 1))
log "run.sh QUICK: $(grep -c '^== PASS' "$OUT/run/summary.txt") passed, $(grep -c '^== FAIL' "$OUT/run/summary.txt") failed"
grep '^== FAIL' "$OUT/run/summary.txt" | tee -a "$OUT/facade.txt"

for s in naive-sk regeneration-sk; do
    R="scenes/cgg-logo/scene.xml -Dresolution=96 --seed 4 --backend cuda --math exact --strategy $s"
    # shellcheck disable=SC2086
    "$VOLPT" render $R --spp 24 -o "$OUT/whole-$s.exr" >"$OUT/whole-$s.log" 2>&1
    # shellcheck disable=SC2086
    "$VOLPT" render $R --spp 24 --checkpoint "$OUT/chunks-$s.ckpt" --checkpoint-interval 0.001 \
        -o "$OUT/chunks-$s.exr" >"$OUT/chunks-$s.log" 2>&1
    check "chunked-equals-whole-$s" "$VOLPT" compare "$OUT/whole-$s.exr" "$OUT/chunks-$s.exr" --identical
    # shellcheck disable=SC2086
    "$VOLPT" render $R --spp 7 --checkpoint "$OUT/resume-$s.ckpt" -o "$OUT/part-$s.exr" >"$OUT/part-$s.log" 2>&1
    # shellcheck disable=SC2086
    "$VOLPT" render $R --spp 24 --resume "$OUT/resume-$s.ckpt" -o "$OUT/resumed-$s.exr" >"$OUT/resumed-$s.log" 2>&1
    check "resumed-equals-whole-$s" "$VOLPT" compare "$OUT/whole-$s.exr" "$OUT/resumed-$s.exr" --identical
    rm -f "$OUT"/*.ckpt
done

A="scenes/example/cube.xml -Dresolution=128 --spp 16 --backend cuda --strategy auto"
# shellcheck disable=SC2086
check auto-calibrates "$VOLPT" render $A -o "$OUT/auto-1.exr"
grep -q "calibrating" "$OUT/auto-calibrates.log" || { log "FAIL auto did not calibrate"; failures=$((failures + 1)); }
# shellcheck disable=SC2086
check auto-cached "$VOLPT" render $A -o "$OUT/auto-2.exr"
grep -q "(cached)" "$OUT/auto-cached.log" || { log "FAIL auto's second render did not use the cache"; failures=$((failures + 1)); }

log "$failures failures"
exit $((failures > 0))
