#!/usr/bin/env bash
# Chromatic extinction on the device machine, from the bundle (issue 38):
#
#   bash bundle/chromatic.sh      # results under $OUT (default ./out), summary in $OUT/summary.txt
#
# 1. CPU vs every GPU strategy at the same seed on chromatic scenes (a homogeneous cube with
#    sigma_t channels 5x apart behind each boundary kind, path tracing and next-event estimation):
#    naive-sk and naive-mk bit-identical (`volpt compare --identical`), the others to 1e-6;
#    fast math against exact math as independent estimates;
# 2. the per-channel identity on the GPU: channel c of the chromatic render against the grey
#    render with channel c's coefficients, FILMS (16) films of FILM_SPP (256) spp and independent
#    seeds each, Welch's z over the films' channel means (chromatic_channel.py): |z| < 5, and it
#    prints the relative standard error (<= 1e-3 sees a 1% bias at 10 sigma);
# 3. the grey scenes' A/B (no slowdown): bin/volpt-base (main before the change) against bin/volpt
#    on the included scenes, regeneration-sk, exact and fast math, `volpt bench --trials 5`.
# Expected: every line of summary.txt PASS; the A/B table's after/before ratios within noise (~2%).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=$PWD/bin/volpt
BASE=$PWD/bin/volpt-base
[ -f "$BASE.gz" ] && [ ! -f "$BASE" ] && gunzip -k "$BASE.gz"
T=${T:-120}
FILMS=${FILMS:-16}
FILM_SPP=${FILM_SPP:-256}
failures=0
log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
check() { # check NAME CMD...
    local name=$1; shift
    if "$@" >"$OUT/$name.log" 2>&1; then log "PASS $name: $(tail -n 1 "$OUT/$name.log")"
    else log "FAIL $name: $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1)); fi
}
log "date $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader)"

# A cube of the given medium lines behind a boundary (Mitsuba 3 spelling: RGB in [0, 1] x scale).
cube() { # cube FILE BSDF MEDIUM_LINES INTEGRATOR
    cat >"$1" <<EOF
<scene version="3.0.0">
    <integrator type="$4"><integer name="max_depth" value="-1"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="64"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1, 0.9, 0.8"/></emitter>
    <shape type="cube">
        $2
        <medium type="homogeneous" name="interior">
            $3
            <phase type="hg"><float name="g" value="0.3"/></phase>
        </medium>
    </shape>
</scene>
EOF
}
mkdir -p "$OUT/scenes"
CHROMATIC='<rgb name="sigma_t" value="0.2, 0.5, 1"/><float name="scale" value="5"/><rgb name="albedo" value="0.95, 0.9, 0.85"/>'
BSDFS=("null:<bsdf type=\"null\"/>" "smooth:<bsdf type=\"dielectric\"><float name=\"int_ior\" value=\"1.33\"/></bsdf>"
    "rough:<bsdf type=\"roughdielectric\"><string name=\"distribution\" value=\"ggx\"/><float name=\"alpha\" value=\"0.3\"/><float name=\"int_ior\" value=\"1.5\"/></bsdf>")
