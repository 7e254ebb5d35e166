"""How map_curves scales with the number of points: 10^2 .. 10^6 points per curve.

    PYTHONPATH=build/dev-NAME/pkg python3 -m pytest bench -k map_curves     (pytest-benchmark)
    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_map_curves.py         (a plain table)
    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_map_curves.py --max 100000

Cases: a circle (radius 0.95) onto the concentric ellipse with semi-axes 2.177 and 1, n points each
(the paper's Table 1 shape; the curves do not meet), and two crossing ellipses (2 x 1 and 1 x 2,
four intersections, split=True) at a few sizes. The script prints the best time of each method and
time / (n log2 n), normalised to its value at the smallest n: a column that stays flat or falls
means growth like n log n or better.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import time

import numpy as np
import pytest

import morphomap as mm

METHODS = ("minimal_distance", "normal", "uniform")
SIZES = (10**2, 10**3, 10**4, 10**5, 10**6)
CROSSING_SIZES = (10**3, 10**5)


def ellipse(n, a, b):
    t = 2 * np.pi * np.arange(n) / n
    return np.column_stack([a * np.cos(t), b * np.sin(t)])


def nested(n):
    """Circle inside a concentric ellipse, n points each; no crossings."""
    return ellipse(n, 0.95, 0.95), ellipse(n, 2.177, 1.0)


def crossing(n):
    """Two ellipses crossing at four points, n points each."""
    return ellipse(n, 2.0, 1.0), ellipse(n, 1.0, 2.0)


def _rounds(n):
    return 10 if n <= 10**4 else (5 if n <= 10**5 else 3)


@pytest.mark.parametrize("n", SIZES, ids=lambda n: f"n1e{round(math.log10(n))}")
@pytest.mark.parametrize("method", METHODS)
def test_map_curves_nested(benchmark, method, n):
    c1, c2 = nested(n)
    benchmark.group = f"map_curves nested n=1e{round(math.log10(n))}"
    benchmark.extra_info.update(points=n, method=method)
    field = benchmark.pedantic(mm.map_curves, args=(c1, c2, method), rounds=_rounds(n), iterations=1,
                               warmup_rounds=1)
    assert len(field) == n and field.valid.all()


@pytest.mark.parametrize("n", CROSSING_SIZES, ids=lambda n: f"n1e{round(math.log10(n))}")
@pytest.mark.parametrize("method", METHODS)
def test_map_curves_crossing_split(benchmark, method, n):
    c1, c2 = crossing(n)
    benchmark.group = f"map_curves crossing split n=1e{round(math.log10(n))}"
    benchmark.extra_info.update(points=n, method=method)
    field = benchmark.pedantic(mm.map_curves, args=(c1, c2, method), kwargs={"split": True},
                               rounds=_rounds(n), iterations=1, warmup_rounds=1)
    assert len(field) == n + 4


def best_time(c1, c2, method, repeats, **kwargs):
    mm.map_curves(c1, c2, method, **kwargs)  # warm-up
    best = math.inf
    for _ in range(repeats):
        tick = time.perf_counter()
        mm.map_curves(c1, c2, method, **kwargs)
        best = min(best, time.perf_counter() - tick)
    return best


def _wait_for_compilers():
    while subprocess.run(["pgrep", "cc1plus"], capture_output=True).returncode == 0:
        print("waiting: a compiler (cc1plus) is running", flush=True)
        time.sleep(15)


def table(title, make, sizes, split):
    print(f"\n{title}")
    head = f"{'n':>9}" + "".join(f"{m + ' s':>20}" for m in METHODS) + "".join(
        f"{m[:10] + ' /nlogn':>18}" for m in METHODS)
    print(head)
    print("-" * len(head))
    first = {}
    for n in sizes:
        c1, c2 = make(n)
        times = {m: best_time(c1, c2, m, 1 if n >= 10**6 else 3, split=split) for m in METHODS}
        cost = n * math.log2(n)
        for m in METHODS:
            first.setdefault(m, times[m] / cost)
        line = f"{n:>9}" + "".join(f"{times[m]:>20.4g}" for m in METHODS)
        line += "".join(f"{times[m] / cost / first[m]:>18.3f}" for m in METHODS)
        print(line, flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max", type=int, default=10**6, help="largest n (default 10^6)")
    args = parser.parse_args()
    _wait_for_compilers()
    info = mm.build_info()
    print(f"morphomap {info['version']}, {info['threads']} threads, {os.cpu_count()} cores; best of 3 (1 at 10^6)")
    table("circle (r 0.95) onto concentric ellipse (2.177 x 1), n points each, no crossings", nested,
          [n for n in SIZES if n <= args.max], split=True)
    table("crossing ellipses (2 x 1 onto 1 x 2), four intersections, split=True", crossing,
          [n for n in (10**3, 10**4, 10**5) if n <= args.max], split=True)


if __name__ == "__main__":
    main()
