#!/usr/bin/env bash
# docs/printing.md's worked example: the three targets of this folder compensated by the command
# line on the CPU, their pictures copied into docs/printing/.
#
#   bash examples/print/worked_example.sh [VOLPT]     # VOLPT: the binary (default target/release/volpt)
#
# Each target is 96 x 96 texels, 100 layers (40 of colour) of examples/print/materials.toml; 16
# samples per texel first, the noise control raising them (at most 256), at most 6 iterations.
set -euo pipefail
cd "$(dirname "$0")/../.."
VOLPT=${1:-target/release/volpt}
OUT=${OUT:-target/print-example}
DOCS=docs/printing
rm -rf "$OUT"
mkdir -p "$OUT" "$DOCS"
for name in lines photo gradient; do
    start=$SECONDS
    "$VOLPT" print compensate "examples/print/$name.png" --materials examples/print/materials.toml \
        -o "$OUT/$name" --layers 100 --colour-layers 40 --spp 16 --max-spp 256 --iterations 6 \
        2>&1 | grep -v "^compensating" | tee "$OUT/$name.log"
    echo "$name: $((SECONDS - start)) s wall" | tee -a "$OUT/$name.log"
    cp "$OUT/$name/comparison.png" "$DOCS/$name-comparison.png"
    cp "$OUT/$name/delta_e.svg" "$DOCS/$name-delta_e.svg"
    cp "$OUT/$name/iterations.csv" "$DOCS/$name-iterations.csv"
    cp "$OUT/$name/naive_slices/slice_0099.png" "$DOCS/$name-naive-top-slice.png"
    cp "$OUT/$name/slices/slice_0099.png" "$DOCS/$name-compensated-top-slice.png"
done
