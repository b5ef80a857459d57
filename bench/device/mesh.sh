#!/usr/bin/env bash
# Mesh boundaries (issue 39) on the device host, with the stripped `volpt` binary only (no cargo).
# The GPU traces meshes with kernels of their own (volpt_device::KernelSet::Mesh: naive-sk and
# regeneration-sk; homogeneous and dense-grid media, every boundary and phase, a constant
# environment); the box kernels compile no mesh code. What this checks:
#   1. `volpt info` describes a mesh boundary (shape line);
#   2. the GPU takes a mesh scene ("GPU takes meshes"), and refuses a strategy without mesh
#      kernels (streaming-sk) with the strategies that have them;
#   3. CPU, 16 cores: scenes/mesh-cube (homogeneous-cube's box as a mesh) renders
#      homogeneous-cube's image bit for bit, and its segments per second against the box's (the
#      distance grid's work: issue target >= 0.8x); the same for cgg-logo (its box written as the
#      same mesh, scenes/cgg-logo/mesh.xml);
#   4. CPU: the sphere mesh scene (Mitsuba `sphere`, 16,128 triangles) renders, and its speed;
#   5. GPU: homogeneous-cube renders on the GPU bit for bit as on the CPU (naive-sk, exact math);
#   6. GPU naive-sk exact = CPU, bit for bit: mesh-cube (and = the box's image), the sphere, a
#      torus (non-convex: generated here as torus.obj, 4,608 triangles) with next-event estimation
#      through an index-matched boundary (shadow rays cross two chords); each log names a `mesh__`
#      kernel;
#   7. regeneration-sk (fast math, another seed) against the CPU's torus: `volpt compare --independent`;
#   8. the analytic absorber on the GPU: albedo 0, index-matched sphere, GPU exact = CPU bit for bit
#      (the CPU's image is exp(-sigma_t chord) by `cargo test -p volpt-core --test mesh`);
#   9. GPU speed: homogeneous-cube box vs mesh-cube, cgg-logo box vs mesh (segments/s, regeneration-sk,
#      fast math, 400x400 at 64 spp; issue target >= 0.8x).
# Run from a bundle (bin/volpt beside scenes/) or a checkout with VOLPT=target/release/volpt:
#   bash bench/device/mesh.sh            -> $OUT/mesh.txt
# Expected (about 60 s on an H200): the shape line, "GPU takes meshes", "OK refused streaming-sk",
# "identical" for the CPU box vs mesh (twice), box CPU vs GPU, mesh-cube, sphere, torus and the
# absorber, "OK torus regeneration-sk", the CPU ratio lines (~0.6), the sphere's segments/s, two GPU
# mesh/box ratio lines, and no line starting with FAIL.
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

# 2. the GPU takes a mesh (its mesh kernels), and refuses a strategy that has none
gpu_meshes=0
if RUST_LOG=volpt_cuda=info "$VOLPT" render scenes/mesh-cube/scene.xml --backend cuda --spp 1 --resolution 16x16 \
    -o "$OUT/probe.exr" >"$OUT/probe.log" 2>&1; then
    gpu_meshes=1
    log "GPU takes meshes: $(grep -o 'mesh__[a-z0-9_]*' "$OUT/probe.log" | head -n 1)"
else
    log "FAIL the GPU refuses a mesh: $(tail -n 2 "$OUT/probe.log")"
fi
if "$VOLPT" render scenes/mesh-cube/scene.xml --backend cuda --strategy streaming-sk --spp 1 --resolution 16x16 \
    -o "$OUT/refused.exr" >"$OUT/refused.log" 2>&1; then
    log "FAIL streaming-sk rendered a mesh (no mesh kernel of it exists)"
