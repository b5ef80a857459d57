#!/usr/bin/env bash
# The GPU strategies (docs/strategies.md), on the device machine from the bundle:
#
#   bash bundle/strategies.sh      # results under $OUT (default ./out)
#
# 1. ptxas -v of both kernel builds (exact, fast) and, if the bundle carries one, of a baseline
#    (ab/base.ptx, the kernels of the commit before a change);
# 2. correctness: every strategy against the CPU at the same seed (naive-sk bit-identical, the
#    others up to the order of their f64 sums), and fast math against exact math as independent
#    estimates (`volpt compare --independent`: a tile or image mean that differs significantly
#    fails); compute-sanitizer on each new strategy;
# 3. the benchmark: every scene x strategy x math (and bin/volpt-base, if carried, as the
#    before), each `volpt bench` with one discarded warm-up; a register-cap sweep on two scenes.
# Knobs: TRIALS (5), SCENES_ONLY (a regex of scene names), STRATEGIES, EXACT_STRATEGIES,
# FAST_STRATEGIES, CAPS, T (seconds per command, 60), PROBE_T (30), RACECHECK_T (300: a racecheck
# of the sorting strategies takes ~80 s on an H100), SKIP_CHECKS=1, SKIP_BENCH=1,
# SKIP_CAPS=1, BENCH_ARGS (added to every benchmark command, e.g. "--spp 16" for naive-mk),
# BASE_STRATEGIES and BASE_MATH (what bin/volpt-base runs: regeneration-sk, exact).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
BASE=$PWD/bin/volpt-base
[ -f "$BASE.gz" ] && [ ! -f "$BASE" ] && gunzip -k "$BASE.gz"
DATA=$PWD/data
TRIALS=${TRIALS:-5}
STRATEGIES=(${STRATEGIES:-naive-sk regeneration-sk regeneration-warp-sk regeneration-block-sk regeneration-2p-sk streaming-sk streaming-sorted-sk sorting-sk naive-mk streaming-mk})
# Fast math is benchmarked for these (all by default).
FAST_STRATEGIES=${FAST_STRATEGIES:-${STRATEGIES[*]:1}}
EXACT_STRATEGIES=${EXACT_STRATEGIES:-${STRATEGIES[*]:1}}
CAPS=${CAPS:-32 40 48 56 64 72 80 96 128}
# Every GPU command runs under a time limit: a hung kernel fails its check instead of the run.
T=${T:-60}
failures=0
log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
check() { # check NAME CMD...: run, record, count failures
    local name=$1; shift
    if "$@" >"$OUT/$name.log" 2>&1; then log "PASS $name: $(tail -n 1 "$OUT/$name.log")"
    else log "FAIL $name: $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1)); fi
}

log "date $(date -u +%Y-%m-%dT%H:%MZ)"
nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv,noheader | tee "$OUT/device.txt"
ARCH=sm_$(nvidia-smi --query-gpu=compute_cap --format=csv,noheader | head -n 1 | tr -d '.')

# ptxas runs on the CPU beside the GPU work (its reports only), on the kernels of every variant
# for regeneration-sk and naive-sk and of three variants for the other strategies.
subset() { # subset IN.ptx OUT.ptx
    python3 ptx_cut.py "$1" "$2" \
        "^(regeneration_sk|naive_sk)__|__(homogeneous__index_matched__isotropic|grid_density__constant_albedo__dense_trilinear__index_matched__isotropic|grid_density__grid_albedo__dense_trilinear__rough_dielectric__isotropic)__constant$" >/dev/null
}
for f in volpt_kernels volpt_kernels_fast; do
    [ -f $f.ptx ] || gunzip -kf $f.ptx.gz
    (subset $f.ptx "$OUT/$f-subset.ptx" && ptxas -arch="$ARCH" -v "$OUT/$f-subset.ptx" -o /dev/null \
        >"$OUT/ptxas-$f.txt" 2>&1; rm -f "$OUT/$f-subset.ptx") &
done
[ -f ab/base.ptx.gz ] && gunzip -kf ab/base.ptx.gz
[ -f ab/base.ptx ] && ptxas -arch="$ARCH" -v ab/base.ptx -o /dev/null >"$OUT/ptxas-base.txt" 2>&1 &

"$VOLPT" scene generate scenes >"$OUT/generate.log" 2>&1 || { log "FAIL generate"; failures=$((failures + 1)); }

