"""Make the bundled example curves (deterministic; no randomness).

    python -m morphomap.synthetic.examples          (from a source checkout)

writes NAME_c1.csv and NAME_c2.csv into morphomap/data for NAME in morphomap.io.EXAMPLES, and checks
that every curve is simple and counter-clockwise.

circle_ellipse -- the paper's Table 1 case: C1 the circle of radius 0.95 about the origin, 100
    points from angle 0 equally spaced in angle; C2 the concentric ellipse with semi-axes 2.177 and 1,
    100 points equally spaced in arc length from angle 0 (a spline through 2000 points equally
    spaced in the parameter angle, resampled).
kidney -- a synthetic branching organ in polar form r(t), t the polar angle. C1: a blob with three
    shallow buds and clefts between them. C2 (later): two buds have grown, one of them has split in
    two; the third bud has flattened, so C2 runs inside C1 there and the curves cross; a new wide
    bud has grown over a cleft of C1, so the normals of C1 in that concave region meet beyond their
    centre of curvature and plain normal mapping gives crossing vectors.
"""

from __future__ import annotations

import pathlib

import numpy as np

import morphomap as mm
from morphomap.io import write_curve

DATA = pathlib.Path(__file__).resolve().parent.parent / "data"


def bump(t, centre, height, width):
    """A smooth periodic bump of the given height about the angle ``centre`` (``width`` in rad)."""
    return height * np.exp((np.cos(t - centre) - 1) / width**2)


def polar(r_of_t, n_dense=4000):
    t = 2 * np.pi * np.arange(n_dense) / n_dense
    r = r_of_t(t)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def kidney_c1(t):
    buds = bump(t, 0.35, 0.40, 0.16) + bump(t, 2.20, 0.36, 0.15) + bump(t, 4.25, 0.42, 0.15)
    clefts = bump(t, 1.30, 0.22, 0.12) + bump(t, 3.20, 0.26, 0.12) + bump(t, 5.35, 0.16, 0.15)
    return 1.0 + buds - clefts


def kidney_c2(t):
    # The bud at 0.35 has grown and split in two tips; the one at 2.20 has grown.
    branching = bump(t, 0.35, 0.70, 0.20) + bump(t, 0.12, 0.55, 0.075) + bump(t, 0.58, 0.50, 0.075)
    grown = bump(t, 2.15, 0.95, 0.15)
    new_bud = bump(t, 3.20, 0.60, 0.17)  # a new bud over the cleft of C1 at 3.20
    flattened = bump(t, 4.25, 0.10, 0.25)  # C2 runs inside C1 across its bud at 4.25
    clefts = bump(t, 1.30, 0.36, 0.10) + bump(t, 5.35, 0.10, 0.20)  # deeper than C1 at 1.30
    return 1.12 + branching + grown + new_bud + flattened - clefts


def examples():
    angles = 2 * np.pi * np.arange(100) / 100
    circle = 0.95 * np.column_stack([np.cos(angles), np.sin(angles)])
    dense = 2 * np.pi * np.arange(2000) / 2000
    ellipse = np.column_stack([2.177 * np.cos(dense), np.sin(dense)])
    yield "circle_ellipse", circle, mm.resample(ellipse, 100, method="spline")
    yield ("kidney", mm.resample(polar(kidney_c1), 400, method="spline"),
           mm.resample(polar(kidney_c2), 560, method="spline"))


def main():
    for name, c1, c2 in examples():
        for curve, points in (("c1", c1), ("c2", c2)):
            assert not mm.is_self_intersecting(points), (name, curve)
            assert mm.orientation(points) == 1, (name, curve)
            write_curve(DATA / f"{name}_{curve}.csv", points)
        crossings = len(mm.curve_intersections(c1, c2))
        print(f"{name}: C1 {len(c1)} points, C2 {len(c2)} points, the curves cross at {crossings} points")


if __name__ == "__main__":
    main()
