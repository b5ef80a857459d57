#!/usr/bin/env bash
# Chromatic media's cost and the material-indexed volume's per-channel identity on the device
# machine, from the bundle (issue 38), in about a minute:
#
#   bash bundle/materials-cost.sh      # results under $OUT (default ./out), summary in $OUT/summary.txt
#
# 1. Cost per segment, chromatic against grey (`volpt bench`, regeneration-sk, fast math, 3
#    trials): scenes/chromatic/cube.xml and slab.xml against the same scenes with a grey medium
#    (the largest channel's sigma_t, the channels' mean albedo, `volpath`); ns per segment and
#    per tracking step of each into $OUT/cost.txt. With bin/volpt-base (main before per-channel
#    majorants) the chromatic scenes also before/after: the new estimator takes no null
#    collisions in these homogeneous media (fewer tracking steps), so after <= before expected.
# 2. The per-channel identity on the GPU for a material-indexed volume: a 16 x 16 x 6 print slab
#    of three materials (one g, which a grey medium can hold) against, per channel, the grey grid
#    medium of that channel's coefficients (nearest-sample .vol grids, `--lookup nearest`), path
#    tracing and next-event estimation, one film each of 64 x 64 pixels at SPP (1024) spp and
#    independent seeds: channel c of the chromatic film minus the grey film, pixel by pixel (each
#    pixel an independent pair, mean 0 where both are unbiased), z of the mean difference
#    (film_pair_z.py): |z| < 5 and the relative standard error printed (<= 1e-3 sees a 1% bias at
#    10 sigma).
# Expected: every summary line PASS, last line "failures 0"; cost.txt's chromatic/grey ratio per
# segment about 1.1-1.5 (the spectral MIS's three exponentials and rescaling per event).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT/scenes"
VOLPT=${VOLPT:-$PWD/bin/volpt}
BACKEND=${BACKEND:-cuda}  # cpu: a dry run of part 2 where there is no GPU
BASE=$PWD/bin/volpt-base
[ -f "$BASE.gz" ] && [ ! -f "$BASE" ] && gunzip -k "$BASE.gz"
T=${T:-120}
SPP=${SPP:-1024}
failures=0
log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
check() { # check NAME CMD...
    local name=$1; shift
    if "$@" >"$OUT/$name.log" 2>&1; then log "PASS $name: $(tail -n 1 "$OUT/$name.log")"
    else log "FAIL $name: $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1)); fi
}
log "date $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader)"

# 1. Cost per segment. The grey twins: the scene file with the medium's RGB sigma_t replaced by
# its largest channel and the albedo by the channels' mean.
CHROMATIC=${CHROMATIC:-scenes/chromatic}  # the bundle's copy of the tree's scenes/chromatic
python3 - "$OUT/scenes" "$CHROMATIC/cube.xml" "$CHROMATIC/slab.xml" <<'EOF'
import os, re, sys
out = sys.argv[1]
for path in sys.argv[2:]:
    text = open(path).read()
    def grey(name, reduce):
        global text
        m = re.search(r'<rgb name="%s" value="([^"]+)"/>' % name, text)
        v = [float(x) for x in m.group(1).replace(",", " ").split()]
        text = text.replace(m.group(0), '<float name="%s" value="%r"/>' % (name, reduce(v)))
    grey("sigma_t", max)
    grey("albedo", lambda v: sum(v) / 3)
    text = text.replace('type="volpathmis"', 'type="volpath"')
    open(os.path.join(out, "grey-" + os.path.basename(path)), "w").write(text)
EOF
bench() { # bench BIN SCENE LABEL
    timeout 300 "$1" bench "$2" --spp 64 --backend cuda --strategy regeneration-sk --math fast --trials 3 2>&1 \
        | tail -n 1 | sed "s|^|$3: |" >>"$OUT/cost.txt"
}
for scene in cube slab; do
    bench "$VOLPT" "$CHROMATIC/$scene.xml" "$scene chromatic after"
    bench "$VOLPT" "$OUT/scenes/grey-$scene.xml" "$scene grey after"
    [ -x "$BASE" ] && bench "$BASE" "$CHROMATIC/$scene.xml" "$scene chromatic before"
done
# ns per segment and per step from the "M segments/s" and "M steps/s" columns.
python3 - "$OUT/cost.txt" <<'EOF' | tee -a "$OUT/cost.txt"
import re, sys
rows = {}
for line in open(sys.argv[1]):
    m = re.match(r"(\w+ \w+ \w+):.*?([\d.]+) M segments/s\s+([\d.]+) M steps/s", line)
    if m:
        rows[m.group(1)] = (1e3 / float(m.group(2)), 1e3 / float(m.group(3)))
for key, (seg, step) in rows.items():
    print(f"{key}: {seg:.3f} ns/segment {step:.3f} ns/step")
for scene in ("cube", "slab"):
    c, g = rows.get(f"{scene} chromatic after"), rows.get(f"{scene} grey after")
    if c and g:
        print(f"{scene}: chromatic/grey per segment {c[0] / g[0]:.2f}")
    b = rows.get(f"{scene} chromatic before")
    if c and b:
        print(f"{scene}: chromatic after/before per segment {c[0] / b[0]:.2f}")
