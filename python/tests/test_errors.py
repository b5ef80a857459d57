"""Every Rust error becomes a Python exception with the Rust message: file, field, expected,
found."""

import pytest

import volpt
from conftest import CUBE, SETTINGS


def test_missing_scene_file(tmp_path):
    missing = tmp_path / "nope.xml"
    with pytest.raises(FileNotFoundError) as raised:
        volpt.load(missing)
    assert isinstance(raised.value, volpt.SceneNotFoundError) and isinstance(raised.value, volpt.SceneError)
    assert str(raised.value).startswith(f"{missing}: ")


def test_malformed_xml_names_file_and_line(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text('<scene version="3.0.0">\n  <integrator type="volpath">\n</scene>\n')
    with pytest.raises(volpt.SceneError, match=rf"^{bad}:\d+: malformed XML"):
        volpt.load(bad)


def test_bad_value_names_field_expected_found(tmp_path):
    bad = tmp_path / "cube.xml"
    bad.write_text(CUBE.read_text().replace('name="fov" value="30"', 'name="fov" value="wide"'))
    with pytest.raises(volpt.SceneError) as raised:
        volpt.load(bad)
    assert str(raised.value) == f'{bad}:14: <float name="fov">: expected a finite number, found "wide"'


def test_unknown_parameter_value_is_the_scene_files_error(tmp_path):
    # -D resolution=big fills $resolution, the film's width: the file's line says so.
    with pytest.raises(volpt.SceneError) as raised:
        volpt.load(CUBE, resolution="big")
    assert str(raised.value) == f'{CUBE}:22: <integer name="width">: expected an integer, found "big"'


@pytest.mark.parametrize(
    "settings,message",
    [
        ({"nope": 1}, "settings: expected one of spp, seed, resolution"),
        ({"resolution": 32}, "settings[\"resolution\"]: expected (width, height), found int 32"),
        ({"resolution": (0, 4)}, "settings[\"resolution\"]: expected an integer from 1 to 4294967295, found int 0"),
        ({"tracking": "fast"}, "settings[\"tracking\"]: expected one of global, grid, found str 'fast'"),
        ({"estimator": 1}, "settings[\"estimator\"]: expected one of pt, nee, found int 1"),
        ({"threads": 0}, "settings[\"threads\"]: expected an integer from 1 to"),
        # The library's bound and words (volpt::MAJORANT_RESOLUTION), the key in Python's spelling.
        ({"majorant_resolution": 0}, 'settings["majorant_resolution"]: expected 1 to 1024 cells, found 0'),
        ({"majorant_resolution": 1025}, 'settings["majorant_resolution"]: expected 1 to 1024 cells, found 1025'),
        # A conflict of two settings: typed in the library, each key in Python's spelling.
        ({"tracking": "global", "majorant_resolution": 8}, 'settings["majorant_resolution"] = 8 with settings["tracking"] = \'global\': global tracking uses one majorant'),
    ],
)
def test_bad_settings(settings, message):
    with pytest.raises(volpt.SettingsError) as raised:
        volpt.load(CUBE, settings)
    assert str(raised.value).startswith(message)
    assert isinstance(raised.value, ValueError)


def test_bad_parameter_type():
    with pytest.raises(volpt.SettingsError, match=r"-D spp: expected a number, .* found dict"):
        volpt.load(CUBE, spp={})


@pytest.fixture(scope="module")
def scene():
    return volpt.load(CUBE, SETTINGS)


@pytest.mark.parametrize(
    "kwargs,message",
    [
        ({"backend": "gpu"}, "backend: expected one of cpu, cuda, found \"gpu\""),
        ({"strategy": "regeneration-sk"}, "strategy='regeneration-sk' with backend='cpu': a strategy schedules GPU work, and the CPU backend has no strategies"),
        ({"math": "fast"}, "math='fast' with backend='cpu': math chooses the GPU's kernels, and the CPU backend always computes exactly"),
        ({"backend": "cuda", "strategy": "quick"}, "strategy: expected one of auto, "),
        ({"backend": "cuda", "math": "sloppy"}, "math: expected one of exact, fast, found \"sloppy\""),
        ({"spp": 0}, "spp: expected an integer from 1 to 4294967295, found int 0"),
        ({"seed": -1}, "seed: expected an integer from 0 to 4294967295, found int -1"),
        ({"spp": 2, "samples": range(2)}, "render: give spp (samples 0 to spp) or samples (a range), not both"),
        ({"samples": range(4, 2)}, "samples: expected a range(start, stop) with 0 <= start < stop"),
        ({"samples": range(0, 8, 2)}, "samples: expected a range(start, stop) with 0 <= start < stop <= 2^32 - 1 and step 1"),
        ({"samples": "0:4"}, "samples: expected a range(start, stop)"),
    ],
)
def test_bad_render_arguments(scene, kwargs, message):
    with pytest.raises(volpt.SettingsError) as raised:
        scene.render(**kwargs)
    assert str(raised.value).startswith(message), str(raised.value)


def test_progress_must_be_callable(scene):
    with pytest.raises(TypeError, match="progress: expected a bool or a callable"):
        scene.render(spp=1, progress=3)


def test_write_refuses_other_formats(tmp_path, scene):
    with pytest.raises(volpt.ImageError, match=r"x\.jpg: expected a file name ending in \.exr or \.png"):
        scene.render(spp=1).write(tmp_path / "x.jpg")
    with pytest.raises(volpt.ImageError, match=r"no/such/dir/x\.exr"):
        scene.render(spp=1).write(tmp_path / "no" / "such" / "dir" / "x.exr")


def test_cuda_without_a_gpu_or_kernels_is_a_render_error(scene):
    # On a machine with a GPU and a build with kernels this renders; elsewhere it says why.
    try:
        film = scene.render(spp=1, backend="cuda")
    except volpt.RenderError as error:
        assert str(error)
    else:
        assert film.samples == range(0, 1)


def test_all_errors_are_volpt_errors():
    for name in volpt.errors.__all__:
        assert issubclass(getattr(volpt, name), volpt.VolptError)
