#!/usr/bin/env python3
"""The per-channel identity of a chromatic render, on films of independent seeds:
`python3 chromatic_channel.py C CHROMATIC.vfilm... -- GREY.vfilm...` compares channel C's image
mean of the chromatic films with the grey films' (the grey medium of channel C's coefficients) by
Welch's z over the films (each film one independent estimate). Exits 1 when |z| >= 5, and prints
the relative standard error of the difference (1% bias at 10 sigma needs it <= 0.1%)."""
import math
import sys

from film_diff import read


def channel_mean(path, c):
    (_, width, height, _, ranges), sums = read(path)
    spp = sum(b - a for a, b in ranges)
    return sum(sums[c::3]) / (width * height * spp)


def moments(xs):
    n = len(xs)
    mean = sum(xs) / n
    var = sum((x - mean) ** 2 for x in xs) / (n - 1)
    return mean, var / n


def main():
    c = int(sys.argv[1])
    split = sys.argv.index("--")
    chromatic = [channel_mean(p, c) for p in sys.argv[2:split]]
    grey = [channel_mean(p, c) for p in sys.argv[split + 1 :]]
    (ma, va), (mb, vb) = moments(chromatic), moments(grey)
    se = math.sqrt(va + vb)
    z = (ma - mb) / se if se > 0 else float("inf")
    print(f"channel {c}: chromatic {ma:.6f} grey {mb:.6f} z {z:.2f} relative se {se / mb:.2e}")
    sys.exit(0 if abs(z) < 5 else 1)


main()
