#!/usr/bin/env python3
"""Issue 40's independent check: a compensated print, rendered by Mitsuba 3, is closer to its
target than the naive print.

For each record of `volpt print compensate` given (a folder with target.png, print.toml and
naive.toml: the kept print's and the naive print's scenes, slice stacks beside them):

  python3 print.py --volpt bin/volpt [--spp 256] [--fine lines] RECORD...

exports both scenes for Mitsuba 3 (`volpt scene export`: the material table expanded per voxel into
RGB gridvolumes of extinction and albedo, read nearest), renders each with Mitsuba 3
(`cuda_ad_rgb`, `volpathmis`: the medium is chromatic) at SPP samples per pixel, writes the EXR,
and measures the CIEDE2000 against the target with `volpt print delta-e --flip-rows` (non-finite
pixels, which volpathmis leaves a few of, are left out and counted). Prints one Markdown row per
record: Mitsuba's mean and p95 for naive and compensated, their ratio, and volpt's own predicted
means (iterations.csv) beside them. Exits 1 unless every compensated mean is below its naive
mean and, on the record named by --fine (the fine-detail target), at least 2x below.
Needs mitsuba with cuda_ad_rgb (bench/peers/mitsuba3/device.sh unpacks it).
"""

import argparse
import csv
import re
import subprocess
import sys
import time
from pathlib import Path

import mitsuba as mi

mi.set_variant("cuda_ad_rgb")


def delta_e(volpt, target, exr):
    run = subprocess.run([volpt, "print", "delta-e", str(target), str(exr), "--flip-rows"],
                         capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"volpt print delta-e {target} {exr} failed: {run.stderr.strip()}")
    out = run.stdout
    m = re.search(r"mean ΔE00 ([0-9.]+), p95 ([0-9.]+) over (\d+) texels \((\d+) not finite", out)
    if not m:
        sys.exit(f"unexpected output of volpt print delta-e: {out}")
    return float(m[1]), float(m[2]), int(m[4])


def render(volpt, scene_toml, work, spp, seed):
    """Mitsuba 3's image of a record's scene (exported by volpt), as an EXR in `work`."""
    name = scene_toml.stem
    subprocess.run([volpt, "scene", "export", str(scene_toml), "-o", str(work), "--name", name],
                   check=True, capture_output=True)
    xml = work / f"{name}.xml"
    text = xml.read_text()
    text = re.sub(r'<integrator type="volpath"', '<integrator type="volpathmis"', text)
    xml.write_text(text)
    scene = mi.load_file(str(xml))
    start = time.time()
    image = mi.render(scene, spp=spp, seed=seed)
    exr = work / f"{name}-mitsuba.exr"
    # Written before volpt reads it: write_bitmap writes asynchronously by default.
    mi.util.write_bitmap(str(exr), image, write_async=False)  # evaluates the render
    return exr, time.time() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("records", nargs="+", type=Path)
    ap.add_argument("--volpt", required=True)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--fine", default="lines", help="the record (folder name) of the fine-detail target")
    args = ap.parse_args()
    print("| target | Mitsuba 3 naive mean / p95 | compensated mean / p95 | naive / compensated "
          "| volpt predicted naive / best | non-finite px | seconds |")
    print("|---|---|---|---|---|---|---|")
    ok = True
    for record in args.records:
        work = record / "mitsuba3"
        work.mkdir(exist_ok=True)
        results, seconds = {}, 0.0
        for which in ("naive", "print"):
            exr, s = render(args.volpt, record / f"{which}.toml", work, args.spp, args.seed)
            seconds += s
            results[which] = delta_e(args.volpt, record / "target.png", exr)
        (nm, np95, nbad), (cm, cp95, cbad) = results["naive"], results["print"]
        rows = list(csv.DictReader(open(record / "iterations.csv")))
        means = [float(r["mean_delta_e"]) for r in rows]
        ratio = nm / cm
        fine = record.name == args.fine
        passed = cm < nm and (ratio >= 2 or not fine)
        ok &= passed
        print(f"| {record.name}{' (fine detail)' if fine else ''} | {nm:.2f} / {np95:.2f} | {cm:.2f} / {cp95:.2f} "
              f"| {ratio:.2f}x {'PASS' if passed else 'FAIL'} | {means[0]:.2f} / {min(means):.2f} "
              f"| {nbad + cbad} | {seconds:.1f} |", flush=True)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
