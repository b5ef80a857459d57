"""Renders from Python equal the command line's bit for bit: same scene, settings, seed, backend."""

import pytest

import volpt
from conftest import CUBE, SETTINGS, SIZE, bits, run_cli

import numpy as np


def scenes(grid_scene):
    return {"cube": CUBE, "grid": grid_scene}


@pytest.mark.parametrize("which", ["cube", "grid"])
@pytest.mark.parametrize("seed", [0, 7])
def test_image_equals_cli_bit_for_bit(tmp_path, volpt_bin, grid_scene, which, seed):
    scene_file = scenes(grid_scene)[which]
    spp = 5
    exr, ck = tmp_path / "cli.exr", tmp_path / "cli.ck"
    run_cli(
        volpt_bin, "render", scene_file, "--resolution", f"{SIZE[0]}x{SIZE[1]}", "--spp", spp,
        "--seed", seed, "-o", exr, "--checkpoint", ck,
    )
    scene = volpt.load(scene_file, SETTINGS)
    film = scene.render(spp=spp, seed=seed)
    assert film.samples == range(0, spp)
    image = film.image()
    assert image.shape == (SIZE[1], SIZE[0], 3) and image.dtype == np.float32
    # The CLI's image as read back, and its file byte for byte.
    assert np.array_equal(bits(volpt.read_exr(exr)), bits(image))
    film.write(tmp_path / "py.exr")
    assert (tmp_path / "py.exr").read_bytes() == exr.read_bytes()
    # The CLI's film sums (its checkpoint), to the last bit of every float64.
    cli = volpt.Film.load(ck, scene)
    assert cli.samples == film.samples and cli.seed == seed == film.seed
    assert cli.fingerprint == film.fingerprint == scene.fingerprint
    assert np.array_equal(bits(cli.sums), bits(film.sums))
    assert image.mean() > 0


def test_scene_default_spp_and_png(tmp_path, volpt_bin):
    # Mitsuba's -D spp=3 through volpt.load's keywords, and the PNG preview the CLI writes.
    run_cli(volpt_bin, "render", CUBE, "-D", "spp=3", "--resolution", f"{SIZE[0]}x{SIZE[1]}", "-o", tmp_path / "c.exr")
    scene = volpt.load(CUBE, SETTINGS, spp=3)
    assert scene.spp == 3
    film = scene.render()
    film.write(tmp_path / "p.png")
    assert (tmp_path / "p.png").read_bytes() == (tmp_path / "c.png").read_bytes()


def format_info(info):
    lines = []
    for key, value in info.items():
        first, *rest = value.split("\n")
        lines.append(f"{key:<10} {first}")
        lines += [" " * 11 + line for line in rest]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("which", ["cube", "grid"])
def test_info_is_volpt_info(volpt_bin, grid_scene, which):
    scene_file = scenes(grid_scene)[which]
    text = run_cli(volpt_bin, "info", scene_file, "--resolution", f"{SIZE[0]}x{SIZE[1]}", "--tracking", "grid")
    info = volpt.load(scene_file, {**SETTINGS, "tracking": "grid"}).info()
    assert list(info)[:3] == ["scene", "variant", "film"]
    assert "light" in info and info["film"].startswith(f"{SIZE[0]}x{SIZE[1]}")
    assert format_info(info) == text
