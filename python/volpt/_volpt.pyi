"""Type stubs of ``volpt._volpt``, the Rust extension module (PyO3) behind ``volpt``."""

import os
from typing import Any, Callable, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

PARAMS: Dict[str, str]
"""Every parameter key of ``Scene.params`` with what it is and the values it takes."""

SETTINGS: Tuple[str, ...]
"""The keys of ``volpt.load``'s ``settings``."""

STRATEGIES: Tuple[str, ...]
"""The GPU strategies ``Scene.render(strategy=...)`` takes: ``auto`` and the fixed ones."""

Value = Union[int, float, Tuple[float, float, float]]
Progress = Union[bool, Callable[[int, int], Any]]

def load(path: str, settings: Optional[Dict[str, Any]], params: List[Tuple[str, str]]) -> Scene:
    """The loader behind ``volpt.load`` (which converts its keyword parameters)."""

def merge(films: Sequence[Film]) -> Film:
    """Adds films of one render's disjoint sample ranges into the film of all their samples.

    The films are added in the order of their ranges, so the same partition gives the same bits
    whatever order they are passed in; the result equals one render of all the samples within
    float64 rounding. Raises ``MergeError`` for films of another scene (fingerprint), seed or
    size, for overlapping ranges and for a gap between ranges, naming the films.
    """

def read_exr(path: Union[str, os.PathLike[str]]) -> npt.NDArray[np.float32]:
    """The first RGB layer of an OpenEXR file, float32 (H, W, 3): what ``volpt render -o`` and
    ``Film.write`` write. Raises ``ImageError``."""

def compensate_print(
    target: Union[str, os.PathLike[str]],
    materials: Union[str, os.PathLike[str]],
    out: Union[str, os.PathLike[str]],
    *,
    layers: int = 100,
    colour_layers: int = 40,
    voxel_size: Optional[Tuple[float, float, float]] = None,
    spp: int = 16,
    max_spp: int = 4096,
    iterations: Optional[int] = None,
    step: Optional[float] = None,
    noise_ratio: Optional[float] = 0.25,
    update: str = "cross-talk",
    ior: Optional[float] = 1.5,
    seed: int = 0,
    backend: Union[str, Backend, None] = None,
    render: Optional[Callable[[str, int, int], "Film"]] = None,
    progress: Union[bool, Callable[[int, int], Any], None] = None,
    iteration: Optional[Callable[[int, Dict[str, Any]], Any]] = None,
) -> Dict[str, Any]:
    """Compensates a colour 3D print's scattering, as ``volpt print compensate`` does (the same
    record from the same arguments; docs/printing.md): the naive print of ``target`` (a PNG, one
    texel of the print's top per pixel) is predicted by a render from straight above, the colours
    its ``colour_layers`` aim for are corrected by the predicted error, and so on, at most
    ``iterations`` predictions (default 10) with update ``step`` (default 1). ``materials`` is a
    TOML material table (``[[materials]]`` with name, colour, sigma_s, sigma_a, g; five of them
    named cyan, magenta, yellow, black and white; optionally ``voxel_size``). Noise control: a
    prediction whose noise (the mean CIEDE2000 of one standard error) exceeds ``noise_ratio``
    times the update's step is made again with four times the samples, up to ``max_spp``
    (``None`` turns it off). ``update``: ``"cross-talk"`` corrects the aims through the print's
    cross-texel response fitted from its predictions, ``"per-texel"`` each texel by its own error.
    ``ior`` is the resin surface's (``None``: no surface).

    Writes into ``out``: target.png, prediction.png, comparison.png, iteration_NN/prediction.png
    and delta_e.png, iterations.csv, delta_e.svg and the best print's slice stack (slices/).
    ``backend``: ``"cpu"``, ``"cuda"`` or a ``volpt.Backend`` (several GPUs:
    ``volpt.Backend("cuda", gpus="all")``, each prediction's samples split between them); default:
    a GPU where one is usable, else the CPU (the result's ``backend`` and ``backend_reason`` say
    which and why). ``render(scene_path, samples, seed)``, instead of a backend, renders each
    prediction elsewhere: it is given a volpt TOML scene written under ``out/renders/`` (with its
    slice stack) and returns the ``volpt.Film`` of samples ``0..samples`` with that seed
    (``volpt.distributed.compensate_print`` passes a Ray cluster's render); an exception it
    raises stops the loop as Ctrl-C does, and is raised after the record is written.

    Returns ``{"iterations": [{"mean", "p95", "noise", "spp"}, ...], "best", "size", "seconds",
    "out", "backend", "backend_reason"}``; ``iteration(k, {"mean", "p95", "noise", "spp"})`` is called as each iteration ends
    (an exception it raises stops the loop as Ctrl-C does, and is raised). ``progress`` is as ``Scene.render``'s, per render.
    The GIL is released; Ctrl-C writes the record of the iterations finished and raises
    ``KeyboardInterrupt`` (the record of an interrupted loop is whole but for the iterations not
    made). Raises ``PrintError`` for a file or argument it cannot use,
    ``SettingsError`` for a bad backend, ``RenderError`` for a failed render.
    """

