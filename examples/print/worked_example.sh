#!/usr/bin/env bash
# docs/printing.md's worked example: the three targets of this folder compensated by the command
# line on the CPU, their pictures copied into docs/printing/.
#
#   bash examples/print/worked_example.sh [VOLPT]     # VOLPT: the binary (default target/release/volpt)
#
# Each target is 96 x 96 texels, 100 layers (40 of colour) of examples/print/materials.toml; 16
# samples per texel first, the noise control raising them (at most 256), at most 6 iterations,
# the default (cross-talk) update. Then, for the page's comparisons: the lines with the per-texel
# update, and a uniform white target's naive print (one prediction at 256 samples per texel: the
# noise floor and what the white resin reaches at these settings).
set -euo pipefail
cd "$(dirname "$0")/../.."
VOLPT=${1:-target/release/volpt}
OUT=${OUT:-target/print-example}
DOCS=docs/printing
rm -rf "$OUT"
mkdir -p "$OUT" "$DOCS"
compensate() { # compensate NAME TARGET ARGS...
    local name=$1 target=$2 start=$SECONDS
    shift 2
    "$VOLPT" print compensate "$target" --materials examples/print/materials.toml -o "$OUT/$name" \
        --layers 100 --colour-layers 40 "$@" 2>&1 | grep -v "^compensating" | tee "$OUT/$name.log"
    echo "$name: $((SECONDS - start)) s wall" | tee -a "$OUT/$name.log"
}
for name in lines photo gradient; do
    compensate "$name" "examples/print/$name.png" --spp 16 --max-spp 256 --iterations 6
    cp "$OUT/$name/comparison.png" "$DOCS/$name-comparison.png"
    cp "$OUT/$name/delta_e.svg" "$DOCS/$name-delta_e.svg"
    cp "$OUT/$name/iterations.csv" "$DOCS/$name-iterations.csv"
    cp "$OUT/$name/naive_slices/slice_0099.png" "$DOCS/$name-naive-top-slice.png"
    cp "$OUT/$name/slices/slice_0099.png" "$DOCS/$name-compensated-top-slice.png"
done
compensate lines-per-texel examples/print/lines.png --spp 16 --max-spp 256 --iterations 6 \
    --update per-texel
cp "$OUT/lines-per-texel/iterations.csv" "$DOCS/lines-per-texel-iterations.csv"
# A uniform white 96 x 96 target (8-bit RGB PNG).
python3 - "$OUT/white.png" <<'PY'
import struct, sys, zlib
n = 96
rows = b"".join(b"\x00" + b"\xff" * 3 * n for _ in range(n))
chunk = lambda k, d: struct.pack(">I", len(d)) + k + d + struct.pack(">I", zlib.crc32(k + d))
open(sys.argv[1], "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", n, n, 8, 2, 0, 0, 0))
                              + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))
PY
compensate white "$OUT/white.png" --spp 256 --noise-ratio 0 --iterations 1
