#!/usr/bin/env bash
# Lights besides the environment on the GPU (issue 42: sun, point and spot), run on the device
# machine from the bundle (`cargo xtask device-bundle`; no cargo there):
#
#   bash bundle/lights.sh      # results under $OUT (default ./out-lights), summary in $OUT/summary.txt
#
# 1. CPU against every GPU strategy at the same seed, exact math, on the light scenes
#    (scenes/lights: a delta sun over a slab, a spot in fog, the same fog chromatic, and a TOML
#    scene with a sun of angular radius 5 degrees and a spot over a grid): naive-sk and naive-mk
#    bit-identical to the CPU (`volpt compare --identical`: same paths, same summation order), the
#    other strategies to 1e-6 (another summation order), as bench/device/chromatic.sh;
# 2. the analytic test on the GPU: sun-slab.xml (fast math, the default) against its closed-form
#    single-scattering radiance (lights_analytic.py: |z| <= 5 and within 2%).
# While the kernels have no lights (volpt_core::light::ENABLED false on the GPU), 1 checks
# instead that the GPU refuses each scene with its error, and 2 runs on the CPU.
# Expected: every line of summary.txt PASS, "failures: 0"; about 40 s on an H200 with the lights in
# the kernels (45 renders of 64x64 at 4 spp, most of it process start-up), seconds without.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out-lights}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
T=${T:-60}
failures=0
log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
check() { # check NAME CMD...
    local name=$1; shift
    if "$@" >"$OUT/$name.log" 2>&1; then log "PASS $name: $(tail -n 1 "$OUT/$name.log")"
    else log "FAIL $name: $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1)); fi
}
log "date $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader)"

STRATEGIES=(${STRATEGIES:-naive-sk regeneration-sk regeneration-warp-sk regeneration-block-sk regeneration-2p-sk streaming-sk streaming-sorted-sk sorting-sk naive-mk streaming-mk})
# name:file:extra arguments
SCENES=("sun-slab:scenes/lights/sun-slab.xml:" "spot-fog:scenes/lights/spot-fog.xml:"
    "spot-fog-chromatic:scenes/lights/spot-fog.xml:-Dsigma_t=0.25,0.5,1" "sun-disc-spot:scenes/lights/lights.toml:")
COMMON=(--spp 4 --seed 7 --resolution 64x64)
for entry in "${SCENES[@]}"; do
    IFS=: read -r name file extra <<<"$entry"
    # shellcheck disable=SC2086
    "$VOLPT" render "$file" $extra "${COMMON[@]}" -o "$OUT/$name-cpu.exr" >"$OUT/$name-cpu.log" 2>&1 \
        || { log "FAIL $name cpu render: $(tail -n 2 "$OUT/$name-cpu.log" | tr '\n' ' ')"; failures=$((failures + 1)); continue; }
    # While the kernels have no lights (volpt_core::light::ENABLED), the GPU must refuse the
    # scene with its error, and there is nothing to compare.
    # shellcheck disable=SC2086
    if ! "$VOLPT" render "$file" $extra "${COMMON[@]}" --backend cuda -o "$OUT/$name-probe.exr" >"$OUT/$name-probe.log" 2>&1; then
        check "$name-gpu-refuses" grep -q "no lights besides the environment" "$OUT/$name-probe.log"
        ANALYTIC_BACKEND=cpu
        continue
    fi
    for s in "${STRATEGIES[@]}"; do
        # shellcheck disable=SC2086
        if timeout "$T" "$VOLPT" render "$file" $extra "${COMMON[@]}" --backend cuda --math exact --strategy "$s" \
            -o "$OUT/$name-$s.exr" >"$OUT/$name-$s.log" 2>&1; then
            case $s in naive-sk | naive-mk) tol=--identical ;; *) tol="--max-relative 1e-6" ;; esac
            # shellcheck disable=SC2086
            check "$name-cpu-vs-$s" "$VOLPT" compare "$OUT/$name-cpu.exr" "$OUT/$name-$s.exr" $tol
        else
            log "FAIL $name $s render: $(tail -n 2 "$OUT/$name-$s.log" | tr '\n' ' ')"
            failures=$((failures + 1))
        fi
    done
done

SPP=1024
# The GPU's where it has lights, the CPU's otherwise.
ANALYTIC_BACKEND=${ANALYTIC_BACKEND:-cuda}
if timeout "$T" "$VOLPT" render scenes/lights/sun-slab.xml --spp $SPP --seed 11 --resolution 16x16 --backend "$ANALYTIC_BACKEND" \
    --film "$OUT/sun-slab-gpu.vfilm" >"$OUT/sun-slab-analytic-render.log" 2>&1; then
    check "sun-slab-analytic-$ANALYTIC_BACKEND" python3 lights_analytic.py "$OUT/sun-slab-gpu.vfilm" $SPP
else
    log "FAIL sun-slab analytic render: $(tail -n 2 "$OUT/sun-slab-analytic-render.log" | tr '\n' ' ')"
    failures=$((failures + 1))
fi
log "failures: $failures"
[ "$failures" -eq 0 ]
