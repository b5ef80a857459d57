#!/usr/bin/env python3
"""Render scenes with Mitsuba 3 and with volpt at the same resolution and spp, time both after a
warm-up render, and test whether the images agree statistically. See docs/peers.md.

  python3 bench/peers/mitsuba3/compare.py scenes/cgg-logo/scene.xml scenes/smoke/scene.xml \
      --resolution 100 --spp 64 --volpt target/release/volpt --out out/peers

Per scene: two Mitsuba renders (seeds 1, 2; the first is the warm-up, which compiles and caches the
kernels) and two volpt renders (seeds 1, 2; the first is the warm-up), whose images are compared;
then `--timed N` - 1 more renders of each (seeds 3, 4, ...). The time reported is the median of the
N renders after the warm-up: one render can include work the warm-up did not cache (a 1.7x outlier
of Mitsuba's second render was seen once on the GPU), and a median of several is robust to that.
Mitsuba's time is `mi.render` plus evaluation and synchronisation of the image (scene
loading excluded); volpt's is the render time it prints (scene loading and EXR writing excluded;
the process's wall time is recorded too). Writes OUT/<name>.json, OUT/<name>-{volpt,mi3}-s{1,2}.exr,
OUT/<name>-mi3.xml (what Mitsuba rendered) and appends a row to OUT/results.md.

A scene that is not Mitsuba XML (a volpt TOML scene, a grid file) is first written as a Mitsuba 3
scene by `volpt scene export` (into OUT/<name>-export/), so that both renderers read the very grids
volpt assembles (after normalisation and transfer functions); volpt itself renders the original
file. `--resolution N` becomes volpt's `--resolution NxN` for such scenes.
"""

import argparse
import datetime
import json
import math
import os
import platform
import re
import shlex
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import mi3scene  # noqa: E402
import stats  # noqa: E402

MD_HEADER = ("| scene | machine | peer variant | volpt backend | res | spp | Mitsuba 3 s | volpt s | speed-up "
             "| MSE Mitsuba 3 | MSE volpt | efficiency volpt / Mitsuba 3 "
             "| rel. mean diff | global z (R,G,B) | worst block \\|z\\| | blocks \\|z\\|>3 | z of 1% bias | agree "
             "| non-finite values Mitsuba 3 / volpt |\n"
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- "
             "| --- | --- |")


def scene_name(path):
    base = os.path.splitext(os.path.basename(path))[0]
    parent = os.path.basename(os.path.dirname(os.path.abspath(path)))
    if base == "scene":
        return parent
    return f"{parent}-{base[len('scene-'):]}" if base.startswith("scene-") else f"{parent}-{base}"


def read_exr(mi, path):
    bmp = mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False)
    h, w = bmp.height(), bmp.width()
    if stats.np is not None:
        return stats.np.array(bmp, copy=True).reshape(-1), h, w
    import drjit as dr  # host-side tensor whatever the variant, so no device round trips
    return list(dr.scalar.TensorXf(bmp).array), h, w


