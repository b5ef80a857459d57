#!/usr/bin/env python3
"""The CUDA driver's share of a small render's process time, without volpt: a child process that
loads libcuda with ctypes, initialises it, retains GPU 0's primary context, allocates 1 MiB, and
exits either normally (`exit`: the C library runs the driver's exit handlers) or at once (`_exit`:
it skips them; the kernel still closes the driver's files). Each mode runs RUNS times, alternating;
printed per mode: the median of cuInit, the context, the first allocation, the exit (from the
child's last line to its end, as the parent sees it) and the whole process.

    python3 driver-startup.py [RUNS]
"""
import ctypes
import os
import statistics
import subprocess
import sys
import time

CHILD = r"""
import ctypes, os, sys, time
mode = sys.argv[1]
t0 = time.perf_counter()
cuda = ctypes.CDLL("libcuda.so.1")
def check(what, rc):
    if rc != 0:
        print(f"{what} failed: {rc}", flush=True)
        os._exit(1)
check("cuInit", cuda.cuInit(0))
t1 = time.perf_counter()
dev = ctypes.c_int()
check("cuDeviceGet", cuda.cuDeviceGet(ctypes.byref(dev), 0))
ctx = ctypes.c_void_p()
check("cuDevicePrimaryCtxRetain", cuda.cuDevicePrimaryCtxRetain(ctypes.byref(ctx), dev))
check("cuCtxSetCurrent", cuda.cuCtxSetCurrent(ctx))
t2 = time.perf_counter()
ptr = ctypes.c_uint64()
check("cuMemAlloc", cuda.cuMemAlloc_v2(ctypes.byref(ptr), 1 << 20))
t3 = time.perf_counter()
print(f"times {t1 - t0:.6f} {t2 - t1:.6f} {t3 - t2:.6f}", flush=True)
if mode == "_exit":
    sys.stdout.flush()
    os._exit(0)
sys.exit(0)
"""

runs = int(sys.argv[1]) if len(sys.argv) > 1 else 7
results = {"exit": [], "_exit": []}
# One untimed run: the first process after boot also loads the driver's files from disk.
subprocess.run([sys.executable, "-c", CHILD, "exit"], stdout=subprocess.DEVNULL)
for _ in range(runs):
    for mode in results:
        start = time.perf_counter()
        proc = subprocess.Popen([sys.executable, "-c", CHILD, mode], stdout=subprocess.PIPE,
                                bufsize=0)
        line = proc.stdout.readline().decode()
        printed = time.perf_counter()
        proc.stdout.read()
        proc.wait()
        end = time.perf_counter()
        if not line.startswith("times"):
            print(f"{mode}: {line.strip()} (exit {proc.returncode})")
            continue
        init, context, alloc = map(float, line.split()[1:])
        results[mode].append((init, context, alloc, end - printed, end - start))
for mode, rows in results.items():
    if not rows:
        continue
    med = [statistics.median(col) * 1000 for col in zip(*rows)]
    print(f"{mode:6} ({len(rows)} runs, median ms): cuInit {med[0]:.1f}, primary context "
          f"{med[1]:.1f}, first 1 MiB allocation {med[2]:.1f}, exit {med[3]:.1f}, process "
          f"{med[4]:.1f}")
    print("        exits (ms): " + " ".join(f"{r[3] * 1000:.1f}" for r in rows))