elif grep -q "are those of naive-sk, regeneration-sk only" "$OUT/refused.log"; then
    log "OK refused streaming-sk: $(grep -o 'the GPU kernels for a scene with a triangle-mesh boundary[^(]*' "$OUT/refused.log" | head -n 1)"
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
              '<shape type="obj"><string name="filename" value="../mesh-cube/box.obj"/>'
              '<boolean name="face_normals" value="true"/>', s)
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
gpu_exact=(--backend cuda --strategy naive-sk --math exact --spp "$SPP" --resolution "${RES}x${RES}" --seed 1)
"$VOLPT" render scenes/homogeneous-cube/scene.xml "${gpu_exact[@]}" -o "$OUT/box-gpu.exr" >"$OUT/box-gpu.log" 2>&1 || log "FAIL box GPU render"
same() { # same NAME A.exr B.exr: bit-identical images
    if "$VOLPT" compare "$2" "$3" --identical >"$OUT/compare-$1.log" 2>&1; then
        log "$1: identical"
    else
        log "FAIL $1: $(tail -n 2 "$OUT/compare-$1.log")"
    fi
}
same "box CPU vs GPU naive-sk exact" "$OUT/box.exr" "$OUT/box-gpu.exr"

[ "$gpu_meshes" = 1 ] || exit 0

# 6. GPU naive-sk exact = CPU on meshes
RUST_LOG=volpt_cuda=info "$VOLPT" render scenes/mesh-cube/scene.xml "${gpu_exact[@]}" -o "$OUT/mesh-gpu.exr" >"$OUT/mesh-gpu.log" 2>&1 || log "FAIL mesh-cube GPU render"
grep -q "mesh__naive_sk__" "$OUT/mesh-gpu.log" || log "FAIL mesh-cube's GPU log names no mesh__naive_sk kernel"
same "mesh-cube GPU vs box CPU" "$OUT/box.exr" "$OUT/mesh-gpu.exr"
"$VOLPT" render scenes/mesh-sphere/scene.xml "${gpu_exact[@]}" -o "$OUT/sphere-gpu.exr" >"$OUT/sphere-gpu.log" 2>&1 || log "FAIL sphere GPU render"
same "sphere CPU vs GPU naive-sk exact" "$OUT/sphere.exr" "$OUT/sphere-gpu.exr"
# A torus (major radius 0.35, minor 0.15, 48 x 48 quads), counter-clockwise seen from outside,
# in the sphere scene's place; index-matched with next-event estimation (volpath's default).
python3 - <<'PY'
import math, re
R, r, n, m = 0.35, 0.15, 48, 48
lines = []
for i in range(n):
    u = 2 * math.pi * i / n
    for j in range(m):
        v = 2 * math.pi * j / m
        x = (R + r * math.cos(v)) * math.cos(u)
        y = (R + r * math.cos(v)) * math.sin(u)
        lines.append(f"v {x:.9f} {y:.9f} {r * math.sin(v):.9f}")
k = lambda i, j: (i % n) * m + (j % m) + 1
for i in range(n):
    for j in range(m):
        a, b, c, d = k(i, j), k(i + 1, j), k(i + 1, j + 1), k(i, j + 1)
        lines += [f"f {a} {b} {c}", f"f {a} {c} {d}"]
open("scenes/mesh-sphere/torus.obj", "w").write("\n".join(lines) + "\n")
s = open("scenes/mesh-sphere/scene.xml").read()
s, count = re.subn(r'<shape type="sphere">\s*<float name="radius" value="0.5"/>',
                   '<shape type="obj"><string name="filename" value="torus.obj"/>'
                   '<boolean name="face_normals" value="true"/>'
                   '<transform name="to_world"><rotate x="1" angle="60"/></transform>', s)
assert count == 1, "mesh-sphere's shape is not the sphere this script expects"
open("scenes/mesh-sphere/torus.xml", "w").write(s)
PY
torus=(scenes/mesh-sphere/torus.xml -D boundary=null -D sigma_t=3)
"$VOLPT" render "${torus[@]}" "${common[@]}" -o "$OUT/torus.exr" >"$OUT/torus.log" 2>&1 || log "FAIL torus CPU render"
"$VOLPT" render "${torus[@]}" "${gpu_exact[@]}" -o "$OUT/torus-gpu.exr" >"$OUT/torus-gpu.log" 2>&1 || log "FAIL torus GPU render"
same "torus CPU vs GPU naive-sk exact" "$OUT/torus.exr" "$OUT/torus-gpu.exr"

