#!/usr/bin/env bash
# Material-indexed volumes on the device machine, from the bundle (issue 38):
#
#   bash bundle/materials.sh      # results under $OUT (default ./out), summary in $OUT/summary.txt
#
# 1. An indexed CMYKW print slab (a 48 x 48 x 12 u8 index grid of five resins, read from a raw
#    file through [[materials]]) and the same slab as a PNG slice stack: CPU against every GPU
#    strategy at the same seed, behind each boundary kind, path tracing and next-event
#    estimation: naive-sk and naive-mk bit-identical (`volpt compare --identical`), the others to
#    1e-6; fast math against exact math as independent estimates (`--independent`); the raw file
#    and the slice stack render the same image bit for bit (CPU);
# 2. a grid of one material everywhere against the chromatic cube of that material (the same
#    scene spelled as a homogeneous medium): independent estimates (`--independent`);
# 3. the grey scenes' A/B (no slowdown from the spectral state's and the material branch's
#    changes): bin/volpt-base (main before the change) against bin/volpt on the included scenes,
#    regeneration-sk, streaming-sk and streaming-mk (the path-parking strategies, whose path
#    state shrank), exact and fast math, `volpt bench --trials 5`, two rounds interleaved.
# Expected: every line of summary.txt PASS ("failures 0" last); the A/B table's after/before
# ratios within noise (~2%), or faster on the path-parking strategies.
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT/scenes"
VOLPT=$PWD/bin/volpt
BASE=$PWD/bin/volpt-base
[ -f "$BASE.gz" ] && [ ! -f "$BASE" ] && gunzip -k "$BASE.gz"
T=${T:-120}
failures=0
log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
check() { # check NAME CMD...
    local name=$1; shift
    if "$@" >"$OUT/$name.log" 2>&1; then log "PASS $name: $(tail -n 1 "$OUT/$name.log")"
    else log "FAIL $name: $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1)); fi
}
log "date $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader)"

