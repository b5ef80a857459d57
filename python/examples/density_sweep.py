"""Renders volpt's example cube at several density scales without reloading it, and plots the
images and their mean radiance with matplotlib.

    pip install ./python matplotlib
    python python/examples/density_sweep.py [SCENE] [--backend cuda] [-o sweep.png]

In a notebook, the same lines work cell by cell; ``progress=True`` draws a bar per render.
"""

import argparse
from pathlib import Path

import numpy as np

import volpt

REPO = Path(__file__).resolve().parents[2]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=REPO / "scenes" / "example" / "cube.xml")
    parser.add_argument("--backend", default="cpu", choices=["cpu", "cuda"])
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("-o", "--output", default="density-sweep.png")
    args = parser.parse_args()

    scene = volpt.load(args.scene, {"resolution": (args.size, args.size)})
    print(scene)
    for key, value in scene.info().items():
        print(f"{key:<10} {value.splitlines()[0]}")

    backend = volpt.Backend(args.backend)  # opened once: a GPU's kernels load once
    base = scene.params["medium.scale"]
    factors = [0.125, 0.5, 1.0, 4.0, 16.0]
    images, means = [], []
    for factor in factors:
        scene.params["medium.scale"] = base * factor  # the grids stay loaded
        film = scene.render(spp=args.spp, backend=backend, progress=True)
        image = film.image()  # float32 (H, W, 3), linear
        images.append(image)
        means.append(image.mean(axis=(0, 1)))
        print(f"scale {base * factor:8.3f}: mean RGB {np.round(means[-1], 4)}, {film.elapsed:.2f} s")
    scene.params["medium.scale"] = base

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no plot (pip install matplotlib)")
        return
    fig, axes = plt.subplots(1, len(factors) + 1, figsize=(3 * (len(factors) + 1), 3.2))
    for ax, factor, image in zip(axes, factors, images):
        # sRGB-ish display: clip and gamma 2.2.
        ax.imshow(np.clip(image, 0, 1) ** (1 / 2.2))
        ax.set_title(f"scale x {factor:g}")
        ax.axis("off")
    means = np.array(means)
    for c, colour in enumerate("rgb"):
        axes[-1].plot(np.array(factors) * base, means[:, c], f"{colour}o-")
    axes[-1].set_xscale("log")
    axes[-1].set_xlabel("medium.scale")
    axes[-1].set_ylabel("mean radiance")
    fig.tight_layout()
    fig.savefig(args.output, dpi=100)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
