#!/usr/bin/env bash
# The printing application on the GPU (issue 40), from the device bundle with the stripped `volpt`
# (no cargo), in one call:
#
#   bash bundle/print.sh      # results under $OUT (default ./out/print), summary in $OUT/summary.txt
#
# Needs the tracked tree beside the bundle (examples/print: the material table and the worked
# example's targets) and python3 (standard library only: it writes the synthetic targets).
# 1. CPU against GPU: the same 32 x 32-texel compensation (100 layers, 40 of colour, 256 samples,
#    no noise control, 3 iterations, seed 1) with `--backend cpu` and `--backend cuda`. Each
#    prediction is an independent unbiased render, so each iteration's mean CIEDE2000 agrees
#    within noise. Expected: PASS, naive means within 2% (and best within 5%). Then the same
#    without --backend (expected: "PASS default-backend: on NVIDIA H200 (no --backend: a GPU is
#    present (1 seen by the driver)") and with --gpus all (expected: a summary line like the
#    others).
# 2. The thesis's slab size: 320 x 320 texels, 100 layers (40 of colour), one compensation on
#    the GPU from 64 samples per texel with the noise control on (at most 1024 samples), at most
#    10 iterations. Expected: a line "320 x 320 texels: N iteration(s) in T s ..." with T well
#    under 120 s (issue 40's target: <= 60 s); the lead records T and the per-iteration lines.
# 3. The worked example's three 96 x 96 targets (examples/print: lines, photo, gradient) on the
#    GPU, 100 layers, for bench/peers/mitsuba3/print.py (the Mitsuba 3 cross-check): records
#    under $OUT/<target>/, each with print.toml and naive.toml, predicted from 1024 samples per
#    texel with the noise control at 0.1 (up to 16384): the record's means then measure the
#    print, not the predictions' noise (docs/printing.md, "Noise floor"). And $OUT/white/: a
#    uniform white 96 x 96 target's naive print (one prediction), the noise floor's reference.
#    Expected: four summary lines, best mean below naive on each of the three.
# PRINT_STEPS (default "1 2 3") runs only the steps named; PRINT_TARGETS (default "lines photo
# gradient") names step 3's targets (the white record is always made): e.g. PRINT_STEPS=3
# PRINT_TARGETS=lines, the fine-detail target's records alone (about 30 s on one H200).
set -uo pipefail
cd "$(dirname "$0")"
OUT=${OUT:-$PWD/out/print}
VOLPT=${VOLPT:-$PWD/bin/volpt}
EXAMPLES=${EXAMPLES:-$PWD/../examples/print}
rm -rf "$OUT"
mkdir -p "$OUT"
failures=0
log() { echo "== $*" | tee -a "$OUT/summary.txt"; }
log "date $(date -u +%Y-%m-%dT%H:%MZ) $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null)"
[ -f "$EXAMPLES/materials.toml" ] || { log "FAIL no $EXAMPLES/materials.toml (the tracked tree)"; exit 2; }

