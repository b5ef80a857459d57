#!/usr/bin/env python3
"""Simulates the batch schedule of several GPUs (`volpt/src/multi.rs`) and prints how close each
rule comes to the ideal render time (every device busy until the same moment).

    python3 bench/multigpu/schedule_sim.py

Model: a device that takes a batch of b samples is busy for b * seconds_per_sample + tail, where
the tail is what every launch pays waiting for its longest path (measured on two H100s,
2026-11-26, bench/results/2026-11-26-h100x2-batches: about 25 ms on `ad`, 4 ms on `smoke`); the
device free first takes the next batch. A rule is (smallest batch as a fraction of a device's
share, the divisor d of batch = remaining / (d * devices)).
"""


def schedule(samples, seconds_per_sample, tail, smallest_fraction, divisor):
    """Fraction of the ideal time (1.0 = ideal) and the number of batches."""
    n = len(seconds_per_sample)
    smallest = max(1, -(-samples // (smallest_fraction * n)))
    taken, busy, batches = 0, [0.0] * n, 0
    while taken < samples:
        device = min(range(n), key=lambda i: busy[i])
        remaining = samples - taken
        size = min(max(int(remaining / (divisor * n)), 1, smallest), remaining)
        taken += size
        batches += 1
        busy[device] += size * seconds_per_sample[device] + tail
    ideal = samples / sum(1 / s for s in seconds_per_sample)
    return ideal / max(busy), batches


RULES = [(32, 2.0), (16, 2.0), (32, 1.5), (16, 1.5)]
CASES = [
    ("ad, 2 alike", [4.05e-3] * 2, 0.025),
    ("ad, one 2x faster", [4.05e-3, 2.02e-3], 0.025),
    ("smoke, 2 alike", [1.06e-3] * 2, 0.004),
    ("smoke, one 2x faster", [1.06e-3, 0.53e-3], 0.004),
    ("ad, 4 alike", [4.05e-3] * 4, 0.025),
    ("ad, 8 alike", [4.05e-3] * 8, 0.025),
]

if __name__ == "__main__":
    print("case".ljust(22) + "".join(f"1/{f} d={d}".rjust(14) for f, d in RULES))
    for name, speeds, tail in CASES:
        cells = []
        for f, d in RULES:
            frac, batches = schedule(2048, speeds, tail, f, d)
            cells.append(f"{frac:.3f} ({batches})".rjust(14))
        print(name.ljust(22) + "".join(cells))
