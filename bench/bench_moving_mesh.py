#!/usr/bin/env python3
"""One solver mesh carried through a series (``Series.extend``), and the default extension on real
limb outlines.

    PYTHONPATH=python python3 bench/bench_moving_mesh.py [series|limb]

series: the budding frames of ``morphomap.examples.growing_frames`` (12 frames, 2D and 3D) and
the limb bud's hourly outlines 300 h to 330 h (``../shared/cases``): ``map_series`` then
``Series.extend()``, per series the mesh, the farthest the mesh's boundary nodes lay from the
frame a step started on, the smallest angle of the last mesh, inverted cells, the extension's
time; each once as shipped and once with the boundary nodes left at the field's ends (no move
onto frame k + 1), to show what that move is for.

limb: ``extend_field(map_curves(c1, c2))`` with its defaults on every hourly pair 248 h to 381 h
and every 10-hour pair: how many leave no inverted cell, and for the others where the cells lie
and whether their corners are all on C1.
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

import morphomap as mm
import morphomap.moving_mesh as moving_mesh
from morphomap.examples.growing_frames import frames, surfaces
from morphomap.extend import measure_ratios

LIMB = Path(__file__).resolve().parents[2] / "shared" / "cases" / "limb-bud" / "2d"


def limb(hour):
    return mm.read_curve(LIMB / f"limb_h{hour}.csv")


def series_row(name, shapes, snap=True):
    onto = moving_mesh._onto
    if not snap:
        moving_mesh._onto = lambda step, frame, nodes: step
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            series = mm.map_series(shapes, reseed=None)
        start = time.perf_counter()
        try:
            moving = series.extend()
        except (ValueError, mm.GeometryError) as error:
            return f"| {name} | {'yes' if snap else 'no'} | refused: {str(error)[:90]}... | | | | |"
        seconds = time.perf_counter() - start
    finally:
        moving_mesh._onto = onto
    q = moving.quality
    return (f"| {name} | {'yes' if snap else 'no'} | {len(moving.steps)} steps, {len(moving.points(0))} nodes, "
            f"{len(moving.cells)} cells | {max(r.boundary_distance for r in q):.3g} | {q[-1].min_angle:.3g} | "
            f"{sum(r.inverted for r in q)} | {seconds:.2f} |")


def run_series():
    print("| series | ends onto frame k + 1 | mesh | farthest boundary node from its frame | smallest angle, "
          "last mesh (deg) | inverted | extend s |")
    print("|---|---|---|---|---|---|---|")
    cases = [("budding outline, 12 frames", frames(12)), ("budding sphere, 12 frames", surfaces(12))]
    if LIMB.exists():
        cases.append(("limb bud 300-330 h hourly", [limb(h) for h in range(300, 331)]))
    for name, shapes in cases:
        for snap in (True, False):
            print(series_row(name, shapes, snap), flush=True)


def run_limb():
    if not LIMB.exists():
        sys.exit(f"the limb-bud cases are not at {LIMB}")
    for step in (1, 10):
        cleared, refused = 0, []
        for hour in range(248, 382 - step, step):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                c1, c2 = (mm.make_simple(limb(h))[0] for h in (hour, hour + step))
                field = mm.map_curves(c1, c2)
            try:
                mm.extend_field(field)
                cleared += 1
            except mm.GeometryError:
                solved = mm.extend_field(field, substeps=1, untangle=False)
                ratios = measure_ratios(solved.points, solved.cells, solved.displacement)
                bad = np.flatnonzero(ratios <= 0)
                on_c1 = np.zeros(len(solved.points), dtype=bool)
                on_c1[moving_mesh.boundary_nodes(solved.cells)] = True
                centre = solved.points[solved.cells[bad]].mean(axis=1)
                refused.append(f"{hour}->{hour + step}: {len(bad)} cells (all corners on C1: "
                               f"{int(on_c1[solved.cells[bad]].all(axis=1).sum())}, smallest ratio {ratios.min():.2g}, "
                               f"x from {centre[:, 0].min():.3g} to {centre[:, 0].max():.3g})")
        print(f"{step}-hour pairs: {cleared} of {cleared + len(refused)} extended with no inverted cell")
        for line in refused:
            print("   refused " + line)


if __name__ == "__main__":
    modes = sys.argv[1:] or ["series", "limb"]
    for mode in modes:
        {"series": run_series, "limb": run_limb}[mode]()
