"""volpt.Backend: every option volpt render has, opened once and reused; each bound the library's,
in the CLI's words with Python's spelling of the key; films that pickle as the film file's bytes."""

import pickle
import subprocess
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import volpt
from conftest import CUBE, SETTINGS, bits


@pytest.fixture(scope="module")
def scene():
    return volpt.load(CUBE, SETTINGS)


def test_a_backend_renders_as_the_named_one(scene):
    cpu = volpt.Backend("cpu")
    assert cpu.kind == "cpu" and cpu.devices == 1 and cpu.strategy is None and cpu.math is None
    assert cpu.gpus is None and repr(cpu) == 'volpt.Backend("cpu")'
    by_name = scene.render(spp=2, seed=3)
    film = scene.render(spp=2, seed=3, backend=cpu)
    assert np.array_equal(bits(film.image()), bits(by_name.image()))
    assert film.fingerprint == by_name.fingerprint
    # One backend, renders in several threads at once.
    with ThreadPoolExecutor(max_workers=4) as pool:
        films = list(pool.map(lambda s: scene.render(spp=2, seed=s, backend=cpu), [3, 4, 3, 4]))
    assert np.array_equal(bits(films[0].image()), bits(by_name.image()))
    assert np.array_equal(bits(films[2].image()), bits(by_name.image()))
    assert not np.array_equal(bits(films[1].image()), bits(by_name.image()))


@pytest.mark.parametrize(
    "kind,options,flags",
    [
        ("cpu", {"max_registers": 8}, ["--max-registers", "8"]),
        ("cuda", {"max_registers": 256}, ["--max-registers", "256"]),
        ("cpu", {"refill_at": 0}, ["--refill-at", "0"]),
        ("cuda", {"refill_at": 33}, ["--refill-at", "33"]),
        ("cpu", {"tiles": (0, 3)}, ["--tiles", "0,3"]),
        ("cuda", {"tiles": (5000, 1)}, ["--tiles", "5000,1"]),
    ],
)
def test_each_bound_is_the_librarys_in_the_clis_words(volpt_bin, kind, options, flags):
    """Refused before any GPU is opened, on either backend: the same words as `volpt render`'s,
    the key spelled as each front end takes it."""
    with pytest.raises(volpt.SettingsError) as raised:
        volpt.Backend(kind, **options)
    python = str(raised.value)
    (key,) = options
    assert python.startswith(f"{key}: expected ")
    out = subprocess.run(
        [str(volpt_bin), "render", str(CUBE), "--backend", kind, *flags], capture_output=True, text=True
    )
    assert out.returncode != 0
    cli = f"{flags[0]}: " + python.split(": ", 1)[1]
    assert cli in out.stderr, (cli, out.stderr)


@pytest.mark.parametrize(
    "options,message",
    [
        ({"strategy": "naive-sk"}, "strategy='naive-sk' with backend='cpu': a strategy schedules GPU work, and the CPU backend has no strategies (use backend='cuda', or drop strategy)"),
        ({"volume_memory": "managed"}, "volume_memory='managed' with backend='cpu': the volume options place grids for the GPU"),
        ({"device_memory_budget": 1 << 30}, "device_memory_budget=1073741824 with backend='cpu': the volume options"),
        ({"bricked": True}, "bricked=True with backend='cpu': the volume options place grids for the GPU"),
        ({"gpus": "all"}, "gpus='all' with backend='cpu': the CPU backend uses every core already"),
        ({"gpus": [0, 2]}, "gpus='0,2' with backend='cpu'"),
    ],
)
def test_gpu_options_on_the_cpu_are_typed_conflicts(options, message):
    with pytest.raises(volpt.SettingsError) as raised:
        volpt.Backend("cpu", **options)
    assert str(raised.value).startswith(message), str(raised.value)


@pytest.mark.parametrize(
    "kwargs,message",
    [
        ({"kind": "gpu"}, 'kind: expected one of cpu, cuda, found "gpu"'),
        ({"volume_memory": "vram"}, "volume_memory: expected one of "),
        ({"gpus": "some"}, "gpus: expected \"all\", a GPU's number (0 to 63) or a sequence of them"),
        ({"gpus": [64]}, "gpus: expected"),
        ({"tiles": 4}, "tiles: expected (columns, rows), found int 4"),
        ({"device_memory_budget": 0}, "device_memory_budget: expected an integer from 1 to"),
    ],
)
def test_bad_backend_arguments(kwargs, message):
    with pytest.raises(volpt.SettingsError) as raised:
        volpt.Backend(**kwargs)
    assert str(raised.value).startswith(message), str(raised.value)


def test_a_backends_options_are_its_own(scene):
    with pytest.raises(volpt.SettingsError, match="strategy and math are a Backend's own options"):
        scene.render(spp=1, backend=volpt.Backend("cpu"), math="exact")
    with pytest.raises(volpt.SettingsError, match="backend: expected one of cpu, cuda or a volpt.Backend, found int 3"):
        scene.render(spp=1, backend=3)


def test_cuda_without_a_gpu_or_kernels_is_a_render_error():
    try:
        backend = volpt.Backend("cuda", strategy="naive-sk", math="exact")
    except volpt.RenderError as error:
        assert str(error)
    else:
        assert backend.kind == "cuda" and backend.strategy == "naive-sk" and backend.math == "exact"


def test_films_pickle_as_the_film_files_bytes(tmp_path, scene):
    film = scene.render(samples=range(2, 5), seed=4)
    data = film.to_bytes()
    film.save_film(tmp_path / "film.vfilm")
    assert data == (tmp_path / "film.vfilm").read_bytes()
    again = pickle.loads(pickle.dumps(film))
    assert isinstance(again, volpt.Film)
    assert (again.samples, again.seed, again.fingerprint) == (film.samples, film.seed, film.fingerprint)
    assert np.array_equal(bits(again.sums), bits(film.sums))
    assert np.array_equal(bits(volpt.Film.from_bytes(data).image()), bits(film.image()))
    damaged = bytearray(data)
    damaged[40] ^= 1
    with pytest.raises(volpt.CheckpointError, match=r"<film bytes>: not a volpt film file, or a damaged one: its checksum"):
        volpt.Film.from_bytes(bytes(damaged))
    with pytest.raises(volpt.CheckpointError, match=r"<film bytes>: .*length"):
        volpt.Film.from_bytes(data[:-1])
