"""volpt from Python: path tracing of solid participating media (a CT scan, a 3D print, smoke).

    import volpt
    scene = volpt.load("scenes/example/cube.xml", spp=16)   # -D spp=16
    film = scene.render(seed=1)                             # the CPU
    gpu = volpt.Backend("cuda", math="exact")               # a GPU, opened once, reused
    film = scene.render(seed=1, backend=gpu)
    image = film.image()                                    # numpy float32 (H, W, 3), linear
    scene.params["medium.scale"] = 2.0                      # no reload of the grids
    film.write("cube.exr")

The classes are ``Scene``, ``SceneParameters`` (``scene.params``), ``Backend`` and ``Film`` (which
pickles); the exceptions are
in ``volpt.errors``. Everything renders through the Rust library ``volpt``, bit for bit as the
``volpt`` command line does.
"""

import os
from typing import Any, Mapping, Optional

from . import errors
from ._volpt import PARAMS, SETTINGS, STRATEGIES, Backend, Film, Scene, SceneParameters, __version__
from ._volpt import load as _load
from ._volpt import compensate_print, merge, read_exr
from .errors import (
    CheckpointError,
    GridError,
    ImageError,
    MergeError,
    ParamError,
    PrintError,
    RenderError,
    SceneError,
    SceneNotFoundError,
    SettingsError,
    UnknownParamError,
    VolptError,
)


def _param_text(name: str, value: Any) -> str:
    """A ``-D`` parameter's value as the scene file's text: Mitsuba's spelling of Python values."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float, str)):
        return str(value)
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, (tuple, list)) and all(
        isinstance(v, (int, float)) and not isinstance(v, bool) for v in value
    ):
        return ", ".join(str(v) for v in value)
    raise SettingsError(
        f"-D {name}: expected a number, a string, a bool, a path or a sequence of numbers, "
        f"found {type(value).__name__} {value!r}"
    )


def load(path: "str | os.PathLike[str]", settings: Optional[Mapping[str, Any]] = None, /, **params: Any) -> Scene:
    """Loads a scene: Mitsuba XML (0.5/0.6 or 3), a volpt TOML scene, or a grid file (``.mha``,
    ``.mhd``, ``.vtk``, ``.vti``, ``.vol``).

    ``params`` are the scene's parameters, as ``volpt render -D name=value`` and Mitsuba's
    ``mi.load_file(path, name=value)`` take them (``$name`` in the file; they override its
    ``<default>``s): ``volpt.load("cube.xml", spp=16, resolution=64)``.

    ``settings`` (positional) overrides what the scene file says, with the ``volpt render`` flags'
    names and values: ``spp``, ``seed``, ``resolution`` ((width, height)), ``max_depth`` and
    ``rr_depth`` (-1: unlimited / never; paths of negligible weight face roulette regardless),
    ``tracking`` ("global", "grid"), ``majorant_resolution``, ``estimator`` ("pt", "nee"), ``lookup`` ("trilinear", "nearest",
    "texture", "texture-f16", "stochastic"), ``roulette`` ("mitsuba", "throughput"), ``effects``
    ("specialised", "general") and ``threads`` (CPU worker threads):
    ``volpt.load("cube.xml", {"resolution": (64, 48), "tracking": "grid"})``.

    Raises ``SceneNotFoundError`` (a ``FileNotFoundError``) for a missing file, ``SceneError`` for
    a file volpt cannot read or render (with its line, field, expected and found values) and
    ``SettingsError`` for a bad setting. The GIL is released while the grids load.
    """
    if settings is not None and not isinstance(settings, Mapping):
        raise SettingsError(
            f"settings: expected a mapping of volpt render's options (e.g. {{'resolution': (64, 64)}}), "
            f"found {type(settings).__name__} {settings!r}"
        )
    pairs = [(name, _param_text(name, value)) for name, value in params.items()]
    return _load(os.fspath(path), dict(settings) if settings is not None else None, pairs)


__all__ = [
    "load",
    "merge",
    "read_exr",
    "compensate_print",
    "Scene",
    "SceneParameters",
    "Backend",
    "Film",
    "PARAMS",
    "SETTINGS",
    "STRATEGIES",
    "errors",
    *errors.__all__,
    "__version__",
]
