#!/usr/bin/env bash
# Volumes larger than the GPU (issue 13, docs/out-of-core.md), run on the device machine from the
# bundle that `cargo xtask device-bundle` builds:
#
#   bash bundle/out-of-core.sh       # results under $OUT (default ./out-ooc); ~4-6 minutes on an H100
#
# 1. identical images: cgg-logo and bucky, same seed, naive-sk (the CPU's summation order), with the
#    grids in device memory, zero-copy, managed (whole, and partly prefetched), auto over its budget,
#    and bricked; every image must equal the device-resident one bit for bit (and the CPU's). An
#    explicit --volume-memory device over its budget must be a clean error.
# 2. a generated volume of 8 GiB (2048 x 1024 x 1024 f32, a gyroid lattice, not a constant) rendered
#    with --device-memory-budget 2G: auto (zero-copy in place), bricked, managed; and device-resident
#    (it fits an H100) as the reference image and time.
# 3. throughput of every placement against device-resident, dense and bricked, in this one run:
#    cgg-logo (16 MB of grids) and a generated 512^3 f32 volume (512 MiB), `volpt bench`.
#
# Files under $OUT: summary.txt (everything, PASS/FAIL lines), throughput.txt (the ratio tables),
# big.txt (the 8 GiB renders), device.txt, logs.tar.gz (every command's output), bench.tar.gz (JSON).
# WORK (default ./ooc-work) holds the generated volumes (8.5 GiB) and images; deleted at the end
# unless KEEP=1. QUICK=1 skips the 8 GiB volume; MID_RES=N makes the throughput volume N^3 and
# BIG_DIMS="X Y Z" the large one X x Y x Z (both for trying the script out on a CPU stand-in).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out-ooc}
WORK=${WORK:-$PWD/ooc-work}
mkdir -p "$OUT" "$WORK/logs" "$WORK/bench"
VOLPT=$PWD/bin/volpt
DATA=$PWD/data
TRIALS=${TRIALS:-3}
export RUST_BACKTRACE=1
failures=0
started=$(date +%s)

log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
elapsed() { echo "$(($(date +%s) - started)) s"; }
# run NAME CMD...: runs CMD (at most 180 s) with its output in logs/NAME.log; returns its status.
run() {
    local name=$1; shift
    local t0; t0=$(date +%s.%N)
    timeout 180 "$@" >"$WORK/logs/$name.log" 2>&1
    local rc=$?
    echo "(exit $rc after $(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s: $*)" \
        >>"$WORK/logs/$name.log"
    return $rc
}
fail() { log "FAIL $*"; failures=$((failures + 1)); }
tail_of() { tail -n "${2:-4}" "$WORK/logs/$1.log" | tr '\n' ' '; }
# The placements a render reported (the CUDA backend logs one `volume:` line per grid).
placements() { grep -o 'volume: .*' "$WORK/logs/$1.log" | sed 's/\x1b\[[0-9;]*m//g' | tr '\n' ';'; }

log "date $(date -u +%Y-%m-%dT%H:%MZ)"
{
    nvidia-smi --query-gpu=name,driver_version,memory.total,memory.free,pcie.link.gen.current,pcie.link.width.current \
        --format=csv
    nvidia-smi topo -m 2>/dev/null | head -n 3
    echo "host memory: $(free -g | awk '/Mem:/ {print $2 " GiB total, " $7 " GiB available"}')"
    echo "ulimit -l: $(ulimit -l)"
    echo "disk at $WORK: $(df -h "$WORK" | tail -n 1)"
    python3 -c 'import numpy; print("numpy", numpy.__version__)'
} >"$OUT/device.txt" 2>&1
cat "$OUT/device.txt" | tee -a "$OUT/summary.txt"

run generate "$VOLPT" scene generate scenes || fail "volpt scene generate: $(tail_of generate)"

