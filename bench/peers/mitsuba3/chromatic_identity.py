#!/usr/bin/env python3
"""Which renderer is right on a chromatic medium: the per-channel identity, for Mitsuba 3 and for
volpt, on the same scene.

Each channel c of a chromatic render equals, in expectation, the render of the grey medium made of
channel c's coefficients (sigma_t_c, albedo_c in every channel). That holds for any correct
estimator, and the grey renders of both renderers agree (docs/peers.md), so a chromatic render that
breaks it is biased. For the scene given (Mitsuba 3 XML, one homogeneous medium with an RGB
`sigma_t`, an RGB `albedo` and an optional `scale`):

  python3 chromatic_identity.py SCENE.xml --volpt bin/volpt [--films 16 --resolution 128 --spp 64]

renders FILMS films of independent seeds of: the chromatic scene with Mitsuba (its integrator,
`volpathmis`), each channel's grey scene with Mitsuba (`volpath`), the chromatic scene with volpt
(`--backend cuda`) and each grey scene with volpt. Each film's image mean per channel is one
independent estimate; Welch's z over the films compares, per channel, chromatic against grey within
each renderer, and grey against grey across them. Prints one line per comparison, with the relative
standard error (a 1% bias shows at 1% / se sigma), and exits 1 when any |z| >= 5.
Needs mitsuba (cuda_ad_rgb) and numpy.
"""

import argparse
import math
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import mitsuba as mi
import numpy as np

mi.set_variant("cuda_ad_rgb")


def rgb_of(el):
    return [float(v) for v in el.get("value").replace(",", " ").split()]


def grey_scene(path, channel, out_dir):
    """The scene with the medium's RGB sigma_t and albedo replaced by channel `channel`'s values,
    rendered by `volpath`."""
    tree = ET.parse(path)
    root = tree.getroot()
    for integrator in root.iter("integrator"):
        integrator.set("type", "volpath")
    media = list(root.iter("medium"))
    if len(media) != 1:
        sys.exit(f"{path}: needs exactly one medium, found {len(media)}")
    for el in media[0]:
        name = el.get("name")
        if el.tag == "rgb" and name == "sigma_t":
            el.tag = "float"
            el.set("value", repr(rgb_of(el)[channel]))
        elif el.tag == "rgb" and name == "albedo":
            v = rgb_of(el)[channel]
            el.set("value", f"{v!r}, {v!r}, {v!r}")
    out = os.path.join(out_dir, f"grey{channel}.xml")
    tree.write(out)
    return out


def mitsuba_means(path, films, resolution, spp):
    scene = mi.load_file(path, resolution=str(resolution), spp=str(spp))
    means = []
    for seed in range(films):
        image = np.array(mi.render(scene, spp=spp, seed=1000 + seed))
        means.append(image[..., :3].reshape(-1, 3).mean(axis=0))
    return np.array(means)


def volpt_means(volpt, path, films, resolution, spp, work):
    means = []
    for seed in range(films):
        exr = os.path.join(work, "volpt.exr")
        subprocess.run([volpt, "render", path, "--backend", "cuda", "--spp", str(spp),
                        "--seed", str(1000 + seed), "--resolution", f"{resolution}x{resolution}",
                        "-o", exr], check=True, capture_output=True)
        image = np.array(mi.Bitmap(exr).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False))
        means.append(image.reshape(-1, 3).mean(axis=0))
    return np.array(means)


def welch(a, b):
    ma, mb = a.mean(), b.mean()
    se = math.sqrt(a.var(ddof=1) / len(a) + b.var(ddof=1) / len(b))
    return ma, mb, (ma - mb) / se if se > 0 else float("inf"), se / abs(mb)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--volpt", required=True)
    ap.add_argument("--films", type=int, default=16)
    ap.add_argument("--resolution", type=int, default=128)
    ap.add_argument("--spp", type=int, default=64)
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="chromatic-identity-")
    greys = [grey_scene(args.scene, c, work) for c in range(3)]
    r = (args.films, args.resolution, args.spp)
    mi_chromatic = mitsuba_means(args.scene, *r)
    vp_chromatic = volpt_means(args.volpt, args.scene, *r, work)
    worst = 0.0
    name = os.path.basename(os.path.dirname(os.path.abspath(args.scene))) + "/" + os.path.basename(args.scene)
    print(f"{name}: {args.films} films x {args.resolution}^2 x {args.spp} spp per renderer and medium")
    for c in range(3):
        mi_grey = mitsuba_means(greys[c], *r)
        vp_grey = volpt_means(args.volpt, greys[c], *r, work)
        for label, a, b in [
            ("Mitsuba volpathmis chromatic vs Mitsuba volpath grey", mi_chromatic[:, c], mi_grey[:, c]),
            ("volpt chromatic vs volpt grey", vp_chromatic[:, c], vp_grey[:, c]),
            ("volpt grey vs Mitsuba grey", vp_grey[:, c], mi_grey[:, c]),
            ("volpt chromatic vs Mitsuba chromatic", vp_chromatic[:, c], mi_chromatic[:, c]),
        ]:
            ma, mb, z, rel = welch(a, b)
            worst = max(worst, abs(z)) if "vs Mitsuba chromatic" not in label else worst
            print(f"channel {'RGB'[c]}: {label}: {ma:.6f} vs {mb:.6f} ({(ma / mb - 1) * 100:+.3f}%), "
                  f"z {z:+.2f}, relative se {rel:.1e}")
    print(f"largest |z| of the identities and the grey parity: {worst:.2f}")
    sys.exit(0 if worst < 5 else 1)


if __name__ == "__main__":
    main()