# name : scene file : extra parameters (the benchmark uses each scene's own spp: 100, bucky 300)
SCENES=(
    "homogeneous-cube:scenes/homogeneous-cube/scene.xml:-Dspp=100"
    "homogeneous-cube-null:scenes/homogeneous-cube/scene.xml:-Dspp=100 -Dboundary=null"
    "cgg-logo:scenes/cgg-logo/scene.xml:"
    "ad:scenes/ad/scene.xml:"
    "smoke:scenes/smoke/scene.xml:-Ddata=$DATA"
    "bucky:scenes/bucky/scene.toml:-Ddata=$DATA"
    "envmap-cube:scenes/envmap-cube/scene.xml:-Dspp=100 -Dresolution=400"
)
# A strategy whose kernel does not finish a tiny render in time is dropped from everything below.
for s in "${STRATEGIES[@]}"; do
    if ! timeout "${PROBE_T:-30}" "$VOLPT" render scenes/cgg-logo/scene.xml -Dresolution=32 --spp 1 --backend cuda \
        --strategy "$s" -o "$OUT/probe-$s.exr" >"$OUT/probe-$s.log" 2>&1; then
        log "FAIL probe $s (exit $?): dropped from this run"; failures=$((failures + 1))
        STRATEGIES=("${STRATEGIES[@]/$s}")
        EXACT_STRATEGIES=${EXACT_STRATEGIES//$s/}
        FAST_STRATEGIES=${FAST_STRATEGIES//$s/}
    fi
done
STRATEGIES=(${STRATEGIES[*]})
selected() { [ -z "${SCENES_ONLY:-}" ] || [[ $1 =~ $SCENES_ONLY ]]; }

if [ -z "${SKIP_CHECKS:-}" ]; then
    for entry in "${SCENES[@]}"; do
        IFS=: read -r name file params <<<"$entry"
        selected "$name" || continue
        # shellcheck disable=SC2086
        "$VOLPT" render "$file" $params --spp 4 --seed 7 -o "$OUT/$name-cpu.exr" >"$OUT/$name-cpu.log" 2>&1 \
            || { log "FAIL $name cpu render"; failures=$((failures + 1)); continue; }
        for s in "${STRATEGIES[@]}"; do
            # shellcheck disable=SC2086
            if timeout "$T" "$VOLPT" render "$file" $params --spp 4 --seed 7 --backend cuda --math exact --strategy "$s" \
                -o "$OUT/$name-$s.exr" >"$OUT/$name-$s.log" 2>&1; then
                # naive-sk sums each pixel's samples in the CPU's order, and so does naive-mk (one
                # sample of every pixel per batch); the others add in the order paths end.
                case $s in naive-sk | naive-mk) tol=--identical ;; *) tol="--max-relative 1e-6" ;; esac
                # shellcheck disable=SC2086
                check "$name-cpu-vs-$s" "$VOLPT" compare "$OUT/$name-cpu.exr" "$OUT/$name-$s.exr" $tol
            else
                log "FAIL $name $s render: $(tail -n 2 "$OUT/$name-$s.log" | tr '\n' ' ')"; failures=$((failures + 1))
            fi
        done
        # Fast math: 16 spp with other seeds against exact math, as independent estimates.
        # shellcheck disable=SC2086
        if timeout "$T" "$VOLPT" render "$file" $params --spp 16 --seed 11 --backend cuda --math exact -o "$OUT/$name-exact16.exr" \
                >"$OUT/$name-exact16.log" 2>&1 \
            && timeout "$T" "$VOLPT" render "$file" $params --spp 16 --seed 12 --backend cuda --math fast \
                -o "$OUT/$name-fast16.exr" >"$OUT/$name-fast16.log" 2>&1; then
            check "$name-exact-vs-fast" "$VOLPT" compare "$OUT/$name-exact16.exr" "$OUT/$name-fast16.exr" --independent
        else
            log "FAIL $name fast-math renders: $(tail -n 2 "$OUT/$name-fast16.log" | tr '\n' ' ')"; failures=$((failures + 1))
        fi
    done
    for s in "${STRATEGIES[@]:2}"; do
        check "memcheck-$s" timeout "$T" compute-sanitizer --tool memcheck --error-exitcode 1 \
            "$VOLPT" render scenes/cgg-logo/scene.xml -Dresolution=64 --spp 2 --backend cuda --strategy "$s" \
            -o "$OUT/memcheck-$s.exr"
    done
    # The strategies that exchange paths, keys or albedos through shared memory.
    for s in streaming-sk streaming-sorted-sk sorting-sk; do
        [[ " ${STRATEGIES[*]} " == *" $s "* ]] && check "racecheck-$s" timeout "${RACECHECK_T:-300}" compute-sanitizer --tool racecheck --error-exitcode 1 \
            "$VOLPT" render scenes/cgg-logo/scene.xml -Dresolution=32 --spp 1 --backend cuda --strategy "$s" \
            -o "$OUT/racecheck-$s.exr"
    done
