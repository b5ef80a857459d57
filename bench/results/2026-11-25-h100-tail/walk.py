"""The index-matched cube's path lengths, simulated (bench/results/notes/strategies.md, "The launch's tail").

    python3 walk.py N   # N paths that hit the cube (numpy)

A unit cube of sigma_t 100 seen head-on: a path enters the front face at a uniform point heading
-z, flies exponential distances, scatters isotropically (albedo only weights, no roulette) and
ends when it leaves the cube. Its segments as the renderer counts them: the camera ray to the box,
every free flight, and the escape to the environment. 32.4% of the image misses the cube (a
1-segment path); the mean over all pixels is then comparable with `volpt`'s segments per path.
"""
import sys

import numpy as np

rng = np.random.default_rng(1)
N = int(sys.argv[1])
sigma_t = 100.0
p = np.zeros((N, 3))
p[:, 0] = rng.uniform(-0.5, 0.5, N)
p[:, 1] = rng.uniform(-0.5, 0.5, N)
p[:, 2] = 0.5
d = np.zeros((N, 3))
d[:, 2] = -1
seg = np.full(N, 1)  # the camera ray to the box
alive = np.arange(N)
lengths = np.zeros(N, int)
while alive.size:
    P, D = p[alive], d[alive]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(D > 0, (0.5 - P) / D, np.where(D < 0, (-0.5 - P) / D, np.inf)).min(axis=1)
    s = -np.log(1 - rng.random(alive.size)) / sigma_t
    seg[alive] += 1
    esc = s >= t
    lengths[alive[esc]] = seg[alive[esc]] + 1  # and the escape to the environment
    col = ~esc
    idx = alive[col]
    p[idx] = P[col] + D[col] * s[col, None]
    u = rng.random(idx.size) * 2 - 1
    phi = rng.random(idx.size) * 2 * np.pi
    r = np.sqrt(1 - u * u)
    d[idx] = np.stack([r * np.cos(phi), r * np.sin(phi), u], 1)
    alive = idx
L = lengths
hit = 0.676
print("mean over hits", L.mean(), "over all pixels", hit * L.mean() + (1 - hit))
for q in [0.5, 0.9, 0.99, 0.999, 0.9999]:
    print("quantile", q, np.quantile(L, q))
print("max", L.max())
s = np.sort(L)[::-1]
c = np.cumsum(s) / s.sum()
for k in [N // 1000, N // 100]:
    print(f"the longest {k} paths hold {c[k - 1]:.3f} of the segments")
