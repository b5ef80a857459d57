#!/usr/bin/env bash
# Load time of a closed mesh of about 1M triangles (issue 39: <= 2 s), on the device host with the
# stripped `volpt` binary only (no cargo). python3 (standard library only) writes a
# latitude-longitude sphere of 500 rings x 1000 segments (998,000 triangles) as a binary PLY, and
# a copy of scenes/mesh-sphere/scene.xml whose `sphere` is that file; `volpt info` loads it (read,
# checks, BVH, distance grid, all of `MeshDesc::placed`), three times, timed from outside.
# Run from a bundle (bin/volpt beside scenes/) or a checkout with VOLPT=target/release/volpt:
#   bash bench/device/mesh_load.sh        -> $OUT/mesh_load.txt
# Expected (about 20 s, most of it python writing the file): the shape line ("998000 triangles")
# and three "load N.NNN s" lines, each <= 2 s on 16 cores (this includes the process's start and
# the XML; CPU only, no GPU is used).
set -uo pipefail
cd "$(dirname "$0")"
[ -d scenes ] || cd ../..
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=${VOLPT:-$PWD/bin/volpt}
DIR=$(mktemp -d)
trap 'rm -rf "$DIR"' EXIT
log() { echo "$@" | tee -a "$OUT/mesh_load.txt"; }
: >"$OUT/mesh_load.txt"
log "# $(date -u +%Y-%m-%dT%H:%MZ) $(nproc) cores"

python3 - "$DIR/sphere.ply" <<'PY'
import math, struct, sys
from array import array
rings, segments = 500, 1000
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
sed -e 's|<shape type="sphere">|<shape type="ply"><string name="filename" value="sphere.ply"/><boolean name="face_normals" value="true"/>|' \
    -e '/<float name="radius" value="0.5"\/>/d' scenes/mesh-sphere/scene.xml >"$DIR/scene.xml"

"$VOLPT" info "$DIR/scene.xml" 2>&1 | grep -E "^shape" | tee -a "$OUT/mesh_load.txt"
for run in 1 2 3; do
    start=$(date +%s.%N)
    "$VOLPT" info "$DIR/scene.xml" >/dev/null 2>&1 || log "FAIL volpt info"
    end=$(date +%s.%N)
    log "load $(python3 -c "print(f'{$end - $start:.3f}')") s"
done
