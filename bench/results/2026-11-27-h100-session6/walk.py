"""The index-matched cube's walks with and without roulette of negligible weights (issue 25).

    python3 walk.py N EPS...   # N paths that hit the cube (numpy), one run per EPS (0: no roulette)

As `../2026-11-25-h100-tail/walk.py` (a unit cube of sigma_t 100 seen head-on, paths entering the
front face heading -z, isotropic scattering, no roulette), plus the albedo 0.9 as a throughput
weight and `volpt_core::path::NEGLIGIBLE_WEIGHT`'s rule: after a collision a path whose throughput
is below EPS survives with probability throughput / EPS and then carries EPS. Prints the segments
per path (as the renderer counts them: camera ray, free flights, escape), their largest value,
and the mean and variance of what a path returns (the environment's radiance 1 times the
throughput at its escape). Every run draws the same random numbers for the walk; roulette draws
from its own generator, so the runs differ only where roulette acts.
"""
import sys

import numpy as np

N = int(sys.argv[1])
SIGMA_T, ALBEDO = 100.0, 0.9
for eps in map(float, sys.argv[2:]):
    rng, rr = np.random.default_rng(1), np.random.default_rng(2)
    p = np.zeros((N, 3))
    p[:, 0] = rng.uniform(-0.5, 0.5, N)
    p[:, 1] = rng.uniform(-0.5, 0.5, N)
    p[:, 2] = 0.5
    d = np.zeros((N, 3))
    d[:, 2] = -1
    throughput = np.ones(N)
    seg = np.full(N, 1)  # the camera ray to the box
    lengths = np.zeros(N, int)
    light = np.zeros(N)
    alive = np.arange(N)
    while alive.size:
        P, D = p[alive], d[alive]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(D > 0, (0.5 - P) / D, np.where(D < 0, (-0.5 - P) / D, np.inf)).min(axis=1)
        s = -np.log(1 - rng.random(alive.size)) / SIGMA_T
        seg[alive] += 1
        esc = s >= t
        lengths[alive[esc]] = seg[alive[esc]] + 1  # and the escape to the environment
        light[alive[esc]] = throughput[alive[esc]]
        col = ~esc
        idx = alive[col]
        p[idx] = P[col] + D[col] * s[col, None]
        u = rng.random(idx.size) * 2 - 1
        phi = rng.random(idx.size) * 2 * np.pi
        r = np.sqrt(1 - u * u)
        d[idx] = np.stack([r * np.cos(phi), r * np.sin(phi), u], 1)
        throughput[idx] *= ALBEDO
        low = throughput[idx] < eps
        q = np.where(low, throughput[idx] / max(eps, 1e-300), 1.0)
        dies = rr.random(idx.size) >= q
        throughput[idx] = np.where(low, eps, throughput[idx])
        lengths[idx[dies]] = seg[idx[dies]]
        alive = idx[~dies]
    print(
        f"EPS {eps:.6g}: segments per path {lengths.mean():.2f}, max {lengths.max()}, "
        f"99th percentile {np.quantile(lengths, 0.99):.0f}; light per path mean {light.mean():.10f}, "
        f"variance {light.var():.10f}"
    )
