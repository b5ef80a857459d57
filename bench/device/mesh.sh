#!/usr/bin/env bash
# Mesh boundaries (issue 39) on the device host, with the stripped `volpt` binary only (no cargo).
# The GPU kernels trace box boundaries (a mesh scene renders on the CPU); what this checks:
#   1. `volpt info` describes a mesh boundary (shape line);
#   2. the GPU refuses a mesh scene with the message that says to render it on the CPU;
#   3. CPU, 16 cores: scenes/mesh-cube (homogeneous-cube's box as a 24-triangle mesh) renders
#      homogeneous-cube's image bit for bit, and its segments per second against the box's (the
#      distance grid's work: issue target >= 0.8x);
#      The same for cgg-logo (its box written as the same mesh, scenes/cgg-logo/mesh.xml);
#   4. CPU: the sphere mesh scene (Mitsuba `sphere`, 16,128 triangles) renders, and its speed;
#   5. GPU: homogeneous-cube still renders on the GPU bit for bit as on the CPU (naive-sk, exact
#      math): the box kernels after the BoundaryShape / FlightEnd changes.
# Run from a bundle (bin/volpt beside scenes/) or a checkout with VOLPT=target/release/volpt:
#   bash bench/device/mesh.sh            -> $OUT/mesh.txt
# Expected (about 40 s): "shape      closed triangle mesh from ...box.obj: 24 triangles",
# "OK refused", "identical" three times, two mesh/box ratio lines, "sphere ... M segments/s".
set -uo pipefail
cd "$(dirname "$0")"
[ -d scenes ] || cd ../..
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
VOLPT=${VOLPT:-$PWD/bin/volpt}
SPP=${SPP:-16}
RES=${RES:-200}
log() { echo "$@" | tee -a "$OUT/mesh.txt"; }
: >"$OUT/mesh.txt"
log "# $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name --format=csv,noheader 2>/dev/null | head -n 1) spp=$SPP res=$RES"

# 1. info
"$VOLPT" info scenes/mesh-cube/scene.xml 2>&1 | grep -E "^(shape|bounds|variant)" | tee -a "$OUT/mesh.txt"

# 2. the GPU refuses a mesh
if "$VOLPT" render scenes/mesh-cube/scene.xml --backend cuda --spp 1 -o "$OUT/refused.exr" >"$OUT/refused.log" 2>&1; then
    log "FAIL the GPU rendered a mesh scene"
elif grep -q "trace box boundaries only" "$OUT/refused.log"; then
    log "OK refused: $(grep -o 'the GPU kernels trace box boundaries only[^)]*)' "$OUT/refused.log" | head -n 1)"
else
    log "FAIL unexpected error: $(tail -n 2 "$OUT/refused.log")"
fi

# 3. box against mesh on the CPU: same seed, same image; speed of each
common=(--backend cpu --spp "$SPP" --resolution "${RES}x${RES}" --seed 1)
"$VOLPT" render scenes/homogeneous-cube/scene.xml "${common[@]}" -o "$OUT/box.exr" >"$OUT/box.log" 2>&1 || log "FAIL box render"
"$VOLPT" render scenes/mesh-cube/scene.xml "${common[@]}" -o "$OUT/mesh.exr" >"$OUT/mesh.log" 2>&1 || log "FAIL mesh render"
if "$VOLPT" compare "$OUT/box.exr" "$OUT/mesh.exr" --identical >"$OUT/compare.log" 2>&1; then
    log "box vs mesh-cube on the CPU: identical"
else
    log "FAIL box vs mesh-cube: $(tail -n 2 "$OUT/compare.log")"
fi
seg() { grep -o '[0-9.]* M segments/s' "$1" | head -n 1 | cut -d' ' -f1; }
box=$(seg "$OUT/box.log")
mesh=$(seg "$OUT/mesh.log")
log "CPU segments/s: box ${box:-?} M, mesh ${mesh:-?} M, ratio $(python3 -c "print(f'{float(\"${mesh:-0}\")/float(\"${box:-1}\"):.3f}')" 2>/dev/null)"

# 3b. the same for cgg-logo (generated grids, a majorant grid): its box as box.obj, written beside it
"$VOLPT" scene generate scenes >/dev/null 2>&1 || log "FAIL scene generate"
python3 - <<'PY'
import re
s = open("scenes/cgg-logo/scene.xml").read()
s, n = re.subn(r'<shape type="cube">\s*<transform name="to_world">\s*<scale value="0.5"/>\s*</transform>',
              '<shape type="obj"><string name="filename" value="../mesh-cube/box.obj"/>', s)
assert n == 1, "cgg-logo's shape is not the cube this script expects"
open("scenes/cgg-logo/mesh.xml", "w").write(s)
PY
"$VOLPT" render scenes/cgg-logo/scene.xml "${common[@]}" -o "$OUT/cgg-box.exr" >"$OUT/cgg-box.log" 2>&1 || log "FAIL cgg-logo box render"
"$VOLPT" render scenes/cgg-logo/mesh.xml "${common[@]}" -o "$OUT/cgg-mesh.exr" >"$OUT/cgg-mesh.log" 2>&1 || log "FAIL cgg-logo mesh render"
if "$VOLPT" compare "$OUT/cgg-box.exr" "$OUT/cgg-mesh.exr" --identical >"$OUT/compare-cgg.log" 2>&1; then
    log "cgg-logo box vs mesh on the CPU: identical"
else
    log "FAIL cgg-logo box vs mesh: $(tail -n 2 "$OUT/compare-cgg.log")"
fi
box=$(seg "$OUT/cgg-box.log")
mesh=$(seg "$OUT/cgg-mesh.log")
log "cgg-logo CPU segments/s: box ${box:-?} M, mesh ${mesh:-?} M, ratio $(python3 -c "print(f'{float(\"${mesh:-0}\")/float(\"${box:-1}\"):.3f}')" 2>/dev/null)"

# 4. the sphere mesh
"$VOLPT" render scenes/mesh-sphere/scene.xml "${common[@]}" -o "$OUT/sphere.exr" >"$OUT/sphere.log" 2>&1 || log "FAIL sphere render"
log "sphere (16,128 triangles) on the CPU: $(seg "$OUT/sphere.log") M segments/s"

# 5. the box kernels: GPU naive-sk exact = CPU, bit for bit
"$VOLPT" render scenes/homogeneous-cube/scene.xml --backend cuda --strategy naive-sk --math exact \
    --spp "$SPP" --resolution "${RES}x${RES}" --seed 1 -o "$OUT/box-gpu.exr" >"$OUT/box-gpu.log" 2>&1 || log "FAIL box GPU render"
if "$VOLPT" compare "$OUT/box.exr" "$OUT/box-gpu.exr" --identical >"$OUT/compare-gpu.log" 2>&1; then
    log "box CPU vs GPU naive-sk exact: identical"
else
    log "FAIL box CPU vs GPU: $(tail -n 2 "$OUT/compare-gpu.log")"
fi
