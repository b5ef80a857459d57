#!/usr/bin/env bash
# Mesh boundaries (issue 39), what a device run should check today. The GPU kernels are still
# instantiated for box scenes only (the registry has no shape axis yet; a mesh scene renders on
# the CPU through volpt-core's generic path step), so the device's part is:
#   1. the box kernels are unchanged by the shape axis: PTX of this checkout against main's
#      before the change (textually identical kernels cannot be slower), and
#   2. the CPU mesh checks on the device host (identical to this machine's), and the box-vs-mesh
#      speed example on its 16 cores.
# Run from a checkout (not a bundle):  bash bench/device/mesh.sh BEFORE_PTX_DIR
#   BEFORE_PTX_DIR: target-ptx of main before the mesh change (nvptx64-nvidia-cuda/nvptx/deps/)
# Expected: "identical" for every strategy's kernels (ptx_diff.py), 8 + 2 tests passing, and
# mesh_speed printing "images identical" on every round.
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
BEFORE=${1:-}
cargo xtask ptx >"$OUT/ptx.log" 2>&1 || { echo "FAIL cargo xtask ptx"; tail "$OUT/ptx.log"; }
if [ -n "$BEFORE" ]; then
    for flavour in "" fast/; do
        python3 bench/device/ptx_diff.py "$BEFORE/${flavour}nvptx64-nvidia-cuda/nvptx/deps/volpt_kernels.s" \
            "target-ptx/${flavour}nvptx64-nvidia-cuda/nvptx/deps/volpt_kernels.s" | tee -a "$OUT/ptx-diff.txt"
    done
fi
cargo test --release -p volpt-core --test mesh 2>&1 | tail -3 | tee "$OUT/mesh-tests.txt"
cargo test --release -p volpt-scene --test mesh_files 2>&1 | tail -3 | tee -a "$OUT/mesh-tests.txt"
# cgg-logo's grids are generated.
cargo run --release -p volpt-cli -- scene generate scenes >/dev/null 2>&1 || echo "FAIL scene generate"
for scene in scenes/homogeneous-cube/scene.xml "scenes/cgg-logo/scene.xml"; do
    echo "== $scene" | tee -a "$OUT/mesh-speed.txt"
    cargo run --release -p volpt-render --example mesh_speed -- "$scene" 4 128 2>&1 | tail -4 | tee -a "$OUT/mesh-speed.txt"
done
