#!/usr/bin/env bash
# Issue 43's GPU checks, on the device machine from the bundle:
#
#   bash bundle/hostile-check.sh      # results under $OUT (default ./out), summary in hostile.txt
#
# 1. Sample numbers at the top of u32 on the GPU: samples 4294967290..4294967295 of the example
#    cube render and return (each strategy named), say they wrote a film of those samples, and
#    naive-sk's image matches the CPU's;
# 2. VDB tiles on the GPU: OpenVDB's fill() of a 1024^3 box and a 594-byte file of one 4096^3 tile
#    (scenes/vdb/fixtures) load and render within their time limits.
# Expected: every line "PASS ..."; the last line "hostile-check: 0 failures".
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
export VOLPT_CACHE_DIR=$OUT/cache
failures=0
log() { echo "== $*" | tee -a "$OUT/hostile.txt"; }
check() { # check NAME SECONDS CMD...: run under a time limit, record, count failures
    local name=$1 seconds=$2; shift 2
    if timeout "$seconds" "$@" >"$OUT/$name.log" 2>&1; then log "PASS $name: $(tail -n 1 "$OUT/$name.log")"
    else log "FAIL $name (exit $?): $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1)); fi
}

log "date $(date -u +%Y-%m-%dT%H:%MZ), $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -n 1)"
for s in naive-sk regeneration-sk auto; do
    check "top-samples-$s" 120 "$VOLPT" render scenes/example/cube.xml -Dresolution=48 --backend cuda \
        --strategy "$s" --math exact --samples 4294967290..4294967295 --film "$OUT/top-$s.vfilm" -o "$OUT/top-$s.exr"
    check "top-samples-$s-film" 60 grep -q "samples 4294967290..4294967295" "$OUT/top-samples-$s.log"
done
check top-samples-cpu 300 "$VOLPT" render scenes/example/cube.xml -Dresolution=48 --backend cpu \
    --samples 4294967290..4294967295 -o "$OUT/top-cpu.exr"
# The CPU and naive-sk with exact math trace the same paths (the same sample numbers).
check top-samples-cpu-vs-gpu 60 "$VOLPT" compare "$OUT/top-cpu.exr" "$OUT/top-naive-sk.exr" \
    --max-relative 1e-3
check fill1024 120 "$VOLPT" render scenes/vdb/fixtures/fill1024.vdb -Dresolution=48 --spp 4 \
    --backend cuda -o "$OUT/fill1024.exr"
check fill4096 300 "$VOLPT" render scenes/vdb/fixtures/fill4096.vdb -Dresolution=48 --spp 4 \
    --backend cuda -o "$OUT/fill4096.exr"
log "hostile-check: $failures failures"
