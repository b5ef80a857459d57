#!/usr/bin/env python3
"""Per-pixel variance of volpt and Mitsuba 3 on one scene, by image region: where does one renderer's
estimator have more variance per sample than the other's? See docs/peers.md.

  python3 bench/peers/mitsuba3/variance.py scenes/envmap-cube/scene.xml --resolution 100 --spp 64 \
      --seeds 8 --volpt target/release/volpt --out out/variance

Renders the scene `--seeds` times with each renderer (seeds 1..N, independent), and estimates each
pixel channel's variance of one render by the sample variance over the N renders (N - 1 degrees of
freedom). Regions, from Mitsuba's camera rays (a 4x4 grid of film positions per pixel intersected
with the scene): `background` (every ray misses the shapes: the pixel sees the environment only),
`object` (every ray hits), `edge` (some do). Within `object`, pixels are also split by brightness (the brightest decile of
both renderers' mean image), to show whether the difference sits in a few bright pixels.

Reports per region: pixels, mean variance of each renderer (MSE of one render, for unbiased
renders), their ratio with a 95% interval from a bootstrap over seeds, and the mean of each image (a
bias check). Writes OUT/<name>-variance.json and, with numpy, OUT/<name>-var-{volpt,mi3,ratio}.exr.
More volpt options: `--volpt-args "--estimator pt" --tag -pt` (the tag names those renders' files;
`--skip-mi3` reuses Mitsuba's renders of an earlier run).
"""

import argparse
import json
import os
import shlex
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import compare  # noqa: E402
import mi3scene  # noqa: E402


