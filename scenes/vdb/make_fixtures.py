#!/usr/bin/python3
"""Writes volpt's VDB test fixtures with the real OpenVDB library (Debian's python3-openvdb,
`import pyopenvdb`), never with volpt's own code: `scripts/openvdb.sh` installs it.

    /usr/bin/python3 scenes/vdb/make_fixtures.py OUT_DIR            # the small test fixtures
    /usr/bin/python3 scenes/vdb/make_fixtures.py OUT_DIR --large N  # also a sparse cloud in an N^3 box

Fixtures (all default OpenVDB compression, i.e. blosc LZ4 with active-mask compression, unless
said otherwise):
- bucky.vdb: scenes/bucky/Bucky.raw (32^3 uint8) as float values 0..255, index (i, j, k) at world
  (-0.5 + (i + 0.5) / 32, ...), so the grid's box is scenes/bucky's [-0.5, 0.5]^3; zero voxels are
  inactive background (pruned leaves), the 8 corner voxels active so the stored box is the whole
  32^3 grid. bucky-half.vdb: the same, leaves saved as half (integers up to 2048 are exact).
- bucky-zip.vdb (float leaves, zip with active-mask compression) and bucky-half-none.vdb (half
  leaves, uncompressed): bucky.vdb and bucky-half.vdb rewritten by OpenVDB's C++ library with
  another compression (recompress.cc, built here with g++ against Debian's libopenvdb-dev: the
  Python module does not expose the file's compression).
- halves.vdb: a 16^3 float grid "density" of values (i + j + k) * 0.1 + 0.01, saved as half,
  so that values are rounded to half by OpenVDB.
- transform.vdb: a float grid "smoke" (and a second float grid "other") over index box
  [-8, 8) x [16, 24) x [0, 24) with voxel size (0.5, 0.25, 2) and translation (1, 2, 3).
- cloud-rgb.vdb: a float grid "density" (a ball) and a vec3s grid "albedo" of (0.25, 0.5, 0.75).
- fill1024.vdb, fill4096.vdb: `fill()` of value 0.5 over the boxes [0, 1024)^3 and [0, 4096)^3:
  OpenVDB stores them as tiles (1024^3: 512 tiles of 128^3 in one 4096^3 node, 8.8 KB; 4096^3:
  one root tile, 594 bytes), no leaves.
- sparse-cloud.vdb: two small balls at opposite corners of a 512^3 index box: about 4,300 active
  voxels, a dense box over 30,000 times larger.
"""

import math
import os
import subprocess
import sys
import tempfile

import numpy as np
import pyopenvdb as vdb

HERE = os.path.dirname(os.path.abspath(__file__))


def bucky(out, half):
    raw = np.fromfile(os.path.join(HERE, "..", "bucky", "Bucky.raw"), dtype=np.uint8)
    # Bucky.raw is x fastest: [z][y][x]; OpenVDB arrays are [i][j][k] = [x][y][z].
    values = raw.reshape(32, 32, 32).transpose(2, 1, 0).astype(np.float32).copy()
    grid = vdb.FloatGrid(0.0)
    grid.copyFromArray(values, ijk=(0, 0, 0), tolerance=0.0)
    acc = grid.getAccessor()
    for i in (0, 31):
        for j in (0, 31):
            for k in (0, 31):
                acc.setValueOn((i, j, k), float(values[i, j, k]))
    grid.name = "density"
    s = 1.0 / 32.0
    grid.transform = vdb.createLinearTransform(
        [[s, 0, 0, 0], [0, s, 0, 0], [0, 0, s, 0], [-0.5 + s / 2, -0.5 + s / 2, -0.5 + s / 2, 1]]
    )
    grid.saveFloatAsHalf = half
    vdb.write(os.path.join(out, "bucky-half.vdb" if half else "bucky.vdb"), grids=[grid])


def halves(out):
    i, j, k = np.meshgrid(np.arange(16), np.arange(16), np.arange(16), indexing="ij")
    values = ((i + j + k) * 0.1 + 0.01).astype(np.float32)
    grid = vdb.FloatGrid(0.0)
    grid.copyFromArray(values, ijk=(0, 0, 0), tolerance=0.0)
    grid.name = "density"
    grid.saveFloatAsHalf = True
    vdb.write(os.path.join(out, "halves.vdb"), grids=[grid])


def transform(out):
    shape = (16, 8, 24)
    values = np.fromfunction(lambda i, j, k: 1.0 + i + 2 * j + 3 * k, shape, dtype=np.float32)
    grid = vdb.FloatGrid(0.0)
    grid.copyFromArray(values.astype(np.float32), ijk=(-8, 16, 0), tolerance=0.0)
    grid.name = "smoke"
    grid.transform = vdb.createLinearTransform(
        [[0.5, 0, 0, 0], [0, 0.25, 0, 0], [0, 0, 2, 0], [1, 2, 3, 1]]
    )
    other = vdb.FloatGrid(0.0)
    other.copyFromArray(np.ones((8, 8, 8), dtype=np.float32), ijk=(0, 0, 0))
    other.name = "other"
    vdb.write(os.path.join(out, "transform.vdb"), grids=[grid, other])


