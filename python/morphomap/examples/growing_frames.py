"""The motion of a growing domain across a series of frames, for a PDE solver: one mesh, moved.

    python -m morphomap.examples.growing_frames OUT [3d]

Frames 0..4 of a growing outline with a bud (closed curves; with ``3d`` closed surfaces), each
consecutive pair mapped (``map_series``, the default method), and the boundary displacement
extended into the domain on one mesh that moves with it (``Series.extend``): frame 0's domain
meshed once, the mesh of frame k + 1 the mesh of frame k moved by the interior field, which
leaves no cell inverted, its boundary nodes on frame k + 1. Writes
``OUT/motion.xdmf`` (+ ``.h5``): the mesh (grid ``mesh``, frame 0) and, per step k at time k·dt,
the nodes of frame k and the displacement that takes them to frame k + 1.
:mod:`morphomap.examples.growing_domain_fenicsx` solves the paper's Eq. 2 on it in dolfinx.
"""

from __future__ import annotations

import os
import sys

import numpy as np
import trimesh

import morphomap as mm


def frames(count: int = 5, points: int = 400):
    """``count`` closed curves ``(points, 2)``: a disc of radius 1 that widens by 8% of it per
    frame while a bud grows out of it by 0.25 per frame."""
    t = 2 * np.pi * np.arange(points) / points
    bud = np.exp(-(np.angle(np.exp(1j * (t - 0.5))) ** 2) / (2 * 0.35 ** 2))
    return [np.column_stack([np.cos(t), np.sin(t)]) * (1 + 0.08 * k + 0.25 * k * bud)[:, None]
            for k in range(count)]


def surfaces(count: int = 5, subdivisions: int = 3):
    """``count`` closed surfaces ``(vertices (V, 3), faces (F, 3))``, the 3D form of
    :func:`frames`: a sphere that widens while a bud grows out of it."""
    sphere = trimesh.creation.icosphere(subdivisions)
    directions = sphere.vertices / np.linalg.norm(sphere.vertices, axis=1)[:, None]
    angle = np.arccos(np.clip(directions @ np.array([np.cos(0.5), np.sin(0.5), 0.0]), -1.0, 1.0))
    bud = np.exp(-angle ** 2 / (2 * 0.35 ** 2))
    return [(directions * (1 + 0.08 * k + 0.25 * k * bud)[:, None], sphere.faces) for k in range(count)]


def prepare(folder, count: int = 5, mesh_size: float = None, dt: float = 1.0, dim: int = 2):
    """Map and extend the frames (curves, or surfaces for ``dim=3``) on one moving mesh; write
    ``folder/motion.xdmf``. ``mesh_size``: of the first frame's mesh (default 0.08 in 2D, 0.15 in 3D).

    Returns
    -------
    list of InteriorField
        Step k: frame k's nodes (``points``) and their displacement to frame k + 1.
    """
    if dim not in (2, 3):
        raise ValueError(f"dim: expected 2 or 3, got {dim!r}")
    shapes = frames(count) if dim == 2 else surfaces(count)
    mesh_size = (0.08 if dim == 2 else 0.15) if mesh_size is None else mesh_size
    series = mm.map_series(shapes, dt=dt, reseed=None)
    moving = series.extend(mesh_size=mesh_size)
    os.makedirs(folder, exist_ok=True)
    moving.write(os.path.join(folder, "motion.xdmf"))
    return moving.steps


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    folder = argv[0] if argv else "growing-frames"
    interiors = prepare(folder, dim=3 if "3d" in argv[1:] else 2)
    print(f"{len(interiors)} steps on one mesh of {len(interiors[0].points)} nodes and {len(interiors[0].cells)} "
          f"cells; inverted cells per step {[i.inverted for i in interiors]}, substeps "
          f"{[i.substeps for i in interiors]}; written to {os.path.join(folder, 'motion.xdmf')}")


if __name__ == "__main__":
    main()
