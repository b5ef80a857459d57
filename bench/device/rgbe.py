"""Radiance .hdr images as numpy arrays (the thesis's renderer writes them with stb_image_write).

    python3 rgbe.py A.hdr B.hdr   # prints the mean of A and B and their mean squared difference
"""
import sys

import numpy as np


def read_rgbe(path):
    """Radiance .hdr, flat or new-style run-length scanlines (what stb_image_write writes)."""
    data = open(path, "rb").read()
    start = data.index(b"\n\n") + 2
    nl = data.index(b"\n", start)
    dims = data[start:nl].split()
    if len(dims) != 4 or dims[0] != b"-Y" or dims[2] != b"+X":
        sys.exit(f"{path}: resolution line {data[start:nl]!r}, expected '-Y H +X W'")
    h, w = int(dims[1]), int(dims[3])
    buf, pos = np.frombuffer(data, np.uint8), nl + 1
    rgbe = np.empty((h, w, 4), np.uint8)
    for y in range(h):
        if 8 <= w < 32768 and buf[pos] == 2 and buf[pos + 1] == 2 and not buf[pos + 2] & 0x80:
            pos += 4
            for c in range(4):
                x = 0
                while x < w:
                    n = int(buf[pos])
                    if n > 128:
                        rgbe[y, x:x + n - 128, c] = buf[pos + 1]
                        x, pos = x + n - 128, pos + 2
                    else:
                        rgbe[y, x:x + n, c] = buf[pos + 1:pos + 1 + n]
                        x, pos = x + n, pos + 1 + n
        else:
            rgbe[y] = buf[pos:pos + 4 * w].reshape(w, 4)
            pos += 4 * w
    # stb_image_write truncates the mantissa: decoding at the bin centre (+0.5) removes the
    # ~0.5% downward bias that stb_image's own decoder keeps.
    e = rgbe[..., 3].astype(np.int32)
    scale = np.where(e > 0, np.ldexp(1.0, e - 136), 0.0)
    return (rgbe[..., :3] + 0.5) * scale[..., None]


if __name__ == "__main__":
    a, b = (read_rgbe(p) for p in sys.argv[1:3])
    if a.shape != b.shape:
        sys.exit(f"{sys.argv[1]} is {a.shape}, {sys.argv[2]} is {b.shape}")
    print(f"mean a {a.mean():.6f} mean b {b.mean():.6f} mse {((a - b) ** 2).mean():.6e}")
