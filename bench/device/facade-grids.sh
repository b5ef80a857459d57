#!/usr/bin/env bash
# Replaceable grids on the GPU (issue 44, part 2), from a checkout with the PTX built
# (`cargo xtask ptx`), in one call:
#
#   bash bench/device/facade-grids.sh
#
# 1. volpt/tests/grids_gpu.rs with VOLPT_REQUIRE_GPU=1: a scene whose density, then albedo, grid
#    is replaced between renders on one GPU (which keeps the grids of the scene it rendered last)
#    renders bit for bit as the scene loaded fresh with the new values, dense and bricked, with
#    the fast math's default lookup and with trilinear; equal values leave the image as it was.
# 2. volpt/tests/grids.rs (CPU), as a control.
# Expected: "test result: ok. 1 passed" for grids_gpu (no "skipped" line), "ok. 5 passed" for
# grids.
set -euo pipefail
cd "$(dirname "$0")/../.."
VOLPT_REQUIRE_GPU=1 VOLPT_REQUIRE_PTX=1 cargo test --release -p volpt --test grids_gpu -- --nocapture
cargo test --release -p volpt --test grids
