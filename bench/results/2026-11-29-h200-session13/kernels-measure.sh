#!/usr/bin/env bash
# Session 13, kernels helper: mesh vs box segments/s, main's kernels against dev/kernels/$PTXF (fast)
# and $PTXE (exact), same binary, same call; and the exactness of the new exact kernels.
set -uo pipefail
W=$(mktemp -d); xz -dc dev/bin/volpt.xz >"$W/volpt"; chmod +x "$W/volpt"; V=$W/volpt
PTXF=${PTXF:-v2-fast.ptx}; PTXE=${PTXE:-v2-exact.ptx}
date -u; nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
seg() { grep -o '[0-9.]* M segments/s' "$1" | head -n 1 | cut -d' ' -f1; }
"$V" scene generate scenes >/dev/null 2>&1
python3 - <<'PY'
import re
s = open("scenes/cgg-logo/scene.xml").read()
s, n = re.subn(r'<shape type="cube">\s*<transform name="to_world">\s*<scale value="0.5"/>\s*</transform>',
              '<shape type="obj"><string name="filename" value="../mesh-cube/box.obj"/>', s)
assert n == 1
open("scenes/cgg-logo/mesh.xml", "w").write(s)
PY
python3 - "$W/sphere.ply" <<'PY'
import math, sys
from array import array
rings, segments = 501, 1000
v = array("f"); v.extend((0.0, 0.0, 0.5))
for i in range(1, rings):
    t = math.pi * i / rings; s, c = 0.5 * math.sin(t), 0.5 * math.cos(t)
    for j in range(segments):
        p = 2 * math.pi * j / segments; v.extend((s * math.cos(p), s * math.sin(p), c))
v.extend((0.0, 0.0, -0.5)); south = len(v) // 3 - 1
ring = lambda i, j: 1 + (i - 1) * segments + j % segments
f = array("i")
for j in range(segments): f.extend((0, ring(1, j), ring(1, j + 1)))
for i in range(1, rings - 1):
    for j in range(segments):
        a, b, c, d = ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1); f.extend((a, b, c, a, c, d))
for j in range(segments): f.extend((ring(rings - 1, j), south, ring(rings - 1, j + 1)))
n = len(f) // 3
with open(sys.argv[1], "wb") as out:
    out.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(v) // 3}\nproperty float x\nproperty float y\nproperty float z\n"
               f"element face {n}\nproperty list uchar int vertex_indices\nend_header\n").encode())
    out.write(v.tobytes()); fb = f.tobytes()
    out.write(b"".join(b"\x03" + fb[12 * k:12 * k + 12] for k in range(n)))
print("sphere triangles", n)
PY
sed -e 's|<shape type="sphere">|<shape type="ply"><string name="filename" value="'$W'/sphere.ply"/>|' -e '/<float name="radius" value="0.5"\/>/d' scenes/mesh-sphere/scene.xml >scenes/mesh-sphere/big.xml
# kernels: main | fast | exact
r() { local k=$1; shift; case $k in main) "$V" "$@";; fast) VOLPT_PTX=dev/kernels/$PTXF "$V" "$@";; exact) VOLPT_PTX=dev/kernels/$PTXE "$V" "$@" --math exact;; mainexact) "$V" "$@" --math exact;; esac; }
pairs=("homogeneous-cube/scene.xml mesh-cube/scene.xml" "cgg-logo/scene.xml cgg-logo/mesh.xml" "homogeneous-cube/scene.xml mesh-sphere/big.xml")
base=(--backend cuda --spp 64 --resolution 400x400 --seed 1 --lookup trilinear)
for mode in "rs fast" "default fast" "default exact"; do set -- $mode; sch=$1; math=$2
  [ $sch = rs ] && s=(--strategy regeneration-sk) || s=()
  for who in main mine; do
    if [ $math = exact ]; then [ $who = main ] && k=mainexact || k=exact; else [ $who = main ] && k=main || k=fast; fi
    for p in "${pairs[@]}"; do set -- $p
      r $k render scenes/$1 "${base[@]}" "${s[@]}" --spp 1 -o $W/w.exr >/dev/null 2>&1
      r $k render scenes/$2 "${base[@]}" "${s[@]}" --spp 1 -o $W/w.exr >/dev/null 2>&1
      b1=$(r $k render scenes/$1 "${base[@]}" "${s[@]}" -o $W/a.exr 2>&1 | grep -o '[0-9.]* M segments/s' | cut -d' ' -f1)
      m1=$(r $k render scenes/$2 "${base[@]}" "${s[@]}" -o $W/b.exr 2>&1 | grep -o '[0-9.]* M segments/s' | cut -d' ' -f1)
      echo "$mode $who $1 vs $2: box $b1, mesh $m1 M seg/s, ratio $(python3 -c "print(f'{float(\"${m1:-0}\")/float(\"${b1:-1}\"):.4f}')")"
    done
  done
  echo "time $SECONDS s"
done
# exactness: the new exact naive-sk mesh kernel against main's CPU on the box, bit for bit
ex=(--spp 4 --resolution 200x200 --seed 3)
"$V" render scenes/homogeneous-cube/scene.xml "${ex[@]}" --backend cpu -o $W/cpu-box.exr >/dev/null 2>&1
VOLPT_PTX=dev/kernels/$PTXE "$V" render scenes/mesh-cube/scene.xml "${ex[@]}" --backend cuda --strategy naive-sk --math exact -o $W/gpu-mesh.exr >$W/g.log 2>&1 || tail -3 $W/g.log
"$V" compare $W/cpu-box.exr $W/gpu-mesh.exr --identical 2>&1 | tail -1
"$V" render scenes/mesh-sphere/scene.xml "${ex[@]}" --backend cpu -o $W/cpu-sph.exr >/dev/null 2>&1
VOLPT_PTX=dev/kernels/$PTXE "$V" render scenes/mesh-sphere/scene.xml "${ex[@]}" --backend cuda --strategy naive-sk --math exact -o $W/gpu-sph.exr >$W/g.log 2>&1 || tail -3 $W/g.log
"$V" compare $W/cpu-sph.exr $W/gpu-sph.exr --identical 2>&1 | tail -1
echo "done $SECONDS s"
