"""scene.params: documented keys, typed and range-checked values, and changes that equal a reload
of the changed scene file bit for bit."""

import math
import re

import numpy as np
import pytest

import volpt
from conftest import CUBE, SETTINGS, bits

KEYS = [
    "spp", "seed", "max_depth", "rr_depth", "camera.origin", "camera.target", "camera.up",
    "camera.fov", "medium.scale", "medium.albedo", "phase.g",
]
# A scene has these where it has the lights (the cube has none): volpt.PARAMS lists them before
# the phase's.
LIGHT_KEYS = [
    "sun.direction", "sun.irradiance", "sun.angular_radius", "light.position", "light.intensity",
    "light.direction",
]


@pytest.fixture
def scene():
    return volpt.load(CUBE, SETTINGS)


def test_keys_are_documented(scene):
    assert list(volpt.PARAMS) == KEYS[:-1] + LIGHT_KEYS + KEYS[-1:]
    assert list(scene.params) == KEYS == scene.params.keys()
    assert len(scene.params) == len(KEYS) and "medium.scale" in scene.params and "nope" not in scene.params
    assert all(isinstance(text, str) and text for text in scene.params.describe().values())
    p = scene.params
    assert p["spp"] == 64 and isinstance(p["spp"], int)
    assert p["max_depth"] == -1 and p["rr_depth"] == 20
    assert p["camera.fov"] == 30.0
    assert p["medium.albedo"] == pytest.approx((0.98, 0.8, 0.45))
    assert p["phase.g"] == pytest.approx(0.6)
    assert p["camera.origin"] == pytest.approx((3.2, 2.4, 4.0))
    assert dict(p.items())["medium.scale"] == 1.0
    assert p.get("nope", 5) == 5


def edited(tmp_path, pattern, replacement):
    text = CUBE.read_text()
    new, n = re.subn(pattern, replacement, text)
    assert n == 1, pattern
    path = tmp_path / "cube.xml"
    path.write_text(new)
    return path


CHANGES = [
    ("medium.scale", 2.5, r'name="scale" value="1"', 'name="scale" value="2.5"'),
    ("medium.albedo", (0.5, 0.9, 0.25), r'name="albedo" value="[^"]*"', 'name="albedo" value="0.5, 0.9, 0.25"'),
    ("phase.g", -0.3, r'name="g" value="0.6"', 'name="g" value="-0.3"'),
    ("max_depth", 3, r'name="maxDepth" value="-1"', 'name="maxDepth" value="3"'),
    ("rr_depth", -1, r'name="rrDepth" value="20"', 'name="rrDepth" value="-1"'),
    ("camera.fov", 41.5, r'name="fov" value="30"', 'name="fov" value="41.5"'),
]


@pytest.mark.parametrize("key,value,pattern,replacement", CHANGES, ids=[c[0] for c in CHANGES])
def test_parameter_change_equals_reload(tmp_path, scene, key, value, pattern, replacement):
    before = scene.render(spp=2, seed=1)
    scene.params[key] = value
    reloaded = volpt.load(edited(tmp_path, pattern, replacement), SETTINGS)
    assert scene.fingerprint == reloaded.fingerprint
    assert reloaded.params[key] == pytest.approx(value)
    changed = scene.render(spp=2, seed=1)
    assert np.array_equal(bits(changed.sums), bits(reloaded.render(spp=2, seed=1).sums))
    assert not np.array_equal(changed.sums, before.sums)


def test_camera_origin_equals_reload(tmp_path, scene):
    # The camera moves keeping its direction: the reloaded file looks at the moved target.
    scene.params["camera.origin"] = (3.0, 2.0, 4.5)
    target = [3.0 - 3.2, 2.0 - 2.4 - 0.1, 4.5 - 4.0]  # origin + (old target - old origin)
    reloaded = volpt.load(
        edited(
            tmp_path, r'origin="3.2, 2.4, 4" target="0, -0.1, 0"',
            f'origin="3.0, 2.0, 4.5" target="{target[0]!r}, {target[1]!r}, {target[2]!r}"',
        ),
        SETTINGS,
    )
    assert scene.params["camera.origin"] == pytest.approx(reloaded.params["camera.origin"])
    a, b = scene.render(spp=2).image(), reloaded.render(spp=2).image()
    # The look-at frame is rebuilt from (origin, target): equal to float rounding, not the bit.
    np.testing.assert_allclose(a, b, rtol=0, atol=0.05)
    assert abs(float(a.mean()) - float(b.mean())) < 1e-2