class Mitsuba:
    def __init__(self, variant):
        import drjit as dr
        import mitsuba as mi
        mi.set_variant(variant)
        self.mi, self.dr, self.variant = mi, dr, variant

    def render(self, xml_path, params, spp, seed, out):
        mi, dr = self.mi, self.dr
        scene = mi.load_file(xml_path, **used_params(xml_path, params))
        dr.sync_thread()
        t0 = time.perf_counter()
        img = mi.render(scene, spp=spp, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        seconds = time.perf_counter() - t0
        bmp = mi.Bitmap(img[..., :3] if img.shape[2] > 3 else img)
        bmp.write(out)
        film = scene.sensors()[0].film()
        return seconds, list(film.size())


def volpt_render(volpt, scene, params, spp, seed, out, backend, threads, extra):
    cmd = [volpt, "render", scene, "-o", out, "--spp", str(spp), "--seed", str(seed)] + extra
    # VOLPT_RENDER_ARGS: more render options for volpt alone (e.g. "--estimator nee"), not exported.
    cmd += shlex.split(os.environ.get("VOLPT_RENDER_ARGS", ""))
    for k, v in params.items():
        cmd += ["-D", f"{k}={v}"]
    if backend != "cpu":
        cmd += ["--backend", backend]
    if threads:
        cmd += ["--threads", str(threads)]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{p.stdout}\n{p.stderr}")
    m = re.search(r"at \d+ spp \((.*?)\) in ([0-9.]+) s", p.stdout)
    if not m:
        raise RuntimeError(f"cannot find the render time in volpt's output:\n{p.stdout}")
    truncated = re.search(r"warning: (\d+) paths reached the segment bound", p.stdout)
    return float(m.group(2)), wall, m.group(1), int(truncated.group(1)) if truncated else 0, " ".join(cmd)


def mse_of_one_render(a, b):
    """The mean squared error of one render, per pixel channel, from two renders of independent
    seeds and without a reference: for unbiased renders E[(a - b)^2] / 2 is the variance of one,
    which is its MSE. Only meaningful where the agreement test passes (a bias would not show)."""
    if stats.np is not None:
        return float(((a - b) ** 2).mean() / 2)
    return sum((x - y) ** 2 for x, y in zip(a, b)) / (2 * len(a))


def fmt_ratio(x):
    return "n/a" if x is None else f"{x:.2f}x"


def fmt(x, nd=3):
    return f"{x:.{nd}f}" if isinstance(x, float) else str(x)


def used_params(xml_path, params):
    """The parameters the converted XML still refers to: Mitsuba 3 rejects unused ones, and the
    conversion has already substituted those it needed (grid paths, for one)."""
    with open(xml_path) as f:
        text = f.read()
    return {k: v for k, v in params.items() if "$" + k in text}


def export(args, path, name, params, extra):
    """`volpt scene export` of a non-XML scene; returns the Mitsuba 3 XML it wrote."""
    out_dir = os.path.join(args.out, f"{name}-export")
    cmd = [args.volpt, "scene", "export", path, "-o", out_dir, "--name", name] + extra
    for k, v in params.items():
        cmd += ["-D", f"{k}={v}"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{p.stdout}\n{p.stderr}")
    return os.path.join(out_dir, f"{name}.xml")


def run_scene(args, mit, path):
    name = args.name or scene_name(path)
    params = dict(args.define)
    os.makedirs(args.out, exist_ok=True)
    extra = []  # volpt options that stand in for Mitsuba parameters
    if path.endswith(".xml"):
        # The -D values are needed already here: converting reads the grids the scene names.
        _, _, declared = mi3scene.convert(path, dict(params))
        for key, val in (("resolution", args.resolution),):
            if val is not None:
                if key not in declared:
                    raise ValueError(f"{path} declares no <default name=\"{key}\">: cannot override it")
                params[key] = str(val)
        xml, notes, _ = mi3scene.convert(path, params)
        volpt_params = params
    else:
        if args.resolution is not None:
            extra = ["--resolution", f"{args.resolution}x{args.resolution}"]
        exported = export(args, path, name, params, extra)
        # The export has consumed the parameters (they named volpt's input files).
        xml, notes, _ = mi3scene.convert(exported, {})
        notes = [f"written as Mitsuba 3 by `volpt scene export` ({exported})"] + notes
        volpt_params, params = params, {}
    xml_path = os.path.join(args.out, f"{name}-mi3.xml")
    with open(xml_path, "w") as f:
        f.write(xml)
    spp = args.spp
    if spp is None:
        spp = int(mit.mi.load_file(xml_path, **used_params(xml_path, params))
                  .sensors()[0].sampler().sample_count())
    seeds = args.seeds
    res = {"scene": path, "name": name, "spp": spp, "params": volpt_params, "volpt_options": extra, "notes": notes,
           "peer": {"renderer": "mitsuba " + mit.mi.__version__, "variant": mit.variant, "times_s": []},
           "volpt": {"backend": args.backend, "times_s": [], "wall_s": []},
           "machine": args.machine or f"{platform.node()} ({os.cpu_count()} cores)",
           "date": args.date or datetime.date.today().isoformat()}
    peer_imgs, volpt_imgs = [], []
    timing_seeds = list(range(max(seeds) + 1, max(seeds) + args.timed))
    for s in seeds + timing_seeds:
        out = os.path.join(args.out, f"{name}-mi3-s{s}.exr")
        t, size = mit.render(xml_path, params, spp, s, out)
        res["peer"]["times_s"].append(t)
        res["resolution"] = size
        if s in seeds:
            peer_imgs.append(out)
        else:
            os.remove(out)
        print(f"[{name}] mitsuba {mit.variant} seed {s}: {t:.3f} s", flush=True)
    for s in seeds + timing_seeds:
        out = os.path.join(args.out, f"{name}-volpt-s{s}.exr")
        t, wall, variant, trunc, cmd = volpt_render(args.volpt, path, volpt_params, spp, s, out, args.backend,
                                                   args.threads, extra)
        res["volpt"]["times_s"].append(t)
        res["volpt"]["wall_s"].append(wall)
        res["volpt"]["variant"] = variant
        res["volpt"]["truncated_paths"] = res["volpt"].get("truncated_paths", 0) + trunc
        res["volpt"]["command"] = cmd
        if s in seeds:
            volpt_imgs.append(out)
        else:
            os.remove(out)
            os.remove(os.path.splitext(out)[0] + ".png")
        print(f"[{name}] volpt {args.backend} seed {s}: {t:.3f} s (wall {wall:.3f} s)", flush=True)
    imgs = [read_exr(mit.mi, p) for p in volpt_imgs + peer_imgs]
    h, w = imgs[0][1], imgs[0][2]
    if any((i[1], i[2]) != (h, w) for i in imgs):
        raise RuntimeError(f"image sizes differ: {[(i[1], i[2]) for i in imgs]}")
    # NaN and Inf values of each renderer's images, counted before anything averages them away.
    non_finite = [sum(1 for v in i[0] if not math.isfinite(v)) for i in imgs]
    res["volpt"]["non_finite"] = sum(non_finite[:len(volpt_imgs)])
    res["peer"]["non_finite"] = sum(non_finite[len(volpt_imgs):])
    agreement = stats.compare(*(i[0] for i in imgs), h, w, block=args.block)
    res["agreement"] = agreement
    # Timed = the renders after the warm-up.
    tp, tv = (statistics.median(res[who]["times_s"][1:]) for who in ("peer", "volpt"))
    res["peer"]["time_s"], res["volpt"]["time_s"] = tp, tv
    res["speedup"] = tp / tv if tv > 0 else None
    # Efficiency 1 / (MSE x time): the speed-up at equal error, where the two estimators' variances
    # per sample differ (Mitsuba 3 samples the emitter at every scattering event and rough surface,
    # volpt by default only under a lat-long map; docs/heterogeneous.md).
    mse_v, mse_p = mse_of_one_render(imgs[0][0], imgs[1][0]), mse_of_one_render(imgs[2][0], imgs[3][0])
    res["volpt"]["mse"], res["peer"]["mse"] = mse_v, mse_p
    res["efficiency_ratio"] = (mse_p * tp) / (mse_v * tv) if mse_v > 0 and tv > 0 else None
    with open(os.path.join(args.out, f"{name}.json"), "w") as f:
        json.dump(res, f, indent=2)
    a = agreement
    row = (f"| {name} | {res['machine']} | {mit.variant} | {args.backend} | {h}x{w} | {spp} | {tp:.3f} | "
           f"{tv:.3f} | {res['speedup']:.2f}x | {mse_p:.3e} | {mse_v:.3e} | "
           f"{fmt_ratio(res['efficiency_ratio'])} | {100 * a['relative_mean_difference']:+.3f}% | "
           f"{', '.join(f'{z:+.2f}' for z in a['global_z_rgb'])} | {a['worst_abs_z']:.2f} | "
           f"{100 * a['fraction_abs_z_above_3']:.2f}% | {min(a['z_of_1pct_bias']):.1f} | "
           f"{'yes' if a['agree'] else '**no**'} | {res['peer']['non_finite']} / {res['volpt']['non_finite']} |")
    md = os.path.join(args.out, "results.md")
    new = not os.path.exists(md)
    with open(md, "a") as f:
        if new:
            f.write(MD_HEADER + "\n")
        f.write(row + "\n")
    print(row, flush=True)
    for n in notes:
        print(f"[{name}] note: {n}")
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--volpt", default=os.environ.get("VOLPT", "volpt"), help="volpt binary")
    ap.add_argument("--backend", default="cpu", choices=["cpu", "cuda"], help="volpt backend")
    ap.add_argument("--variant", default=None,
                    help="Mitsuba variant (default: cuda_ad_rgb with --backend cuda, else llvm_ad_rgb)")
    ap.add_argument("--resolution", type=int, help="sets -D resolution=N (the scene must declare it)")
    ap.add_argument("--spp", type=int, help="samples per pixel (default: the scene's sampler)")
    ap.add_argument("-D", dest="define", action="append", default=[], type=lambda s: tuple(s.split("=", 1)),
                    metavar="NAME=VALUE", help="scene parameter for both renderers")
    ap.add_argument("--seeds", type=int, nargs=2, default=[1, 2], help="two seeds; the first render is the warm-up")
    ap.add_argument("--timed", type=int, default=3,
                    help="timed renders per renderer after the warm-up (median reported; at least 1)")
    ap.add_argument("--block", type=int, default=10, help="block size in pixels")
    ap.add_argument("--threads", type=int, help="volpt CPU threads (default: all)")
    ap.add_argument("--name", help="result name (one scene only)")
    ap.add_argument("--machine", help="machine description for the table")
    ap.add_argument("--date", help="date for the table (default: today)")
    ap.add_argument("--out", default="out/peers")
    args = ap.parse_args()
    if args.timed < 1:
        ap.error("--timed must be at least 1")
    variant = args.variant or ("cuda_ad_rgb" if args.backend == "cuda" else "llvm_ad_rgb")
    mit = Mitsuba(variant)
    results, failed = [], 0
    for s in args.scenes:
        try:
            results.append(run_scene(args, mit, s))
        except Exception as e:  # keep going: one broken scene should not hide the others
            failed += 1
            print(f"[{s}] ERROR: {e}", file=sys.stderr, flush=True)
    disagree = sum(1 for r in results if not r["agreement"]["agree"])
    print(f"{len(results)} compared, {disagree} disagree, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
