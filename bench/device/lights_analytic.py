#!/usr/bin/env python3
"""scenes/lights/sun-slab.xml's film against its closed-form radiance (bench/device/lights.sh):

    python3 lights_analytic.py FILM.vfilm SPP

Every pixel of that scene (orthographic rays straight up through a slab wider than any light path,
a delta sun 40 degrees from the zenith, one scattering event) is an independent mean of SPP paths
of the single-scattering radiance
    L = sigma_s p_HG(cos 40) E exp(-sigma_t d / cos 40) (1 - exp(-k d)) / k,  k = sigma_t (1 - 1 / cos 40).
Exits 1 unless the pixels' mean lies within 5 standard errors and 2% of L (volpt/tests/lights.rs
checks the same on the CPU)."""
import math
import sys

from film_diff import read


def expected():
    sigma_t, albedo, g, d, irradiance = 1.5, 0.8, 0.4, 1.0, 2.0
    mu = math.cos(math.radians(40.0))
    hg = (1 - g * g) / (4 * math.pi * (1 + g * g - 2 * g * mu) ** 1.5)
    k = sigma_t * (1 - 1 / mu)
    return sigma_t * albedo * hg * irradiance * math.exp(-sigma_t * d / mu) * (1 - math.exp(-k * d)) / k


def main():
    (_, width, height, _, _), sums = read(sys.argv[1])
    spp = int(sys.argv[2])
    values = [sums[3 * i] / spp for i in range(width * height)]
    n = len(values)
    mean = sum(values) / n
    se = math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1) / n)
    want = expected()
    z = (mean - want) / se
    ok = abs(z) <= 5 and abs(mean - want) <= 0.02 * want
    print(f"mean {mean:.6f} +- {se:.6f} over {n} pixels of {spp} spp, expected {want:.6f}, z {z:+.2f}")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
