#!/usr/bin/env bash
# On a machine with an NVIDIA GPU: one CUDA render from Python equals the CLI's bit for bit.
#
#   python/device_check.sh [WHEEL] [VOLPT_BIN]
#
# WHEEL: a volpt wheel built with the GPU kernels embedded (`cargo xtask ptx`, then
# `maturin build --release -m python/Cargo.toml`; default: the newest target/wheels/volpt-*.whl).
# VOLPT_BIN: the `volpt` CLI of the same checkout, built with the kernels (default:
# target/release/volpt). Installs the wheel into a fresh venv (with the system's site-packages:
# numpy from there if it has it; else from PyPI, or offline from a folder of wheels with
# VOLPT_PIP_ARGS="--no-index --find-links DIR", e.g. one `pip download numpy -d DIR` filled), renders scenes/example/cube.xml at 64x64,
# 16 spp, seed 3 with `--backend cuda --strategy naive-sk` (exact math: the CPU's paths, summed in
# the CPU's order; regeneration-sk's f64 sums take the order its atomics happen in) from both, and
# compares the EXR files byte for byte, the images and the film sums (the CLI's checkpoint)
# bit for bit, and the CUDA render against the CPU's. Exit 0 if all are equal.
set -euo pipefail
cd "$(dirname "$0")/.."

wheel="${1:-$(ls -t target/wheels/volpt-*.whl 2>/dev/null | head -1)}"
volpt_bin="${2:-target/release/volpt}"
[[ -f "$wheel" ]] || { echo "device_check: no wheel (give one, or build target/wheels/volpt-*.whl)" >&2; exit 2; }
[[ -x "$volpt_bin" ]] || { echo "device_check: no volpt binary at $volpt_bin" >&2; exit 2; }
nvidia-smi -L || true

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
python3 -m venv --system-site-packages "$work/venv"
if ! "$work/venv/bin/python" -c "import numpy" 2>/dev/null; then
    # shellcheck disable=SC2086
    "$work/venv/bin/python" -m pip install -q ${VOLPT_PIP_ARGS:-} numpy
fi
"$work/venv/bin/python" -m pip install -q --no-deps --no-index "$wheel"

scene=scenes/example/cube.xml
# VOLPT_CHECK_BACKEND=cpu runs the same comparison on the CPU (the script's own test, no GPU).
backend="${VOLPT_CHECK_BACKEND:-cuda}"
gpu=()
[[ "$backend" == cuda ]] && gpu=(--strategy naive-sk)
args=(--resolution 64x64 --spp 16 --seed 3 --backend "$backend" "${gpu[@]}")
time "$volpt_bin" render "$scene" "${args[@]}" -o "$work/cli.exr" --checkpoint "$work/cli.ck"

"$work/venv/bin/python" - "$scene" "$work" "$backend" <<'PY'
import sys, time
from pathlib import Path
import numpy as np
import volpt

scene_file, work, backend = sys.argv[1], Path(sys.argv[2]), sys.argv[3]
gpu = {"strategy": "naive-sk"} if backend == "cuda" else {}
scene = volpt.load(scene_file, {"resolution": (64, 64)})
start = time.monotonic()
film = scene.render(spp=16, seed=3, backend=backend, **gpu)
print(f"device_check: Python {backend} render {time.monotonic() - start:.3f} s (wall, first CUDA render: "
      f"with the kernels' JIT), {film.elapsed:.3f} s rendering; notes: {film.notes}")
film.write(work / "py.exr")
cli = volpt.Film.load(work / "cli.ck", scene)
bits = lambda a: np.ascontiguousarray(a).view(np.uint64 if a.dtype == np.float64 else np.uint32)
checks = {
    "EXR files byte for byte": (work / "py.exr").read_bytes() == (work / "cli.exr").read_bytes(),
    "images bit for bit": np.array_equal(bits(film.image()), bits(volpt.read_exr(work / "cli.exr"))),
    "film sums bit for bit": np.array_equal(bits(film.sums), bits(cli.sums)),
    "same samples and seed": (cli.samples, cli.seed) == (film.samples, film.seed),
}
cpu = scene.render(spp=16, seed=3)
checks[f"{backend} equals the CPU bit for bit (exact math)"] = np.array_equal(bits(cpu.sums), bits(film.sums))
again = scene.render(spp=16, seed=3, backend=backend, **gpu)
print(f"device_check: second Python {backend} render {again.elapsed:.3f} s rendering")
checks[f"a second {backend} render, same bits"] = np.array_equal(bits(again.sums), bits(film.sums))
for name, ok in checks.items():
    print(f"device_check: {'ok  ' if ok else 'FAIL'} {name}")
sys.exit(0 if all(checks.values()) else 1)
PY
