"""The GIL is released while rendering; Ctrl-C stops a render promptly with KeyboardInterrupt and
leaves the interpreter usable; progress callbacks run, and their exceptions stop the render."""

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import pytest

import volpt
from conftest import CUBE, SETTINGS

# The child installs Python's Ctrl-C handler itself: a child of a process that ignores SIGINT (a
# runner started in the background of a shell, a Ray driver) starts with SIGINT ignored, and an
# interpreter that starts so installs none.
CHILD = textwrap.dedent(
    """
    import signal, sys, time
    signal.signal(signal.SIGINT, signal.default_int_handler)
    import volpt
    scene = volpt.load(sys.argv[1], {"resolution": (64, 64)})
    print("rendering", flush=True)
    try:
        scene.render(spp=1_000_000)
    except KeyboardInterrupt:
        print("interrupted", time.monotonic(), flush=True)
    else:
        print("finished", flush=True)
        sys.exit(1)
    film = scene.render(spp=1)
    print("after", film.samples, float(film.image().mean()) > 0, flush=True)
    """
)


def test_ctrl_c_raises_keyboard_interrupt_promptly():
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(CUBE)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        assert child.stdout.readline().strip() == "rendering"
        time.sleep(1.5)  # well into the render
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=60)
    finally:
        child.kill()
    lines = out.splitlines()
    assert child.returncode == 0, (out, err)
    assert lines[0].startswith("interrupted"), (out, err)
    latency = float(lines[0].split()[1]) - sent
    assert latency < 1.0, f"the render stopped {latency:.2f} s after Ctrl-C"
    assert lines[1] == "after range(0, 1) True"


def test_the_gil_is_released_while_rendering():
    scene = volpt.load(CUBE, {"resolution": (48, 48)})
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.005)

    thread = threading.Thread(target=tick)
    film = None
    thread.start()
    try:
        # Long enough to tell, whatever the machine's speed: more samples until it takes 0.3 s.
        spp = 600
        while True:
            start = time.monotonic()
            film = scene.render(spp=spp)
            end = time.monotonic()
            if end - start > 0.3 or spp >= 600 * 4**4:
                break
            spp *= 4
    finally:
        stop.set()
        thread.join()
    assert film is not None and end - start > 0.3, "render too short to tell"
    during = [t for t in ticks if start < t < end]
    # A thread that needs the GIL every 5 ms ran throughout the render.
    assert len(during) >= 10, (len(during), end - start)


def test_progress_callback():
    scene = volpt.load(CUBE, SETTINGS)
    calls = []
    scene.render(spp=32, progress=lambda done, total: calls.append((done, total)))
    assert calls, "never called"
    assert calls[-1][0] == calls[-1][1] > 0
    assert all(0 <= d <= t for d, t in calls)
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)


def test_progress_true_draws_a_bar(capfd):
    volpt.load(CUBE, SETTINGS).render(spp=4, progress=True)
    assert "100.0%" in capfd.readouterr().err


def test_an_exception_in_the_callback_stops_the_render():
    scene = volpt.load(CUBE, {"resolution": (64, 64)})

    def fail(done, total):
        raise RuntimeError(f"stop at {done}")

    start = time.monotonic()
    with pytest.raises(RuntimeError, match="stop at"):
        scene.render(spp=100_000, progress=fail)
    assert time.monotonic() - start < 5
    # The scene renders again, with its seed as it was.
    assert scene.render(spp=1).samples == range(0, 1) and scene.seed == 0
