#!/usr/bin/env bash
# Render requests on the GPU (issue 44, part 1), from a checkout with the PTX built
# (`cargo xtask ptx`), in one call:
#
#   bash bench/device/facade-request.sh
#
# 1. volpt/tests/request_gpu.rs with VOLPT_REQUIRE_GPU=1: a scene the GPU reads otherwise than
#    loaded (bricked storage, the fast math's stochastic default lookup) renders from a copy of its
#    description bit for bit as the scene adopted by the backend (dense and bricked), with the same
#    fingerprint; threads sharing one scene and one GPU render the images of serial renders.
# 2. volpt/tests/request.rs (CPU) and facade.rs, as a control.
# Expected: "test result: ok. 2 passed" for request_gpu (no "skipped" line), and ok for the rest.
set -euo pipefail
cd "$(dirname "$0")/../.."
VOLPT_REQUIRE_GPU=1 VOLPT_REQUIRE_PTX=1 cargo test --release -p volpt --test request_gpu -- --nocapture
cargo test --release -p volpt --test request --test facade
