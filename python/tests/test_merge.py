"""Films of sample ranges: merged, saved, loaded; refusals of films of another render."""

import numpy as np
import pytest

import volpt
from conftest import CUBE, SETTINGS, bits


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