EOF
log "cost per segment: $OUT/cost.txt ($(grep -c 'ns/segment' "$OUT/cost.txt") rows)"

# 2. The indexed slab and each channel's grey grids (Mitsuba VOL v3, cell-centred over the box).
python3 - "$OUT/scenes" <<'EOF'
import os, struct, sys
out = sys.argv[1]
nx, ny, nz = 16, 16, 6
box = (-1.6, -1.6, -0.6, 1.6, 1.6, 0.6)
# sigma_s, sigma_a per channel: cyan, magenta, white resins (one g: 0.3).
materials = [([4.0, 6.0, 7.0], [6.0, 0.8, 0.2]), ([6.0, 4.0, 6.5], [0.3, 5.0, 0.6]),
             ([12.0, 12.0, 12.0], [0.02, 0.03, 0.05])]
index = [((x // 4) + (y // 4) + z // 2) % 3 for z in range(nz) for y in range(ny) for x in range(nx)]
open(os.path.join(out, "print.raw"), "wb").write(bytes(index))
def vol(path, channels, values):
    with open(path, "wb") as f:
        f.write(b"VOL" + bytes([3]) + struct.pack("<iiiii", 1, nx, ny, nz, channels))
        f.write(struct.pack("<6f", *box) + struct.pack(f"<{len(values)}f", *values))
for c in range(3):
    t = [materials[k][0][c] + materials[k][1][c] for k in index]
    a = [materials[k][0][c] / (materials[k][0][c] + materials[k][1][c]) for k in index]
    vol(os.path.join(out, f"sigma-{c}.vol"), 1, t)
    vol(os.path.join(out, f"albedo-{c}.vol"), 3, [v for x in a for v in (x, x, x)])
table = "".join(f'[[materials]]\nname = "m{k}"\nsigma_s = {s}\nsigma_a = {a}\ng = 0.3\n'
                for k, (s, a) in enumerate(materials))
camera = "[camera]\norigin = [0.0, -4.0, 8.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 30.0\n[film]\nwidth = 64\nheight = 64\n"
open(os.path.join(out, "print.toml"), "w").write(
    '[volume]\nfile = "print.raw"\nformat = "raw"\ntype = "u8"\nresolution = [16, 16, 6]\n'
    'bounds = [[-1.6, -1.6, -0.6], [1.6, 1.6, 0.6]]\n[boundary]\nbsdf = "null"\n'
    '[integrator]\nmax_depth = -1\nrr_depth = -1\n' + camera + table)
# Mitsuba 3 places a grid's cell centres over [0, 1]^3, which to_world takes to the box.
to_world = ('<transform name="to_world"><scale x="3.2" y="3.2" z="1.2"/>'
            '<translate x="-1.6" y="-1.6" z="-0.6"/></transform>')
for c in range(3):
    open(os.path.join(out, f"grey-print-{c}.xml"), "w").write(f"""<scene version="3.0.0">
    <integrator type="volpath"><integer name="max_depth" value="-1"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="30"/><string name="fov_axis" value="x"/>
        <transform name="to_world"><lookat origin="0, -4, 8" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="64"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
    <shape type="cube">
        <transform name="to_world"><scale x="1.6" y="1.6" z="0.6"/></transform>
        <bsdf type="null"/>
        <medium type="heterogeneous" name="interior">
            <volume type="gridvolume" name="sigma_t"><string name="filename" value="sigma-{c}.vol"/>
                <string name="filter_type" value="nearest"/>{to_world}</volume>
            <volume type="gridvolume" name="albedo"><string name="filename" value="albedo-{c}.vol"/>
                <string name="filter_type" value="nearest"/>{to_world}</volume>
            <phase type="hg"><float name="g" value="0.3"/></phase>
        </medium>
    </shape>
</scene>
""")
EOF
"$VOLPT" info "$OUT/scenes/print.toml" >"$OUT/info-print.txt" 2>&1
for estimator in pt nee; do
    timeout "$T" "$VOLPT" render "$OUT/scenes/print.toml" --estimator $estimator --spp "$SPP" --seed 31 --backend "$BACKEND" \
        --film "$OUT/print-$estimator.vfilm" >"$OUT/print-$estimator.log" 2>&1 \
        || { log "FAIL print-$estimator render: $(tail -n 2 "$OUT/print-$estimator.log" | tr '\n' ' ')"; failures=$((failures + 1)); continue; }
    for c in 0 1 2; do
        if timeout "$T" "$VOLPT" render "$OUT/scenes/grey-print-$c.xml" --estimator $estimator --lookup nearest --spp "$SPP" \
            --seed $((41 + c)) --backend "$BACKEND" --film "$OUT/grey-$estimator-$c.vfilm" >"$OUT/grey-$estimator-$c.log" 2>&1; then
            check "indexed-identity-$estimator-channel-$c" python3 film_pair_z.py "$c" "$OUT/print-$estimator.vfilm" "$OUT/grey-$estimator-$c.vfilm"
        else
            log "FAIL grey-$estimator-$c render: $(tail -n 2 "$OUT/grey-$estimator-$c.log" | tr '\n' ' ')"; failures=$((failures + 1))
        fi
    done
done
log "failures $failures"
[ "$failures" -eq 0 ]