def ball(grid, centre, radius, value):
    acc = grid.getAccessor()
    r = int(math.ceil(radius))
    for i in range(-r, r + 1):
        for j in range(-r, r + 1):
            for k in range(-r, r + 1):
                if i * i + j * j + k * k <= radius * radius:
                    acc.setValueOn((centre[0] + i, centre[1] + j, centre[2] + k), value)


def cloud_rgb(out):
    density = vdb.FloatGrid(0.0)
    ball(density, (12, 12, 12), 9.5, 5.0)
    density.name = "density"
    albedo = vdb.Vec3SGrid((0.0, 0.0, 0.0))
    acc = albedo.getAccessor()
    for (i, j, k) in [(x, y, z) for x in range(0, 24) for y in range(0, 24) for z in range(0, 24)]:
        acc.setValueOn((i, j, k), (0.25, 0.5, 0.75))
    albedo.name = "albedo"
    for g in (density, albedo):
        g.transform = vdb.createLinearTransform(voxelSize=1.0 / 24.0)
    vdb.write(os.path.join(out, "cloud-rgb.vdb"), grids=[density, albedo])


def sparse_cloud(out):
    grid = vdb.FloatGrid(0.0)
    ball(grid, (10, 10, 10), 10.0, 3.0)
    ball(grid, (501, 501, 501), 10.0, 3.0)
    grid.name = "density"
    grid.transform = vdb.createLinearTransform(voxelSize=1.0 / 512.0)
    vdb.write(os.path.join(out, "sparse-cloud.vdb"), grids=[grid])


def fills(out):
    for n in (1024, 4096):
        grid = vdb.FloatGrid(0.0)
        grid.fill((0, 0, 0), (n - 1, n - 1, n - 1), 0.5, True)
        grid.name = "density"
        vdb.write(os.path.join(out, f"fill{n}.vdb"), grids=[grid])


def large_cloud(out, n, seed=7):
    """Smooth blobs filling a few percent of an n^3 box: the benchmark's sparse volume, never
    committed. One blob in each of 24 of the 27 cells of a 3^3 lattice, so that no two blobs'
    arrays overlap (copyFromArray overwrites); values quantised to 1/64, as simulation output
    often is, so that blosc finds repeats."""
    rng = np.random.default_rng(seed)
    grid = vdb.FloatGrid(0.0)
    cell = n / 3.0
    cells = [(a, b, c) for a in range(3) for b in range(3) for c in range(3)]
    for index in rng.permutation(len(cells))[:24]:
        r = rng.uniform(0.06 * n, 0.08 * n)
        c = np.array(cells[index], dtype=float) * cell + cell / 2 + rng.uniform(-0.05, 0.05, 3) * n
        lo = np.maximum(np.floor(c - r).astype(int), 0)
        hi = np.minimum(np.ceil(c + r).astype(int) + 1, n)
        i, j, k = np.meshgrid(*[np.arange(lo[a], hi[a]) for a in range(3)], indexing="ij",
                              sparse=True)
        d2 = ((i - c[0]) ** 2 + (j - c[1]) ** 2 + (k - c[2]) ** 2) / (r * r)
        values = np.where(d2 < 1.0, (1.0 - d2) ** 2 * 4.0, 0.0)
        values = (np.round(values * 64.0) / 64.0).astype(np.float32)
        grid.copyFromArray(values, ijk=tuple(int(v) for v in lo), tolerance=0.0)
        del values, d2
    grid.name = "density"
    grid.transform = vdb.createLinearTransform(voxelSize=1.0 / n)
    path = os.path.join(out, f"large-cloud-{n}.vdb")
    vdb.write(path, grids=[grid])
    print(f"{path}: {grid.activeVoxelCount()} active voxels of {n}^3 "
          f"({100.0 * grid.activeVoxelCount() / n ** 3:.2f}%), {grid.leafCount()} leaves, "
          f"{os.path.getsize(path)} bytes")


def recompress(out):
    """bucky.vdb as zip, bucky-half.vdb uncompressed, by OpenVDB's own C++ writer."""
    with tempfile.TemporaryDirectory() as tmp:
        tool = os.path.join(tmp, "recompress")
        subprocess.run(["g++", "-std=c++17", "-O1", os.path.join(HERE, "recompress.cc"), "-o", tool,
                        "-lopenvdb", "-ltbb"], check=True)
        for source, target, how in [("bucky.vdb", "bucky-zip.vdb", "zip"),
                                    ("bucky-half.vdb", "bucky-half-none.vdb", "none")]:
            subprocess.run([tool, os.path.join(out, source), os.path.join(out, target), how],
                           check=True)


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    if "--large" in sys.argv:
        large_cloud(out, int(sys.argv[sys.argv.index("--large") + 1]))
        return
    bucky(out, half=False)
    bucky(out, half=True)
    recompress(out)
    halves(out)
    transform(out)
    cloud_rgb(out)
    sparse_cloud(out)
    fills(out)
    print(f"OpenVDB {vdb.LIBRARY_VERSION}, file format {vdb.FILE_FORMAT_VERSION}: fixtures in {out}")


if __name__ == "__main__":
    main()
