"""One render on a Ray cluster: one Ray task per sample range, the films merged as they arrive.

    import volpt.distributed
    film = volpt.distributed.render("/shared/scenes/cgg-logo/scene.xml", 4096, parts=16,
                                    out="cgg-logo.exr", progress=True)

Sample ``s`` of every pixel is the same path on every machine (``volpt.merge``), so a render split
into sample ranges, each rendered by a task anywhere in the cluster, merges into the film of the
whole render. The films are added in the order of their ranges, whatever order they arrive in: the
same ``parts`` give the same bits every time, and the image equals the one-process render of the
same samples within ``float64`` rounding of the sums.

Needs Ray (``pip install 'volpt[ray]'``, or ``pip install ray``), imported only when ``render`` is
called. The tasks need the same ``volpt`` installed on every node, and the scene at the same path
on every node (a shared file system, or the same files copied to each): a scene is a file that
names others (grids, a sky map), so the tasks read it where they run rather than receive it. The
films come back through Ray's object store pickled as bytes of volpt's film file format (``VOLPTFL1``, what
``volpt render --film`` writes): no shared file system is needed for them, and their checksum is
verified when the driver reads them.

A task whose worker process or node dies is run again by Ray (``max_retries``); a task that raises
(a scene that does not load, a backend that fails) is not, as it would fail again. See
``docs/distributed.md``.
"""

import os
import socket
import sys
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Mapping, Optional, Tuple, Union

from . import _volpt
from .errors import RenderError, SettingsError, VolptError

__all__ = ["render", "compensate_print", "sample_ranges", "PartDone"]


@dataclass(frozen=True)
class PartDone:
    """A part that arrived, as ``render``'s ``progress`` callable receives it."""

    #: The part's index in ``sample_ranges(spp, parts)``.
    index: int
    #: The part's samples of every pixel.
    samples: range
    #: The Ray node that rendered it: its IP address, its Ray node ID (hex), and the worker
    #: process there.
    node: str
    node_id: str
    pid: int
    #: Seconds its render took on the worker (without loading the scene).
    seconds: float
    #: Parts arrived so far, of ``total``.
    done: int
    total: int


