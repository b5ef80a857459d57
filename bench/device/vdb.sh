#!/usr/bin/env bash
# VDB volumes on the GPU (issue 29, docs/out-of-core.md "Sparse grids (VDB)"), run on the device
# machine from the bundle that `cargo xtask device-bundle` builds:
#
#   /usr/bin/python3 scenes/vdb/make_fixtures.py target/vdb-bench --large 512   # here, with OpenVDB
#   cargo xtask device-bundle          # copies target/vdb-bench/*.vdb into bundle/vdb-bench
#   bash bundle/vdb.sh                 # on the device; results under $OUT (default ./out-vdb)
#
# 1. identical images: scenes/vdb/bucky.toml (Bucky from bucky.vdb and bucky-half.vdb, kept sparse)
#    against scenes/bucky/scene.toml (Bucky.raw, dense), naive-sk with exact math (the CPU's
#    summation order), 4 spp, seed 7, 200x200; and the sparse render against the CPU's. Every
#    image must equal the raw grid's device image bit for bit.
# 2. speed: the large sparse cloud (bundle/vdb-bench/large-cloud-*.vdb, a few percent of its box
#    active) kept sparse, read dense, and read dense with --bricked; `volpt bench`, regeneration-sk,
#    TRIALS trials each; and the images of the three (naive-sk) compared bit for bit.
#
# Files under $OUT: summary.txt (PASS/FAIL lines and the times), device.txt, logs.tar.gz.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out-vdb}
WORK=${WORK:-$PWD/vdb-work}
mkdir -p "$OUT" "$WORK/logs"
VOLPT=$PWD/bin/volpt
TRIALS=${TRIALS:-5}
RES=${RES:-400x400}
SPP=${SPP:-64}
export RUST_BACKTRACE=1
failures=0

log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
run() {
    local name=$1; shift
    timeout 300 "$@" >"$WORK/logs/$name.log" 2>&1
    local rc=$?
    echo "(exit $rc: $*)" >>"$WORK/logs/$name.log"
    return $rc
}
fail() { log "FAIL $*"; failures=$((failures + 1)); }
tail_of() { tail -n "${2:-4}" "$WORK/logs/$1.log" | tr '\n' ' '; }
same() { # same NAME A.exr B.exr: bit-identical or FAIL
    if run "$1" "$VOLPT" compare "$2" "$3" --identical; then log "PASS $1: $(tail_of "$1" 2)"
    else fail "$1: $(tail_of "$1" 2)"; fi
}

log "date $(date -u +%Y-%m-%dT%H:%MZ)"
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv >"$OUT/device.txt" 2>&1
cat "$OUT/device.txt" | tee -a "$OUT/summary.txt"

# 1. Identical images.
COMMON=(--spp 4 --seed 7 --resolution 200x200)
GPU=(--backend cuda --strategy naive-sk --math exact)
run bucky-raw-gpu "$VOLPT" render scenes/bucky/scene.toml "${COMMON[@]}" "${GPU[@]}" -o "$WORK/raw-gpu.exr" \
    || fail "bucky raw on the GPU: $(tail_of bucky-raw-gpu)"
run bucky-raw-cpu "$VOLPT" render scenes/bucky/scene.toml "${COMMON[@]}" -o "$WORK/raw-cpu.exr" \
    || fail "bucky raw on the CPU: $(tail_of bucky-raw-cpu)"
same raw-cpu-vs-gpu "$WORK/raw-cpu.exr" "$WORK/raw-gpu.exr"
for vdb in bucky bucky-half; do
    run "$vdb-gpu" "$VOLPT" render scenes/vdb/bucky.toml -Dvdb="fixtures/$vdb.vdb" "${COMMON[@]}" "${GPU[@]}" \
        -o "$WORK/$vdb-gpu.exr" || { fail "$vdb.vdb on the GPU: $(tail_of "$vdb-gpu")"; continue; }
    grep -o 'volume: .*' "$WORK/logs/$vdb-gpu.log" | head -n 2 | sed 's/^/   /' | tee -a "$OUT/summary.txt"
    same "$vdb-vdb-gpu-vs-raw-gpu" "$WORK/raw-gpu.exr" "$WORK/$vdb-gpu.exr"
done

# 2. Sparse against dense on a large cloud.
cloud=$(ls vdb-bench/large-cloud-*.vdb 2>/dev/null | tail -n 1)
if [ -z "$cloud" ]; then
    fail "no vdb-bench/large-cloud-*.vdb in the bundle (make it with make_fixtures.py --large N)"
else
    log "2. $cloud ($(du -h "$cloud" | cut -f1)): sparse vs dense, regeneration-sk, $RES, $SPP spp"
    dir=$(mktemp -d)
    for mode in always never; do
        printf '[volume]\nfile = "%s"\nsparse = "%s"\nnormalise = 100\n[boundary]\nbsdf = "null"\n[camera]\nfov = 0.8\n' \
            "$PWD/$cloud" "$mode" >"$dir/$mode.toml"
    done
    run info "$VOLPT" info "$dir/always.toml" && grep '^memory' "$WORK/logs/info.log" | tee -a "$OUT/summary.txt"
    for v in "sparse:always:" "dense:never:" "bricked:never:--bricked"; do
        IFS=: read -r name mode flags <<<"$v"
        # shellcheck disable=SC2086
        run "image-$name" "$VOLPT" render "$dir/$mode.toml" "${COMMON[@]}" "${GPU[@]}" $flags \
            -o "$WORK/cloud-$name.exr" || fail "cloud $name render: $(tail_of "image-$name")"
        # shellcheck disable=SC2086
        if run "bench-$name" "$VOLPT" bench "$dir/$mode.toml" --backend cuda --strategy regeneration-sk \
            --resolution "$RES" --spp "$SPP" --trials "$TRIALS" $flags; then
            # volpt bench's table row: time +- spread, paths, segments and steps per second.
            log "   $name: $(grep -E ' s \+- ' "$WORK/logs/bench-$name.log" | head -n 1 | tr -s ' ')"
            grep -o 'volume: .*' "$WORK/logs/bench-$name.log" | head -n 1 | sed 's/^/     /' | tee -a "$OUT/summary.txt"
        else
            fail "cloud $name bench: $(tail_of "bench-$name")"
        fi
    done
    same cloud-sparse-vs-dense "$WORK/cloud-dense.exr" "$WORK/cloud-sparse.exr"
    same cloud-bricked-vs-dense "$WORK/cloud-dense.exr" "$WORK/cloud-bricked.exr"
fi

tar -czf "$OUT/logs.tar.gz" -C "$WORK" logs
log "failures: $failures"
[ "$failures" -eq 0 ]
