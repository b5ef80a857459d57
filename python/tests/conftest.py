"""Fixtures of the volpt Python tests: the repository, the CLI to compare with, small scenes."""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
CUBE = REPO / "scenes" / "example" / "cube.xml"
#: Small renders: the tests compare bits, not pictures.
SIZE = (24, 20)
SETTINGS = {"resolution": SIZE}


@pytest.fixture(scope="session")
def volpt_bin() -> Path:
    """The `volpt` command line of this checkout (python/ci.sh builds it; VOLPT_BIN overrides)."""
    path = Path(os.environ.get("VOLPT_BIN", REPO / "target" / "release" / "volpt"))
    if not path.is_file():
        pytest.fail(f"{path}: no volpt binary (cargo build --release -p volpt-cli, or set VOLPT_BIN)")
    return path


def run_cli(volpt_bin: Path, *args: str) -> str:
    out = subprocess.run(
        [str(volpt_bin), *map(str, args)], capture_output=True, text=True, env={**os.environ, "RUST_LOG": "warn"}
    )
    assert out.returncode == 0, f"volpt {' '.join(map(str, args))} failed:\n{out.stderr}"
    return out.stdout


def write_grid(path: Path, n: int = 12) -> Path:
    """A heterogeneous medium as a bare MetaImage grid (a scene source of its own): a ball of
    density falling off from the centre, with noise-free structure on every axis."""
    ax = (np.arange(n) + 0.5) / n - 0.5
    z, y, x = np.meshgrid(ax, ax, ax, indexing="ij")
    density = np.clip(1.0 - 2.2 * np.sqrt(x**2 + y**2 + z**2), 0.0, None) * (1.0 + 0.5 * np.sin(9 * x))
    path.write_text(
        "ObjectType = Image\nNDims = 3\n"
        f"DimSize = {n} {n} {n}\nElementType = MET_FLOAT\nElementDataFile = {path.stem}.raw\n"
    )
    density.astype("<f4").tofile(path.with_suffix(".raw"))
    return path


@pytest.fixture(scope="session")
def grid_scene(tmp_path_factory) -> Path:
    return write_grid(tmp_path_factory.mktemp("grid") / "ball.mhd")


def bits(a: np.ndarray) -> np.ndarray:
    """The array's bits, so that equality is bit equality (NaNs, signed zeros included)."""
    a = np.ascontiguousarray(a)
    return a.view(np.uint32 if a.dtype == np.float32 else np.uint64)