# The print slab: five resins (cyan, magenta, yellow, black, white; coefficients per mm of the
# order of Elek et al. 2017's) in a pattern of coloured squares over a white base; as raw u8 and
# as PNG slices (stdlib zlib, one slice per layer, palette colours naming the resins).
python3 - "$OUT/scenes" <<'EOF'
import struct, sys, zlib, os
out = sys.argv[1]
nx, ny, nz = 48, 48, 12
palette = [(0, 255, 255), (255, 0, 255), (255, 255, 0), (0, 0, 0), (255, 255, 255)]
def index(x, y, z):
    if z < 4:
        return 4                                  # white base
    return ((x // 12) + 2 * (y // 12) + z // 4) % 5
raw = bytes(index(x, y, z) for z in range(nz) for y in range(ny) for x in range(nx))
open(os.path.join(out, "slab.raw"), "wb").write(raw)
open(os.path.join(out, "one.raw"), "wb").write(bytes([1]) * (nx * ny * nz))
os.makedirs(os.path.join(out, "slices"), exist_ok=True)
def chunk(kind, data):
    c = kind + data
    return struct.pack(">I", len(data)) + c + struct.pack(">I", zlib.crc32(c) & 0xffffffff)
for z in range(nz):
    rows = b"".join(b"\0" + bytes(v for x in range(nx) for v in palette[index(x, y, z)]) for y in range(ny))
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", nx, ny, 8, 2, 0, 0, 0)) \
        + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")
    open(os.path.join(out, "slices", f"layer{z}.png"), "wb").write(png)
EOF
MATERIALS='
[[materials]]
name = "cyan"
sigma_s = [4.0, 6.0, 7.0]
sigma_a = [6.0, 0.8, 0.2]
g = 0.3
colour = [0, 255, 255]
[[materials]]
name = "magenta"
sigma_s = [6.0, 4.0, 6.5]
sigma_a = [0.3, 5.0, 0.6]
g = 0.3
colour = [255, 0, 255]
[[materials]]
name = "yellow"
sigma_s = [7.0, 6.5, 4.0]
sigma_a = [0.1, 0.4, 5.5]
g = 0.3
colour = [255, 255, 0]
[[materials]]
name = "black"
sigma_s = [1.0, 1.0, 1.0]
sigma_a = [9.0, 9.0, 9.0]
g = 0.0
colour = [0, 0, 0]
[[materials]]
name = "white"
sigma_s = [12.0, 12.0, 12.0]
sigma_a = [0.02, 0.03, 0.05]
g = -0.2
colour = [255, 255, 255]
'
slab() { # slab FILE VOLUME_LINES BOUNDARY_LINES
    cat >"$1" <<EOF
[volume]
$2
[boundary]
$3
[camera]
origin = [0.0, -14.0, 30.0]
target = [0.0, 0.0, 0.0]
fov = 35.0
[film]
width = 64
height = 64
$MATERIALS
EOF
}
RAW='file = "slab.raw"
format = "raw"
type = "u8"
resolution = [48, 48, 12]
bounds = [[-4.8, -4.8, -1.2], [4.8, 4.8, 1.2]]'
SLICES='file = "slices"
format = "png"
voxel_size = [0.2, 0.2, 0.2]'
BOUNDARIES=("null:bsdf = \"null\"" "smooth:bsdf = \"dielectric\"" "rough:bsdf = \"roughdielectric\"")
STRATEGIES=(${STRATEGIES:-naive-sk regeneration-sk regeneration-warp-sk regeneration-block-sk regeneration-2p-sk streaming-sk streaming-sorted-sk sorting-sk naive-mk streaming-mk})
for entry in "${BOUNDARIES[@]}"; do
    name=${entry%%:*}; boundary=${entry#*:}
    scene="$OUT/scenes/slab-$name.toml"
    slab "$scene" "$RAW" "$boundary"
    slab "$OUT/scenes/slices-$name.toml" "$SLICES" "$boundary"
    for estimator in pt nee; do
        [ "$name" = smooth ] && [ $estimator = nee ] && continue
        extra=""; [ $estimator = nee ] && extra="--estimator nee"
        # shellcheck disable=SC2086
        "$VOLPT" render "$scene" $extra --spp 4 --seed 7 -o "$OUT/$name-$estimator-cpu.exr" >"$OUT/$name-$estimator-cpu.log" 2>&1 \
            || { log "FAIL slab-$name-$estimator cpu render: $(tail -n 2 "$OUT/$name-$estimator-cpu.log" | tr '\n' ' ')"; failures=$((failures + 1)); continue; }
        # shellcheck disable=SC2086
        "$VOLPT" render "$OUT/scenes/slices-$name.toml" $extra --spp 4 --seed 7 -o "$OUT/$name-$estimator-slices.exr" >/dev/null 2>&1
        check "slab-$name-$estimator-raw-vs-slices" "$VOLPT" compare "$OUT/$name-$estimator-cpu.exr" "$OUT/$name-$estimator-slices.exr" --identical
        for s in "${STRATEGIES[@]}"; do
            # shellcheck disable=SC2086
            if timeout "$T" "$VOLPT" render "$scene" $extra --spp 4 --seed 7 --backend cuda --math exact --strategy "$s" \
                -o "$OUT/$name-$estimator-$s.exr" >"$OUT/$name-$estimator-$s.log" 2>&1; then
                case $s in naive-sk | naive-mk) tol=--identical ;; *) tol="--max-relative 1e-6" ;; esac
                # shellcheck disable=SC2086
                check "slab-$name-$estimator-cpu-vs-$s" "$VOLPT" compare "$OUT/$name-$estimator-cpu.exr" "$OUT/$name-$estimator-$s.exr" $tol
            else
                log "FAIL slab-$name-$estimator $s render: $(tail -n 2 "$OUT/$name-$estimator-$s.log" | tr '\n' ' ')"
                failures=$((failures + 1))
            fi
        done
        # shellcheck disable=SC2086
        if timeout "$T" "$VOLPT" render "$scene" $extra --spp 64 --seed 11 --backend cuda --math exact -o "$OUT/$name-$estimator-exact.exr" >/dev/null 2>&1 \
            && timeout "$T" "$VOLPT" render "$scene" $extra --spp 64 --seed 12 --backend cuda --math fast -o "$OUT/$name-$estimator-fast.exr" >/dev/null 2>&1; then
            check "slab-$name-$estimator-exact-vs-fast" "$VOLPT" compare "$OUT/$name-$estimator-exact.exr" "$OUT/$name-$estimator-fast.exr" --independent
        else
            log "FAIL slab-$name-$estimator fast-math renders"; failures=$((failures + 1))
        fi
    done
