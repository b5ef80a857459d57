#!/usr/bin/env python3
"""Where a small GPU render's process time goes: runs `volpt render` on a tiny scene once untimed
(the driver's JIT cache then holds its kernel), then several times, and stamps every line the last
run prints (stdout and stderr, with RUST_LOG=volpt=debug,volpt_cuda=debug) with the time since the
process started, and the process's exit.

    python3 startup.py bin/volpt [RUNS]      # from a device bundle: scenes/example/cube.xml
"""
import os
import subprocess
import sys
import time

volpt = sys.argv[1] if len(sys.argv) > 1 else "bin/volpt"
runs = int(sys.argv[2]) if len(sys.argv) > 2 else 5
out = os.environ.get("OUT", "/tmp")
os.makedirs(out, exist_ok=True)
args = [volpt, "render", "scenes/example/cube.xml", "--resolution", "16x16", "--spp", "1",
        "--backend", "cuda", "-o", os.path.join(out, "tiny.exr")]
env = dict(os.environ, RUST_LOG="volpt=debug,volpt_cuda=debug,volpt_scene=debug", NO_COLOR="1")
subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
totals = []
for run in range(runs):
    start = time.perf_counter()
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env,
                            bufsize=0)
    lines = []
    for raw in iter(proc.stdout.readline, b""):
        lines.append((time.perf_counter() - start, raw.decode(errors="replace").rstrip()))
    proc.wait()
    total = time.perf_counter() - start
    totals.append(total)
    print(f"run {run + 1}: {total:.3f} s (exit {proc.returncode})")
    if run == runs - 1:
        for at, line in lines:
            print(f"  {at * 1000:7.1f} ms  {line[:160]}")
        print(f"  {total * 1000:7.1f} ms  (process exited)")
totals.sort()
print(f"median {totals[len(totals) // 2]:.3f} s of {runs}")
