#!/usr/bin/env bash
# The kernel builds that separate the causes of the slowdown the merge of issues 10, 11 and 13
# brought to the exact kernels (docs/strategies.md): each is the current source with one more
# runtime choice taken out, cut down to the regeneration-sk kernels of bench/device/ab.sh's scenes
# and written to bundle/ab/ for `bash bundle/ab.sh` on the device.
#   v0-current            the tree as it is
#   v1-dense-trilinear    grid reads without the layout and lookup dispatch
#   v2-no-dda             also delta tracking without the majorant grid's walk (global majorant)
#   v3-no-dda-no-nee      also no NEE code in the index-matched kernels
# Run from the repository root after `cargo xtask device-bundle`; it edits the sources and restores
# them from git after, so it refuses to start while they have uncommitted changes. NAME_PREFIX
# (default empty) prefixes the file names, to keep builds of several commits side by side.
set -euo pipefail
cd "$(dirname "$0")/../.."
edited="volpt-core/src/grid.rs volpt-core/src/tracking.rs volpt-core/src/path.rs"
# shellcheck disable=SC2086
git diff --quiet HEAD -- $edited || { echo "commit or stash the changes to $edited first" >&2; exit 1; }
prefix=${NAME_PREFIX:-}
mkdir -p bundle/ab
# shellcheck disable=SC2086
trap 'git checkout -- $edited' EXIT

build() { # build NAME: the exact PTX of the working tree, cut down, as bundle/ab/PREFIXNAME.ptx
    RUSTC_BOOTSTRAP=1 CARGO_TARGET_NVPTX64_NVIDIA_CUDA_RUSTFLAGS="-C target-cpu=sm_70 --emit=asm" \
        CARGO_TARGET_NVPTX64_NVIDIA_CUDA_LINKER=/bin/true \
        cargo build -q -Zbuild-std=core --target nvptx64-nvidia-cuda --profile nvptx -p volpt-kernels \
        --target-dir target-ptx/ab
    python3 bench/device/ptx_cut.py target-ptx/ab/nvptx64-nvidia-cuda/nvptx/deps/volpt_kernels.s \
        "bundle/ab/$prefix$1.ptx" "^regeneration_sk__(homogeneous__index_matched__isotropic|homogeneous__rough_dielectric__isotropic|grid_density__grid_albedo__dense_trilinear__rough_dielectric__isotropic|grid_density__constant_albedo__dense_trilinear__index_matched__isotropic|grid_density__grid_albedo__dense_trilinear__rough_dielectric__henyey_greenstein)__constant$"
}

replace() { # replace FILE OLD NEW: one literal replacement, or fail
    python3 - "$@" <<'PY'
import sys
path, old, new = sys.argv[1:]
s = open(path).read()
if old not in s:
    sys.exit(f"{path}: {old!r} not found (the source moved on: update this script)")
open(path, "w").write(s.replace(old, new, 1))
PY
}

build v0-current
replace volpt-core/src/grid.rs '        match self.layout {
            GridLayout::Dense => self.interpolate(p, dense_index),
            GridLayout::Bricked => self.interpolate(p, bricked_index),
        }' '        self.interpolate(p, dense_index)'
replace volpt-core/src/grid.rs '        match self.lookup {
            GridLookup::Trilinear => trilinear(q, max_index, self.res, at),
            GridLookup::Nearest => {
                let n = q.round();
                at(n.x as u32, n.y as u32, n.z as u32)
            }
        }' '        trilinear(q, max_index, self.res, at)'
build v1-dense-trilinear
replace volpt-core/src/tracking.rs 'let Some(grid) = medium.majorant_grid() else {' \
    'let Some(grid) = medium.majorant_grid().filter(|_| false) else {'
build v2-no-dda
replace volpt-core/src/path.rs 'S::Bsdf::IS_NULL && scene.settings().estimator == Estimator::NextEvent' \
    'false && S::Bsdf::IS_NULL && scene.settings().estimator == Estimator::NextEvent'
build v3-no-dda-no-nee
