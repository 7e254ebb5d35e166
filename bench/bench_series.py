"""Time series: `map_series` against the same pairs mapped one by one.

    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_series.py            (plain tables)

1. A 10-frame 2D series, 1,000 points per curve (a circle growing three buds, `method="auto"`):
   per step, `map_series`' own seconds (mapping + quality, from its table) and a plain
   `map_curves` call on the same pair, and `quality` on its field; the totals, and `map_series`'
   whole time (carrying the points, the growth maps and re-seeding included).
2. A 5-frame 3D series, 5,120 faces per surface (an icosphere growing a bud), the same with
   `map_surfaces`. Both with `--method` (default "auto"); series times are the best of `--rounds`.
`map_batch` against a sequential loop is bench/bench_batch.py.

Prints what else was running (compilers) so that a loaded machine shows in the numbers.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import time

import numpy as np
import trimesh

import morphomap as mm


def budding_curve(t: float, n: int = 1000) -> np.ndarray:
    """A circle at t = 0 that grows three buds (the shape of tests/test_series.py)."""
    theta = 2 * np.pi * np.arange(n) / n
    bumps = sum(np.exp(-(np.angle(np.exp(1j * (theta - c))) / 0.3) ** 2) for c in (0.3, 2.4, 4.5))
    r = 1 + 0.1 * t + 0.12 * t**2 * bumps
    return np.column_stack([r * np.cos(theta), r * np.sin(theta)])


def budding_surface(t: float, subdivisions: int = 4) -> trimesh.Trimesh:
    """An icosphere (5,120 faces at 4 subdivisions) growing a bud at its north pole."""
    sphere = trimesh.creation.icosphere(subdivisions)
    tip = np.array([0.0, 0.0, 1.0])
    bump = np.exp(-np.sum((sphere.vertices - tip) ** 2, axis=1) / 0.3)
    return trimesh.Trimesh(sphere.vertices * (1 + 0.05 * t + 0.15 * t * bump)[:, None], sphere.faces, process=False)


def busy() -> str:
    """What else is compiling or testing on the machine now."""
    found = subprocess.run(["pgrep", "-c", "cc1plus"], capture_output=True, text=True).stdout.strip() or "0"
    load = os.getloadavg()[0]
    return f"{found} compiler processes, load {load:.1f}"


def best(run, rounds):
    """The smallest wall time of ``rounds`` runs, and the last result."""
    times = []
    for _ in range(rounds):
        start = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - start)
    return min(times), result


def series_table(frames, map_pair, method, label, rounds):
    whole, series = best(lambda: mm.map_series(frames, method, progress=False), rounds)
    steps = [min(q.seconds for q in column) for column in zip(*(mm.map_series(frames, method, progress=False).quality
                                                               for _ in range(rounds)))]
    plain, judged = [], []
    for a, b in zip(frames[:-1], frames[1:]):
        seconds, field = best(lambda: map_pair(a, b, method), rounds)
        plain.append(seconds)
        judged.append(best(lambda: mm.quality(field, a, b), rounds)[0])
    print(f"\n**{label}**, best of {rounds} ({busy()} at the end)\n")
    print("| step | map_series step (map + quality) s | independent map s | + quality s | step / (map + quality) |")
    print("|---:|---:|---:|---:|---:|")
    for k, (step, p, q) in enumerate(zip(steps, plain, judged)):
        print(f"| {k} | {step:.4f} | {p:.4f} | {q:.4f} | {step / (p + q):.2f} |")
    total, maps, checks = sum(steps), sum(plain), sum(judged)
    print(f"| total | {total:.4f} | {maps:.4f} | {checks:.4f} | {total / (maps + checks):.2f} |")
    print(f"\nmap_series whole call {whole:.4f} s = {whole / maps:.2f}x the independent maps, "
          f"{whole / (maps + checks):.2f}x maps + quality; carrying the points, growth maps and re-seeding "
          f"{whole - total:.4f} s; {series!r}")
    return series


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--method", default="auto", help="the series' method, 2D and 3D (default auto)")
    parser.add_argument("--rounds", type=int, default=5, help="series timings: best of this many runs (default 5)")
    parser.add_argument("--skip", default="", help="comma-separated parts to skip: 2d, 3d")
    args = parser.parse_args()
    skip = set(filter(None, args.skip.split(",")))
    print(f"morphomap {mm.__version__}, {os.cpu_count()} cores; {busy()} at the start")
    if "2d" not in skip:
        series_table([budding_curve(0.4 * t) for t in range(10)], mm.map_curves, args.method,
                     f"2D: 10 frames, 1,000 points per curve, {args.method}", args.rounds)
    if "3d" not in skip:
        series_table([budding_surface(t) for t in range(5)], mm.map_surfaces, args.method,
                     f"3D: 5 frames, 5,120 faces per surface, {args.method}", args.rounds)


if __name__ == "__main__":
    main()
