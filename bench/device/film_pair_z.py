#!/usr/bin/env python3
"""Channel C of film A against channel C of film B, pixel by pixel: `python3 film_pair_z.py C
A.vfilm B.vfilm`. Each pixel's two values are independent estimates of one expectation where
both renders are unbiased for it (the per-channel identity: a chromatic render's channel C and
the grey render of channel C's coefficients), and pixels are independent of each other (their
own random streams), so the pixels' differences have mean 0 and z = mean / (sd / sqrt(pixels)).
Exits 1 when |z| >= 5; prints the relative standard error (1% bias at 10 sigma needs <= 1e-3)."""
import math
import sys

from film_diff import read


def channel(path, c):
    (_, _, _, _, ranges), sums = read(path)
    spp = sum(b - a for a, b in ranges)
    return [s / spp for s in sums[c::3]]


def main():
    c, a, b = int(sys.argv[1]), channel(sys.argv[2], int(sys.argv[1])), channel(sys.argv[3], int(sys.argv[1]))
    if len(a) != len(b):
        sys.exit("films of different sizes")
    d = [x - y for x, y in zip(a, b)]
    n = len(d)
    mean = sum(d) / n
    se = math.sqrt(sum((x - mean) ** 2 for x in d) / (n - 1) / n)
    level = sum(b) / n
    z = mean / se if se > 0 else 0.0
    print(f"channel {c}: A {sum(a) / n:.6f} B {level:.6f} difference {mean / level:+.4%} "
          f"(z {z:+.2f}, relative se {se / level:.2e}, {n} pixels)")
    sys.exit(0 if abs(z) < 5 else 1)


if __name__ == "__main__":
    main()