# The synthetic target: fine bars over the left half, a hue gradient on the right (8-bit RGB PNG);
# with a third argument `white`, a uniform white one.
target() { # target SIZE FILE [white]
    python3 - "$1" "$2" "${3:-}" <<'PY'
import struct, sys, zlib
n, path, white = int(sys.argv[1]), sys.argv[2], sys.argv[3] == "white"
bars = [(200, 60, 60), (60, 120, 200), (240, 220, 120)]
rows = b""
for y in range(n):
    row = bytearray(b"\x00")
    for x in range(n):
        if white:
            row += bytes((255, 255, 255))
        elif x < n // 2:
            row += bytes(bars[([1, 1, 2, 2, 4, 4, 4][x % 7] + x // 7) % 3])
        else:
            t = y / n
            row += bytes(round(255 * v) for v in (0.3 + 0.6 * t, 0.8 - 0.4 * t, 0.5))
    rows += bytes(row)
chunk = lambda k, d: struct.pack(">I", len(d)) + k + d + struct.pack(">I", zlib.crc32(k + d))
open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", n, n, 8, 2, 0, 0, 0))
                       + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))
PY
}
compensate() { # compensate NAME TARGET ARGS...
    local name=$1 tgt=$2; shift 2
    local start=$SECONDS
    if timeout 300 "$VOLPT" print compensate "$tgt" --materials "$EXAMPLES/materials.toml" \
        -o "$OUT/$name" "$@" >"$OUT/$name.log" 2>&1; then
        log "$name ($((SECONDS - start)) s wall): $(tail -n 1 "$OUT/$name.log")"
    else
        log "FAIL $name: $(tail -n 3 "$OUT/$name.log" | tr '\n' ' ')"; failures=$((failures + 1))
    fi
}

STEPS=" ${PRINT_STEPS:-1 2 3} "
step() { [[ "$STEPS" == *" $1 "* ]]; }

# 1. CPU against GPU.
if step 1; then
target 32 "$OUT/bars32.png"
small=(--layers 100 --colour-layers 40 --spp 256 --noise-ratio 0 --iterations 3 --seed 1)
compensate small-cpu "$OUT/bars32.png" "${small[@]}" --backend cpu
compensate small-cuda "$OUT/bars32.png" "${small[@]}" --backend cuda
python3 - "$OUT" <<'PY' | tee -a "$OUT/summary.txt"
import csv, sys
out = sys.argv[1]
try:
    cpu, gpu = ([float(r["mean_delta_e"]) for r in csv.DictReader(open(f"{out}/{n}/iterations.csv"))]
                for n in ("small-cpu", "small-cuda"))
except OSError as e:
    print(f"== FAIL cpu-vs-cuda: {e}"); sys.exit()
naive = abs(cpu[0] - gpu[0]) / cpu[0]
best = abs(min(cpu) - min(gpu)) / min(cpu)
ok = naive < 0.02 and best < 0.05
print(f"== {'PASS' if ok else 'FAIL'} cpu-vs-cuda: mean dE00 per iteration cpu {cpu}, cuda {gpu}; "
      f"naive differ by {100 * naive:.2f}% (< 2%), best by {100 * best:.2f}% (< 5%)")
PY
grep -q "FAIL cpu-vs-cuda" "$OUT/summary.txt" && failures=$((failures + 1))

# 1b. No --backend: the GPU where one is usable (said on the first line), and --gpus all (every GPU
#     of the machine splitting each prediction's samples).
compensate small-default "$OUT/bars32.png" "${small[@]}"
if grep -q "(no --backend: a GPU is present" "$OUT/small-default.log"; then
    log "PASS default-backend: $(grep -o 'on [^(]*(no --backend: [^;]*' "$OUT/small-default.log" | head -1)"
else
    log "FAIL default-backend: $(head -n 2 "$OUT/small-default.log" | tr '\n' ' ')"; failures=$((failures + 1))
fi
compensate small-gpus "$OUT/bars32.png" "${small[@]}" --gpus all
fi

# 2. The thesis's slab size, timed.
if step 2; then
target 320 "$OUT/bars320.png"
compensate thesis-cuda "$OUT/bars320.png" --layers 100 --colour-layers 40 --spp 64 --max-spp 1024 \
    --iterations 10 --backend cuda
grep "iteration [0-9]*:" "$OUT/thesis-cuda.log" | sed 's/^/   /' | tee -a "$OUT/summary.txt"
fi

# 3. The worked example's targets, for the Mitsuba 3 cross-check.
if step 3; then
for name in ${PRINT_TARGETS:-lines photo gradient}; do
    compensate "$name" "$EXAMPLES/$name.png" --layers 100 --colour-layers 40 --spp 1024 \
        --max-spp 16384 --noise-ratio 0.1 --iterations 10 --backend cuda
done
target 96 "$OUT/white96.png" white
compensate white "$OUT/white96.png" --layers 100 --colour-layers 40 --spp 1024 --iterations 1 \
    --backend cuda
fi
log "failures $failures"
