"""volpt.distributed on a real local Ray cluster: a head node without CPUs and two worker nodes of
one CPU each (two raylets, two object stores, one worker process rendering on each), CPU backend.

The merged film equals the one-process render of the same partition bit for bit, and the whole
render within float64 rounding; a worker process killed mid-task has its task retried by Ray and
the image is still complete and the same. The cluster's tests are skipped where Ray is not
installed, unless VOLPT_REQUIRE_RAY is set (python/ci.sh sets it): then they fail.
"""

import faulthandler
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import volpt
import volpt.distributed as vd
from conftest import REPO, bits, run_cli

try:
    import ray
except ImportError:
    if os.environ.get("VOLPT_REQUIRE_RAY"):
        raise
    ray = None
needs_ray = pytest.mark.skipif(ray is None, reason="Ray is not installed (pip install ray)")

SIZE = (48, 40)
SETTINGS = {"resolution": SIZE}
#: The object store's smallest size: the films are kilobytes.
STORE = 80 * 2**20


@pytest.fixture(scope="module")
def cluster():
    if ray is None:
        pytest.skip("Ray is not installed (pip install ray)")
    from ray.cluster_utils import Cluster

    # A hung cluster must not hang CI: tracebacks and exit after 10 minutes.
    faulthandler.dump_traceback_later(600, exit=True)
    started = time.monotonic()
    c = Cluster(
        initialize_head=True,
        head_node_args={"num_cpus": 0, "include_dashboard": False, "object_store_memory": STORE},
    )
    try:
        for _ in range(2):
            c.add_node(num_cpus=1, object_store_memory=STORE)
        ray.init(address=c.address, log_to_driver=False)
        c.wait_for_nodes()
        assert ray.cluster_resources().get("CPU") == 2
        print(f"Ray cluster up in {time.monotonic() - started:.1f} s", file=sys.stderr)
        yield c
    finally:
        ray.shutdown()
        c.shutdown()
        faulthandler.cancel_dump_traceback_later()


def partition_render(scene, spp, parts, seed=None):
    """The one-process render of the same sample ranges, merged: what the cluster must give."""
    return volpt.merge([scene.render(samples=r, seed=seed) for r in vd.sample_ranges(spp, parts)])


def test_sample_ranges():
    assert vd.sample_ranges(10, 3) == [range(0, 3), range(3, 6), range(6, 10)]
    assert vd.sample_ranges(4, 4) == [range(i, i + 1) for i in range(4)]
    for spp, parts in [(1, 1), (7, 2), (1000, 7)]:
        r = vd.sample_ranges(spp, parts)
        assert r[0].start == 0 and r[-1].stop == spp and all(a.stop == b.start for a, b in zip(r, r[1:]))
        assert max(map(len, r)) - min(map(len, r)) <= 1
    with pytest.raises(volpt.SettingsError, match=r"parts: expected an integer from 1 to spp \(4\), found 5"):
        vd.sample_ranges(4, 5)
    with pytest.raises(volpt.SettingsError, match=r"spp: expected a positive integer"):
        vd.sample_ranges(0, 1)


