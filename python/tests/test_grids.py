"""scene.set_grid: a grid's values replaced from numpy render as the scene loaded from a file of
them, bit for bit; equal values change nothing; values of the wrong shape or range, or for a grid
the scene lacks, raise GridError and leave the scene as it was."""

import numpy as np
import pytest

import volpt
from conftest import CUBE, SETTINGS, bits

SHAPE = (4, 5, 6)  # (z, y, x)


def ball(peak: float) -> np.ndarray:
    """A density grid of SHAPE: a ball of density `peak` falling off to the corners."""
    z, y, x = np.meshgrid(*[(np.arange(n) + 0.5) / n - 0.5 for n in SHAPE], indexing="ij")
    return (peak * np.clip(1.0 - 1.5 * (x**2 + y**2 + z**2), 0.0, None)).astype(np.float32)


def write_scene(directory, density: np.ndarray):
    """A volpt TOML scene of `density` (raw float32, not normalised) in `directory`."""
    density.astype("<f4").tofile(directory / "density.raw")
    z, y, x = density.shape
    path = directory / "scene.toml"
    path.write_text(
        '[volume]\nfile = "density.raw"\nformat = "raw"\ntype = "f32"\n'
        f"resolution = [{x}, {y}, {z}]\n"
        "bounds = [[-0.5, -0.5, -0.5], [0.5, 0.5, 0.5]]\n"
        "[camera]\norigin = [2.0, 1.5, 2.5]\ntarget = [0.0, 0.0, 0.0]\nfov = 40.0\n"
    )
    return path


def load(directory, density):
    return volpt.load(write_scene(directory, density), {**SETTINGS, "spp": 4})


def test_a_replaced_grid_renders_as_the_scene_loaded_with_it(tmp_path):
    scene = load(tmp_path, ball(20.0))
    assert scene.grids == ["density"]
    assert scene.grid("density").dtype == np.float32
    assert np.array_equal(scene.grid("density"), ball(20.0))
    first, fingerprint = scene.render().sums, scene.fingerprint

    scene.set_grid("density", ball(45.0))
    assert np.array_equal(scene.grid("density"), ball(45.0))
    replaced = scene.render()
    assert not np.array_equal(replaced.sums, first)
    fresh_dir = tmp_path / "fresh"
    fresh_dir.mkdir()
    fresh = load(fresh_dir, ball(45.0))
    assert np.array_equal(bits(replaced.sums), bits(fresh.render().sums))
    assert scene.fingerprint == fresh.fingerprint != fingerprint

    # Flat, float64: converted to the grid's float32 values in its order.
    scene.set_grid("density", ball(20.0).astype(np.float64).ravel())
    assert np.array_equal(bits(scene.render().sums), bits(first))
    assert scene.fingerprint == fingerprint


def test_the_same_values_change_nothing(tmp_path):
    scene = load(tmp_path, ball(20.0))
    before = (scene.render().sums, scene.fingerprint)
    scene.set_grid("density", ball(20.0))
    assert np.array_equal(bits(scene.render().sums), bits(before[0]))
    assert scene.fingerprint == before[1]


BAD = [
    ("density", np.zeros((4, 5, 7), np.float32), "expected an array of shape [4, 5, 6]"),
    ("density", np.zeros(119, np.float32), "expected 120 values (6 x 5 x 4 samples x 1 channels), found 119 values"),
    ("density", -ball(1.0) - 1.0, "expected values in [0"),
    ("density", np.full(SHAPE, np.nan, np.float32), "found NaN"),
    ("albedo", ball(1.0), "expected one of the medium's grids: density, found no such grid"),
    ("density", "dense", "expected an array of numbers, found str 'dense'"),
]


@pytest.mark.parametrize("name,values,message", BAD, ids=[m for _, _, m in BAD])
def test_bad_values_raise_grid_error_and_leave_the_scene(tmp_path, name, values, message):
    scene = load(tmp_path, ball(20.0))
    before = (scene.render().sums, scene.fingerprint)
    with pytest.raises(volpt.GridError, match=None) as raised:
        scene.set_grid(name, values)
    assert isinstance(raised.value, ValueError)
    assert str(raised.value).startswith(f"grid {name}: ")
    assert message in str(raised.value)
    assert np.array_equal(bits(scene.render().sums), bits(before[0]))
    assert scene.fingerprint == before[1]


def test_a_scene_without_grids_names_none():
    scene = volpt.load(CUBE, SETTINGS)
    assert scene.grids == []
    with pytest.raises(volpt.GridError, match="has none"):
        scene.grid("density")
