"""Statistical agreement of two Monte Carlo renders of one scene (volpt vs a peer).

Each renderer contributes two independent renders (different seeds): X1, X2 (volpt) and Y1, Y2
(peer). Pixels are independent estimates, so the variance of a block mean of one render is the sum of
its pixels' variances over n^2, and each pixel's variance is estimated without bias by
(X1 - X2)^2 / 2. That gives a variance estimate per block with ~n degrees of freedom (n = pixels in
the block) from the two renders alone.

  d_b    = mean_b((X1 + X2) / 2) - mean_b((Y1 + Y2) / 2)
  var_b  = [sum_b (X1 - X2)^2 + sum_b (Y1 - Y2)^2] / (4 n^2)
  z_b    = d_b / sqrt(var_b)

per block b of BxB pixels and per channel. Under "same expectation" z_b is ~N(0,1): the worst |z|
grows like sqrt(2 ln(#tests)) and about 0.27% of the blocks lie beyond 3. The same construction over
the whole image gives a global z per channel, which is what catches a small uniform bias (a 1% bias
is many global sigmas at the resolutions and sample counts used here; `z_of_1pct_bias` reports how
many, so a run that could not see a 1% bias says so).

Works with numpy when it is importable and falls back to plain Python lists otherwise (the device
machine's venv may have no numpy); both give the same numbers.
"""

import math

try:
    import numpy as np
except ImportError:  # pragma: no cover - exercised on machines without numpy
    np = None


def _verdict(worst_z, frac3, global_z, n_tests, z_1pct):
    # Bonferroni-style bound for the worst block: P(max |z| > t) <= n * P(|z| > t) = 1e-3.
    t = _normal_isf(0.5e-3 / max(n_tests, 1))
    checks = {
        "worst_block_z_below": round(t, 3),
        "worst_block_ok": worst_z < t,
        "fraction_beyond_3_ok": frac3 <= 0.01,
        "global_ok": max(abs(g) for g in global_z) < 4.0,
        "sensitive_to_1pct_bias": min(z_1pct) >= 5.0,
    }
    checks["agree"] = checks["worst_block_ok"] and checks["fraction_beyond_3_ok"] and checks["global_ok"]
    return checks


def _normal_isf(p):
    """Upper-tail quantile of N(0,1) (bisection on erfc; no scipy)."""
    lo, hi = 0.0, 40.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if 0.5 * math.erfc(mid / math.sqrt(2.0)) > p:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def compare(x1, x2, y1, y2, height, width, block=10):
    """x1, x2, y1, y2: flat row-major H*W*3 float sequences (numpy arrays or lists)."""
    if np is not None:
        return _compare_numpy(*(np.asarray(a, dtype=np.float64).reshape(height, width, 3)
                                for a in (x1, x2, y1, y2)), block)
    return _compare_python(x1, x2, y1, y2, height, width, block)


def _finish(d, var, ref, dx_glob, var_glob, mean_x, mean_y, n_blocks_y, n_blocks_x, block, height, width):
    """d, var, ref (peer block mean): lists of (block, channel) values; the rest per channel."""
    zs = []
    for di, vi, ri in zip(d, var, ref):
        # Blocks without any noise in either renderer (pure background): float32 rounding of the
        # same constant is not a disagreement, so allow a 1e-6 relative floor.
        vi = vi + (1e-6 * abs(ri)) ** 2
        zs.append(di / math.sqrt(vi) if vi > 0 else (0.0 if di == 0 else math.inf))
    absz = [abs(z) for z in zs]
    worst = max(absz) if absz else 0.0
    frac3 = sum(1 for z in absz if z > 3.0) / max(len(absz), 1)
    global_z = [dg / math.sqrt(vg) if vg > 0 else (0.0 if dg == 0 else math.inf)
                for dg, vg in zip(dx_glob, var_glob)]
    z_1pct = [0.01 * abs(my) / math.sqrt(vg) if vg > 0 else math.inf
              for my, vg in zip(mean_y, var_glob)]
    rel = [(mx - my) / my if my != 0 else math.nan for mx, my in zip(mean_x, mean_y)]
    lum = lambda c: 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
    out = {
        "block": block,
        "blocks": [n_blocks_y, n_blocks_x],
        "tests": len(zs),
        "worst_abs_z": worst,
        "fraction_abs_z_above_3": frac3,
        "global_z_rgb": global_z,
        "mean_volpt_rgb": mean_x,
        "mean_peer_rgb": mean_y,
        "relative_mean_difference_rgb": rel,
        "relative_mean_difference": (lum(mean_x) - lum(mean_y)) / lum(mean_y) if lum(mean_y) else math.nan,
        "z_of_1pct_bias": z_1pct,
        "cropped_to": [n_blocks_y * block, n_blocks_x * block],
        "image": [height, width],
    }
    out.update(_verdict(worst, frac3, global_z, len(zs), z_1pct))
    return out


def _compare_numpy(x1, x2, y1, y2, block):
    h, w, _ = x1.shape
    by, bx = h // block, w // block
    crop = lambda a: a[: by * block, : bx * block].reshape(by, block, bx, block, 3)
    n = block * block
    xm, ym = (x1 + x2) * 0.5, (y1 + y2) * 0.5
    d = crop(xm - ym).sum(axis=(1, 3)) / n
    var = (crop((x1 - x2) ** 2).sum(axis=(1, 3)) + crop((y1 - y2) ** 2).sum(axis=(1, 3))) / (4.0 * n * n)
    npx = h * w
    dx_glob = (xm - ym).reshape(-1, 3).sum(axis=0) / npx
    var_glob = (((x1 - x2) ** 2).reshape(-1, 3).sum(axis=0)
                + ((y1 - y2) ** 2).reshape(-1, 3).sum(axis=0)) / (4.0 * npx * npx)
    mean_x = xm.reshape(-1, 3).mean(axis=0)
    mean_y = ym.reshape(-1, 3).mean(axis=0)
    ref = crop(ym).sum(axis=(1, 3)) / n
    return _finish(d.reshape(-1).tolist(), var.reshape(-1).tolist(), ref.reshape(-1).tolist(), dx_glob.tolist(), var_glob.tolist(),
                   mean_x.tolist(), mean_y.tolist(), by, bx, block, h, w)


def _compare_python(x1, x2, y1, y2, h, w, block):
    by, bx = h // block, w // block
    n = block * block
    d = [0.0] * (by * bx * 3)
    var = [0.0] * (by * bx * 3)
    ref = [0.0] * (by * bx * 3)
    dg, vg, sx, sy = [0.0] * 3, [0.0] * 3, [0.0] * 3, [0.0] * 3
    for row in range(h):
        brow = row // block
        for col in range(w):
            bcol = col // block
            inside = brow < by and bcol < bx
            base = (row * w + col) * 3
            for c in range(3):
                a, b, p, q = x1[base + c], x2[base + c], y1[base + c], y2[base + c]
                xm, ym = 0.5 * (a + b), 0.5 * (p + q)
                s = (a - b) ** 2 + (p - q) ** 2
                dg[c] += xm - ym
                vg[c] += s
                sx[c] += xm
                sy[c] += ym
                if inside:
                    k = (brow * bx + bcol) * 3 + c
                    d[k] += xm - ym
                    var[k] += s
                    ref[k] += ym
    npx = h * w
    d = [v / n for v in d]
    var = [v / (4.0 * n * n) for v in var]
    ref = [v / n for v in ref]
    return _finish(d, var, ref, [v / npx for v in dg], [v / (4.0 * npx * npx) for v in vg],
                   [v / npx for v in sx], [v / npx for v in sy], by, bx, block, h, w)