fi

row() { # row LABEL JSON: one line of the benchmark table
    python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(f\"{sys.argv[2]:<52} {r['time_median_s']*1e3:9.2f} ms (mean {r['time_mean_s']*1e3:8.2f} +- {r['time_std_s']*1e3:6.2f})  {r['segments_per_s']/1e9:7.3f} G seg/s  {r['paths_per_s']/1e6:9.1f} M paths/s  {r['segments']/r['paths']:6.1f} seg/path\")" "$2" "$1"
}
bench() { # bench LABEL BINARY ARGS...: one benchmark row, JSON kept
    local label=$1 bin=$2; shift 2
    local json="$OUT/bench-${label//[^A-Za-z0-9_.-]/_}.json"
    # shellcheck disable=SC2086
    if timeout "$T" "$bin" bench "$@" ${BENCH_ARGS:-} --backend cuda --trials "$TRIALS" --json >"$json" 2>"$OUT/bench.err"; then
        row "$label" "$json" | tee -a "$OUT/bench.txt"
    else
        log "FAIL bench $label: $(tail -n 2 "$OUT/bench.err" | tr '\n' ' ')"; failures=$((failures + 1))
    fi
}

echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(head -n 1 "$OUT/device.txt") trials=$TRIALS (median of the trials after a warm-up)" >>"$OUT/bench.txt"
for entry in "${SCENES[@]}"; do
    [ -n "${SKIP_BENCH:-}" ] && break
    IFS=: read -r name file params <<<"$entry"
    selected "$name" || continue
    # shellcheck disable=SC2086
    for s in ${BASE_STRATEGIES:-regeneration-sk}; do
        # shellcheck disable=SC2086
        [ -x "$BASE" ] && bench "$name before $s ${BASE_MATH:-exact}" "$BASE" "$file" $params --strategy "$s" \
            --math "${BASE_MATH:-exact}"
    done
    for s in $EXACT_STRATEGIES; do
        # shellcheck disable=SC2086
        bench "$name $s exact" "$VOLPT" "$file" $params --strategy "$s" --math exact
    done
    for s in $FAST_STRATEGIES; do
        # shellcheck disable=SC2086
        bench "$name $s fast" "$VOLPT" "$file" $params --strategy "$s" --math fast
    done
done

if [ -z "${SKIP_CAPS:-}" ] && [ -z "${SKIP_BENCH:-}" ]; then
    for entry in "${SCENES[@]:0:3}"; do
        IFS=: read -r name file params <<<"$entry"
        selected "$name" || continue
        for cap in $CAPS; do
            # shellcheck disable=SC2086
            bench "$name regeneration-sk fast maxreg $cap" "$VOLPT" "$file" $params --strategy regeneration-sk \
                --math fast --max-registers "$cap"
        done
    done
fi
wait

# Registers of the kernels the benchmark ran (the registry's full list is in the ptxas files).
for f in "$OUT"/ptxas-*.txt; do
    python3 - "$f" >"${f%.txt}-summary.txt" <<'EOF'
import re, sys
text = open(sys.argv[1]).read()
for m in re.finditer(r"Compiling entry function '(\w+)'.*?Used (\d+) registers(?:, used (\d+) barriers)?[^\n]*", text, re.S):
    name, regs = m.group(1), m.group(2)
    spill = re.search(r"(\d+) bytes spill stores, (\d+) bytes spill loads", text[m.start():m.end()] )
    stack = re.search(r"(\d+) bytes stack frame", text[m.start():m.end()])
    print(f"{name:<90} {regs:>4} regs  stack {stack.group(1) if stack else '?':>4}  spills {spill.group(1) if spill else '?'}")
EOF
    gzip -f "$f"
done

(cd "$OUT" && tar czf images.tar.gz ./*.exr 2>/dev/null && rm -f ./*.exr ./*.png)
(cd "$OUT" && tar czf logs.tar.gz ./*.log ./*.err ./ptxas-*.txt.gz 2>/dev/null && rm -f ./*.log ./*.err ./ptxas-*.txt.gz)
(cd "$OUT" && tar czf bench-json.tar.gz ./bench-*.json && rm -f ./bench-*.json)
log "failures: $failures"
exit $((failures > 0))
