"""Files in for the command line: a frame (a curve, a surface or a mask read with the options
given) and a solver's mesh."""

from __future__ import annotations

import sys

from ..io.frames import read_sourced_boundary


def read_frame(path: str, args):
    """``(frame, from_image, unit)`` for the command line: read_sourced_boundary with its options,
    the spacing used said on stderr."""
    return read_sourced_boundary(
        path,
        spacing=args.spacing,
        label=args.label,
        smooth=args.smooth,
        edge_length=args.edge_length,
        report=lambda text: print(text, file=sys.stderr),
    )


def read_solver_mesh(path: str, dim: int, parser):
    """The solver's mesh file (any that meshio reads) as ``(points, cells)``: triangles in 2D,
    tetrahedra in 3D; a file that is not one is a usage error naming it."""
    import meshio

    try:
        mesh = meshio.read(path)
    except (OSError, ValueError, KeyError, meshio.ReadError) as error:
        parser.error(f"cannot read the mesh {path}: {error}")
    kind = "triangle" if dim == 2 else "tetra"
    if kind not in mesh.cells_dict:
        parser.error(f"{path}: has no {kind} cells (found: {', '.join(mesh.cells_dict) or 'none'})")
    return mesh.points[:, :dim], mesh.cells_dict[kind]
