"""A synthetic branching lung-like pair of closed surfaces (deterministic; no randomness).

    from morphomap.synthetic.lung import lung_pair
    s1, s2 = lung_pair()          # two trimesh.Trimesh, S1 strictly inside S2

Both surfaces are level sets of implicit functions built from capsules (the distance to a segment
minus a radius), sampled on a regular grid and meshed with marching cubes (scikit-image).

S1 (time t): a trunk tube that splits into two daughter tubes (a plain union, so the crotch
    between the daughters is a sharp concave crease).
S2 (time t + dt): S1's function smoothly unioned with the growth -- each daughter continues
    further and buds a short new branch out of the plane of the first split -- then dilated by
    ``DILATION``. The smooth union never exceeds either argument, so S2's function is at most
    S1's minus ``DILATION``: S1 lies strictly inside S2, at least ``DILATION`` from it (up to the
    marching-cubes error, far smaller than ``DILATION`` at the default resolution).

Normal mapping folds on this pair: the normals of S1 on the two sides of the concave crotch, and
of the saddles between the trunk and the daughters, cross before they reach S2.
"""

from __future__ import annotations

import numpy as np
import trimesh
from skimage.measure import marching_cubes

#: Capsules (start, end, radius) of S1: the trunk and the two daughters.
S1_CAPSULES = (
    ((0.0, 0.0, -1.6), (0.0, 0.0, 0.0), 0.32),
    ((0.0, 0.0, 0.0), (0.85, 0.0, 0.75), 0.26),
    ((0.0, 0.0, 0.0), (-0.80, 0.0, 0.80), 0.26),
)
#: The growth between t and t + dt, as capsules (start, direction, radius) that end at
#: ``start + growth * direction``: the daughters grow on and each buds a side branch out of the
#: plane of the first split.
GROWTH_CAPSULES = (
    ((0.85, 0.0, 0.75), (0.50, 0.0, 0.65), 0.26),
    ((-0.80, 0.0, 0.80), (-0.45, 0.0, 0.70), 0.26),
    ((0.60, 0.0, 0.53), (0.20, 0.60, 0.22), 0.20),
    ((-0.55, 0.0, 0.55), (-0.15, -0.55, 0.30), 0.20),
)
#: Blend radius of the smooth union of S1 with the growth.
BLEND = 0.15
#: How far S2 lies outside S1 at least.
DILATION = 0.10
#: A node of the sampling grid.
GRID_ORIGIN = np.array([0.0137, 0.0291, 0.0073])


def capsule(points: np.ndarray, start, end, radius: float) -> np.ndarray:
    """Signed distance from each of ``points`` (..., 3) to the capsule around segment start-end."""
    a, b = np.asarray(start, float), np.asarray(end, float)
    d = b - a
    t = np.clip(((points - a) @ d) / (d @ d), 0.0, 1.0)
    return np.linalg.norm(points - a - t[..., None] * d, axis=-1) - radius


def smooth_min(a: np.ndarray, b: np.ndarray, k: float) -> np.ndarray:
    """Polynomial smooth minimum: equal to min(a, b) where |a - b| >= k, below it (by at most
    k / 4) in between; never above min(a, b)."""
    h = np.clip(0.5 + 0.5 * (b - a) / k, 0.0, 1.0)
    return b + (a - b) * h - k * h * (1.0 - h)


def s1_function(points: np.ndarray) -> np.ndarray:
    """Implicit function of S1 (negative inside): the union of its capsules."""
    return np.minimum.reduce([capsule(points, *c) for c in S1_CAPSULES])


def growth_capsules(growth: float):
    """The capsules (start, end, radius) of the growth, scaled by ``growth``."""
    return tuple((a, tuple(np.add(a, growth * np.asarray(d))), r) for a, d, r in GROWTH_CAPSULES)


def s2_function(points: np.ndarray, growth: float = 0.6) -> np.ndarray:
    """Implicit function of S2: S1's smoothly unioned with the growth, minus ``DILATION``."""
    new = np.minimum.reduce([capsule(points, *c) for c in growth_capsules(growth)])
    return smooth_min(s1_function(points), new, BLEND) - DILATION


def mesh_level_set(function, step: float, low, high):
    """Mesh the zero level set of ``function`` in the box [low, high] with cells of size ``step``.

    Returns a closed, consistently outward-oriented ``trimesh.Trimesh`` without degenerate faces.
    """
    # Grid nodes at GRID_ORIGIN + step * integers: the same nodes whatever the box, and off the
    # axes and end points of the capsules.
    low = GRID_ORIGIN + step * np.floor((np.asarray(low, float) - GRID_ORIGIN) / step - 2)
    high = np.asarray(high, float) + 2 * step
    counts = np.ceil((high - low) / step).astype(int) + 1
    axes = [low[k] + step * np.arange(counts[k]) for k in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
    values = function(grid)
    # Keep samples off the level: every vertex then lies at least ~10% of a cell from the grid
    # nodes, so no triangle collapses to a point.
    values = np.where(np.abs(values) < 0.1 * step, np.where(values < 0, -0.1, 0.1) * step, values)
    vertices, faces, _, _ = marching_cubes(values.astype(np.float64), level=0.0, spacing=(step,) * 3,
                                           allow_degenerate=False)
    mesh = trimesh.Trimesh(vertices.astype(np.float64) + low, faces.astype(np.int64), process=True)
    mesh.update_faces(mesh.nondegenerate_faces())
    mesh.update_faces(mesh.unique_faces())
    mesh.remove_unreferenced_vertices()
    if mesh.volume < 0:
        mesh.invert()
    return mesh


def lung_pair(resolution: float = 10.0, growth: float = 0.6):
    """The lung-like pair ``(s1, s2)``: two closed ``trimesh.Trimesh``, S1 strictly inside S2.

    resolution : float
        Grid cells per unit length (the trunk of S1 has radius 0.32; the pair spans about
        3 x 1.3 x 3.6 units). The default gives 2200 faces on S1 and about 4100 on S2.
    growth : float
        Scales how far the daughters grow on and the buds grow out between t and t + dt: the
        tips move by ``growth`` times about 3.2 tube radii (a bud's measured from the daughter's
        axis). From about 0.85 on, the sides of the buds face more than 90 degrees away from the
        patches of S1 they grow from.
    """
    resolution, growth = float(resolution), float(growth)
    if not np.isfinite(resolution) or resolution < 4:
        raise ValueError(f"resolution: must be a finite number >= 4, got {resolution}")
    if not np.isfinite(growth) or growth < 0:
        raise ValueError(f"growth: must be a finite number >= 0, got {growth}")
    step = 1.0 / resolution
    ends = np.array([p for c in S1_CAPSULES + growth_capsules(growth) for p in c[:2]])
    pad = 0.32 + DILATION + BLEND
    low, high = ends.min(axis=0) - pad, ends.max(axis=0) + pad
    s2 = mesh_level_set(lambda points: s2_function(points, growth), step, low, high)
    return mesh_level_set(s1_function, step, low, high), s2
