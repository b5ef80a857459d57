#!/usr/bin/env bash
# 2026-11-26, branch ptx-size (issue 24, item 3): the packed kernels on the GPU, from a trimmed
# bundle carried as .dev/ptx-size (bin/volpt of the branch, stripped, both kernel builds embedded;
# the scenes; this script; volpt_kernels.ptx.gz, the exact build's PTX as text):
#
#   bash .dev/ptx-size/device.sh       # results under $OUT
#
# 1. `volpt selftest`, exact and fast kernels;
# 2. every strategy the binary offers renders cgg-logo (64x64, 4 spp, seed 7) with both kernel
#    builds; the exact images against the CPU's, with strategies.sh's tolerances: naive-sk and
#    naive-mk bit-identical, the others up to the order of their f64 sums;
# 3. first-render latency: the process's wall time for a 32x32, 1-spp render (regeneration-sk,
#    exact) with the driver's JIT cache off, so that every run cuts and JIT-compiles its kernel:
#    5 runs with the embedded pack ("pack") alternating with 5 with the same kernels as one text
#    through VOLPT_PTX ("text": what main as forked does, which embeds the text, apart from reading
#    the file; main's binary, 188 MB, does not fit the 64 MiB carry); one run of each with the
#    renderer's debug log (the cut's time against the JIT's).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
TEXT=$PWD/volpt_kernels.ptx
failures=0
log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
check() { # check NAME CMD...: run, record, count failures
    local name=$1; shift
    if timeout 120 "$@" >"$OUT/$name.log" 2>&1; then log "PASS $name: $(tail -n 1 "$OUT/$name.log")"
    else log "FAIL $name: $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1)); fi
}

log "date $(date -u +%Y-%m-%dT%H:%MZ)"
log "device $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -n 1)"
log "binary $(stat -c %s "$VOLPT") bytes"
[ -f "$TEXT.gz" ] && gunzip -kf "$TEXT.gz"

for math in exact fast; do check "selftest-$math" "$VOLPT" selftest --math "$math"; done

"$VOLPT" scene generate scenes >"$OUT/generate.log" 2>&1 || { log "FAIL generate"; failures=$((failures + 1)); }
SCENE="scenes/cgg-logo/scene.xml -Dresolution=64 --spp 4 --seed 7"
# The strategies from the binary itself: clap lists --strategy's values when given an unknown one.
STRATEGIES=$("$VOLPT" render scenes/cgg-logo/scene.xml --strategy '?' 2>&1 | sed -n 's/.*possible values: \(.*\)\]/\1/p' | tr -d ',' | sed 's/\bauto\b//')
log "strategies: $STRATEGIES"
# shellcheck disable=SC2086
"$VOLPT" render $SCENE -o "$OUT/cpu.exr" >"$OUT/cpu.log" 2>&1 || { log "FAIL cpu render"; failures=$((failures + 1)); }
for s in $STRATEGIES; do
    for math in exact fast; do
        # shellcheck disable=SC2086
        check "render-$s-$math" "$VOLPT" render $SCENE --backend cuda --strategy "$s" --math "$math" -o "$OUT/$s-$math.exr"
    done
    case $s in naive-sk | naive-mk) tol=--identical ;; *) tol="--max-relative 1e-6" ;; esac
    # shellcheck disable=SC2086
    check "compare-cpu-$s" "$VOLPT" compare "$OUT/cpu.exr" "$OUT/$s-exact.exr" $tol
done

LATENCY="render scenes/cgg-logo/scene.xml -Dresolution=32 --spp 1 --backend cuda --strategy regeneration-sk --math exact"
latency() { # latency LABEL [ENV...]: one run's wall time in seconds
    local label=$1 start end; shift
    start=$(date +%s.%N)
    # shellcheck disable=SC2086
    env CUDA_CACHE_DISABLE=1 "$@" "$VOLPT" $LATENCY -o "$OUT/latency.exr" >>"$OUT/latency.log" 2>&1 \
        || { log "FAIL latency $label"; failures=$((failures + 1)); }
    end=$(date +%s.%N)
    echo "$label $(python3 -c "print(f'{$end - $start:.3f}')")" | tee -a "$OUT/latency.txt"
}
for run in 1 2 3 4 5; do
    latency pack
    [ -f "$TEXT" ] && latency text VOLPT_PTX="$TEXT"
done
latency debug-pack RUST_LOG=volpt_cuda=debug
[ -f "$TEXT" ] && latency debug-text RUST_LOG=volpt_cuda=debug VOLPT_PTX="$TEXT"
grep "loaded kernel" "$OUT/latency.log" | tee -a "$OUT/latency.txt"
python3 - "$OUT/latency.txt" <<'PY' | tee -a "$OUT/summary.txt"
import statistics, sys
runs = {}
for line in open(sys.argv[1]):
    label, _, value = line.partition(" ")
    if label in ("pack", "text"):
        runs.setdefault(label, []).append(float(value))
for label, times in runs.items():
    print(f"== latency {label}: median {statistics.median(times):.3f} s of {times}")
PY
rm -f "$OUT"/*.exr "$OUT"/*.png
(cd "$OUT" && tar czf logs.tar.gz ./*.log && rm -f ./*.log)
log "failures: $failures"
exit $((failures > 0))
