#!/usr/bin/env bash
# The printing application's compensation loop on a GPU (issue 40), in one call, from a checkout
# with cargo and the PTX built (`cargo xtask ptx`), as bench/device/facade-grids.sh runs:
#
#   bash bench/device/print.sh
#
# 1. The same 32 x 32-texel print (100 layers, 40 of colour), 256 samples per texel and channel,
#    3 iterations, on the CPU and on the GPU: each prints its per-iteration mean CIEDE2000. The
#    predictions are independent unbiased renders, so the means agree within their noise.
#    Expected: the two "mean dE00 naive" values within 2% of each other, and likewise "best".
# 2. The thesis's slab size on the GPU: 320 x 320 texels, 100 layers (40 of colour), 64 samples
#    per texel and channel, 10 iterations: prints seconds per iteration and in all (target of
#    issue 40: the whole compensation in <= 60 s on one GPU).
#    Expected: "320 x 320 texels, ... iterations in T s (t s each)"; the lead records T and t.
# Records go to $OUT (default /tmp/volpt-print): iteration_NN/prediction.png, delta_e.png,
# iterations.csv, slices/.
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=${OUT:-/tmp/volpt-print}
rm -rf "$OUT"
run() { cargo run --release -q -p volpt-print --example compensate -- "$@"; }
run cpu 32 100 40 256 3 "$OUT/small-cpu"
run cuda 32 100 40 256 3 "$OUT/small-cuda"
run cuda 320 100 40 64 10 "$OUT/thesis-cuda"
