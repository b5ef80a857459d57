#!/usr/bin/env bash
# Lights besides the environment on the GPU (issue 42: sun, point and spot) with their own kernels
# (volpt_device::KernelSet::Lit: naive-sk and regeneration-sk for the index-matched variants; the
# box kernels compile without lights), run on the device machine from the bundle (`cargo xtask
# device-bundle`; no cargo there):
#
#   bash bundle/lights.sh      # results under $OUT (default ./out-lights), summary in $OUT/summary.txt
#
# 1. CPU against the lit kernels at the same seed, exact math, on the light scenes (scenes/lights:
#    a delta sun over a slab, a spot in fog, the same fog chromatic, and a TOML scene with a sun of
#    angular radius 5 degrees and a spot over a grid): naive-sk bit-identical to the CPU
#    (`volpt compare --identical`: same paths, same summation order), regeneration-sk to 1e-6
#    (another summation order); each GPU log must name a `lit__` kernel;
# 2. a strategy without lit kernels (streaming-sk) is refused with the strategies that have them,
#    and a render without --strategy (auto) renders the lit scene;
# 3. the analytic test on the GPU: sun-slab.xml (fast math, the default) against its closed-form
#    single-scattering radiance (lights_analytic.py: |z| <= 5 and within 2%);
# 4. speed: spot-fog with its spot (the lit kernel) against the same fog without it (the box
#    kernel), regeneration-sk, fast math, 256x256 at 64 spp: M segments/s of each; and the lit
#    kernel under the default schedule (at most 64 registers).
# Expected: every line of summary.txt PASS, "failures: 0", then the speed line; about 40 s on an
# H200 (some 20 renders, most of it process start-up and the JIT of 10 kernels).
set -uo pipefail
cd "$(dirname "$0")"
[ -d scenes ] || cd ../..
OUT=${OUT:-$PWD/out-lights}
mkdir -p "$OUT"
: >"$OUT/summary.txt"
VOLPT=${VOLPT:-$PWD/bin/volpt}
ANALYTIC=$PWD/lights_analytic.py
[ -f "$ANALYTIC" ] || ANALYTIC=$PWD/bench/device/lights_analytic.py
T=${T:-60}
failures=0
log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
check() { # check NAME CMD...
    local name=$1; shift
    if "$@" >"$OUT/$name.log" 2>&1; then log "PASS $name: $(tail -n 1 "$OUT/$name.log")"
    else log "FAIL $name: $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1)); fi
}
log "date $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader)"

# name:file:extra arguments
SCENES=("sun-slab:scenes/lights/sun-slab.xml:" "spot-fog:scenes/lights/spot-fog.xml:"
    "spot-fog-chromatic:scenes/lights/spot-fog.xml:-Dsigma_t=0.25,0.5,1" "sun-disc-spot:scenes/lights/lights.toml:")
COMMON=(--spp 4 --seed 7 --resolution 64x64)
for entry in "${SCENES[@]}"; do
    IFS=: read -r name file extra <<<"$entry"
    # shellcheck disable=SC2086
    "$VOLPT" render "$file" $extra "${COMMON[@]}" -o "$OUT/$name-cpu.exr" >"$OUT/$name-cpu.log" 2>&1 \
        || { log "FAIL $name cpu render: $(tail -n 2 "$OUT/$name-cpu.log" | tr '\n' ' ')"; failures=$((failures + 1)); continue; }
    for s in naive-sk regeneration-sk; do
        # shellcheck disable=SC2086
        if RUST_LOG=volpt_cuda=info timeout "$T" "$VOLPT" render "$file" $extra "${COMMON[@]}" --backend cuda \
            --math exact --strategy "$s" -o "$OUT/$name-$s.exr" >"$OUT/$name-$s.log" 2>&1; then
            check "$name-$s-lit-kernel" grep -o "lit__[a-z0-9_]*" "$OUT/$name-$s.log"
            case $s in naive-sk) tol=--identical ;; *) tol="--max-relative 1e-6" ;; esac
            # shellcheck disable=SC2086
            check "$name-cpu-vs-$s" "$VOLPT" compare "$OUT/$name-cpu.exr" "$OUT/$name-$s.exr" $tol
        else
            log "FAIL $name $s render: $(tail -n 2 "$OUT/$name-$s.log" | tr '\n' ' ')"
            failures=$((failures + 1))
        fi
    done
