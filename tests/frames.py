"""Pairs of frames made the way labs make them: rasterised masks, contoured (issue "Real segmentations").

Every generator is a pure function of an integer seed.

2D (:func:`curve_pair`): a smooth random blob (random Fourier radius r(theta) with k <= 6, buds as
Gaussian bumps in r(theta), necks as narrow dips, sometimes a knob: a disc stuck onto the boundary)
and a grown version of it (scaled non-uniformly, a bud grown out, a knob grown, or only part of
the boundary moved so that at least ~10% of it stays where it was). Both are rasterised on the
SAME pixel grid with anisotropic spacing (sy, sx) as boolean masks, optionally smoothed (Gaussian
then threshold, or the smoothed float image contoured directly), optionally with debris (a small
separate blob) and holes, and contoured with ``skimage.measure.find_contours`` at 0.5; physical
coordinates are x = col * sx, y = row * sy. Pixel stretches the growth did not touch are
therefore shared exactly by both curves.

- style ``"careful"``: the largest contour of each frame, its repeated last point dropped.
- style ``"raw"``: what a careless user passes on: ``"first"`` (``find_contours(...)[0]``, with
  its repeated last point: may be debris or a hole), ``"concat"`` (all contours of a frame
  concatenated into one array) or ``"debris"`` (a debris contour kept as a curve of its own).

3D (:func:`surface_pair`): the same with voxel volumes (24-34 voxels along the finest axis, anisotropic spacing
(sz, sy, sx)): a lumpy ball (zonal-harmonic-like radius perturbations about random axes, buds,
knobs) and a grown version on the same grid (or one moved by a fifth of its size or more, so that
the two cross), optionally debris and a cavity and smoothing;
``skimage.measure.marching_cubes`` on the zero-padded volume with the spacing, vertices reordered
to (x, y, z), faces oriented outward (by the signed volume), duplicate vertices merged
(``trimesh.Trimesh(process=True)``).

- style ``"careful"``: the largest connected component.
- style ``"raw"``: ``"all_components"`` (debris and cavity kept in the one mesh) or
  ``"unoriented"`` (the marching-cubes faces after the axis swap, not re-oriented: inward).

Run as a script to print a summary of some seeds: ``python tests/frames.py [2d|3d] [N]``.
"""

from __future__ import annotations

from frame_seeds import STYLES, style_of
from frames_2d import CurvePair, curve_pair
from frames_3d import SurfacePair, surface_pair

__all__ = ["STYLES", "CurvePair", "SurfacePair", "curve_pair", "pair", "style_of", "surface_pair"]


def pair(dim: int, seed: int, style: str | None = None, fine: int = 1, capped: bool = False):
    """``curve_pair`` (dim 2) or ``surface_pair`` (dim 3; ``fine``: its voxels that many times smaller;
    ``capped``: cut by a plane and closed by caps of long thin triangles)."""
    if dim == 2:
        return curve_pair(seed, style)
    if dim == 3:
        return surface_pair(seed, style, fine, capped)
    raise ValueError(f"dim: expected 2 or 3, got {dim!r}")


if __name__ == "__main__":  # a summary of some seeds, for looking at what the generators make
    import sys
    import time

    dim = 3 if len(sys.argv) > 1 and sys.argv[1] == "3d" else 2
    count = int(sys.argv[2]) if len(sys.argv) > 2 else 20
    for seed in range(count):
        clock = time.perf_counter()
        made = pair(dim, seed)
        print(f"{time.perf_counter() - clock:6.3f}s", made.info)
