"""Segmented frames the way a lab has them: binary masks on pixel and voxel grids (deterministic).

    from morphomap.synthetic.masks import kidney_masks, ellipsoid_stacks, lung_stacks
    mask1, mask2, spacing = kidney_masks()       # 2D, (rows, columns), spacing (sy, sx) in um
    stack1, stack2, spacing = lung_stacks()      # 3D, [z, y, x], spacing (sz, sy, sx) in um

Made here from shapes the package already has, so that the wheel carries no image files:

- ``kidney_masks``: the bundled kidney pair (``load_example("kidney")``) scaled to microns and
  filled on a pixel grid (pixel centres inside the curve).
- ``ellipsoid_stacks``: the paper's Figure 12 case, a sphere onto the ellipsoid with semi-axes
  2 : 1.5 : 1.2, at 10 um per unit, in an anisotropic confocal-like stack.
- ``lung_stacks``: the branching lung-like pair of :mod:`morphomap.synthetic.lung` (its implicit
  functions), voxelised.
"""

from __future__ import annotations

import numpy as np
from skimage.draw import polygon

from ..io import load_example
from .lung import s1_function, s2_function

#: Microns per unit of the shapes the frames are made from.
KIDNEY_SCALE = 60.0
ELLIPSOID_SCALE = 10.0
LUNG_SCALE = 40.0
ELLIPSOID_AXES = (2.0, 1.5, 1.2)


def _voxel_centres(low, high, spacing):
    """(z, y, x) voxel-centre coordinates covering the box [low, high] (given as (x, y, z))."""
    sz, sy, sx = spacing
    x = np.arange(low[0], high[0] + sx, sx)
    y = np.arange(low[1], high[1] + sy, sy)
    z = np.arange(low[2], high[2] + sz, sz)
    Z, Y, X = np.meshgrid(z, y, x, indexing="ij")
    return X, Y, Z


def kidney_masks(spacing: float = 0.65):
    """``(mask1, mask2, (spacing, spacing))``: the kidney pair as boolean (rows, columns) masks."""
    curves = [c * KIDNEY_SCALE for c in load_example("kidney")]
    low = np.min([c.min(axis=0) for c in curves], axis=0) - 10.0
    high = np.max([c.max(axis=0) for c in curves], axis=0) + 10.0
    shape = tuple(np.ceil((high - low)[::-1] / spacing).astype(int))
    masks = []
    for curve in curves:
        mask = np.zeros(shape, bool)
        rows, columns = polygon((curve[:, 1] - low[1]) / spacing, (curve[:, 0] - low[0]) / spacing, shape)
        mask[rows, columns] = True
        masks.append(mask)
    return masks[0], masks[1], (spacing, spacing)


def ellipsoid_stacks(spacing=(2.0, 0.5, 0.5)):
    """``(sphere, ellipsoid, spacing)``: boolean [z, y, x] stacks of the Figure 12 pair, both centred
    in the stack; radius 10 um onto semi-axes 20, 15, 12 um."""
    half = np.array(ELLIPSOID_AXES) * ELLIPSOID_SCALE + 3 * max(spacing)
    X, Y, Z = _voxel_centres(-half, half, spacing)
    r = ELLIPSOID_SCALE
    sphere = X**2 + Y**2 + Z**2 <= r**2
    a, b, c = np.array(ELLIPSOID_AXES) * r
    ellipsoid = (X / a) ** 2 + (Y / b) ** 2 + (Z / c) ** 2 <= 1.0
    return sphere, ellipsoid, tuple(spacing)


def lung_stacks(spacing=(2.0, 1.0, 1.0), growth: float = 0.6):
    """``(stack1, stack2, spacing)``: the lung-like pair (S1 inside S2) as boolean [z, y, x] stacks."""
    low, high = np.array([-1.6, -1.0, -2.0]) * LUNG_SCALE, np.array([1.6, 1.0, 1.6]) * LUNG_SCALE
    X, Y, Z = _voxel_centres(low, high, spacing)
    points = np.stack([X, Y, Z], axis=-1) / LUNG_SCALE
    return s1_function(points) <= 0, s2_function(points, growth) <= 0, tuple(spacing)
