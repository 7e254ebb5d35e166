"""``morphomap map`` and ``morphomap extend``: two frames, the field between them, its quality."""

from __future__ import annotations

import os
import sys
import warnings

import numpy as np

import morphomap

from .._core import GeometryError, InvalidInput
from ..best import candidate_table
from ..extend import extend_field
from ..figure_style import method_summary
from ..io.formats import write_field, write_interior, writer
from ..mapping import map_curves
from ..quality import quality
from ..surfaces import map_surfaces
from .frames import read_frame, read_solver_mesh


def _read_and_map(args, parser):
    """The two frames of `map` / `extend`, the field between them and its quality."""
    frames = []
    for path in (args.c1, args.c2):
        try:
            frames.append(read_frame(path, args))
        except OSError as error:
            parser.error(f"cannot read {path}: {error.strerror or error}")
        except (ValueError, TypeError) as error:
            parser.error(f"{path}: {error}")
    (c1, from_image, unit), (c2, _, _) = frames
    look = {"y_down": from_image, "unit": unit}  # how its figure is drawn: masks as the image looks
    surfaces = [not isinstance(frame, np.ndarray) for frame in (c1, c2)]
    if surfaces[0] != surfaces[1]:
        parser.error(f"{args.c1} is a {'surface' if surfaces[0] else 'curve'} but {args.c2} is a "
                     f"{'surface' if surfaces[1] else 'curve'}: map two of a kind")
    try:
        if surfaces[0]:
            for option, given in _CURVE_ONLY.items():
                if given(args):
                    parser.error(f"{option} applies to curves, not to surfaces")
            field = map_surfaces(c1, c2, args.method, reverse=args.reverse, mesh_size=args.mesh_size)
            q = quality(field, c1, c2)
        else:
            # A traced contour that make_simple repairs is mapped repaired: say so on stderr.
            with warnings.catch_warnings(record=True) as told:
                warnings.simplefilter("always", UserWarning)
                field = map_curves(c1, c2, args.method, closed=args.closed, n=args.n, reverse=args.reverse,
                                   transform=args.transform, split=args.split,
                                   contact_tolerance=args.contact_tolerance, mesh_size=args.mesh_size)
            for warning in told:
                print(f"morphomap: warning: {warning.message}", file=sys.stderr)
            q = quality(field, c1, c2, closed=args.closed)
    except (ValueError, TypeError, InvalidInput, GeometryError) as error:
        parser.error(f"cannot map {args.c1} onto {args.c2} with --method {args.method}: {error}")
    return c1, c2, look, field, q


def _summary(field, q) -> str:
    used = method_summary(field.method)
    defects = f"folds {q.folds}" if field.dim == 3 else f"crossings {q.crossings}"
    return (f"{len(field)} vectors, {int(field.valid.sum())} valid, {int((~field.valid).sum())} missed ({used}); "
            f"QM1 {q.qm1:.4g}  QM2 {q.qm2:.4g}  QM {q.qm:.4g}  {defects}")


def run_map(args, parser) -> int:
    # "-" and a device such as /dev/null are streams: CSV, as to an open text file.
    stream = args.output == "-" or (os.path.exists(args.output) and not os.path.isfile(args.output))
    if not stream:
        try:
            writer(args.output, "field")  # an unknown suffix before the work, not a traceback after it
        except ValueError as error:
            parser.error(f"-o {args.output}: {error}")
    c1, c2, look, field, q = _read_and_map(args, parser)
    title = f"{args.method}: QM1 {q.qm1:.4g}  QM2 {q.qm2:.4g}  QM {q.qm:.4g}"
    try:
        if args.output == "-":
            write_field(sys.stdout, field)
        elif stream:
            with open(args.output, "w") as device:
                write_field(device, field)
        else:
            write_field(args.output, field)
        if args.plot:
            # Through the package's lazy names: matplotlib (about 0.3 s) only where a picture is asked for.
            plot = morphomap.plot
            fig = plot.offscreen_figure(7, 7)
            if field.dim == 3:
                plot.plot_field_3d(field, c1, c2, ax=fig.add_subplot(projection="3d"), title=title, **look)
            else:
                plot.plot_field(field, c1, c2, ax=fig.subplots(), closed=args.closed, title=title, **look)
            plot.save_figure(fig, args.plot, dpi=100)
    except OSError as error:
        parser.error(f"cannot write {error.filename}: {error.strerror or error}")
    where = "" if args.output == "-" else f"; field written to {args.output}"
    where += f", plot to {args.plot}" if args.plot else ""
    print(_summary(field, q) + where, file=sys.stderr)
    if field.candidates is not None:  # --method best: every candidate it tried
        print(candidate_table(field), file=sys.stderr)
    return 0


def run_extend(args, parser) -> int:
    try:
        writer(args.output, "interior")  # an unknown suffix before the work, not after it
    except ValueError as error:
        parser.error(f"-o {args.output}: {error}")
    _, _, _, field, q = _read_and_map(args, parser)
    mesh = read_solver_mesh(args.mesh, field.dim, parser) if args.mesh else None
    try:
        interior = extend_field(field, mesh=mesh, mesh_size=args.extend_mesh_size, method=args.extension,
                                poisson_ratio=args.poisson_ratio, substeps=args.substeps, untangle=args.untangle)
    except (ValueError, TypeError, InvalidInput, GeometryError) as error:
        parser.error(f"cannot extend the field into {args.mesh or 'the domain'}: {error}")
    try:
        write_interior(args.output, interior, dt=args.dt)
    except OSError as error:
        parser.error(f"cannot write {error.filename}: {error.strerror or error}")
    tried = ", ".join(f"{s} substep{'s' if s > 1 else ''}{' + untangle' if u else ''}: "
                      f"{'no solution' if n is None else f'{n} inverted'}" for s, u, n, _ in interior.attempts)
    print(f"{_summary(field, q)}; {interior!r} (tried {tried}), boundary nodes within "
          f"{interior.boundary_distance:.3g} of C1; written to {args.output}", file=sys.stderr)
    return 0


# Options of `map` that only curves have, and how to tell that one was given.
_CURVE_ONLY = {
    "--n": lambda args: args.n is not None,
    "--open": lambda args: not args.closed,
    "--transform": lambda args: args.transform,
    "--no-split": lambda args: not args.split,
    "--contact-tolerance": lambda args: args.contact_tolerance is not None,
}
