#!/usr/bin/env bash
# Issue 38's last parts on the device machine, from the bundle, in about a minute:
#
#   bash bundle/materials-s10.sh      # results under $OUT (default ./out), summary in $OUT/summary.txt
#
# 1. A density per channel (Mitsuba 3's RGB `sigma_t` gridvolume: a 24 x 24 x 8 density with
#    holes times (2, 5, 10) per channel, trilinear, constant albedo (0.9, 0.7, 0.5)):
#    a. CPU against the GPU strategies at the same seed, null boundary (path tracing and
#       next-event estimation) and rough dielectric (path tracing), 4 spp: naive-sk bit-identical
#       (`volpt compare --identical`), regeneration-sk, streaming-sk and sorting-sk to 1e-6;
#    b. the per-channel identity on the GPU: channel c of its film against the film of the grey
#       grid of channel c's coefficients (sigma-c.vol, albedo c), null boundary, path tracing and
#       next-event estimation, 64 x 64 pixels at SPP (1024) spp, independent seeds, pixel-paired z
#       (film_pair_z.py): |z| < 5, relative se about 3e-4.
# 2. 16-bit material indices: a 24 x 24 x 8 print of 300 materials (indices past 255 in every
#    layer, read from a raw u16 grid through [[materials]]), null boundary, path tracing and
#    next-event estimation, 4 spp: CPU against naive-sk bit-identical and regeneration-sk to 1e-6;
#    `volpt info` says 2 bytes a voxel.
# Expected: every summary line PASS, the last "failures 0" (26 PASS lines).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT/scenes"
VOLPT=${VOLPT:-$PWD/bin/volpt}
BACKEND=${BACKEND:-cuda}  # cpu: a dry run where there is no GPU (the CPU-against-GPU checks then compare the CPU with itself)
T=${T:-120}
SPP=${SPP:-1024}
failures=0
log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
check() { # check NAME CMD...
    local name=$1; shift
    if "$@" >"$OUT/$name.log" 2>&1; then log "PASS $name: $(tail -n 1 "$OUT/$name.log")"
    else log "FAIL $name: $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1)); fi
}
render() { # render NAME SCENE ARGS...: $OUT/NAME.exr, or a FAIL line
    local name=$1 scene=$2; shift 2
    if timeout "$T" "$VOLPT" render "$scene" "$@" -o "$OUT/$name.exr" >"$OUT/$name.render.log" 2>&1; then return 0; fi
    log "FAIL $name render: $(tail -n 2 "$OUT/$name.render.log" | tr '\n' ' ')"; failures=$((failures + 1)); return 1
}
against_cpu() { # against_cpu NAME SCENE "STRATEGIES" ARGS...: CPU against each strategy, 4 spp
    local name=$1 scene=$2 strategies=$3; shift 3
    render "$name-cpu" "$scene" --spp 4 --seed 7 "$@" || return
    for s in $strategies; do
        local backend=(--backend "$BACKEND" --math exact --strategy "$s")
        [ "$BACKEND" = cpu ] && backend=()
        render "$name-$s" "$scene" --spp 4 --seed 7 "${backend[@]}" "$@" || continue
        case $s in naive-sk | naive-mk) tol=(--identical) ;; *) tol=(--max-relative 1e-6) ;; esac
        check "$name-cpu-vs-$s" "$VOLPT" compare "$OUT/$name-cpu.exr" "$OUT/$name-$s.exr" "${tol[@]}"
    done
}
log "date $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null)"

