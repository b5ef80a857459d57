#!/usr/bin/env bash
# Session 13, kernels helper, device call 1: where mesh-cube's GPU time goes against the box's.
# Run from /work/main's tree on the device with dev/bin and dev/kernels carried.
set -uo pipefail
OUT=${OUT:-$PWD/out}; mkdir -p "$OUT"
W=$(mktemp -d); xz -dc dev/bin/volpt.xz >"$W/volpt"; chmod +x "$W/volpt"; V=$W/volpt
PTX=${PTX:-v1-fast.ptx}
date -u; nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
seg() { grep -o '[0-9.]* M segments/s' "$1" | head -n 1 | cut -d' ' -f1; }
spp() { grep -o '([0-9.]* segments/path)' "$1" | head -n1 | tr -d '(' | cut -d' ' -f1; }
speed=(--backend cuda --strategy regeneration-sk --spp 64 --resolution 400x400 --seed 1)
# warm the JIT cache, then timed renders, alternated twice: main's kernels and dev/kernels/$PTX
run_() { if [ "$1" = main ]; then shift; "$V" "$@"; else shift; VOLPT_PTX=dev/kernels/$PTX "$V" "$@"; fi; }
for k in main mine; do for s in homogeneous-cube mesh-cube; do run_ $k render scenes/$s/scene.xml "${speed[@]}" --spp 1 -o $W/w.exr >/dev/null 2>&1; done; done
for r in 1 2; do for k in main mine; do for s in homogeneous-cube mesh-cube; do
  run_ $k render scenes/$s/scene.xml "${speed[@]}" -o $W/$s-$k.exr >$W/$s.log 2>&1
  echo "round $r $k $s: $(seg $W/$s.log) M seg/s, $(spp $W/$s.log) seg/path"
done; done; done
tail -n 2 $W/mesh-cube.log
cmp $W/mesh-cube-main.exr $W/mesh-cube-mine.exr >/dev/null && echo "main and mine mesh-cube images identical (fast regeneration-sk)" || echo "main and mine mesh-cube images differ"
# cgg-logo (trilinear lookup: the mesh kernels' dense grids) box vs its box as a mesh, and a 1M-triangle sphere vs the box
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
import math, struct, sys
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
for r in 1 2; do for k in main mine; do
  for s in cgg-logo/scene.xml cgg-logo/mesh.xml; do
    run_ $k render scenes/$s "${speed[@]}" --lookup trilinear -o $W/c.exr >$W/c.log 2>&1 || tail -2 $W/c.log
    echo "round $r $k $s trilinear: $(seg $W/c.log) M seg/s"
  done
  [ $r = 1 ] && [ $k = main ] && run_ $k render scenes/mesh-sphere/big.xml "${speed[@]}" --spp 1 -o $W/w.exr >/dev/null 2>&1
  [ $r = 1 ] && [ $k = mine ] && run_ $k render scenes/mesh-sphere/big.xml "${speed[@]}" --spp 1 -o $W/w.exr >/dev/null 2>&1
  run_ $k render scenes/mesh-sphere/big.xml "${speed[@]}" -o $W/b.exr >$W/b.log 2>&1 || tail -2 $W/b.log
  echo "round $r $k 1M-sphere: $(seg $W/b.log) M seg/s, $(spp $W/b.log) seg/path; $(grep -o 'in [0-9.]* s' $W/b.log | head -1)"
  run_ $k render scenes/mesh-sphere/scene.xml "${speed[@]}" -o $W/b.exr >$W/b.log 2>&1 || tail -2 $W/b.log
  echo "round $r $k 16k-sphere: $(seg $W/b.log) M seg/s"
done; done
echo "time $SECONDS s"
prof() { # name regex paths args...
  local n=$1 k=$2 paths=$3; shift 3
  timeout 35 ncu --set full --import-source no -k "regex:$k" --launch-count 1 -o $W/$n "$V" render "$@" >$W/$n.ncu.log 2>&1 || { echo "FAIL ncu $n"; tail -5 $W/$n.ncu.log; return; }
  grep -o '[0-9.]* M segments/s.*' $W/$n.ncu.log | head -1
  ncu -i $W/$n.ncu-rep --page raw --csv >$W/$n-raw.csv 2>&1
  ncu -i $W/$n.ncu-rep --page details >$OUT/$n-details.txt 2>&1
  python3 - $W/$n-raw.csv $n "$(grep -o '([0-9.]* segments/path)' $W/$n.ncu.log | head -1 | tr -d '(' | cut -d' ' -f1)" $paths <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1], errors="replace")))
h = next(i for i, r in enumerate(rows) if "Kernel Name" in r)
raw = dict(zip(rows[h], rows[h + 2]))
def num(k):
    try: return float(raw[k].replace(",", ""))
    except Exception: return float("nan")
segs = float(sys.argv[3] or "nan") * float(sys.argv[4])
inst = num("smsp__inst_executed.sum")
print(f"{sys.argv[2]}: {raw.get('Kernel Name','?')[:70]} dur {num('gpu__time_duration.sum')/1e6:.3f} ms regs {raw.get('launch__registers_per_thread')}"
      f" occ {num('sm__warps_active.avg.pct_of_peak_sustained_active'):.1f}% issue {num('sm__inst_issued.avg.pct_of_peak_sustained_active'):.1f}%"
      f" warp-inst/seg {inst/segs:.2f} thread-inst/seg {num('smsp__thread_inst_executed.sum')/segs:.1f} SIMT {100*num('smsp__thread_inst_executed.sum')/max(inst*32,1):.1f}%")
loc = {k: num(k) for k in raw if "local" in k and k.endswith(".sum")}
for k, v in sorted(loc.items()):
    if v == v and v > 0: print(f"   {k} {v:.3g} ({v/segs:.2f}/seg)")
st = sorted(((num(k), k) for k in raw if k.startswith("smsp__average_warps_issue_stalled_") and k.endswith("_per_issue_active.ratio")), reverse=True)
print("   stalls/issue: " + ", ".join(f"{k[len('smsp__average_warps_issue_stalled_'):-len('_per_issue_active.ratio')]} {v:.2f}" for v, k in st[:8] if v == v))
for k in ["l1tex__t_sectors_pipe_lsu_mem_global_op_ld.sum", "lts__t_sectors_srcunit_tex_op_read.sum", "dram__bytes_read.sum", "smsp__inst_executed_op_local_ld.sum", "smsp__inst_executed_op_local_st.sum", "smsp__inst_executed_op_global_ld.sum"]:
    if k in raw: print(f"   {k} {num(k):.3g} ({num(k)/segs:.3f}/seg)")
PY
}
small=(--backend cuda --strategy regeneration-sk --spp 8 --resolution 200x200 --seed 1 -o $W/p.exr)
prof box '^regeneration_sk__homogeneous' 320000 scenes/homogeneous-cube/scene.xml "${small[@]}"
prof mesh '^mesh__regeneration_sk__homogeneous' 320000 scenes/mesh-cube/scene.xml "${small[@]}"
VOLPT_PTX=dev/kernels/$PTX prof mesh-mine '^mesh__regeneration_sk__homogeneous' 320000 scenes/mesh-cube/scene.xml "${small[@]}"
cp $W/mesh-raw.csv $W/box-raw.csv $W/mesh-mine-raw.csv $OUT/ 2>/dev/null
echo done $(date -u)
