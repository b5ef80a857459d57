#!/usr/bin/env bash
# The stability suite's hard cases (docs/stability.md) on the GPU, from the device bundle
# (`cargo xtask device-bundle`, with this script copied beside run.sh):
#
#   bash bundle/stability.sh      # writes $OUT/stability.txt (default OUT: ./out)
#
# The CPU suite (tests/tests/stability.rs) checks the values; the GPU runs the same core step, so
# each case passes on the GPU when naive-sk's image is bit-identical to the CPU's (same seed), and
# regeneration-sk's within summation-order rounding. Every case is scenes/stability/cube.xml with
# -D parameters; a case the loader refuses (extreme extinction) must be refused on both backends.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT/stability"
VOLPT=$PWD/bin/volpt
SCENE=scenes/stability/cube.xml
failures=0
log() { echo "$*" | tee -a "$OUT/stability.txt"; }

CASES=(
    "hg-1:-Dg=-0.999999"
    "hg-tiny-neg:-Dg=-1e-7"
    "hg-0:-Dg=0"
    "hg-tiny:-Dg=1e-7"
    "hg+1:-Dg=0.999999"
    "density-0:-Dsigma_t=0 -Dalbedo=0.5"
    "density-1e-8:-Dsigma_t=1e-8 -Dalbedo=0"
    "density-1e6:-Dsigma_t=1e6 -Dalbedo=0"
    "albedo-1-roulette:-Dsigma_t=200 -Dboundary=dielectric -Dint_ior=1.5 -Drr_depth=1"
    "albedo-1-no-roulette:-Dsigma_t=50 -Dboundary=dielectric -Dint_ior=1.5"
    "ggx-1e-6:-Dboundary=roughdielectric -Dalpha=1e-6"
    "ggx-1:-Dboundary=roughdielectric -Dalpha=1"
    "ior-1:-Dboundary=dielectric -Dint_ior=1"
    "ior-1+1e-7:-Dboundary=dielectric -Dint_ior=1.0000001"
    "rough-ior-1:-Dboundary=roughdielectric -Dint_ior=1"
    "camera-inside:-Dorigin=0.1,0.2,0.3 -Dalbedo=0.8"
    "corner-view:-Dorigin=2,2,2 -Dboundary=roughdielectric"
    "edge-on:-Dorigin=0,0.5,3 -Dtarget=0,0.5,0"
    "world-1e5:-Doffset=1e5 -Dorigin=100002,1.5,2.5 -Dtarget=1e5,0,0 -Dsigma_t=4 -Dalbedo=0.8"
)
REFUSED=(
    "extinction-1e8:-Dsigma_t=1e8 -Dalbedo=0.9"
    "extinction-1e10:-Dsigma_t=1e10 -Dalbedo=0.9"
)

log "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader)"
for entry in "${CASES[@]}"; do
    IFS=: read -r name params <<<"$entry"
    base="$OUT/stability/$name"
    # shellcheck disable=SC2086
    if ! "$VOLPT" render "$SCENE" $params --spp 16 --seed 3 -o "$base-cpu.exr" >"$base-cpu.log" 2>&1; then
        log "FAIL $name: cpu render: $(tail -n 1 "$base-cpu.log")"; failures=$((failures + 1)); continue
    fi
    for s in naive-sk regeneration-sk; do
        # shellcheck disable=SC2086
        if ! "$VOLPT" render "$SCENE" $params --spp 16 --seed 3 --backend cuda --math exact --strategy "$s" \
            -o "$base-$s.exr" >"$base-$s.log" 2>&1; then
            log "FAIL $name $s: render: $(tail -n 1 "$base-$s.log")"; failures=$((failures + 1)); continue
        fi
        if [ "$s" = naive-sk ]; then check=(--identical); else check=(--max-relative 1e-5); fi
        if "$VOLPT" compare "$base-cpu.exr" "$base-$s.exr" "${check[@]}" >"$base-$s-compare.log" 2>&1; then
            log "PASS $name $s: $(head -n 1 "$base-$s-compare.log") | $(grep -h 'paths reached' "$base-$s.log")"
        else
            log "FAIL $name $s: $(tr '\n' ' ' <"$base-$s-compare.log")"; failures=$((failures + 1))
        fi
    done
done
for entry in "${REFUSED[@]}"; do
    IFS=: read -r name params <<<"$entry"
    # shellcheck disable=SC2086
    if "$VOLPT" render "$SCENE" $params --spp 1 --backend cuda -o "$OUT/stability/$name.exr" \
        >"$OUT/stability/$name.log" 2>&1; then
        log "FAIL $name: rendered, expected a refusal"; failures=$((failures + 1))
    else
        log "PASS $name refused: $(grep -m1 Error "$OUT/stability/$name.log" | cut -c1-160)"
    fi
done
log "failures: $failures"
exit $((failures > 0))
