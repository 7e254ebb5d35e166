#!/usr/bin/env python3
"""LDDMM with a varifold loss (scikit-shapes) on the lung-like pair, beside ``method="optimal"``.

    PYTHONPATH=python /path/to/venv/bin/python bench/bench_lddmm.py

Needs the ``lddmm`` extra (CPU torch and scikit-shapes, in a virtual environment of its own); slow
(minutes on 2 cores), so it is run by hand once and never in CI. S1 of
``morphomap.synthetic.lung.lung_pair(resolution=15.0)`` flows by geodesic shooting of a Gaussian
kernel from momenta on 512 control points (an 8 x 8 x 8 grid around both surfaces), the momenta
found by 2 L-BFGS iterations on the varifold distance to S2 plus the kinetic energy, as in
Deformetrica. The flowed vertices are then put on S2 by closest point and measured as the rows of
bench_even_surfaces.py: QM (QM1), folds, the farthest flowed vertex off S2 before that projection
over S2's size, seconds (one run, the registration and the projection).
"""

from __future__ import annotations

import time

import numpy as np

import morphomap as mm
from morphomap.synthetic.lung import lung_pair

GRID = 8  # control points per axis: 512
KERNEL_SCALE = 0.5  # the deformation kernel's width, in the pair's units (S2 is 2.9 x 1.3 x 3.6)
VARIFOLD_WIDTH = 0.2  # the varifold's radial kernel width (edges are about 0.065 long)
N_STEPS = 5  # time steps of the geodesic shooting
N_ITER = 2  # L-BFGS iterations (each up to 20 evaluations with its line search)
REGULARIZATION = 0.1  # the kinetic energy's weight beside the varifold distance


def flow(v1, f1, v2, f2):
    """S1's vertices flowed onto S2 by LDDMM; torch and scikit-shapes are imported here only."""
    import torch
    import skshapes as sks

    dtype = sks.float_dtype
    source = sks.PolyData(torch.as_tensor(v1, dtype=dtype), triangles=torch.as_tensor(f1))
    target = sks.PolyData(torch.as_tensor(v2, dtype=dtype), triangles=torch.as_tensor(f2))
    both = sks.PolyData(torch.as_tensor(np.vstack([v1, v2]), dtype=dtype))
    source.control_points = both.bounding_grid(N=GRID, offset=0.05)
    registration = sks.Registration(
        model=sks.ExtrinsicDeformation(n_steps=N_STEPS, kernel="gaussian", scale=KERNEL_SCALE,
                                       control_points=True),
        loss=sks.VarifoldLoss(radial_bandwidth=VARIFOLD_WIDTH),
        optimizer=sks.LBFGS(), regularization_weight=REGULARIZATION, n_iter=N_ITER, gpu=False, verbose=1)
    registration.fit(source=source, target=target)
    return registration.morphed_shape_.points.detach().cpu().numpy().astype(np.float64)


def main():
    s1, s2 = lung_pair(resolution=15.0)
    v1, f1 = np.asarray(s1.vertices), np.asarray(s1.faces)
    v2, f2 = np.asarray(s2.vertices), np.asarray(s2.faces)
    start = time.perf_counter()
    flowed = flow(v1, f1, v2, f2)
    on_s2 = mm.SurfaceIndex(v2, f2).closest_points(flowed)
    seconds = time.perf_counter() - start
    field = mm.DisplacementField(v1, on_s2.points, "minimal_distance", f1)
    q = mm.quality(field, s1, s2)
    off = on_s2.distances.max() / np.linalg.norm(s2.extents)
    print("| pair | method | QM (QM1) | folds | farthest end off S2 before projection | s |")
    print("|---|---|---|---:|---:|---:|")
    print(f"| lung-like pair | LDDMM (scikit-shapes, varifold) | {q.qm:.3g} ({q.qm1:.3g}) | {q.folds} | {off:.1e} "
          f"| {seconds:.0f} |", flush=True)


if __name__ == "__main__":
    main()
