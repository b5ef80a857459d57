"""Films of sample ranges: merged, saved, loaded; refusals of films of another render."""

import numpy as np
import pytest

import volpt
from conftest import CUBE, SETTINGS, SIZE, bits, run_cli


@pytest.fixture(scope="module")
def scene(grid_scene):
    return volpt.load(grid_scene, SETTINGS)


def test_two_ranges_merge_to_the_whole_render(scene):
    whole = scene.render(spp=8, seed=2)
    a = scene.render(samples=range(0, 3), seed=2)
    b = scene.render(samples=range(3, 8), seed=2)
    merged = volpt.merge([a, b])
    assert merged.samples == range(0, 8) and merged.seed == 2
    # The same samples, added in another grouping: equal within float64 rounding.
    np.testing.assert_allclose(merged.sums, whole.sums, rtol=1e-12, atol=0)
    np.testing.assert_allclose(merged.image(), whole.image(), rtol=1e-6, atol=0)
    # The same partition gives the same bits every time, in whatever order the films come.
    again = volpt.merge([scene.render(samples=(3, 8), seed=2), scene.render(samples=range(0, 3), seed=2)])
    assert np.array_equal(bits(again.sums), bits(merged.sums))
    assert np.array_equal(bits(volpt.merge([b, a]).sums), bits(merged.sums))


def test_merge_refuses_other_renders(scene):
    a = scene.render(samples=range(0, 2))
    with pytest.raises(volpt.MergeError, match=r"overlap"):
        volpt.merge([a, scene.render(samples=range(1, 3))])
    with pytest.raises(volpt.MergeError, match=r"samples 2\.\.3 are in no film"):
        volpt.merge([a, scene.render(samples=range(3, 4))])
    with pytest.raises(volpt.MergeError, match=r"its seed is 9, the first film's is 0"):
        volpt.merge([a, scene.render(samples=range(2, 4), seed=9)])
    other = volpt.load(CUBE, SETTINGS)
    with pytest.raises(volpt.MergeError, match=r"is of another render: its scene fingerprint is"):
        volpt.merge([a, other.render(samples=range(2, 4))])
    with pytest.raises(volpt.MergeError, match=r"nothing to merge"):
        volpt.merge([])
    assert isinstance(volpt.MergeError("x"), ValueError)


def test_changed_parameter_is_another_render(scene):
    a = scene.render(samples=range(0, 2))
    scene.params["medium.scale"] = 2.0
    try:
        b = scene.render(samples=range(2, 4))
    finally:
        scene.params["medium.scale"] = 1.0
    with pytest.raises(volpt.MergeError, match=r"fingerprint"):
        volpt.merge([a, b])


def test_save_load_and_resume(tmp_path, scene):
    head = scene.render(spp=3, seed=5)
    head.save(tmp_path / "film.ck")
    loaded = volpt.Film.load(tmp_path / "film.ck")
    assert loaded.samples == range(0, 3) and loaded.seed == 5 and loaded.fingerprint == scene.fingerprint
    assert np.array_equal(bits(loaded.sums), bits(head.sums))
    assert np.array_equal(bits(loaded.image()), bits(head.image()))
    # Resumed: the rest of the samples, merged.
    rest = scene.render(samples=range(3, 6), seed=5)
    resumed = volpt.merge([volpt.Film.load(tmp_path / "film.ck", scene), rest])
    np.testing.assert_allclose(resumed.sums, scene.render(spp=6, seed=5).sums, rtol=1e-12, atol=0)


def test_save_and_load_refusals(tmp_path, scene):
    with pytest.raises(volpt.CheckpointError, match=r"holds samples 0\.\.n.*samples 2\.\.4"):
        scene.render(samples=range(2, 4)).save(tmp_path / "late.ck")
    scene.render(spp=1).save(tmp_path / "film.ck")
    other = volpt.load(CUBE, SETTINGS)
    with pytest.raises(volpt.CheckpointError, match=r"film\.ck: the checkpoint is of another render: its scene"):
        volpt.Film.load(tmp_path / "film.ck", other)
    with pytest.raises(volpt.CheckpointError, match=r"missing\.ck"):
        volpt.Film.load(tmp_path / "missing.ck")
    (tmp_path / "junk.ck").write_bytes(b"not a checkpoint at all, just text" * 3)
    with pytest.raises(volpt.CheckpointError, match=r"junk\.ck: not a volpt checkpoint"):
        volpt.Film.load(tmp_path / "junk.ck")
    data = bytearray((tmp_path / "film.ck").read_bytes())
    data[40] ^= 1
    (tmp_path / "bad.ck").write_bytes(bytes(data))
    with pytest.raises(volpt.CheckpointError, match=r"checksum"):
        volpt.Film.load(tmp_path / "bad.ck")


def test_film_files_are_the_command_lines(tmp_path, scene, volpt_bin, grid_scene):
    # Film.save_film writes what `volpt render --samples --film` writes; load_film reads both.
    late = scene.render(samples=range(2, 5), seed=4)
    late.save_film(tmp_path / "py.vfilm")
    loaded = volpt.Film.load_film(tmp_path / "py.vfilm")
    assert loaded.samples == range(2, 5) and loaded.seed == 4 and loaded.fingerprint == scene.fingerprint
    assert np.array_equal(bits(loaded.sums), bits(late.sums))
    run_cli(
        volpt_bin, "render", grid_scene, "--resolution", f"{SIZE[0]}x{SIZE[1]}", "--seed", 4,
        "--samples", "2..5", "--film", tmp_path / "cli.vfilm",
    )
    assert (tmp_path / "cli.vfilm").read_bytes() == (tmp_path / "py.vfilm").read_bytes()
    # A checkpoint reads as a film of samples 0..n; `volpt merge` takes the Python films.
    scene.render(spp=2, seed=4).save(tmp_path / "head.ck")
    head = volpt.Film.load_film(tmp_path / "head.ck")
    assert head.samples == range(0, 2)
    run_cli(volpt_bin, "merge", tmp_path / "py.vfilm", tmp_path / "head.ck", "--spp", 5, "-o", tmp_path / "m.exr")
    assert np.array_equal(bits(volpt.read_exr(tmp_path / "m.exr")), bits(volpt.merge([head, loaded]).image()))
    # Refused: a film of several ranges (a merge with gaps), a damaged file, a missing one.
    scene.render(samples=range(7, 8), seed=4).save_film(tmp_path / "far.vfilm")
    run_cli(volpt_bin, "merge", tmp_path / "head.ck", tmp_path / "far.vfilm", "--allow-gaps",
            "-o", tmp_path / "gaps.exr", "--film", tmp_path / "gaps.vfilm")
    with pytest.raises(volpt.CheckpointError, match=r"gaps\.vfilm: the film holds samples 0\.\.2, 7\.\.8, not one range"):
        volpt.Film.load_film(tmp_path / "gaps.vfilm")
    data = bytearray((tmp_path / "py.vfilm").read_bytes())
    data[60] ^= 1
    (tmp_path / "bad.vfilm").write_bytes(bytes(data))
    with pytest.raises(volpt.CheckpointError, match=r"bad\.vfilm: not a volpt film file, or a damaged one: its checksum"):
        volpt.Film.load_film(tmp_path / "bad.vfilm")
    with pytest.raises(volpt.CheckpointError, match=r"missing\.vfilm"):
        volpt.Film.load_film(tmp_path / "missing.vfilm")
