#!/usr/bin/env python3
"""Variance at equal samples of two volpt binaries' estimators on one scene (CPU): which has the
lower pixel variance, and is the difference significant.

  python3 bench/identity/chromatic_variance.py SCENE --old OLD_VOLPT --new NEW_VOLPT \
      [--films 16 --spp 16 --resolution 64]

Each binary renders FILMS films of independent seeds (`volpt render --samples 0..SPP --film`,
the CPU backend). Per pixel and channel, the films' sample variance of the pixel value estimates
the variance of a SPP-sample pixel; both estimators are unbiased (the per-channel identity tests),
so that is their MSE at equal samples. Pixels are independent (their own random streams), so the
per-pixel difference new - old over the pixels the medium covers (variance > 0 in either) has a
mean with a standard error: z = mean / se. Prints per channel and over all channels the ratio of
mean variances new / old and z; exits 1 unless the new estimator's mean variance is lower with
z < -5 over all channels.
"""

import argparse
import os
import struct
import subprocess
import sys
import tempfile

import numpy as np


def read_film(path):
    """The pixel sums of a `VOLPTFL1` film file (volpt-film/src/film_file.rs), height x width x 3."""
    data = open(path, "rb").read()
    if data[:8] != b"VOLPTFL1":
        sys.exit(f"{path}: not a film file")
    width, height, _seed, ranges = struct.unpack_from("<4I", data, 16)
    offset = 32 + 8 * ranges
    sums = np.frombuffer(data, dtype="<f8", count=3 * width * height, offset=offset)
    return sums.reshape(height, width, 3)


def films(volpt, scene, args, out_dir, tag):
    images = []
    for k in range(args.films):
        path = os.path.join(out_dir, f"{tag}-{k}.film")
        cmd = [volpt, "render", scene, "--backend", "cpu", "--seed", str(1000 + k),
               "--resolution", f"{args.resolution}x{args.resolution}",
               "--samples", f"0..{args.spp}", "--film", path]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        images.append(read_film(path) / args.spp)
    return np.stack(images)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("scene")
    parser.add_argument("--old", required=True)
    parser.add_argument("--new", required=True)
    parser.add_argument("--films", type=int, default=16)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--resolution", type=int, default=64)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as out_dir:
        old = films(args.old, args.scene, args, out_dir, "old")
        new = films(args.new, args.scene, args, out_dir, "new")
    var_old = old.var(axis=0, ddof=1)
    var_new = new.var(axis=0, ddof=1)
    covered = (var_old.sum(axis=2) > 0) | (var_new.sum(axis=2) > 0)
    print(f"{args.scene}: {args.films} films x {args.spp} spp, {args.resolution}^2 pixels, "
          f"{covered.sum()} covered by the medium")
    ok = True
    for c, name in enumerate(["R", "G", "B", "all"]):
        if c < 3:
            vo, vn = var_old[..., c][covered], var_new[..., c][covered]
        else:
            vo, vn = var_old[covered].sum(axis=1), var_new[covered].sum(axis=1)
        d = vn - vo
        z = d.mean() / (d.std(ddof=1) / np.sqrt(d.size))
        print(f"  {name:>3}: mean pixel variance old {vo.mean():.4e} new {vn.mean():.4e} "
              f"new/old {vn.mean() / vo.mean():.3f} (z {z:+.1f})")
        if c == 3:
            ok = vn.mean() < vo.mean() and z < -5
    print("PASS" if ok else "FAIL")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
