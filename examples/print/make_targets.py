#!/usr/bin/env python3
"""Writes the three targets of docs/printing.md's worked example (Pillow needed; the committed PNGs
are its output):

  python3 examples/print/make_targets.py ASTRONAUT.png

- lines.png: fine detail: black text and one- to three-texel coloured lines on white;
- photo.png: a photograph: the head of scikit-image's `astronaut` (NASA, public domain: "no known
  copyright restrictions, released into the public domain", skimage/data), cropped and scaled;
- gradient.png: a smooth gradient: hue across, lightness down.
Each is 96 x 96 texels, a size the CPU compensates in minutes."""

import colorsys
import sys
from pathlib import Path

from PIL import Image, ImageDraw

SIZE = 96
HERE = Path(__file__).resolve().parent


def lines() -> Image.Image:
    im = Image.new("RGB", (SIZE, SIZE), "white")
    d = ImageDraw.Draw(im)
    d.text((6, 4), "volpt", fill="black")
    d.text((6, 18), "print 3D", fill=(200, 0, 0))
    colours = [(0, 90, 200), (200, 30, 30), (20, 140, 40), (0, 0, 0)]
    x = 6
    for k, width in enumerate([1, 1, 2, 2, 3, 3, 1, 2, 3]):
        d.rectangle([x, 40, x + width - 1, 90], fill=colours[k % len(colours)])
        x += width + 2 + k % 3
    for k, y in enumerate(range(40, 92, 4)):
        d.line([(52, y), (90, y + (k % 3))], fill=colours[(k + 1) % len(colours)], width=1)
    return im


def photo(source: Path) -> Image.Image:
    im = Image.open(source).convert("RGB")
    # The astronaut's head and shoulders, square.
    return im.crop((150, 20, 390, 260)).resize((SIZE, SIZE), Image.LANCZOS)


def gradient() -> Image.Image:
    im = Image.new("RGB", (SIZE, SIZE))
    px = im.load()
    for y in range(SIZE):
        for x in range(SIZE):
            r, g, b = colorsys.hls_to_rgb(x / SIZE * 0.85, 0.3 + 0.45 * y / SIZE, 0.7)
            px[x, y] = (round(255 * r), round(255 * g), round(255 * b))
    return im


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    lines().save(HERE / "lines.png")
    photo(Path(sys.argv[1])).save(HERE / "photo.png")
    gradient().save(HERE / "gradient.png")
