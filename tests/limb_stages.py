"""The mouse limb bud's 3D stages (../shared/cases/limb-bud/3d) as a lab would have them from masks:
filled on one voxel grid and contoured by ``surface_from_mask``. Shared by the real-case tests and
``bench/bench_real_3d.py``; frames on one grid share the marching-cubes planes where the tissue
did not move, which is what the crossing region's contact handling meets on them."""

from __future__ import annotations

import numpy as np

import morphomap as mm


def voxelised(stages, pitch=12.0, smooth=0.0):
    """Each stage (hour -> trimesh.Trimesh) filled on one grid of ``pitch`` and contoured back,
    the masks blurred by a Gaussian of width ``smooth`` (physical units) first where it is set."""
    low = np.min([s.bounds[0] for s in stages.values()], axis=0) - 2 * pitch
    out = {}
    for hour, surface in stages.items():
        index = np.round((surface.voxelized(pitch=pitch).fill().points - low) / pitch).astype(int)
        mask = np.zeros(tuple(index.max(0)[::-1] + 3), bool)  # (z, y, x)
        mask[index[:, 2], index[:, 1], index[:, 0]] = True
        contoured = mm.surface_from_mask(mask, (pitch, pitch, pitch), smooth=smooth)
        contoured.apply_translation(low)
        out[hour] = contoured
    return out