done

# 2. A strategy without lit kernels: refused, naming those with them. auto: renders.
if "$VOLPT" render scenes/lights/spot-fog.xml "${COMMON[@]}" --backend cuda --strategy streaming-sk \
    -o "$OUT/refused.exr" >"$OUT/refused.log" 2>&1; then
    log "FAIL streaming-sk rendered a lit scene (no lit kernel of it exists)"
    failures=$((failures + 1))
else
    check "streaming-sk-refused" grep -o "are those of naive-sk, regeneration-sk only.*" "$OUT/refused.log"
fi
check "auto-renders-lit" "$VOLPT" render scenes/lights/spot-fog.xml "${COMMON[@]}" --backend cuda -o "$OUT/auto.exr"

# 3. The analytic sun over a slab, on the GPU.
SPP=1024
if timeout "$T" "$VOLPT" render scenes/lights/sun-slab.xml --spp $SPP --seed 11 --resolution 16x16 --backend cuda \
    --film "$OUT/sun-slab-gpu.vfilm" >"$OUT/sun-slab-analytic-render.log" 2>&1; then
    check "sun-slab-analytic-cuda" python3 "$ANALYTIC" "$OUT/sun-slab-gpu.vfilm" $SPP
else
    log "FAIL sun-slab analytic render: $(tail -n 2 "$OUT/sun-slab-analytic-render.log" | tr '\n' ' ')"
    failures=$((failures + 1))
fi

# 4. Speed: the lit kernel on spot-fog, the box kernel on the same fog without the spot.
python3 - "$OUT/fog-unlit.xml" <<'PY'
import re, sys
s = open("scenes/lights/spot-fog.xml").read()
s, n = re.subn(r'\s*<emitter type="spot">.*?</emitter>', "", s, flags=re.S)
assert n == 1, "spot-fog.xml has not the one spot this script removes"
open(sys.argv[1], "w").write(s.replace("<scene", "<!-- spot-fog.xml without its spot -->\n<scene", 1))
PY
cp scenes/lights/spot-fog.xml "$OUT/fog-lit.xml"
seg() { grep -o '[0-9.]* M segments/s' "$1" | head -n 1 | cut -d' ' -f1; }
speed=(--backend cuda --strategy regeneration-sk --spp 64 --resolution 256x256 --seed 1)
for kind in lit unlit; do
    RUST_LOG=volpt_cuda=info "$VOLPT" render "$OUT/fog-$kind.xml" "${speed[@]}" -o "$OUT/speed-$kind.exr" \
        >"$OUT/speed-$kind.log" 2>&1 || { log "FAIL speed $kind render: $(tail -n 2 "$OUT/speed-$kind.log" | tr '\n' ' ')"; failures=$((failures + 1)); }
done
# The default schedule (no --strategy: regeneration-sk with at most 64 registers) on the lit kernel:
# ptxas spills more there than in the box kernel (docs/gpu.md, kernel sets).
"$VOLPT" render "$OUT/fog-lit.xml" --backend cuda --spp 64 --resolution 256x256 --seed 1 -o "$OUT/speed-lit-default.exr" \
    >"$OUT/speed-lit-default.log" 2>&1 || { log "FAIL speed lit default render: $(tail -n 2 "$OUT/speed-lit-default.log" | tr '\n' ' ')"; failures=$((failures + 1)); }
lit=$(seg "$OUT/speed-lit.log"); unlit=$(seg "$OUT/speed-unlit.log"); capped=$(seg "$OUT/speed-lit-default.log")
log "failures: $failures"
log "speed (regeneration-sk, fast, 256x256x64): spot-fog $(grep -o 'lit__regeneration_sk' "$OUT/speed-lit.log" | head -n 1) ${lit:-?} M segments/s; without the spot $(grep -o 'regeneration_sk__homogeneous[a-z_]*' "$OUT/speed-unlit.log" | head -n 1) ${unlit:-?} M segments/s; ratio $(python3 -c "print(f'{float(\"${lit:-0}\")/float(\"${unlit:-1}\"):.3f}')" 2>/dev/null); lit with the default schedule (<= 64 registers) ${capped:-?} M segments/s"
[ "$failures" -eq 0 ]