STRATEGIES=(${STRATEGIES:-naive-sk regeneration-sk regeneration-warp-sk regeneration-block-sk regeneration-2p-sk streaming-sk streaming-sorted-sk sorting-sk naive-mk streaming-mk})
for entry in "${BSDFS[@]}"; do
    name=${entry%%:*}; bsdf=${entry#*:}
    for estimator in pt nee; do
        # A smooth dielectric rules next-event estimation out.
        [ "$name" = smooth ] && [ $estimator = nee ] && continue
        scene="$OUT/scenes/chromatic-$name-$estimator.xml"
        integrator=volpathmis
        cube "$scene" "$bsdf" "$CHROMATIC" "$integrator"
        extra=""; [ $estimator = nee ] && extra="--estimator nee"
        # shellcheck disable=SC2086
        "$VOLPT" render "$scene" $extra --spp 4 --seed 7 -o "$OUT/$name-$estimator-cpu.exr" >"$OUT/$name-$estimator-cpu.log" 2>&1 \
            || { log "FAIL $name-$estimator cpu render"; failures=$((failures + 1)); continue; }
        for s in "${STRATEGIES[@]}"; do
            # shellcheck disable=SC2086
            if timeout "$T" "$VOLPT" render "$scene" $extra --spp 4 --seed 7 --backend cuda --math exact --strategy "$s" \
                -o "$OUT/$name-$estimator-$s.exr" >"$OUT/$name-$estimator-$s.log" 2>&1; then
                case $s in naive-sk | naive-mk) tol=--identical ;; *) tol="--max-relative 1e-6" ;; esac
                # shellcheck disable=SC2086
                check "chromatic-$name-$estimator-cpu-vs-$s" "$VOLPT" compare "$OUT/$name-$estimator-cpu.exr" "$OUT/$name-$estimator-$s.exr" $tol
            else
                log "FAIL chromatic-$name-$estimator $s render: $(tail -n 2 "$OUT/$name-$estimator-$s.log" | tr '\n' ' ')"
                failures=$((failures + 1))
            fi
        done
        # shellcheck disable=SC2086
        if timeout "$T" "$VOLPT" render "$scene" $extra --spp 64 --seed 11 --backend cuda --math exact -o "$OUT/$name-$estimator-exact.exr" >/dev/null 2>&1 \
            && timeout "$T" "$VOLPT" render "$scene" $extra --spp 64 --seed 12 --backend cuda --math fast -o "$OUT/$name-$estimator-fast.exr" >/dev/null 2>&1; then
            check "chromatic-$name-$estimator-exact-vs-fast" "$VOLPT" compare "$OUT/$name-$estimator-exact.exr" "$OUT/$name-$estimator-fast.exr" --independent
        else
            log "FAIL chromatic-$name-$estimator fast-math renders"; failures=$((failures + 1))
        fi
        # Per-channel identity on the GPU: channel c against the grey medium of channel c, films
        # of FILMS independent seeds each (chromatic_channel.py).
        films() { # films SCENE PREFIX SEED0
            for k in $(seq 0 $((FILMS - 1))); do
                # shellcheck disable=SC2086
                timeout "$T" "$VOLPT" render "$1" $extra --spp "$FILM_SPP" --seed $(($3 + k)) --backend cuda \
                    --film "$2-$k.vfilm" >/dev/null 2>&1
            done
        }
        films "$scene" "$OUT/chromatic-$name-$estimator" 200
        for c in 0 1 2; do
            sigma=$(python3 -c "print([1.0, 2.5, 5.0][$c])"); albedo=$(python3 -c "print([0.95, 0.9, 0.85][$c])")
            grey="$OUT/scenes/grey-$name-$estimator-$c.xml"
            cube "$grey" "$bsdf" "<float name=\"sigma_t\" value=\"$sigma\"/><rgb name=\"albedo\" value=\"$albedo, $albedo, $albedo\"/>" volpath
            films "$grey" "$OUT/grey-$name-$estimator-$c" $((300 + 100 * c))
            check "identity-$name-$estimator-channel-$c" python3 chromatic_channel.py "$c" \
                "$OUT/chromatic-$name-$estimator"-*.vfilm -- "$OUT/grey-$name-$estimator-$c"-*.vfilm
        done
    done
done

# Grey scenes must not get slower: main before the change against this binary, same session.
if [ -x "$BASE" ]; then
    "$VOLPT" scene generate scenes >/dev/null
    for entry in homogeneous-cube:scenes/homogeneous-cube/scene.xml cgg-logo:scenes/cgg-logo/scene.xml; do
        name=${entry%%:*}; file=${entry#*:}
        for math in exact fast; do
            for round in 1 2; do
                for bin in "$BASE" "$VOLPT"; do
                    timeout 300 "$bin" bench "$file" --spp 100 --backend cuda --strategy regeneration-sk --math "$math" \
                        --trials 5 2>&1 | tail -n 1 | sed "s|^|$name $math round $round $(basename "$bin"): |" >>"$OUT/ab.txt"
                done
            done
        done
    done
    log "A/B grey scenes: $OUT/ab.txt"
else
    log "SKIP A/B: no bin/volpt-base (main at 02bb40f) in the bundle"
fi
log "failures $failures"
[ "$failures" -eq 0 ]