# ---------------------------------------------------------------------------------------------
# 1. Identical images.
log "1. identical images (naive-sk, seed 7, 4 spp, 200x200)"
# name:flags. PARTIAL is a budget that prefetches part of the scene's grids: cgg-logo's density
# (4 MB) whole and 2 MiB of its albedo (12 MB); bucky's grids (0.5 MB) are below the 2 MiB unit
# of managed prefetch, so there it leaves everything in host memory.
PLACEMENTS=(
    "zerocopy:--volume-memory zerocopy"
    "managed:--volume-memory managed"
    "managed-partial:--volume-memory managed --device-memory-budget PARTIAL"
    "auto-over-budget:--volume-memory auto --device-memory-budget 1K"
    "device-bricked:--volume-memory device --bricked"
    "zerocopy-bricked:--volume-memory zerocopy --bricked"
    "managed-bricked-partial:--volume-memory managed --bricked --device-memory-budget PARTIAL"
)
# name:file:partial budget:parameters
SCENES=(
    "cgg-logo:scenes/cgg-logo/scene.xml:6M:"
    "bucky:scenes/bucky/scene.toml:1K:-Ddata=$DATA"
)
COMMON=(--spp 4 --seed 7 --resolution 200x200)
GPU=(--backend cuda --math exact --strategy naive-sk)
for entry in "${SCENES[@]}"; do
    IFS=: read -r scene file partial params <<<"$entry"
    [ -f "$file" ] || { log "SKIP $scene: $file not in this bundle"; continue; }
    # shellcheck disable=SC2086
    run "$scene-cpu" "$VOLPT" render "$file" $params "${COMMON[@]}" -o "$WORK/$scene-cpu.exr" \
        || { fail "$scene cpu render: $(tail_of "$scene-cpu")"; continue; }
    # shellcheck disable=SC2086
    run "$scene-device" "$VOLPT" render "$file" $params "${COMMON[@]}" "${GPU[@]}" \
        --volume-memory device -o "$WORK/$scene-device.exr" \
        || { fail "$scene device render: $(tail_of "$scene-device")"; continue; }
    log "   $scene device: $(placements "$scene-device")"
    if run "$scene-cpu-vs-device" "$VOLPT" compare "$WORK/$scene-cpu.exr" "$WORK/$scene-device.exr" --identical
    then log "PASS $scene cpu = device: $(tail_of "$scene-cpu-vs-device" 2)"
    else fail "$scene cpu vs device: $(tail_of "$scene-cpu-vs-device" 2)"; fi
    for p in "${PLACEMENTS[@]}"; do
        IFS=: read -r name flags <<<"$p"
        flags=${flags//PARTIAL/$partial}
        # shellcheck disable=SC2086
        if run "$scene-$name" "$VOLPT" render "$file" $params "${COMMON[@]}" "${GPU[@]}" $flags \
            -o "$WORK/$scene-$name.exr"; then
            if run "$scene-$name-compare" "$VOLPT" compare "$WORK/$scene-device.exr" "$WORK/$scene-$name.exr" --identical
            then log "PASS $scene $name = device: $(placements "$scene-$name")"
            else fail "$scene $name differs: $(tail_of "$scene-$name-compare" 2) [$(placements "$scene-$name")]"; fi
        else
            fail "$scene $name render: $(tail_of "$scene-$name")"
        fi
    done
done
# Errors, not crashes: an explicit device placement over its budget.
if run over-budget "$VOLPT" render scenes/cgg-logo/scene.xml "${COMMON[@]}" "${GPU[@]}" \
    --volume-memory device --device-memory-budget 1M -o "$WORK/over.exr"; then
    fail "device over budget rendered instead of refusing"
elif grep -q "does not fit the device memory budget" "$WORK/logs/over-budget.log" \
    && ! grep -q panicked "$WORK/logs/over-budget.log"; then
    log "PASS device over budget is a clean error: $(grep -m 1 '^Error' "$WORK/logs/over-budget.log")"
else
    fail "device over budget: $(tail_of over-budget)"
fi
log "   section 1 done at $(elapsed)"

# ---------------------------------------------------------------------------------------------
# The generator: a gyroid lattice (a 3D print's infill) of sheets of density 1 in a slowly varying
# envelope, written slice by slice straight to the file (one pass, no copy of the whole volume).
cat >"$WORK/generate.py" <<'EOF'
import sys, time
import numpy as np
path, nx, ny, nz = sys.argv[1], *map(int, sys.argv[2:5])
t0 = time.time()
# The volume's box: [-1, 1] along the longest axis, cell-centred samples.
ext = np.array([nx, ny, nz], dtype=np.float64) / max(nx, ny, nz)
def axis(n, e):
    return ((np.arange(n, dtype=np.float64) + 0.5) / n - 0.5) * 2.0 * e
x, y, z = axis(nx, ext[0]), axis(ny, ext[1]), axis(nz, ext[2])
w = 4.0 * np.pi  # 4 cells of the lattice per unit
sx, cx = np.sin(w * x)[None, :], np.cos(w * x)[None, :]
sy, cy = np.sin(w * y)[:, None], np.cos(w * y)[:, None]
envelope_xy = 0.55 + 0.45 * np.cos(1.3 * x)[None, :] * np.cos(2.1 * y)[:, None]
with open(path, "wb") as f:
    for k in range(nz):
        sz, cz = np.sin(w * z[k]), np.cos(w * z[k])
        g = sx * cy + sy * cz + sz * cx
        d = np.clip(1.0 - 2.5 * np.abs(g), 0.0, 1.0) * envelope_xy * (0.7 + 0.3 * np.cos(3.0 * z[k]))
        d.astype("<f4").tofile(f)
print(f"wrote {path}: {nx}x{ny}x{nz} f32, {nx*ny*nz*4/2**30:.2f} GiB in {time.time()-t0:.1f} s")
EOF
scene_toml() { # scene_toml FILE RAW NX NY NZ SCALE
    local file=$1 raw=$2 nx=$3 ny=$4 nz=$5 scale=$6
    local ex ey ez
    read -r ex ey ez < <(awk -v x="$nx" -v y="$ny" -v z="$nz" \
        'BEGIN { m = x; if (y > m) m = y; if (z > m) m = z; printf "%.6f %.6f %.6f\n", x / m, y / m, z / m }')
    cat >"$file" <<EOF
[volume]
file = "$raw"
format = "raw"
resolution = [$nx, $ny, $nz]
type = "f32"
bounds = [[-$ex, -$ey, -$ez], [$ex, $ey, $ez]]
scale = $scale

[albedo]
value = [0.95, 0.8, 0.6]

[phase]
g = 0.3

[boundary]
bsdf = "null"

[camera]
origin = [1.5, 1.0, 2.3]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 45.0

[film]
width = 256
height = 256

[sampler]
spp = 16

[environment]
radiance = 1.0
EOF
}
# A render's summary line: "WxH at N spp (...) in T s: X M paths/s, ...".
summary_line() { grep -m 1 ' spp (' "$WORK/logs/$1.log"; }

# ---------------------------------------------------------------------------------------------
# 2. 8 GiB under a 2 GiB budget.
if [ "${QUICK:-0}" = 1 ]; then
    log "2. SKIP the 8 GiB volume (QUICK=1)"
else
    log "2. a generated 8 GiB volume (2048x1024x1024 f32) under --device-memory-budget 2G"
    BIG=$WORK/big.raw
    read -r bx by bz <<<"${BIG_DIMS:-2048 1024 1024}"
    if [ "$(stat -c %s "$BIG" 2>/dev/null)" != "$((bx * by * bz * 4))" ]; then
        run generate-big python3 "$WORK/generate.py" "$BIG" "$bx" "$by" "$bz" \
            || fail "generating the 8 GiB volume: $(tail_of generate-big)"
    fi
    log "   $(tail -n 2 "$WORK/logs/generate-big.log" 2>/dev/null | head -n 1)"
    scene_toml "$WORK/big.toml" "$BIG" "$bx" "$by" "$bz" 60
    BIGRUN=(--spp 4 --seed 7 --resolution 256x256 --backend cuda --math exact --strategy naive-sk --memory-limit 16G)
    : >"$OUT/big.txt"
    for p in "device:--volume-memory device" \
             "auto-2G:--volume-memory auto --device-memory-budget 2G" \
             "auto-2G-bricked:--volume-memory auto --device-memory-budget 2G --bricked" \
             "managed-2G:--volume-memory managed --device-memory-budget 2G"; do
        IFS=: read -r name flags <<<"$p"
        # shellcheck disable=SC2086
        if run "big-$name" "$VOLPT" render "$WORK/big.toml" "${BIGRUN[@]}" $flags -o "$WORK/big-$name.exr"; then
            line="big $name: $(summary_line "big-$name") [$(placements "big-$name")] $(tail -n 1 "$WORK/logs/big-$name.log")"
            echo "$line" >>"$OUT/big.txt"
            log "PASS $line"
            if [ "$name" != device ] && [ -f "$WORK/big-device.exr" ]; then
                if run "big-$name-compare" "$VOLPT" compare "$WORK/big-device.exr" "$WORK/big-$name.exr" --identical
                then log "PASS big $name = device: $(tail_of "big-$name-compare" 2)"
                else fail "big $name differs from device: $(tail_of "big-$name-compare" 2)"; fi
            fi
        else
            fail "big $name: $(tail_of "big-$name" 6)"
            echo "FAIL big $name: $(tail_of "big-$name" 6)" >>"$OUT/big.txt"
        fi
        log "   at $(elapsed); host: $(free -g | awk '/Mem:/ {print $7 " GiB available"}')"
    done
    cp "$WORK/big-auto-2G.png" "$OUT/big-auto-2G.png" 2>/dev/null
    [ "${KEEP:-0}" = 1 ] || rm -f "$BIG"
fi

# ---------------------------------------------------------------------------------------------
# 3. Throughput against device-resident, one run (regeneration-sk, the default strategy).
log "3. throughput: $TRIALS trials after a warm-up, regeneration-sk"
MID=$WORK/mid.raw
N=${MID_RES:-512}
run generate-mid python3 "$WORK/generate.py" "$MID" "$N" "$N" "$N" || fail "generating the $N^3 volume: $(tail_of generate-mid)"
scene_toml "$WORK/mid.toml" "$MID" "$N" "$N" "$N" 60
# cgg-logo: 16 MB of grids (inside the H100's 50 MB L2); mid: 512 MiB, which is not.
BENCH_SCENES=(
    "cgg-logo:scenes/cgg-logo/scene.xml:--spp 64 --resolution 400x400"
    "gyroid-$N:$WORK/mid.toml:--spp 16 --resolution 256x256"
)
BENCH_PLACEMENTS=(
    "device:--volume-memory device"
    "zerocopy:--volume-memory zerocopy"
    "managed:--volume-memory managed"
    "managed-half:--volume-memory managed --device-memory-budget HALF"
    "device-bricked:--volume-memory device --bricked"
    "zerocopy-bricked:--volume-memory zerocopy --bricked"
    "managed-half-bricked:--volume-memory managed --device-memory-budget HALF --bricked"
)
for entry in "${BENCH_SCENES[@]}"; do
    IFS=: read -r scene file params <<<"$entry"
    # Half of the scene's grid bytes: managed memory with half of the volume prefetched.
    case $scene in cgg-logo) half=8M ;; *) half=256M ;; esac
    for p in "${BENCH_PLACEMENTS[@]}"; do
        IFS=: read -r name flags <<<"$p"
        flags=${flags//HALF/$half}
        # shellcheck disable=SC2086
        if run "bench-$scene-$name" "$VOLPT" bench "$file" $params --backend cuda --trials "$TRIALS" --json $flags; then
            sed -n '/^{/,/^}/p' "$WORK/logs/bench-$scene-$name.log" >"$WORK/bench/$scene--$name.json"
            log "   bench $scene $name: $(grep -o '"time_mean_s": [0-9.e-]*' "$WORK/bench/$scene--$name.json") [$(placements "bench-$scene-$name" | cut -c 1-200)]"
        else
            fail "bench $scene $name: $(tail_of "bench-$scene-$name")"
        fi
    done
done
python3 - "$WORK/bench" >"$OUT/throughput.txt" <<'EOF'
import json, os, sys
d = sys.argv[1]
rows = {}
for f in sorted(os.listdir(d)):
    scene, _, name = f[: -len(".json")].partition("--")
    rows.setdefault(scene, {})[name] = json.load(open(os.path.join(d, f)))
order = ["device", "zerocopy", "managed", "managed-half", "device-bricked", "zerocopy-bricked", "managed-half-bricked"]
for scene, r in rows.items():
    base = r.get("device")
    print(f"## {scene}" + (f" ({base['width']}x{base['height']}, {base['spp']} spp, {base['device']})" if base else ""))
    print("| placement | time mean (s) | std (s) | M paths/s | G tracking steps/s | vs device |")
    print("|---|---|---|---|---|---|")
    for name in order:
        if name not in r:
            print(f"| {name} | failed | | | | |")
            continue
        x = r[name]
        ratio = x["paths_per_s"] / base["paths_per_s"] if base else float("nan")
        print(f"| {name} | {x['time_mean_s']:.4f} | {x['time_std_s']:.4f} | {x['paths_per_s']/1e6:.2f} | "
              f"{x['tracking_steps_per_s']/1e9:.3f} | {ratio:.3f} |")
    print()
EOF
cat "$OUT/throughput.txt" | tee -a "$OUT/summary.txt"

log "done in $(elapsed): $failures failure(s)"
tar -czf "$OUT/logs.tar.gz" -C "$WORK" logs
tar -czf "$OUT/bench.tar.gz" -C "$WORK" bench
[ "${KEEP:-0}" = 1 ] || rm -f "$WORK"/*.raw
exit $((failures > 0))
