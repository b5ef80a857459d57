#!/usr/bin/env bash
# Mesh boundaries' GPU speed and exactness (issue 39), on the device host with the stripped `volpt`
# binary only (no cargo): one call, about 60 s.
#
#   bash bench/device/mesh-speed.sh        -> $OUT/mesh-speed.txt
#
# 1. Segments/s of each mesh scene against its box scene, rendered one after the other (after a
#    warm-up render of each for the JIT): homogeneous-cube vs mesh-cube (its box as a mesh),
#    cgg-logo vs its box as a mesh (`--lookup trilinear`: the mesh kernels' dense grids), and
#    homogeneous-cube vs a latitude-longitude sphere of 1,000,000 triangles (501 rings x 1000,
#    written by python3 as a binary PLY) holding the same medium; each under regeneration-sk
#    (uncapped registers), the defaults (fast math, <= 64 registers) and the defaults with
#    `--math exact`. Issue 39 asks >= 0.8 for the first two, >= 0.5 for the third.
# 2. Exactness of the mesh kernels (naive-sk, `--math exact`) against the CPU, bit for bit:
#    mesh-cube on the GPU against homogeneous-cube's box on the CPU, the 16k-triangle sphere, and
#    the Mitsuba peer torus under its environment map (the lat-long mesh kernels).
# Expected: nine "ratio" lines (session 13: 0.18-0.35 for the cubes, 0.011-0.023 for the 1M
# sphere, H200) and three "identical" lines; no line starts with FAIL.
set -uo pipefail
cd "$(dirname "$0")"
[ -d scenes ] || cd ../..
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=${VOLPT:-$PWD/bin/volpt}
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
log() { echo "$@" | tee -a "$OUT/mesh-speed.txt"; }
: >"$OUT/mesh-speed.txt"
log "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null | head -n 1)"
seg() { grep -o '[0-9.]* M segments/s' "$1" | head -n 1 | cut -d' ' -f1; }

"$VOLPT" scene generate scenes >/dev/null 2>&1 || log "FAIL scene generate"
python3 - <<'PY'
import re
s = open("scenes/cgg-logo/scene.xml").read()
s, n = re.subn(r'<shape type="cube">\s*<transform name="to_world">\s*<scale value="0.5"/>\s*</transform>',
              '<shape type="obj"><string name="filename" value="../mesh-cube/box.obj"/>'
              '<boolean name="face_normals" value="true"/>', s)
assert n == 1, "cgg-logo's shape is not the cube this script expects"
open("scenes/cgg-logo/mesh.xml", "w").write(s)
PY
python3 - "$W/sphere.ply" <<'PY'
import math, sys
from array import array
rings, segments = 501, 1000
v = array("f")
v.extend((0.0, 0.0, 0.5))
for i in range(1, rings):
    t = math.pi * i / rings
    s, c = 0.5 * math.sin(t), 0.5 * math.cos(t)
    for j in range(segments):
        p = 2 * math.pi * j / segments
        v.extend((s * math.cos(p), s * math.sin(p), c))
v.extend((0.0, 0.0, -0.5))
south = len(v) // 3 - 1
ring = lambda i, j: 1 + (i - 1) * segments + j % segments
f = array("i")
for j in range(segments):
    f.extend((0, ring(1, j), ring(1, j + 1)))
for i in range(1, rings - 1):
    for j in range(segments):
        a, b, c, d = ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)
        f.extend((a, b, c, a, c, d))
for j in range(segments):
    f.extend((ring(rings - 1, j), south, ring(rings - 1, j + 1)))
if sys.byteorder != "little":
    v.byteswap(); f.byteswap()
n = len(f) // 3
with open(sys.argv[1], "wb") as out:
    out.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(v) // 3}\n"
               "property float x\nproperty float y\nproperty float z\n"
               f"element face {n}\nproperty list uchar int vertex_indices\nend_header\n").encode())
    out.write(v.tobytes())
    fb = f.tobytes()
    out.write(b"".join(b"\x03" + fb[12 * k:12 * k + 12] for k in range(n)))
PY
# face_normals: the mesh kernels refract at the triangles' own normals (a dielectric obj or ply
# without it is shaded with vertex normals, as in Mitsuba, which only the CPU renders).
sed -e 's|<shape type="sphere">|<shape type="ply"><string name="filename" value="'"$W"'/sphere.ply"/><boolean name="face_normals" value="true"/>|' \
    -e '/<float name="radius" value="0.5"\/>/d' scenes/mesh-sphere/scene.xml >"$W/million.xml"

# 1. speed
pairs=("scenes/homogeneous-cube/scene.xml scenes/mesh-cube/scene.xml"
       "scenes/cgg-logo/scene.xml scenes/cgg-logo/mesh.xml"
       "scenes/homogeneous-cube/scene.xml $W/million.xml")
base=(--backend cuda --spp 64 --resolution 400x400 --seed 1 --lookup trilinear)
for mode in regeneration-sk defaults exact; do
    case $mode in
        regeneration-sk) args=(--strategy regeneration-sk) ;;
        defaults) args=() ;;
        exact) args=(--math exact) ;;
    esac
    for pair in "${pairs[@]}"; do
        set -- $pair
        for scene in "$1" "$2"; do
            "$VOLPT" render "$scene" "${base[@]}" "${args[@]}" --spp 1 -o "$W/warm.exr" >/dev/null 2>&1
        done
        "$VOLPT" render "$1" "${base[@]}" "${args[@]}" -o "$W/box.exr" >"$W/box.log" 2>&1 || log "FAIL $1 ($mode)"
        "$VOLPT" render "$2" "${base[@]}" "${args[@]}" -o "$W/mesh.exr" >"$W/mesh.log" 2>&1 || log "FAIL $2 ($mode)"
        box=$(seg "$W/box.log")
        mesh=$(seg "$W/mesh.log")
        log "$mode: $(basename "$(dirname "$1")") ${box:-?} M vs $(basename "$(dirname "$2")")/$(basename "$2") ${mesh:-?} M segments/s, ratio $(python3 -c "print(f'{float(\"${mesh:-0}\")/float(\"${box:-1}\"):.4f}')" 2>/dev/null)"
    done
done

# 2. exactness
same() { # same WHAT CPU-SCENE GPU-SCENE
    local ex=(--spp 4 --resolution 160x160 --seed 3)
    "$VOLPT" render "$2" "${ex[@]}" --backend cpu -o "$W/cpu.exr" >"$W/cpu.log" 2>&1 || { log "FAIL $1: CPU render"; return; }
    "$VOLPT" render "$3" "${ex[@]}" --backend cuda --strategy naive-sk --math exact -o "$W/gpu.exr" >"$W/gpu.log" 2>&1 \
        || { log "FAIL $1: GPU render: $(tail -n 1 "$W/gpu.log")"; return; }
    if "$VOLPT" compare "$W/cpu.exr" "$W/gpu.exr" --identical >"$W/compare.log" 2>&1; then
        log "$1: identical"
    else
        log "FAIL $1: $(tail -n 1 "$W/compare.log")"
    fi
}
same "mesh-cube GPU naive-sk exact vs box CPU" scenes/homogeneous-cube/scene.xml scenes/mesh-cube/scene.xml
same "sphere GPU naive-sk exact vs CPU" scenes/mesh-sphere/scene.xml scenes/mesh-sphere/scene.xml
same "peer torus (environment map) GPU naive-sk exact vs CPU" scenes/mesh-peers/torus.xml scenes/mesh-peers/torus.xml
log "done in ${SECONDS} s"
