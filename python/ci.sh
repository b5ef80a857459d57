#!/usr/bin/env bash
# The Python package's CI: builds the extension (maturin, release) and installs it into a fresh
# virtual environment with pytest, numpy and ray, builds the `volpt` CLI the tests compare with, and
# runs python/tests. Needs python3 (>= 3.9) with venv and pip, and network access to PyPI for
# maturin, pytest, numpy and ray (volpt.distributed's tests start a local Ray cluster of two worker
# nodes on this machine; VOLPT_REQUIRE_RAY makes them fail rather than skip without Ray).
#
#   python/ci.sh                 # from anywhere in the checkout
#   VOLPT_PYTHON=python3.12 python/ci.sh
#
# The venv is target/python-venv (recreated each run). The wheel embeds the GPU kernels if
# `cargo xtask ptx` has written them (volpt-cuda/build.rs), as the CLI does.
set -euo pipefail
cd "$(dirname "$0")/.."

python="${VOLPT_PYTHON:-python3}"
venv=target/python-venv
start=$SECONDS

rm -rf "$venv"
"$python" -m venv "$venv"
# maturin's build backend runs the `maturin` of the environment's PATH.
export PATH="$PWD/$venv/bin:$PATH"
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q "maturin>=1.5,<2" "pytest>=7" "numpy>=1.20" "ray>=2.9"
# The CLI as the README's `cargo test --release` builds it (a no-op after CI's test step; `-p
# volpt-cli` alone would unify other dependency features and rebuild the workspace).
cargo test --release --no-run -q
echo "python/ci.sh: venv and CLI ready in $((SECONDS - start)) s"
# In place (no isolated build environment): the workspace's target/ and its compiled crates are
# reused, and maturin comes from the venv.
"$venv/bin/python" -m pip install -q --no-build-isolation ./python
echo "python/ci.sh: built and installed in $((SECONDS - start)) s"
# From outside the checkout, so that `import volpt` is the installed package.
(cd "$venv" && VOLPT_REQUIRE_RAY=1 VOLPT_BIN="$OLDPWD/target/release/volpt" bin/python -m pytest -q -p no:cacheprovider --durations=5 "$OLDPWD/python/tests")
echo "python/ci.sh: done in $((SECONDS - start)) s"
