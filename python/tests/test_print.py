"""volpt.compensate_print: the same record as ``volpt print compensate`` from the same arguments,
clear errors for bad files and arguments, and Ctrl-C keeping the iterations finished."""

import os
import signal
import struct
import subprocess
import sys
import textwrap
import time
import zlib
from pathlib import Path

import pytest

import volpt
from conftest import REPO, run_cli

MATERIALS = REPO / "examples" / "print" / "materials.toml"


def write_png(path: Path, width: int, height: int, rgb) -> Path:
    """An 8-bit RGB PNG of ``rgb(x, y) -> (r, g, b)``, written with zlib alone."""
    rows = b"".join(
        b"\x00" + bytes(v for x in range(width) for v in rgb(x, y)) for y in range(height)
    )

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")
    )
    return path


def bars(x: int, y: int):
    return (200, 40, 40) if (x // 2) % 2 == 0 else (40, 60, 200 - 3 * (y % 60))


def test_the_record_equals_the_command_line_s(tmp_path, volpt_bin):
    target = write_png(tmp_path / "target.png", 10, 8, bars)
    args = dict(layers=8, colour_layers=4, spp=4, iterations=3, seed=3)
    seen = []
    result = volpt.compensate_print(
        target, MATERIALS, tmp_path / "py", **args, iteration=lambda k, it: seen.append((k, it))
    )
    run_cli(
        volpt_bin, "print", "compensate", target, "--materials", MATERIALS, "-o", tmp_path / "cli",
        "--layers", 8, "--colour-layers", 4, "--spp", 4, "--iterations", 3, "--seed", 3, "--quiet",
    )
    its = result["iterations"]
    assert result["size"] == (10, 8) and 1 <= len(its) <= 3
    assert [k for k, _ in seen] == list(range(len(its))) and [it for _, it in seen] == its
    assert all(it["mean"] > 0 and it["p95"] >= 0 and it["spp"] >= 4 for it in its)
    assert its[result["best"]]["mean"] == min(it["mean"] for it in its)
    py, cli = tmp_path / "py", tmp_path / "cli"
    files = sorted(p.relative_to(cli) for p in cli.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(py) for p in py.rglob("*") if p.is_file())
    assert Path("slices/slice_0007.png") in files and Path("delta_e.svg") in files
    for name in files:
        assert (py / name).read_bytes() == (cli / name).read_bytes(), name
    # The CSV says what the result says.
    rows = (py / "iterations.csv").read_text().splitlines()[1:]
    assert [float(r.split(",")[1]) for r in rows] == pytest.approx([it["mean"] for it in its], abs=1e-6)


def test_update_chooses_the_command_line_s_update_and_refuses_others(tmp_path, volpt_bin):
    target = write_png(tmp_path / "target.png", 10, 8, bars)
    args = dict(layers=8, colour_layers=4, spp=4, iterations=2, seed=5)
    volpt.compensate_print(target, MATERIALS, tmp_path / "py", **args, update="per-texel")
    run_cli(
        volpt_bin, "print", "compensate", target, "--materials", MATERIALS, "-o", tmp_path / "cli",
        "--layers", 8, "--colour-layers", 4, "--spp", 4, "--iterations", 2, "--seed", 5,
        "--update", "per-texel", "--quiet",
    )
    volpt.compensate_print(target, MATERIALS, tmp_path / "cross", **args)
    py, cli, cross = tmp_path / "py", tmp_path / "cli", tmp_path / "cross"
    csv = "iterations.csv"
    assert (py / csv).read_bytes() == (cli / csv).read_bytes()
    # The default is the other update: the same first prediction, different aims after it.
    assert (py / csv).read_bytes() != (cross / csv).read_bytes()
    with pytest.raises(volpt.SettingsError, match='"cross-talk" or "per-texel"'):
        volpt.compensate_print(target, MATERIALS, tmp_path / "bad", **args, update="sideways")


def test_bad_files_and_arguments_raise_clear_errors(tmp_path):
    target = write_png(tmp_path / "target.png", 4, 4, bars)
    soot = tmp_path / "soot.toml"
    soot.write_text(MATERIALS.read_text().replace('"black"', '"soot"'))
    with pytest.raises(volpt.PrintError, match="no material named black") as caught:
        volpt.compensate_print(target, soot, tmp_path / "a", layers=4, colour_layers=2)
    assert str(soot) in str(caught.value)
    assert isinstance(caught.value, ValueError)
    not_png = tmp_path / "not.png"
    not_png.write_text("text")
    with pytest.raises(volpt.PrintError, match="not.png"):
        volpt.compensate_print(not_png, MATERIALS, tmp_path / "b")
    with pytest.raises(volpt.PrintError, match="colour layers"):
        volpt.compensate_print(target, MATERIALS, tmp_path / "c", layers=4, colour_layers=5)
    with pytest.raises(volpt.SettingsError, match="backend"):
        volpt.compensate_print(target, MATERIALS, tmp_path / "d", backend="tpu")
    with pytest.raises(volpt.SettingsError, match="iteration"):
        volpt.compensate_print(target, MATERIALS, tmp_path / "e", iteration=3)
    for name in "abcde":
        assert not (tmp_path / name / "iterations.csv").exists()


CHILD = textwrap.dedent(
    """
    import signal, sys
    signal.signal(signal.SIGINT, signal.default_int_handler)
    import volpt
    def told(k, it):
        print("iteration", k, flush=True)
    try:
        volpt.compensate_print(sys.argv[1], sys.argv[2], sys.argv[3], layers=60, colour_layers=20,
                               spp=64, noise_ratio=None, iterations=50, iteration=told)
    except KeyboardInterrupt:
        print("interrupted", flush=True)
    else:
        print("finished", flush=True)
        sys.exit(1)
    """
)


def test_ctrl_c_writes_the_iterations_finished_and_raises_keyboard_interrupt(tmp_path):
    target = write_png(tmp_path / "target.png", 48, 48, bars)
    out = tmp_path / "out"
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(target), str(MATERIALS), str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    try:
        assert child.stdout.readline().strip() == "iteration 0"
        child.send_signal(signal.SIGINT)
        rest, err = child.communicate(timeout=120)
    finally:
        child.kill()
    assert child.returncode == 0, (rest, err)
    assert rest.splitlines()[-1] == "interrupted", (rest, err)
    rows = (out / "iterations.csv").read_text().splitlines()[1:]
    assert 1 <= len(rows) < 50
    assert (out / "slices" / "materials.toml").is_file() and (out / "delta_e.svg").is_file()


def test_no_backend_named_is_a_gpu_where_one_is_usable_else_the_cpu_and_says_which(tmp_path):
    target = write_png(tmp_path / "target.png", 4, 3, bars)
    args = dict(layers=4, colour_layers=2, spp=2, iterations=1)
    result = volpt.compensate_print(target, MATERIALS, tmp_path / "a", **args)
    if result["backend"].startswith("CPU"):
        no_gpu = ("this build carries no GPU kernels", "no GPU is usable", "the CUDA driver sees no GPU",
                  "the GPU did not open")
        assert result["backend_reason"].startswith(no_gpu), result
    else:
        assert result["backend_reason"].startswith("a GPU is present"), result
    # A backend named wins.
    named = volpt.compensate_print(target, MATERIALS, tmp_path / "b", **args, backend="cpu")
    assert named["backend"].startswith("CPU") and named["backend_reason"] == "backend="


def test_render_renders_each_prediction_from_its_scene_files(tmp_path):
    # What volpt.distributed.compensate_print passes: here, the same render in this process.
    target = write_png(tmp_path / "target.png", 6, 5, bars)
    args = dict(layers=6, colour_layers=3, spp=8, iterations=2, seed=2, noise_ratio=None)
    calls = []

    def render(scene, samples, seed):
        calls.append((Path(scene).relative_to(tmp_path / "files"), samples, seed))
        return volpt.load(scene).render(samples=range(samples), seed=seed)

    files = volpt.compensate_print(target, MATERIALS, tmp_path / "files", **args, render=render)
    assert files["backend"] == "render=" and files["backend_reason"] == "render="
    assert calls == [(Path("renders/scene.toml"), 4, seed) for _ in files["iterations"] for seed in (2, 3)]
    assert not (tmp_path / "files" / "renders").exists()  # removed once the loop ends
    here = volpt.compensate_print(target, MATERIALS, tmp_path / "here", **args, backend="cpu")
    # The scene files are the predictor's scene, to the float rounding of the camera's transform.
    assert [it["mean"] for it in files["iterations"]] == pytest.approx(
        [it["mean"] for it in here["iterations"]], rel=1e-3)
    with pytest.raises(volpt.SettingsError, match="render and backend"):
        volpt.compensate_print(target, MATERIALS, tmp_path / "c", render=render, backend="cpu")
    with pytest.raises(volpt.SettingsError, match="render: expected a callable"):
        volpt.compensate_print(target, MATERIALS, tmp_path / "d", render=3)
    # A render's exception stops the loop as Ctrl-C does, and is raised once the record is written.
    def broken(scene, samples, seed):
        raise RuntimeError("the cluster is gone")

    with pytest.raises(RuntimeError, match="the cluster is gone"):
        volpt.compensate_print(target, MATERIALS, tmp_path / "e", **args, render=broken)
    with pytest.raises(volpt.SettingsError, match="expected a film of samples 0..4"):
        volpt.compensate_print(target, MATERIALS, tmp_path / "f", **args,
                               render=lambda s, n, seed: volpt.load(s).render(samples=range(1), seed=seed))