class Scene:
    """A loaded scene: its grids, its settings and the parameters that change between renders."""

    @property
    def params(self) -> SceneParameters:
        """The scene's parameters, as a mapping (Mitsuba's ``mi.traverse``): set one and the next
        render uses it, without reloading the grids."""
    @property
    def spp(self) -> int:
        """Samples per pixel a render takes by default (``params["spp"]``)."""
    @property
    def seed(self) -> int:
        """Seed of the random streams by default (``params["seed"]``)."""
    @property
    def resolution(self) -> Tuple[int, int]:
        """The film's (width, height)."""
    @property
    def variant(self) -> str:
        """The monomorphised variant the scene renders with (``volpt info``'s ``variant``)."""
    @property
    def fingerprint(self) -> int:
        """What makes two renders the same render (scene, grids, settings; not spp or seed), as
        a 64-bit hash: films of one fingerprint and seed merge."""
    @property
    def source(self) -> str:
        """The scene file."""
    @property
    def grids(self) -> List[str]:
        """The names of the medium's grids (``"density"``, ``"albedo"``); empty for a medium of
        constants."""
    def grid(self, name: str) -> npt.NDArray[np.float32]:
        """Grid ``name``'s values (a copy): float32 of shape (z, y, x), or (z, y, x, 3) for an RGB
        albedo; x varies fastest, as in the grid files. Raises ``GridError`` for a grid the
        scene lacks."""
    def set_grid(self, name: str, values: npt.ArrayLike) -> None:
        """Replaces grid ``name``'s values: an array of the grid's shape (``grid(name).shape``),
        or flat in its order, converted to float32. The next render renders the scene as loaded
        from a file of these values, bit for bit, with that scene's fingerprint; the grids a
        GPU keeps are copied again. Values equal to the grid's own change nothing. Raises
        ``GridError`` (a ``ValueError``) for a grid the scene lacks, a grid kept sparse (a VDB),
        the wrong shape or count, or a value out of range, leaving the scene as it was."""
    def info(self) -> Dict[str, str]:
        """What ``volpt info`` prints, as a dict in its order: ``scene``, ``variant``, ``film``,
        ``camera``, ``integrator``, ``bounds``, ``boundary``, ``density``, ``majorant``,
        ``tracking``, ``estimator``, ``albedo``, ``phase``, ``light``. A value of several lines
        (the variant's specialisations, the tracking's default) has them joined by ``\\n``."""
    def render(
        self,
        *,
        spp: Optional[int] = None,
        seed: Optional[int] = None,
        samples: Optional[Union[range, Tuple[int, int]]] = None,
        backend: Union[str, Backend, None] = None,
        strategy: Optional[str] = None,
        math: Optional[str] = None,
        progress: Optional[Progress] = None,
    ) -> Film:
        """Renders samples ``samples`` of every pixel (default: ``range(0, spp)``, with ``spp``
        the scene's unless given; give one of the two) with ``seed`` (default: the scene's).

        Sample ``s`` of pixel ``p`` is the same path on every backend and in every range, so the
        image equals ``volpt render``'s bit for bit for the same scene, seed and backend, and
        films of disjoint ranges merge (``volpt.merge``) into the whole render's.

        ``backend``: a ``Backend`` (opened once and reused: a GPU's kernels load once, and
        ``auto``'s calibrations are kept), or a kind's name, opened for this render: ``"cpu"``
        (every core, the default) or ``"cuda"`` (GPU 0) with ``strategy`` (``STRATEGIES``;
        default: ``auto``'s choice or regeneration-sk, as ``volpt render``) and ``math``
        (``"fast"``, the default, statistically equal, or ``"exact"``, the CPU's bits), which are
        the GPU's: the CPU refuses them. A ``Backend``'s options are its own: ``strategy`` or
        ``math`` beside one raises ``SettingsError``.

        ``progress``: ``True`` draws a bar on stderr; a callable is called ``progress(done,
        total)`` (paths) between chunks of samples, on the calling thread; an exception it raises
        stops the render and propagates.

        The GIL is released while rendering. Ctrl-C (``KeyboardInterrupt``) stops the render
        within about 0.1 s on the CPU (0.5 s on a GPU): the render runs in chunks of samples and
        looks at Python's signals between them. Raises ``SettingsError`` for a bad argument,
        ``RenderError`` if the backend fails (no GPU, a build without GPU kernels).
        """