def test_without_ray_says_what_to_install(monkeypatch, grid_scene):
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` raises ImportError
    with pytest.raises(ImportError, match=r"pip install 'volpt\[ray\]'"):
        vd.render(grid_scene, 4, parts=2, backend="cpu")


@needs_ray
def test_example_on_a_local_cluster(tmp_path, grid_scene):
    # python/examples/ray_render.py as its docstring runs it: its own local cluster of two CPUs
    # (two worker processes). Before the module's cluster starts, so that one cluster runs at once.
    spp, parts = 16, 4
    env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}
    out = subprocess.run(
        [
            sys.executable, str(REPO / "python" / "examples" / "ray_render.py"), str(grid_scene),
            "--spp", str(spp), "--parts", str(parts), "--resolution", f"{SIZE[0]}x{SIZE[1]}",
            "--backend", "cpu", "--local-cpus", "2", "-o", str(tmp_path / "ray.exr"),
        ],
        capture_output=True, text=True, timeout=300, env=env,
    )
    assert out.returncode == 0, out.stderr
    assert f"part {parts}/{parts} " in out.stderr and "'CPU': 2.0" in out.stderr, out.stderr
    local = partition_render(volpt.load(grid_scene, SETTINGS), spp, parts)
    assert np.array_equal(bits(volpt.read_exr(tmp_path / "ray.exr")), bits(local.image()))


def test_merged_image_equals_single_process_render(cluster, tmp_path, volpt_bin, grid_scene):
    spp, parts = 48, 3  # parts of a few tenths of a second: both nodes take one
    arrived = []
    film = vd.render(
        grid_scene, spp, parts=parts, seed=3, backend="cpu", settings=SETTINGS,
        out=tmp_path / "ray.exr", parts_dir=tmp_path / "parts", progress=arrived.append,
    )
    assert film.samples == range(0, spp) and film.seed == 3 and (film.width, film.height) == SIZE
    # Every part arrived once, and the two worker nodes both rendered.
    assert sorted(p.index for p in arrived) == list(range(parts))
    assert [p.done for p in arrived] == list(range(1, parts + 1))
    assert {p.samples for p in arrived} == set(vd.sample_ranges(spp, parts))
    assert len({p.node_id for p in arrived}) == 2, arrived

    # The same partition in one process: the same bits (the parts are added in range order).
    scene = volpt.load(grid_scene, SETTINGS)
    local = partition_render(scene, spp, parts, seed=3)
    assert local.fingerprint == film.fingerprint == scene.fingerprint
    assert np.array_equal(bits(film.sums), bits(local.sums))
    assert np.array_equal(bits(film.image()), bits(local.image()))
    # The whole render, sample by sample: the same sums within float64 rounding.
    whole = scene.render(spp=spp, seed=3)
    np.testing.assert_allclose(film.sums, whole.sums, rtol=1e-12, atol=0)
    assert film.image().mean() > 0
    # The EXR written is the film's image.
    assert np.array_equal(bits(volpt.read_exr(tmp_path / "ray.exr")), bits(film.image()))

    # The parts' films are the command line's: `volpt merge` of them writes the same EXR, and so
    # does the Slurm recipe (`volpt render --samples A..B --film`, then `volpt merge`).
    saved = sorted((tmp_path / "parts").iterdir())
    assert [p.name for p in saved] == [f"part-{i:04d}.vfilm" for i in range(parts)]
    run_cli(volpt_bin, "merge", *saved, "--spp", spp, "-o", tmp_path / "merged.exr")
    assert (tmp_path / "merged.exr").read_bytes() == (tmp_path / "ray.exr").read_bytes()
    cli_parts = []
    for i, r in enumerate(vd.sample_ranges(spp, parts)):
        cli_parts.append(tmp_path / f"cli-{i}.vfilm")
        run_cli(
            volpt_bin, "render", grid_scene, "--resolution", f"{SIZE[0]}x{SIZE[1]}", "--seed", 3,
            "--samples", f"{r.start}..{r.stop}", "--film", cli_parts[-1],
        )
    run_cli(volpt_bin, "merge", *reversed(cli_parts), "--spp", spp, "-o", tmp_path / "cli.exr")
    assert (tmp_path / "cli.exr").read_bytes() == (tmp_path / "ray.exr").read_bytes()
    assert np.array_equal(bits(volpt.Film.load_film(cli_parts[1]).sums), bits(volpt.Film.load_film(saved[1]).sums))


def test_task_error_is_raised_as_its_class(cluster, tmp_path):
    with pytest.raises(volpt.SceneNotFoundError, match=r"nowhere\.xml"):
        vd.render(tmp_path / "nowhere.xml", 4, parts=2, backend="cpu")
    with pytest.raises(volpt.SettingsError, match=r"the Ray cluster has no GPUs"):
        vd.render(tmp_path / "nowhere.xml", 4, parts=2, backend="cuda")


# --- A worker killed mid-task ---------------------------------------------------------------


def render_task_pids():
    """The processes running a render task now: Ray titles a worker process `ray::<task>`."""
    pids = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                title = Path(f"/proc/{entry}/cmdline").read_bytes().split(b"\0")[0]
            except OSError:
                continue
            if title == b"ray::_render_part":
                pids.append(int(entry))
    return pids


class Killer(threading.Thread):
    """Kills (SIGKILL) the first worker process seen running a render task, `after` seconds after
    it was first seen, if it still runs one then."""

    def __init__(self, after):
        super().__init__(daemon=True)
        self.after = after
        self.killed = None
        self.stop = threading.Event()

    def run(self):
        deadline = time.monotonic() + 120
        while not self.stop.is_set() and time.monotonic() < deadline:
            pids = render_task_pids()
            if pids:
                time.sleep(self.after)
                if pids[0] in render_task_pids():
                    os.kill(pids[0], signal.SIGKILL)
                    self.killed = pids[0]
                    return
            time.sleep(0.01)


def long_parts_spp(grid_scene, seconds=1.5):
    """Samples per part for a part of about `seconds` on one thread (at least): long enough to be
    killed in the middle, whatever this machine's speed."""
    scene = volpt.load(grid_scene, {**SETTINGS, "threads": 1})
    spp = 8
    while True:
        start = time.monotonic()
        scene.render(spp=spp)
        took = time.monotonic() - start
        if took > 0.2:
            return max(spp, int(spp * seconds / took))
        spp *= 4


pytestmark_linux = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")


@pytestmark_linux
def test_killed_worker_is_retried_and_the_image_is_complete(cluster, grid_scene):
    parts = 2
    spp = parts * long_parts_spp(grid_scene)
    killer = Killer(after=0.4)
    killer.start()
    arrived = []
    try:
        film = vd.render(grid_scene, spp, parts=parts, backend="cpu", settings=SETTINGS, progress=arrived.append)
    finally:
        killer.stop.set()
        killer.join()
    # A worker was killed while it rendered a part...
    assert killer.killed is not None, "no render task was seen running"
    assert not Path(f"/proc/{killer.killed}").exists() or b"zombie" in Path(f"/proc/{killer.killed}/status").read_bytes()
    # ...and every part arrived, none from the killed process: its part was rendered again.
    assert sorted(p.index for p in arrived) == list(range(parts))
    assert killer.killed not in {p.pid for p in arrived}, (killer.killed, arrived)
    assert film.samples == range(0, spp)
    assert np.array_equal(bits(film.sums), bits(partition_render(volpt.load(grid_scene, SETTINGS), spp, parts).sums))


@pytestmark_linux
def test_task_killed_beyond_its_retries_is_named(cluster, tmp_path, grid_scene):
    parts = 2
    spp = parts * long_parts_spp(grid_scene)
    killer = Killer(after=0.4)
    killer.start()
    try:
        with pytest.raises(volpt.RenderError, match=r"1 of 2 parts failed \(max_retries=0\):\n  samples \d+\.\.\d+ \(part [01]\): The worker died") as e:
            vd.render(grid_scene, spp, parts=parts, backend="cpu", settings=SETTINGS, max_retries=0, parts_dir=tmp_path)
    finally:
        killer.stop.set()
        killer.join()
    assert killer.killed is not None
    assert str(tmp_path) in str(e.value)
    # The part that arrived is kept, for `volpt merge` with the missing range's film.
    kept = list(tmp_path.iterdir())
    assert len(kept) == 1 and kept[0].name in ("part-0000.vfilm", "part-0001.vfilm")


def test_a_compensation_renders_its_predictions_on_the_cluster(cluster, tmp_path):
    # volpt.distributed.compensate_print: each prediction's halves split into sample ranges
    # rendered on the two worker nodes; the same compensation as this process's render of the
    # same scene files and partitions, bit for bit.
    from test_print import MATERIALS, bars, write_png

    target = write_png(tmp_path / "target.png", 6, 5, bars)
    # Parts of tenths of a second, so that both nodes take some (Ray gives parts of a quarter of a
    # millisecond to whichever node is free first, which may be the same one every time).
    args = dict(layers=6, colour_layers=3, spp=4096, iterations=3, seed=2, noise_ratio=None)
    arrived = []
    ray_result = vd.compensate_print(
        target, MATERIALS, tmp_path / "ray", parts=2, backend="cpu", parts_done=arrived.append, **args
    )

    def here(scene, samples, seed):
        s = volpt.load(scene)
        return volpt.merge([s.render(samples=r, seed=seed) for r in vd.sample_ranges(samples, 2)])

    local = volpt.compensate_print(target, MATERIALS, tmp_path / "local", render=here, **args)
    assert [it["mean"] for it in ray_result["iterations"]] == [it["mean"] for it in local["iterations"]]
    # Two parts per half, two halves per prediction, from both nodes.
    assert len(arrived) == 2 * 2 * len(ray_result["iterations"])
    assert len({p.node_id for p in arrived}) == 2, arrived
    for name in ["iterations.csv", *(f"slices/{p.name}" for p in (tmp_path / "local" / "slices").iterdir())]:
        assert (tmp_path / "ray" / name).read_bytes() == (tmp_path / "local" / name).read_bytes(), name
    with pytest.raises(volpt.SettingsError, match="render: not an option"):
        vd.compensate_print(target, MATERIALS, tmp_path / "x", render=here)