def region_mask(mi, scene, res):
    """Per pixel: how many of a 4x4 grid of film positions see a shape (0..16)."""
    import drjit as dr
    sensor = scene.sensors()[0]
    n = 4
    hits = np.zeros((res, res), dtype=np.int32)
    ys, xs = np.meshgrid(np.arange(res), np.arange(res), indexing="ij")
    for a in range(n):
        for b in range(n):
            fx = (xs + (b + 0.5) / n) / res
            fy = (ys + (a + 0.5) / n) / res
            pos = mi.Point2f(fx.ravel().astype(np.float32), fy.ravel().astype(np.float32))
            ray, _ = sensor.sample_ray(0.0, 0.5, pos, mi.Point2f(0.5, 0.5))
            si = scene.ray_intersect(ray)
            valid = np.array(si.is_valid(), dtype=bool)
            hits += valid.reshape(res, res)
    del dr
    return hits


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--resolution", type=int, default=100)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--volpt", default="target/release/volpt")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--out", default="out/variance")
    ap.add_argument("--name", default=None)
    ap.add_argument("--skip-mi3", action="store_true", help="reuse the Mitsuba renders already in OUT")
    ap.add_argument("-D", dest="define", action="append", default=[], type=lambda s: tuple(s.split("=", 1)))
    ap.add_argument("--volpt-args", default="", help="more volpt render options, e.g. '--estimator pt'")
    ap.add_argument("--tag", default="", help="suffix of the volpt files (renders with other options)")
    args = ap.parse_args()
    args.volpt_extra = shlex.split(args.volpt_args)

    import mitsuba as mi
    mi.set_variant(args.variant)
    name = args.name or compare.scene_name(args.scene)
    os.makedirs(args.out, exist_ok=True)
    params = dict(args.define)
    params["resolution"] = str(args.resolution)
    xml, _, _ = mi3scene.convert(args.scene, params)
    xml_path = os.path.join(args.out, f"{name}-mi3.xml")
    with open(xml_path, "w") as f:
        f.write(xml)
    mparams = compare.used_params(xml_path, params)
    seeds = list(range(args.first_seed, args.first_seed + args.seeds))
    mit, vol = [], []
    scene = mi.load_file(xml_path, **mparams)
    for s in seeds:
        out = os.path.join(args.out, f"{name}-mi3-s{s}.exr")
        if not (args.skip_mi3 and os.path.exists(out)):
            img = mi.render(scene, spp=args.spp, seed=s)
            mi.Bitmap(img).write(out)
        mit.append(compare.read_exr(mi, out)[0].reshape(args.resolution, args.resolution, 3))
        out = os.path.join(args.out, f"{name}-volpt{args.tag}-s{s}.exr")
        cmd = [args.volpt, "render", args.scene, "-o", out, "--spp", str(args.spp), "--seed", str(s)]
        cmd += [x for k, v in params.items() for x in ("-D", f"{k}={v}")] + args.volpt_extra
        subprocess.run(cmd, check=True, capture_output=True)
        vol.append(compare.read_exr(mi, out)[0].reshape(args.resolution, args.resolution, 3))
        print(f"seed {s} done", flush=True)
    mit, vol = np.array(mit, dtype=np.float64), np.array(vol, dtype=np.float64)
    hits = region_mask(mi, scene, args.resolution)
    regions = {"all": np.ones_like(hits, dtype=bool), "background": hits == 0,
               "object": hits == 16, "edge": (hits > 0) & (hits < 16)}
    var_m = mit.var(axis=0, ddof=1).mean(axis=2)
    var_v = vol.var(axis=0, ddof=1).mean(axis=2)
    obj = regions["object"]
    if obj.any():
        # Object pixels by brightness (the mean of both renderers' images, which neither one's
        # noise selects): the brightest decile vs the rest.
        bright = (mit.mean(axis=0) + vol.mean(axis=0)).mean(axis=2)
        cut = np.quantile(bright[obj], 0.9)
        regions["object, brightest 10%"] = obj & (bright >= cut)
        regions["object, other 90%"] = obj & (bright < cut)
    rng = np.random.default_rng(0)
    report = {"scene": args.scene, "resolution": args.resolution, "spp": args.spp, "seeds": seeds,
              "volpt_options": args.volpt_extra, "variant": args.variant, "regions": {}}
    print(f"{name}: {args.resolution}x{args.resolution}, {args.spp} spp, seeds {seeds[0]}..{seeds[-1]}, "
          f"volpt {' '.join(args.volpt_extra) or '(defaults)'}")
    print(f"{'region':40s} {'pixels':>6s} {'var volpt':>10s} {'var mi3':>10s} {'ratio':>6s} {'95% (boot)':>14s} "
          f"{'mean volpt':>10s} {'mean mi3':>10s}")
    for rname, mask in regions.items():
        if not mask.any():
            continue
        vv, vm = var_v[mask].mean(), var_m[mask].mean()
        boots = []
        for _ in range(200):
            idx = rng.integers(0, len(seeds), len(seeds))
            bv = vol[idx][:, mask].var(axis=0, ddof=1).mean()
            bm = mit[idx][:, mask].var(axis=0, ddof=1).mean()
            boots.append(bv / bm if bm > 0 else np.nan)
        lo, hi = np.nanquantile(boots, [0.025, 0.975])
        mv, mm = vol[:, mask].mean(), mit[:, mask].mean()
        report["regions"][rname] = {"pixels": int(mask.sum()), "var_volpt": vv, "var_mi3": vm,
                                    "ratio": vv / vm if vm > 0 else None, "ratio_95": [lo, hi],
                                    "mean_volpt": mv, "mean_mi3": mm}
        print(f"{rname:40s} {int(mask.sum()):6d} {vv:10.3e} {vm:10.3e} {vv / vm:6.2f} [{lo:5.2f}, {hi:5.2f}] "
              f"{mv:10.5f} {mm:10.5f}")
    with open(os.path.join(args.out, f"{name}{args.tag}-variance.json"), "w") as f:
        json.dump(report, f, indent=2)
    for tag, img in (("volpt", var_v), ("mi3", var_m), ("ratio", var_v / np.maximum(var_m, 1e-12))):
        mi.Bitmap(np.repeat(img[:, :, None], 3, axis=2).astype(np.float32)).write(
            os.path.join(args.out, f"{name}{args.tag}-var-{tag}.exr"))


if __name__ == "__main__":
    main()