class SceneParameters:
    """``scene.params``: the parameters of a scene that change between renders, as a mapping.

    Keys (``volpt.PARAMS`` says each one's range): ``spp``, ``seed``, ``max_depth``,
    ``rr_depth`` (int; -1 unlimited / never), ``camera.origin``, ``camera.target``,
    ``camera.up`` (3 floats), ``camera.fov`` (degrees), ``medium.scale`` (float),
    ``medium.albedo`` (RGB; scenes with a constant albedo), ``phase.g`` (float in (-1, 1));
    where the scene has them, its lights': ``sun.direction`` (3 floats, where the light travels),
    ``sun.irradiance`` (RGB), ``sun.angular_radius`` (degrees), ``light.position``,
    ``light.intensity`` (RGB, W/sr) and ``light.direction`` (a spot's axis).

    Values are ints, floats and tuples of three floats; a set value is checked as a loaded scene
    is, and a refusal (``ParamError``, a ``ValueError``; ``UnknownParamError``, a ``KeyError``,
    for a key that is no parameter) leaves the scene unchanged.
    """

    def __getitem__(self, key: str) -> Value: ...
    def __setitem__(self, key: str, value: Union[int, float, Sequence[float], npt.ArrayLike]) -> None: ...
    def __contains__(self, key: object) -> bool: ...
    def __iter__(self) -> Iterator[str]: ...
    def __len__(self) -> int: ...
    def keys(self) -> List[str]: ...
    def values(self) -> List[Value]: ...
    def items(self) -> List[Tuple[str, Value]]: ...
    def get(self, key: str, default: Optional[Value] = None) -> Optional[Value]: ...
    def update(self, values: Optional[Mapping[str, Any]] = None, **kwargs: Any) -> None:
        """Sets several parameters: all of them, or on a refusal none."""
    def describe(self) -> Dict[str, str]:
        """Each key this scene has, with what it is and the values it takes."""

class Backend:
    """The CPU or GPUs a render runs on, with every option ``volpt render`` has, opened once and
    reused by the renders given it (``scene.render(backend=...)``): a GPU's kernels load once,
    and ``auto``'s calibrations are kept per scene. Renders on one backend may run in several
    threads at once."""

    def __init__(
        self,
        kind: str = "cpu",
        *,
        strategy: Optional[str] = None,
        math: Optional[str] = None,
        max_registers: Optional[int] = None,
        refill_at: Optional[int] = None,
        tiles: Optional[Tuple[int, int]] = None,
        volume_memory: Optional[str] = None,
        device_memory_budget: Optional[int] = None,
        bricked: bool = False,
        gpus: Union[None, str, int, Sequence[int]] = None,
    ) -> None:
        """Opens the backend ``kind`` (``"cpu"``, ``"cuda"``), with ``volpt render``'s options
        of the same names: ``strategy`` (``STRATEGIES``), ``math`` (``"fast"``, ``"exact"``),
        ``max_registers`` (16 to 255) and ``refill_at`` (1 to 32; regeneration-sk's), ``tiles``
        ((columns, rows) of the image, each rendered by its own launches), ``volume_memory``
        (``"auto"``, ``"device"``, ``"zero-copy"``, ``"managed"``), ``device_memory_budget``
        (bytes the grids may take on the GPU), ``bricked`` (grids in 8^3 bricks) and ``gpus``
        (``"all"``, a GPU's number or several: one render on several GPUs). Each bound is the
        library's, in the CLI's words. Raises ``SettingsError`` for an option out of range or
        that does not apply (a GPU option with ``"cpu"``), ``RenderError`` where the GPU cannot
        be opened (no GPU, a build without GPU kernels)."""
    @property
    def kind(self) -> str: ...
    @property
    def devices(self) -> int:
        """The devices that render together: 1 but for several GPUs."""
    @property
    def device_name(self) -> str: ...
    @property
    def strategy(self) -> Optional[str]:
        """The strategy asked for (``"auto"`` or a fixed one); ``None`` on the CPU."""
    @property
    def math(self) -> Optional[str]:
        """The GPU's math; ``None`` on the CPU."""
    @property
    def gpus(self) -> Union[None, str, List[int]]:
        """The GPUs asked for: ``None`` (GPU 0), ``"all"`` or their numbers."""