done
"$VOLPT" info "$OUT/scenes/slab-null.toml" >"$OUT/info-slab.txt" 2>&1 && log "info: $OUT/info-slab.txt (material table and memory)"

# One material everywhere (magenta) against the homogeneous chromatic slab of magenta (Mitsuba
# 0.6 spelling of its coefficients; the same box, camera and film): independent estimates.
one="$OUT/scenes/one.toml"
slab "$one" "${RAW/slab.raw/one.raw}" 'bsdf = "null"'
cat >"$OUT/scenes/one.xml" <<'EOF'
<scene version="0.6.0">
    <integrator type="volpath"><integer name="maxDepth" value="-1"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="35"/>
        <transform name="toWorld"><lookat origin="0, -14, 30" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="64"/></film>
    </sensor>
    <emitter type="constant"><spectrum name="radiance" value="1"/></emitter>
    <shape type="cube">
        <transform name="toWorld"><scale x="4.8" y="4.8" z="1.2"/></transform>
        <bsdf type="null"/>
        <medium type="homogeneous" name="interior">
            <rgb name="sigmaS" value="6.0, 4.0, 6.5"/>
            <rgb name="sigmaA" value="0.3, 5.0, 0.6"/>
            <phase type="hg"><float name="g" value="0.3"/></phase>
        </medium>
    </shape>
</scene>
EOF
if timeout "$T" "$VOLPT" render "$one" --spp 256 --seed 21 --backend cuda -o "$OUT/one-indexed.exr" >"$OUT/one-indexed.log" 2>&1 \
    && timeout "$T" "$VOLPT" render "$OUT/scenes/one.xml" --spp 256 --seed 22 --backend cuda -o "$OUT/one-homogeneous.exr" >"$OUT/one-homogeneous.log" 2>&1; then
    check "one-material-vs-homogeneous" "$VOLPT" compare "$OUT/one-indexed.exr" "$OUT/one-homogeneous.exr" --independent
else
    log "FAIL one-material renders: $(tail -n 2 "$OUT/one-indexed.log" "$OUT/one-homogeneous.log" | tr '\n' ' ')"; failures=$((failures + 1))
fi

# Grey scenes must not get slower: main before the change against this binary, same session.
if [ -x "$BASE" ]; then
    "$VOLPT" scene generate scenes >/dev/null
    for entry in homogeneous-cube:scenes/homogeneous-cube/scene.xml cgg-logo:scenes/cgg-logo/scene.xml; do
        name=${entry%%:*}; file=${entry#*:}
        for s in regeneration-sk streaming-sk streaming-mk; do
            for math in exact fast; do
                for round in 1 2; do
                    for bin in "$BASE" "$VOLPT"; do
                        timeout 300 "$bin" bench "$file" --spp 100 --backend cuda --strategy "$s" --math "$math" \
                            --trials 5 2>&1 | tail -n 1 | sed "s|^|$name $s $math round $round $(basename "$bin"): |" >>"$OUT/ab.txt"
                    done
                done
            done
        done
    done
    log "A/B grey scenes: $OUT/ab.txt"
else
    log "SKIP A/B: no bin/volpt-base (main at ca0b929) in the bundle"
fi
log "failures $failures"
[ "$failures" -eq 0 ]