# 7. regeneration-sk, fast math, against the CPU (statistically)
for s in regeneration-sk; do
    "$VOLPT" render "${torus[@]}" --backend cuda --strategy "$s" --spp "$SPP" --resolution "${RES}x${RES}" --seed 2 \
        -o "$OUT/torus-$s.exr" >"$OUT/torus-$s.log" 2>&1 || { log "FAIL torus $s render"; continue; }
    if "$VOLPT" compare "$OUT/torus.exr" "$OUT/torus-$s.exr" --independent >"$OUT/compare-torus-$s.log" 2>&1; then
        log "OK torus $s within the statistical test"
    else
        log "FAIL torus $s: $(tail -n 2 "$OUT/compare-torus-$s.log")"
    fi
done

# 8. the analytic absorber (albedo 0, index-matched sphere mesh): GPU = CPU bit for bit
absorber=(scenes/mesh-sphere/scene.xml -D boundary=null -D albedo=0 -D sigma_t=2)
"$VOLPT" render "${absorber[@]}" "${common[@]}" -o "$OUT/absorber.exr" >"$OUT/absorber.log" 2>&1 || log "FAIL absorber CPU render"
"$VOLPT" render "${absorber[@]}" "${gpu_exact[@]}" -o "$OUT/absorber-gpu.exr" >"$OUT/absorber-gpu.log" 2>&1 || log "FAIL absorber GPU render"
same "absorber sphere CPU vs GPU naive-sk exact" "$OUT/absorber.exr" "$OUT/absorber-gpu.exr"

# 9. GPU speed: box against mesh (regeneration-sk, fast math, 64 spp)
gpu_speed=(--backend cuda --strategy regeneration-sk --spp 64 --resolution 400x400 --seed 1)
for pair in "homogeneous-cube/scene.xml mesh-cube/scene.xml" "cgg-logo/scene.xml cgg-logo/mesh.xml"; do
    set -- $pair
    "$VOLPT" render "scenes/$1" "${gpu_speed[@]}" -o "$OUT/speed-box.exr" >"$OUT/speed-box.log" 2>&1 || log "FAIL $1 GPU speed render"
    if ! "$VOLPT" render "scenes/$2" "${gpu_speed[@]}" -o "$OUT/speed-mesh.exr" >"$OUT/speed-mesh.log" 2>&1; then
        # A variant outside the mesh kernels (cgg-logo's texture grid) is a typed refusal, not a failure.
        if grep -q "do not cover this scene's parts" "$OUT/speed-mesh.log"; then
            log "not covered by the mesh kernels on the GPU (it renders on the CPU): $2"
            continue
        fi
        log "FAIL $2 GPU speed render"
    fi
    box=$(seg "$OUT/speed-box.log")
    mesh=$(seg "$OUT/speed-mesh.log")
    # The default schedule (no --strategy: regeneration-sk with at most 64 registers) on the mesh.
    "$VOLPT" render "scenes/$2" --backend cuda --spp 64 --resolution 400x400 --seed 1 -o "$OUT/speed-mesh-default.exr" \
        >"$OUT/speed-mesh-default.log" 2>&1 || log "FAIL $2 GPU default-schedule render"
    capped=$(seg "$OUT/speed-mesh-default.log")
    log "GPU segments/s $1 ${box:-?} M vs $2 ${mesh:-?} M, ratio $(python3 -c "print(f'{float(\"${mesh:-0}\")/float(\"${box:-1}\"):.3f}')" 2>/dev/null); mesh with the default schedule (<= 64 registers) ${capped:-?} M"
done