class Film:
    """The per-pixel sums of one render's samples ``samples``, with the render's fingerprint and
    seed. Films pickle (as ``to_bytes``), so they pass between processes (Ray's tasks) as they
    are; the render's ``elapsed``, ``paths`` and ``notes`` stay behind."""

    @property
    def sums(self) -> npt.NDArray[np.float64]:
        """The per-pixel sums of the film's samples, float64 (H, W, 3) (a copy)."""
    @property
    def samples(self) -> range:
        """The samples of every pixel the film holds."""
    @property
    def seed(self) -> int: ...
    @property
    def fingerprint(self) -> int:
        """The rendered scene's fingerprint (``Scene.fingerprint``)."""
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def elapsed(self) -> float:
        """Seconds the render took (summed over merged films; 0 for a loaded film)."""
    @property
    def paths(self) -> int:
        """Paths traced (summed over merged films; 0 for a loaded film)."""
    @property
    def notes(self) -> List[str]:
        """What the render said (on a GPU: ``auto``'s calibration and choice)."""
    def image(self) -> npt.NDArray[np.float32]:
        """The image, float32 (H, W, 3), linear RGB, top row first: each pixel's sums over the
        number of samples, rounded to float32, as ``volpt render`` writes it."""
    def write(self, path: Union[str, os.PathLike[str]]) -> None:
        """Writes the image as OpenEXR (``.exr``, float32, what ``volpt render -o`` writes) or
        PNG (``.png``, the CLI's sRGB preview). Raises ``ImageError``."""
    def save(self, path: Union[str, os.PathLike[str]]) -> None:
        """Saves the film in volpt's checkpoint format (``volpt render --checkpoint``'s; ``volpt
        render --resume`` continues it). The format holds samples ``0..n``: a film of a range that
        starts later raises ``CheckpointError`` (merge it with the films before it first)."""
    def save_film(self, path: Union[str, os.PathLike[str]]) -> None:
        """Writes the film in volpt's film file format (``VOLPTFL1``, atomically): what ``volpt
        render --samples A..B --film FILE`` writes and ``volpt merge`` reads, for a film of any
        sample range. Raises ``CheckpointError``."""
    @staticmethod
    def load_film(path: Union[str, os.PathLike[str]]) -> Film:
        """Reads a film file (``Film.save_film``, ``volpt render --film``, ``volpt merge --film``)
        or a checkpoint, checked as ``volpt merge`` checks it (magic, length, checksum, ranges).
        A film of several ranges (a merge with ``--allow-gaps``) raises ``CheckpointError``, as
        does a damaged file."""
    def to_bytes(self) -> bytes:
        """The film in volpt's film file format (``VOLPTFL1``), as ``save_film`` writes it."""
    @staticmethod
    def from_bytes(data: bytes) -> Film:
        """The film of ``to_bytes``' bytes, checked as a film file is (magic, length, checksum,
        one sample range). Raises ``CheckpointError``."""
    @staticmethod
    def load(path: Union[str, os.PathLike[str]], scene: Optional[Scene] = None) -> Film:
        """Reads a film saved by ``Film.save`` or ``volpt render --checkpoint``. With ``scene``,
        refuses a film of another scene or size (``CheckpointError``, naming the field)."""