python3 - "$OUT/scenes" <<'EOF'
import math, os, random, struct, sys
out = sys.argv[1]
nx, ny, nz = 24, 24, 8
box = (-1.6, -1.6, -0.5, 1.6, 1.6, 0.5)
rng = random.Random(5)
def density(x, y, z):
    p = [(x + 0.5) / nx - 0.5, (y + 0.5) / ny - 0.5, (z + 0.5) / nz - 0.5]
    if (x // 3 + y // 3 + z // 2) % 4 == 0:
        return 0.0  # holes: empty cells for the majorant grid
    return (0.2 + 0.8 * (0.5 + 0.5 * math.sin(6 * p[0] + 4 * p[1] * p[2]))) * (0.5 + 0.5 * rng.random())
d = [density(x, y, z) for z in range(nz) for y in range(ny) for x in range(nx)]
scales, albedo = (2.0, 5.0, 10.0), (0.9, 0.7, 0.5)
def vol(path, channels, values):
    with open(path, "wb") as f:
        f.write(b"VOL" + bytes([3]) + struct.pack("<iiiii", 1, nx, ny, nz, channels))
        f.write(struct.pack("<6f", *box) + struct.pack(f"<{len(values)}f", *values))
vol(os.path.join(out, "rgb.vol"), 3, [v * s for v in d for s in scales])
for c in range(3):
    vol(os.path.join(out, f"sigma-{c}.vol"), 1, [v * scales[c] for v in d])
to_world = ('<transform name="to_world"><scale x="3.2" y="3.2" z="1.0"/>'
            '<translate x="-1.6" y="-1.6" z="-0.5"/></transform>')
def scene(name, sigma_t, albedo, bsdf, integrator):
    open(os.path.join(out, name), "w").write(f"""<scene version="3.0.0">
    <integrator type="{integrator}"><integer name="max_depth" value="-1"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="30"/><string name="fov_axis" value="x"/>
        <transform name="to_world"><lookat origin="0, -5, 8" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="64"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1, 0.9, 0.8"/></emitter>
    <shape type="cube">
        <transform name="to_world"><scale x="1.6" y="1.6" z="0.5"/></transform>
        {bsdf}
        <medium type="heterogeneous" name="interior">
            <volume type="gridvolume" name="sigma_t"><string name="filename" value="{sigma_t}"/>{to_world}</volume>
            {albedo}
            <phase type="hg"><float name="g" value="0.4"/></phase>
        </medium>
    </shape>
</scene>
""")
null = '<bsdf type="null"/>'
rough = ('<bsdf type="roughdielectric"><string name="distribution" value="ggx"/><float name="alpha" value="0.2"/>'
         '<float name="int_ior" value="1.3"/></bsdf>')
rgb_albedo = '<rgb name="albedo" value="%g, %g, %g"/>' % albedo
scene("rgb-null.xml", "rgb.vol", rgb_albedo, null, "volpathmis")
scene("rgb-rough.xml", "rgb.vol", rgb_albedo, rough, "volpathmis")
for c in range(3):
    scene(f"grey-{c}.xml", f"sigma-{c}.vol", f'<float name="albedo" value="{albedo[c]}"/>', null, "volpath")

# 300 materials, material k of extinction about 2 + k / 30 and its own albedo; every layer holds
# indices past 255.
n = 300
index = [(x + 7 * y + 13 * z) * 37 % n for z in range(nz) for y in range(ny) for x in range(nx)]
assert max(index) > 255
open(os.path.join(out, "wide.raw"), "wb").write(struct.pack(f"<{len(index)}H", *index))
table = "".join(
    f'[[materials]]\nname = "m{k}"\nsigma_s = [{1 + k / 40:.4f}, {1.5 + k / 60:.4f}, {2.0:.4f}]\n'
    f'sigma_a = [{0.2 + (k % 7) / 10:.4f}, {0.1 + (k % 5) / 8:.4f}, {(k % 11) / 6:.4f}]\ng = 0.2\n'
    for k in range(n))
open(os.path.join(out, "wide.toml"), "w").write(
    '[volume]\nfile = "wide.raw"\nformat = "raw"\ntype = "u16"\nresolution = [24, 24, 8]\n'
    'bounds = [[-1.6, -1.6, -0.5], [1.6, 1.6, 0.5]]\n[boundary]\nbsdf = "null"\n'
    '[camera]\norigin = [0.0, -5.0, 8.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 30.0\n'
    '[film]\nwidth = 64\nheight = 64\n' + table)
EOF

# 1a. The density per channel: CPU against the strategies.
STRATEGIES=${STRATEGIES:-naive-sk regeneration-sk streaming-sk sorting-sk}
against_cpu rgb-null-pt "$OUT/scenes/rgb-null.xml" "$STRATEGIES" --estimator pt
against_cpu rgb-null-nee "$OUT/scenes/rgb-null.xml" "$STRATEGIES" --estimator nee
against_cpu rgb-rough-pt "$OUT/scenes/rgb-rough.xml" "$STRATEGIES" --estimator pt
"$VOLPT" info "$OUT/scenes/rgb-null.xml" >"$OUT/info-rgb.txt" 2>&1 && log "info: $OUT/info-rgb.txt"

# 1b. The per-channel identity on the GPU.
for estimator in pt nee; do
    timeout "$T" "$VOLPT" render "$OUT/scenes/rgb-null.xml" --estimator $estimator --spp "$SPP" --seed 31 --backend "$BACKEND" \
        --film "$OUT/rgb-$estimator.vfilm" >"$OUT/rgb-$estimator.log" 2>&1 \
        || { log "FAIL rgb-$estimator render: $(tail -n 2 "$OUT/rgb-$estimator.log" | tr '\n' ' ')"; failures=$((failures + 1)); continue; }
    for c in 0 1 2; do
        if timeout "$T" "$VOLPT" render "$OUT/scenes/grey-$c.xml" --estimator $estimator --spp "$SPP" --seed $((41 + c)) \
            --backend "$BACKEND" --film "$OUT/grey-$estimator-$c.vfilm" >"$OUT/grey-$estimator-$c.log" 2>&1; then
            check "rgb-identity-$estimator-channel-$c" python3 film_pair_z.py "$c" "$OUT/rgb-$estimator.vfilm" "$OUT/grey-$estimator-$c.vfilm"
        else
            log "FAIL grey-$estimator-$c render: $(tail -n 2 "$OUT/grey-$estimator-$c.log" | tr '\n' ' ')"; failures=$((failures + 1))
        fi
    done
done

# 2. 16-bit material indices.
against_cpu wide-pt "$OUT/scenes/wide.toml" "naive-sk regeneration-sk" --estimator pt
against_cpu wide-nee "$OUT/scenes/wide.toml" "naive-sk regeneration-sk" --estimator nee
"$VOLPT" info "$OUT/scenes/wide.toml" >"$OUT/info-wide.txt" 2>&1
check wide-info grep -E "300 materials.*|GPU memory" "$OUT/info-wide.txt"

log "failures $failures"
[ "$failures" -eq 0 ]
