#!/usr/bin/env python3
"""Growth kinematics (``mm.growth``) against the mapping it is computed from.

    PYTHONPATH=python python3 bench/bench_growth.py

Per series: ``map_series`` (the mapping, carrying and re-seeding of every step) and then
``mm.growth(series)`` (per step and accumulated, every element), each timed once (best of 3 for
growth); and the limb bud's accumulated values at the last frame by part of the outline.
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np

import morphomap as mm
from morphomap.examples.growing_frames import frames, surfaces

LIMB = Path(__file__).resolve().parents[2] / "shared" / "cases" / "limb-bud" / "2d"


def row(name, shapes, dt=1.0):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        series = mm.map_series(shapes, dt=dt)
        mapping = time.perf_counter() - start
    best = np.inf
    for _ in range(3):
        start = time.perf_counter()
        found = mm.growth(series)
        best = min(best, time.perf_counter() - start)
    elements = sum(len(g.cells) for g in found.steps)
    print(f"| {name} | {len(series.fields)} | {elements:,} | {mapping:.2f} | {best:.3f} | {best / mapping:.1%} |",
          flush=True)
    return series, found


def limb_parts(series, found):
    k = len(series.fields) - 1
    last = found.accumulated[k]
    centre = series.trajectories[k + 1][series.cells[k]].mean(axis=1)
    reach = np.nanmax(series.trajectories[-1][:, 0])
    print("\n| part of the limb outline at 381 h | pieces | median accumulated length ratio | median rate (ln/h) "
          "| median normal velocity (units/h) |")
    print("|---|---:|---:|---:|---:|")
    for name, inside in (("distal (x > 0.8 of the reach)", centre[:, 0] > 0.8 * reach),
                         ("middle (0.3-0.6)", (centre[:, 0] > 0.3 * reach) & (centre[:, 0] < 0.6 * reach)),
                         ("flank (x < 0.05)", centre[:, 0] < 0.05 * reach)):
        medians = [np.nanmedian(values[inside]) for values in
                   (last.areal_growth, last.areal_growth_rate, last.normal_velocity)]
        print(f"| {name} | {int(inside.sum())} | {medians[0]:.3f} | {medians[1]:.4f} | {medians[2]:.3f} |")


if __name__ == "__main__":
    print("| series | steps | elements (all steps) | map_series s | growth s | growth / mapping |")
    print("|---|---:|---:|---:|---:|---:|")
    row("budding outline, 400 points, 12 frames", frames(12))
    row("budding sphere, 1,280 triangles, 12 frames", surfaces(12, 3))
    row("budding sphere, 20,480 triangles, 6 frames", surfaces(6, 5))
    if LIMB.exists():
        limb = row("limb bud 248-381 h, hourly", [mm.read_curve(LIMB / f"limb_h{h}.csv") for h in range(248, 382)])
        limb_parts(*limb)
