#!/usr/bin/env python3
"""3D ``method="optimal"`` (auto's field evened along S2) beside ``auto`` and ``diffusion``.

    PYTHONPATH=python python3 bench/bench_even_surfaces.py

Pairs: the lung-like pair (``morphomap.synthetic.lung.lung_pair(resolution=15.0)``), the paper's
Figure 12 sphere onto an ellipsoid around it, concentric spheres, and the limb-bud stages
(``../shared/cases/limb-bud/3d``, remeshed to edges of 30 units). Per method: QM (QM1), folds,
the farthest end from S2 over S2's size, seconds (one run). Beside them trimesh's non-rigid ICP
(``trimesh.registration.nricp_amberg`` and ``nricp_sumner``, needs rtree), whose ends do not lie on
S2: they are put on S2 by closest point before the quality is measured, and the column gives how
far they were.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import trimesh
import trimesh.registration

import morphomap as mm
from morphomap.synthetic.lung import lung_pair

LIMB = Path(__file__).resolve().parents[2] / "shared" / "cases" / "limb-bud" / "3d"


def pairs():
    yield "lung-like pair", lung_pair(resolution=15.0)
    sphere = trimesh.creation.icosphere(3)
    ellipsoid = sphere.copy()
    ellipsoid.vertices = ellipsoid.vertices * [1.6, 1.2, 1.1]
    yield "Figure 12: sphere onto ellipsoid", (sphere, ellipsoid)
    yield "concentric spheres (r 1, 2)", (sphere, sphere.copy().apply_scale(2.0))
    if LIMB.exists():
        for a, b in (("250", "270"), ("270", "290"), ("290", "270")):
            yield f"limb {a} h -> {b} h, remeshed 30", tuple(
                mm.remesh_surface(mm.read_surface(LIMB / f"limb_{h}h_closed.ply"), 30.0) for h in (a, b))


def main():
    print("| pair | method | QM (QM1) | folds | farthest end off S2 | s |")
    print("|---|---|---|---:|---:|---:|")
    for name, (s1, s2) in pairs():
        index = mm.SurfaceIndex(np.asarray(s2.vertices), np.asarray(s2.faces))
        for method in ("auto", "diffusion", "optimal"):
            start = time.perf_counter()
            try:
                field = mm.map_surfaces(s1, s2, method)
            except (mm.GeometryError, ValueError) as error:
                print(f"| {name} | {method} | refused: {str(error)[:80]}... | | | |", flush=True)
                continue
            seconds = time.perf_counter() - start
            row(name, method, field, s1, s2, index, seconds)
        for peer in ("nricp_amberg", "nricp_sumner"):
            start = time.perf_counter()
            ends = np.asarray(getattr(trimesh.registration, peer)(s1, s2))
            seconds = time.perf_counter() - start
            hits = index.closest_points(ends)
            field = mm.DisplacementField(np.asarray(s1.vertices), hits.points, "minimal_distance",
                                         np.asarray(s1.faces))
            row(name, f"trimesh {peer}", field, s1, s2, index, seconds, off=hits.distances.max())


def row(name, method, field, s1, s2, index, seconds, off=None):
    q = mm.quality(field, s1, s2)
    if off is None:
        off = index.closest_points(field.ends[field.valid]).distances.max()
    off /= np.linalg.norm(s2.extents)
    print(f"| {name} | {method} | {q.qm:.3g} ({q.qm1:.3g}) | {q.folds} | {off:.1e} | {seconds:.2f} |", flush=True)


if __name__ == "__main__":
    main()