def sample_ranges(spp: int, parts: int) -> List[range]:
    """``range(0, spp)`` split into ``parts`` consecutive ranges whose sizes differ by at most one:
    the partition ``render`` gives its tasks (and the Slurm and Kubernetes recipes of
    ``docs/distributed.md`` compute with shell arithmetic)."""
    if not isinstance(spp, int) or isinstance(spp, bool) or spp < 1:
        raise SettingsError(f"spp: expected a positive integer, found {spp!r}")
    if not isinstance(parts, int) or isinstance(parts, bool) or not 1 <= parts <= spp:
        raise SettingsError(f"parts: expected an integer from 1 to spp ({spp}), found {parts!r}")
    return [range(i * spp // parts, (i + 1) * spp // parts) for i in range(parts)]


def _import_ray() -> Any:
    try:
        import ray
    except ImportError as e:
        raise ImportError(
            "volpt.distributed needs Ray, which is not installed: pip install 'volpt[ray]' "
            "(or pip install ray)"
        ) from e
    return ray


def _render_part(
    scene_path: str,
    settings: Dict[str, Any],
    params: Dict[str, Any],
    samples: Tuple[int, int],
    seed: Optional[int],
    backend: str,
) -> Tuple["_volpt.Film", Dict[str, Any]]:
    """One task: loads the scene where it runs, renders ``samples`` and returns the film (Ray
    pickles it as the film file's bytes, checked as ``volpt merge`` checks a film file) with
    where and how long it rendered."""
    from . import load  # the package's, with its keyword parameters

    scene = load(scene_path, settings, **params)
    film = scene.render(samples=range(*samples), seed=seed, backend=backend)
    try:
        import ray

        node, node_id = ray.util.get_node_ip_address(), ray.get_runtime_context().get_node_id()
    except Exception:  # outside Ray (a direct call): the host's name
        node, node_id = socket.gethostname(), ""
    where = {"node": node, "node_id": node_id, "pid": os.getpid(), "seconds": film.elapsed}
    return film, where


def _reason(error: BaseException) -> str:
    """A failed task's error in one line: a task's own exception (Ray's ``cause``) by its class and
    message, Ray's own (a worker or node lost) by its message."""
    cause = getattr(error, "cause", None)
    if isinstance(cause, BaseException):
        text = f"{type(cause).__name__}: {cause}"
    else:
        text = str(error)
    lines = text.strip().splitlines()
    return lines[0] if lines else type(error).__name__


def _print_progress(part: PartDone) -> None:
    print(
        f"volpt.distributed: part {part.done}/{part.total} (samples {part.samples.start}.."
        f"{part.samples.stop}, part {part.index}) from {part.node} pid {part.pid} in "
        f"{part.seconds:.2f} s",
        file=sys.stderr,
        flush=True,
    )


def render(
    scene_path: "str | os.PathLike[str]",
    spp: int,
    *,
    parts: Optional[int] = None,
    seed: Optional[int] = None,
    backend: str = "auto",
    settings: Optional[Mapping[str, Any]] = None,
    params: Optional[Mapping[str, Any]] = None,
    out: "str | os.PathLike[str] | None" = None,
    parts_dir: "str | os.PathLike[str] | None" = None,
    progress: Union[bool, Callable[[PartDone], Any], None] = None,
    num_cpus: int = 1,
    max_retries: int = 3,
    address: Optional[str] = None,
) -> "_volpt.Film":
    """Renders samples ``0..spp`` of ``scene_path`` on a Ray cluster, one task per sample range,
    and returns the merged film (``volpt.Film``); with ``out``, writes its image there too
    (``.exr`` or ``.png``, as ``Film.write``).

    - ``parts``: the number of tasks (sample ranges, ``sample_ranges(spp, parts)``). Default: the
      cluster's GPUs (``backend="cuda"``) or its CPUs over ``num_cpus``, at most ``spp``.
    - ``seed``: the render's seed (default: the scene's). ``settings`` and ``params``: what
      ``volpt.load`` takes (``settings`` positional there, ``params`` its keywords), applied on
      every node; the tasks must load the same scene, which their films' fingerprints confirm.
    - ``backend``: ``"cpu"``, ``"cuda"`` or ``"auto"`` (``"cuda"`` where the cluster has GPUs,
      else ``"cpu"``). A CUDA task reserves one GPU (``num_gpus=1``; Ray sets the task's
      ``CUDA_VISIBLE_DEVICES``, and gives each GPU task a fresh worker process); a CPU task
      reserves ``num_cpus`` CPUs and renders with as many threads (unless ``settings`` names
      ``threads``).
    - ``parts_dir``: a folder where each part's film is written as it arrives
      (``part-0003.vfilm``): after a failure, ``volpt merge`` takes them with the films of the
      missing ranges (``volpt render --samples A..B --film FILE``).
    - ``progress``: ``True`` prints a line on stderr per part; a callable is called with a
      ``PartDone`` per part, on the calling thread, in the order the parts arrive.
    - ``max_retries``: how many times Ray runs a task again whose worker process or node died.
      A task that raises is not retried: its exception (a ``volpt.VolptError`` such as
      ``SceneNotFoundError``) is raised here, and the other tasks are cancelled.
    - ``address``: passed to ``ray.init`` when Ray is not initialised yet (``None``: the cluster
      of ``RAY_ADDRESS`` or of ``ray start`` on this machine, else a new local one).

    Raises ``RenderError`` naming the sample ranges whose tasks failed beyond their retries
    (after the other parts arrived), ``SettingsError`` for a bad argument, and ``ImportError``
    if Ray is not installed.
    """
    if backend not in ("auto", "cpu", "cuda"):
        raise SettingsError(f"backend: expected 'auto', 'cpu' or 'cuda', found {backend!r}")
    if not isinstance(num_cpus, int) or isinstance(num_cpus, bool) or num_cpus < 1:
        raise SettingsError(f"num_cpus: expected a positive integer, found {num_cpus!r}")
    if not isinstance(max_retries, int) or isinstance(max_retries, bool) or max_retries < -1:
        raise SettingsError(f"max_retries: expected an integer >= 0 (-1: unlimited), found {max_retries!r}")
    if settings is not None and not isinstance(settings, Mapping):
        raise SettingsError(f"settings: expected a mapping of volpt.load's settings, found {settings!r}")
    if params is not None and not isinstance(params, Mapping):
        raise SettingsError(f"params: expected a mapping of the scene's parameters, found {params!r}")
    if progress is not None and not isinstance(progress, bool) and not callable(progress):
        raise SettingsError(f"progress: expected True, False or a callable, found {progress!r}")
    # Sample ranges are checked before Ray starts (a bad spp costs no cluster).
    if parts is not None:
        sample_ranges(spp, parts)
    else:
        sample_ranges(spp, 1)
    ray = _import_ray()
    if not ray.is_initialized():
        ray.init(address=address)
    gpus = int(ray.cluster_resources().get("GPU", 0))
    if backend == "auto":
        backend = "cuda" if gpus > 0 else "cpu"
    if backend == "cuda" and gpus == 0:
        raise SettingsError(
            "backend 'cuda': the Ray cluster has no GPUs (ray.cluster_resources() lists none); "
            "start its nodes with GPUs (ray start --num-gpus N), or render with backend='cpu'"
        )
    if parts is None:
        cpus = int(ray.cluster_resources().get("CPU", 1))
        parts = min(spp, max(1, gpus if backend == "cuda" else cpus // num_cpus))
    ranges = sample_ranges(spp, parts)

    task_settings = dict(settings or {})
    if backend == "cpu":
        task_settings.setdefault("threads", num_cpus)
    resources = {"num_gpus": 1, "num_cpus": 1} if backend == "cuda" else {"num_cpus": num_cpus}
    # Created here, not at import: Ray is optional. With num_gpus, Ray runs each task in a fresh
    # worker process (max_calls=1), so that a process's CUDA context is never on another GPU than
    # the one CUDA_VISIBLE_DEVICES gives its task.
    task = ray.remote(max_retries=max_retries, retry_exceptions=False, **resources)(_render_part)
    scene = os.path.abspath(os.fspath(scene_path))
    params = dict(params or {})
    pending = {
        task.remote(scene, task_settings, params, (r.start, r.stop), seed, backend): i
        for i, r in enumerate(ranges)
    }
    report = _print_progress if progress is True else progress or None
    if parts_dir is not None:
        os.makedirs(parts_dir, exist_ok=True)

    arrived: Dict[int, "_volpt.Film"] = {}  # parts waiting for the parts before them
    merged: Optional["_volpt.Film"] = None
    next_part = 0  # merged holds the parts before it
    first: Optional[Tuple[int, int, str]] = None  # (part, fingerprint, node) of the first arrival
    failed: List[Tuple[int, BaseException]] = []
    done = 0
    try:
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1)
            ref = ready[0]
            i = pending.pop(ref)
            try:
                film, where = ray.get(ref)
            except VolptError:
                raise  # the task's own error (Ray's exception is also of the task's class)
            except Exception as e:  # the worker or node died beyond the retries, and the like
                failed.append((i, e))
                continue
            if first is None:
                first = (i, film.fingerprint, where["node"])
            elif film.fingerprint != first[1]:
                raise RenderError(
                    f"part {i} (samples {ranges[i].start}..{ranges[i].stop}), rendered on "
                    f"{where['node']}, is of another scene than part {first[0]}, rendered on "
                    f"{first[2]}: scene fingerprints {film.fingerprint:016x} and {first[1]:016x}. "
                    f"Every node must read the same scene files at {scene}"
                )
            if parts_dir is not None:
                film.save_film(os.path.join(parts_dir, f"part-{i:04d}.vfilm"))
            arrived[i] = film
            # Parts are added in the order of their ranges, as soon as the ones before are in:
            # the same partition gives the same bits whatever order the parts arrive in.
            while next_part in arrived:
                film = arrived.pop(next_part)
                merged = film if merged is None else _volpt.merge([merged, film])
                next_part += 1
            done += 1
            if report is not None:
                report(
                    PartDone(
                        index=i,
                        samples=ranges[i],
                        node=where["node"],
                        node_id=where["node_id"],
                        pid=where["pid"],
                        seconds=where["seconds"],
                        done=done,
                        total=len(ranges),
                    )
                )
    finally:
        for ref in pending:  # an error above: the tasks still running are of no use
            ray.cancel(ref, force=False)

    if failed:
        failed.sort(key=lambda f: f[0])
        lines = [f"  samples {ranges[i].start}..{ranges[i].stop} (part {i}): {_reason(e)}" for i, e in failed]
        kept = f" The other parts' films are in {os.fspath(parts_dir)}." if parts_dir is not None else ""
        raise RenderError(
            f"{len(failed)} of {len(ranges)} parts failed (max_retries={max_retries}):\n"
            + "\n".join(lines)
            + f"\nRender them with `volpt render SCENE --samples A..B --film FILE` and merge "
            f"them with the others (`volpt merge`).{kept}"
        ) from failed[0][1]
    assert merged is not None and merged.samples == range(0, spp), merged
    if out is not None:
        merged.write(out)
    return merged


def compensate_print(
    target: "str | os.PathLike[str]",
    materials: "str | os.PathLike[str]",
    out: "str | os.PathLike[str]",
    *,
    parts: Optional[int] = None,
    backend: str = "auto",
    num_cpus: int = 1,
    max_retries: int = 3,
    address: Optional[str] = None,
    parts_done: Optional[Callable[[PartDone], Any]] = None,
    **options: Any,
) -> Dict[str, Any]:
    """``volpt.compensate_print`` with every prediction rendered on a Ray cluster: each of a
    prediction's two independent halves is one ``render`` of the print's scene (written under
    ``out/renders/``, which every node must read at the same path: a shared file system), split
    into ``parts`` sample ranges (default: as ``render``'s, at most the half's samples) rendered as
    Ray tasks and merged. ``backend``, ``num_cpus``, ``max_retries`` and ``address`` are
    ``render``'s; ``parts_done`` is called with each part as it arrives (``render``'s
    ``progress``); ``options`` are ``volpt.compensate_print``'s (``layers``, ``spp``,
    ``iterations``, ``iteration``, ...; not ``render``).

    The record is the one ``volpt.compensate_print`` writes (its ``backend`` says ``render=``).
    A part that fails beyond its retries raises ``RenderError`` after the record of the iterations
    finished is written, as Ctrl-C does.
    """
    if "render" in options:
        raise SettingsError("render: not an option of volpt.distributed.compensate_print (the Ray cluster renders)")

    def render_on_cluster(scene: str, samples: int, seed: int) -> "_volpt.Film":
        return render(
            scene,
            samples,
            parts=None if parts is None else min(parts, samples),
            seed=seed,
            backend=backend,
            num_cpus=num_cpus,
            max_retries=max_retries,
            address=address,
            progress=parts_done,
        )

    return _volpt.compensate_print(target, materials, out, render=render_on_cluster, **options)
