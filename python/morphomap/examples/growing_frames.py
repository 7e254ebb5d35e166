"""The motion of a growing domain across a series of frames, for a PDE solver: one mesh, moved.

    python -m morphomap.examples.growing_frames OUT

Frames 0..4 of a growing outline with a bud (closed curves), each consecutive pair mapped
(``map_curves``, the default method), and the boundary displacement extended into the domain on
one mesh that moves with it: frame 0's domain meshed once, the mesh of frame k + 1 the mesh of
frame k moved by the interior field (``extend_field``, which leaves no cell inverted). Writes
``OUT/motion.xdmf`` (+ ``.h5``): the mesh (grid ``mesh``, frame 0) and, per step k at time k·dt,
the nodes of frame k and the displacement that takes them to frame k + 1.
:mod:`morphomap.examples.growing_domain_fenicsx` solves the paper's Eq. 2 on it in dolfinx.
"""

from __future__ import annotations

import os
import sys

import numpy as np


def frames(count: int = 5, points: int = 400):
    """``count`` closed curves ``(points, 2)``: a disc of radius 1 that widens by 8% of it per
    frame while a bud grows out of it by 0.25 per frame."""
    t = 2 * np.pi * np.arange(points) / points
    bud = np.exp(-(np.angle(np.exp(1j * (t - 0.5))) ** 2) / (2 * 0.35 ** 2))
    return [np.column_stack([np.cos(t), np.sin(t)]) * (1 + 0.08 * k + 0.25 * k * bud)[:, None]
            for k in range(count)]


def prepare(folder, count: int = 5, mesh_size: float = 0.08, dt: float = 1.0):
    """Map and extend the frames on one moving mesh; write ``folder/motion.xdmf``.

    Returns
    -------
    list of InteriorField
        Step k: frame k's nodes (``points``) and their displacement to frame k + 1.
    """
    import morphomap as mm
    from morphomap.io import write_interior_series

    curves = frames(count)
    interiors = []
    mesh = None
    for k in range(count - 1):
        field = mm.map_curves(curves[k], curves[k + 1])
        interior = mm.extend_field(field, mesh=mesh, mesh_size=mesh_size)
        interiors.append(interior)
        mesh = (interior.points + interior.displacement, interior.cells)
    os.makedirs(folder, exist_ok=True)
    write_interior_series(os.path.join(folder, "motion.xdmf"), interiors, [k * dt for k in range(count - 1)])
    return interiors


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    folder = argv[0] if argv else "growing-frames"
    interiors = prepare(folder)
    print(f"{len(interiors)} steps on one mesh of {len(interiors[0].points)} nodes and {len(interiors[0].cells)} "
          f"triangles; inverted cells per step {[i.inverted for i in interiors]}, substeps "
          f"{[i.substeps for i in interiors]}; written to {os.path.join(folder, 'motion.xdmf')}")


if __name__ == "__main__":
    main()