def test_spp_and_seed_parameters(scene):
    scene.params["spp"] = 3
    scene.params["seed"] = 11
    film = scene.render()
    assert film.samples == range(0, 3) and film.seed == 11
    # A render's own seed does not change the scene's.
    assert scene.render(spp=1, seed=4).seed == 4 and scene.seed == 11


BAD = [
    ("medium.scale", -1.0, "parameter medium.scale: expected a finite number >= 0, found Float(-1.0)"),
    ("medium.scale", math.inf, "parameter medium.scale: expected a finite number >= 0, found Float(inf)"),
    ("medium.scale", "2", "parameter medium.scale: expected the density's scale (extinction = scale x density), finite and >= 0, found str '2'"),
    ("phase.g", 1.0, "parameter phase.g: expected a number in (-1, 1), found Float(1.0)"),
    ("camera.fov", 180, "parameter camera.fov: expected degrees in (0, 180), found Int(180)"),
    ("medium.albedo", (1.5, 0, 0), "parameter medium.albedo: expected RGB in [0, 1], found Vec3([1.5, 0.0, 0.0])"),
    ("medium.albedo", (1, 2), "parameter medium.albedo: expected the constant single-scattering albedo, RGB in [0, 1] (not a grid's), found tuple (1, 2)"),
    ("spp", 0, "parameter spp: expected an integer from 1 to 4294967295, found Int(0)"),
    ("spp", 2.0, "parameter spp: expected an integer from 1 to 4294967295, found Float(2.0)"),
    ("spp", True, "parameter spp: expected samples per pixel, an integer of at least 1, found bool True"),
    ("max_depth", -2, "parameter max_depth: expected an integer from -1 to 4294967295, found Int(-2)"),
    ("camera.target", (3.2, 2.4, 4), "parameter camera.target: expected a camera whose direction (target - origin) and up are non-zero and not parallel"),
    ("camera.origin", None, "parameter camera.origin: expected the camera's position, a 3-vector, found NoneType None"),
    # Refused by the scene's own checks (a medium too dense for f32 positions): still this
    # parameter's bad value.
    ("medium.scale", 1e12, "parameter medium.scale: expected a finite extinction whose mean free path spans"),
]


@pytest.mark.parametrize("key,value,message", BAD, ids=[f"{k}={v!r}" for k, v, _ in BAD])
def test_bad_values_raise_and_leave_the_scene(scene, key, value, message):
    before = dict(scene.params.items())
    fingerprint = scene.fingerprint
    with pytest.raises(volpt.ParamError) as raised:
        scene.params[key] = value
    assert str(raised.value).startswith(message)
    assert isinstance(raised.value, ValueError)
    assert dict(scene.params.items()) == before and scene.fingerprint == fingerprint


def test_unknown_key(scene):
    with pytest.raises(KeyError) as raised:
        scene.params["medium.density"]
    assert isinstance(raised.value, volpt.UnknownParamError)
    assert str(raised.value) == (
        "parameter medium.density: expected one of "
        + ", ".join(KEYS[:-1] + LIGHT_KEYS + KEYS[-1:])
        + ", found no such parameter"
    )
    with pytest.raises(volpt.UnknownParamError, match="parameter nope: expected one of spp"):
        scene.params["nope"] = 1.0


def test_update_is_all_or_nothing(scene):
    with pytest.raises(volpt.ParamError, match="phase.g"):
        scene.params.update({"medium.scale": 3.0, "phase.g": 2.0})
    assert scene.params["medium.scale"] == 1.0
    scene.params.update({"medium.scale": 3.0}, **{"phase.g": 0.1})
    assert scene.params["medium.scale"] == 3.0 and scene.params["phase.g"] == pytest.approx(0.1)


def test_numpy_values(scene):
    scene.params["medium.scale"] = np.float32(1.5)
    scene.params["spp"] = np.int64(2)
    scene.params["camera.origin"] = np.array([3.0, 2.0, 4.0])
    assert scene.params["medium.scale"] == 1.5 and scene.params["spp"] == 2
    assert scene.params["camera.origin"] == pytest.approx((3.0, 2.0, 4.0))
