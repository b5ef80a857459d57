#!/usr/bin/env bash
# The orthographic sensor on the device machine, from the bundle (issue 40; no cargo needed):
#
#   bash bundle/orthographic.sh      # results under $OUT (default ./out), summary in $OUT/summary.txt
#
# The sensor is a run-time branch of the camera every kernel shares (no new kernel variant), so
# the GPU must give the CPU's image: a slab seen straight down by Mitsuba 3's `orthographic` sensor
# (a dielectric surface, a homogeneous medium; and the thesis's cgg-logo grid behind a rough
# dielectric, seen by an orthographic sensor of a non-square film),
# CPU against GPU strategies at the same seed: naive-sk and naive-mk bit-identical
# (`volpt compare --identical`), the others to 1e-6; fast math against exact math as independent
# estimates (`--independent`). The CPU's images are tested analytically by `cargo test` (volpt-core
# camera, tests/orthographic.rs, volpt-print predict.rs).
# Expected: every line of summary.txt PASS ("failures 0" last), in well under a minute.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT/scenes"
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

cat >"$OUT/scenes/slab.xml" <<'EOF'
<scene version="3.0.0">
    <integrator type="volpath"><integer name="max_depth" value="-1"/></integrator>
    <sensor type="orthographic">
        <transform name="to_world"><scale value="2"/><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="32"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
    <shape type="cube">
        <transform name="to_world"><scale x="10" y="10" z="0.1"/></transform>
        <bsdf type="dielectric"><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/></bsdf>
        <medium type="homogeneous" name="interior">
            <float name="sigma_t" value="5"/>
            <rgb name="albedo" value="0.9, 0.6, 0.3"/>
        </medium>
    </shape>
</scene>
EOF
# The thesis's cgg-logo cube (a 100^3 grid behind a rough dielectric), its sensor made
# orthographic: a 40 x 30 film 1.6 x 1.2 units wide, beside the scene so its grid paths resolve.
"$VOLPT" scene generate scenes >/dev/null
ortho=scenes/cgg-logo/orthographic.xml
python3 - scenes/cgg-logo/scene.xml "$ortho" <<'EOF'
import re, sys
text = open(sys.argv[1]).read()
sensor = re.search(r'<sensor type="perspective">.*?</sensor>', text, re.S).group(0)
new = sensor.replace('type="perspective"', 'type="orthographic"')
new = re.sub(r'\s*<float name="fov"[^>]*/>', '', new)
new = re.sub(r'(<transform name="to_world">)', r'\1<scale x="0.8" y="0.8" z="1"/>', new, count=1)
new = re.sub(r'(<integer name="width" value=")[^"]*"', r'\g<1>40"', new)
new = re.sub(r'(<integer name="height" value=")[^"]*"', r'\g<1>30"', new)
assert 'orthographic' in new and 'fov' not in new, new
open(sys.argv[2], "w").write(text.replace(sensor, new))
EOF
SCENES=("$OUT/scenes/slab.xml" "$ortho")
STRATEGIES=(${STRATEGIES:-naive-sk regeneration-sk streaming-sk naive-mk streaming-mk})
for scene in "${SCENES[@]}"; do
    name=$(basename "$(dirname "$scene")")-$(basename "$scene" .xml)
    "$VOLPT" info "$scene" >"$OUT/$name-info.txt" 2>&1
    if ! "$VOLPT" render "$scene" --spp 4 --seed 7 -o "$OUT/$name-cpu.exr" >"$OUT/$name-cpu.log" 2>&1; then
        log "FAIL $name cpu render: $(tail -n 2 "$OUT/$name-cpu.log" | tr '\n' ' ')"; failures=$((failures + 1)); continue
    fi
    for s in "${STRATEGIES[@]}"; do
        if timeout "$T" "$VOLPT" render "$scene" --spp 4 --seed 7 --backend cuda --math exact --strategy "$s" \
            -o "$OUT/$name-$s.exr" >"$OUT/$name-$s.log" 2>&1; then
            case $s in naive-sk | naive-mk) tol=--identical ;; *) tol="--max-relative 1e-6" ;; esac
            # shellcheck disable=SC2086
            check "$name-cpu-vs-$s" "$VOLPT" compare "$OUT/$name-cpu.exr" "$OUT/$name-$s.exr" $tol
        else
            log "FAIL $name $s render: $(tail -n 2 "$OUT/$name-$s.log" | tr '\n' ' ')"; failures=$((failures + 1))
        fi
    done
    if timeout "$T" "$VOLPT" render "$scene" --spp 256 --seed 11 --backend cuda --math exact -o "$OUT/$name-exact.exr" >/dev/null 2>&1 \
        && timeout "$T" "$VOLPT" render "$scene" --spp 256 --seed 12 --backend cuda --math fast -o "$OUT/$name-fast.exr" >/dev/null 2>&1; then
        check "$name-exact-vs-fast" "$VOLPT" compare "$OUT/$name-exact.exr" "$OUT/$name-fast.exr" --independent
    else
        log "FAIL $name fast-math renders"; failures=$((failures + 1))
    fi
done
log "failures $failures"
[ "$failures" -eq 0 ]
