"""The morphomap command line."""

from __future__ import annotations

import argparse
import os
import sys
import warnings

import numpy as np


def _info(args) -> int:
    import morphomap

    info = morphomap.build_info()
    print(f"morphomap {info['version']}")
    print(f"CGAL      {info['cgal']}")
    print(f"Embree    {info['embree']}")
    print(f"Eigen     {info['eigen']}")
    print(f"TBB       {info['tbb']}")
    print(f"threads   {info['threads']}")
    return 0


def _demo(args) -> int:
    from .demo import run

    rows = run(args.out)
    failed = [row for row in rows if row.note.startswith("failed")]
    if failed:
        print(f"morphomap demo: {len(failed)} mappings failed (see the table)", file=sys.stderr)
        return 1
    return 0


def _read_and_map(args, parser):
    """The two frames of `map` / `extend`, the field between them and its quality."""
    import morphomap

    frames = []
    for path in (args.c1, args.c2):
        try:
            frames.append(_read_frame(path, args))
        except OSError as error:
            parser.error(f"cannot read {path}: {error.strerror or error}")
        except (ValueError, TypeError) as error:
            parser.error(f"{path}: {error}")
    (c1, from_image), (c2, _) = frames
    surfaces = [not isinstance(frame, np.ndarray) for frame in (c1, c2)]
    if surfaces[0] != surfaces[1]:
        parser.error(f"{args.c1} is a {'surface' if surfaces[0] else 'curve'} but {args.c2} is a "
                     f"{'surface' if surfaces[1] else 'curve'}: map two of a kind")
    try:
        if surfaces[0]:
            for option, given in _CURVE_ONLY.items():
                if given(args):
                    parser.error(f"{option} applies to curves, not to surfaces")
            field = morphomap.map_surfaces(c1, c2, args.method, reverse=args.reverse, mesh_size=args.mesh_size)
            q = morphomap.quality(field, c1, c2)
        else:
            # A traced contour that make_simple repairs is mapped repaired: say so on stderr.
            with warnings.catch_warnings(record=True) as told:
                warnings.simplefilter("always", UserWarning)
                field = morphomap.map_curves(c1, c2, args.method, closed=args.closed, n=args.n,
                                             reverse=args.reverse, transform=args.transform, split=args.split,
                                             contact_tolerance=args.contact_tolerance, mesh_size=args.mesh_size)
            for warning in told:
                print(f"morphomap: warning: {warning.message}", file=sys.stderr)
            q = morphomap.quality(field, c1, c2, closed=args.closed)
    except (ValueError, TypeError, morphomap.InvalidInput, morphomap.GeometryError) as error:
        parser.error(f"cannot map {args.c1} onto {args.c2} with --method {args.method}: {error}")
    return c1, c2, from_image, field, q


def _summary(field, q) -> str:
    names, counts = np.unique(field.method, return_counts=True)
    used = ", ".join(f"{name} {count}" for name, count in zip(names, counts))
    defects = f"folds {q.folds}" if field.dim == 3 else f"crossings {q.crossings}"
    return (f"{len(field)} vectors, {int(field.valid.sum())} valid, {int((~field.valid).sum())} missed ({used}); "
            f"QM1 {q.qm1:.4g}  QM2 {q.qm2:.4g}  QM {q.qm:.4g}  {defects}")


def _map(args, parser) -> int:
    import morphomap
    from ..io.formats import writer

    # "-" and a device such as /dev/null are streams: CSV, as to an open text file.
    stream = args.output == "-" or (os.path.exists(args.output) and not os.path.isfile(args.output))
    if not stream:
        try:
            writer(args.output, "field")  # an unknown suffix before the work, not a traceback after it
        except ValueError as error:
            parser.error(f"-o {args.output}: {error}")
    c1, c2, from_image, field, q = _read_and_map(args, parser)
    title = f"{args.method}: QM1 {q.qm1:.4g}  QM2 {q.qm2:.4g}  QM {q.qm:.4g}"
    try:
        if args.output == "-":
            morphomap.write_field(sys.stdout, field)
        elif stream:
            with open(args.output, "w") as device:
                morphomap.write_field(device, field)
        else:
            morphomap.write_field(args.output, field)
        if args.plot:
            from matplotlib.figure import Figure

            from ..plot import plot_field, plot_field_3d, save_figure

            fig = Figure(figsize=(7, 7), layout="constrained")
            if field.dim == 3:
                plot_field_3d(field, c1, c2, ax=fig.add_subplot(projection="3d"), title=title)
            else:
                plot_field(field, c1, c2, ax=fig.subplots(), closed=args.closed, title=title, y_down=from_image)
            save_figure(fig, args.plot, dpi=100)
    except OSError as error:
        parser.error(f"cannot write {error.filename}: {error.strerror or error}")
    where = "" if args.output == "-" else f"; field written to {args.output}"
    where += f", plot to {args.plot}" if args.plot else ""
    print(_summary(field, q) + where, file=sys.stderr)
    if field.candidates is not None:  # --method best: every candidate it tried
        from ..best import candidate_table

        print(candidate_table(field), file=sys.stderr)
    return 0


def _extend(args, parser) -> int:
    import morphomap
    from ..io.formats import writer

    try:
        writer(args.output, "interior")  # an unknown suffix before the work, not after it
    except ValueError as error:
        parser.error(f"-o {args.output}: {error}")
    _, _, _, field, q = _read_and_map(args, parser)
    mesh = None
    if args.mesh:
        import meshio

        try:
            solver_mesh = meshio.read(args.mesh)
        except (OSError, ValueError, KeyError, meshio.ReadError) as error:
            parser.error(f"cannot read the mesh {args.mesh}: {error}")
        kind = "triangle" if field.dim == 2 else "tetra"
        if kind not in solver_mesh.cells_dict:
            parser.error(f"{args.mesh}: has no {kind} cells (found: {', '.join(solver_mesh.cells_dict) or 'none'})")
        mesh = (solver_mesh.points[:, : field.dim], solver_mesh.cells_dict[kind])
    try:
        interior = morphomap.extend_field(field, mesh=mesh, mesh_size=args.extend_mesh_size, method=args.extension,
                                          poisson_ratio=args.poisson_ratio, substeps=args.substeps,
                                          untangle=args.untangle)
    except (ValueError, TypeError, morphomap.InvalidInput, morphomap.GeometryError) as error:
        parser.error(f"cannot extend the field into {args.mesh or 'the domain'}: {error}")
    try:
        morphomap.write_interior(args.output, interior, dt=args.dt)
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


def _series(args, parser) -> int:
    import morphomap

    frames = []
    for path in args.frames:
        try:
            frames.append(_read_frame(path, args)[0])
        except OSError as error:
            parser.error(f"cannot read {path}: {error.strerror or error}")
        except (ValueError, TypeError) as error:
            parser.error(f"{path}: {error}")
    try:
        series = morphomap.map_series(frames, args.method, dt=args.dt, reseed=args.reseed,
                                      progress=False if args.no_progress else None)
    except (ValueError, TypeError, morphomap.InvalidInput, morphomap.GeometryError) as error:
        parser.error(str(error))
    try:
        written = series.write(args.out)
    except OSError as error:
        parser.error(f"cannot write {error.filename}: {error.strerror or error}")
    for q in series.quality:
        kind = "crossings" if series.dim == 2 else "folds"
        print(f"step {q.step}: QM1 {q.qm1:.4g}  QM2 {q.qm2:.4g}  QM {q.qm:.4g}  {kind} {q.defects}  misses {q.misses}  "
              f"{q.seconds:.2f} s", file=sys.stderr)
    print(f"{series!r}; {len(written)} files written to {args.out}", file=sys.stderr)
    return 0


def _batch(args, parser) -> int:
    import csv
    import os

    from ..batch import Job, map_batch

    try:
        with open(args.manifest, newline="", encoding="utf-8") as handle:
            rows = [row for row in csv.reader(handle) if row and not row[0].startswith("#")]
    except OSError as error:
        parser.error(f"cannot read {args.manifest}: {error.strerror or error}")
    if rows and rows[0][:2] == ["c1", "c2"]:
        rows = rows[1:]
    base = os.path.dirname(os.path.abspath(args.manifest))
    os.makedirs(args.out, exist_ok=True)
    jobs = []
    for number, row in enumerate(rows, start=1):
        if len(row) not in (2, 3):
            parser.error(f"{args.manifest}: row {number}: expected c1,c2[,method], got {len(row)} values")
        c1, c2 = (p if os.path.isabs(p) else os.path.join(base, p) for p in row[:2])
        stem = f"{number:03d}_{os.path.splitext(os.path.basename(c1))[0]}_{os.path.splitext(os.path.basename(c2))[0]}"
        jobs.append(Job(c1, c2, os.path.join(args.out, stem + ".csv"), row[2] if len(row) == 3 else args.method,
                        args.spacing, args.smooth))
    client = None
    if args.scheduler:
        from distributed import Client

        client = Client(args.scheduler)
    results = map_batch(jobs, client=client, workers=args.workers, progress=False if args.no_progress else None)
    for r in results:
        print(f"{r.status:8s} {r.job.c1} -> {r.job.c2}: {r.message}", file=sys.stderr)
    failed = sum(r.status == "failed" for r in results)
    print(f"{len(results)} jobs: {len(results) - failed} done or skipped, {failed} failed; fields in {args.out}",
          file=sys.stderr)
    return 1 if failed else 0


def _share(common, parser, options) -> None:
    """Give ``parser`` the same ``options`` as ``common`` (one definition of each option's rules)."""
    for option in options:
        parser._add_action(next(a for a in common._actions if option in a.option_strings))


def main(argv=None) -> int:
    from ..mapping import CURVE_METHODS

    parser = argparse.ArgumentParser(prog="morphomap", description="Displacement fields between growing boundaries.")
    commands = parser.add_subparsers(dest="command", required=True)
    info = commands.add_parser(
        "info", help="print the version, the libraries it was built against and the threads it uses")
    info.set_defaults(run=_info)
    demo = commands.add_parser(
        "demo",
        help="run every algorithm on the bundled example curves; write fields, figures and the quality table",
        description="Map the bundled example pairs with every algorithm (plain, reverse, transformed; all with the "
        "curves split where they cross), print the quality table and write the fields (CSV) and "
        "figures (PNG).",
    )
    demo.add_argument(
        "--out", default="morphomap-demo", metavar="DIR", help="folder to write into (default: ./morphomap-demo)"
    )
    demo.set_defaults(run=_demo)
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument(
        "c1", metavar="C1", help="the boundary at time t: a CSV curve, a mesh file, a 2D mask or a 3D stack"
    )
    common.add_argument("c2", metavar="C2", help="the boundary at time t + dt, likewise")
    common.add_argument(
        "--spacing",
        type=_spacing,
        default=None,
        metavar="S[,S[,S]]",
        help="pixel or voxel size of masks: one value, or one per axis (rows,columns; sz,sy,sx) "
        "(default: what the file states, else 1)",
    )
    common.add_argument("--label", type=int, default=None, help="the object's value in a label image")
    common.add_argument(
        "--smooth",
        type=_length,
        default=None,
        metavar="W",
        help="Gaussian width (physical units) applied to masks before contouring (default: about a "
        "pixel for 2D masks, a sub-pixel outline; 0 for 3D stacks; 0: the pixels as they are)",
    )
    common.add_argument(
        "--edge-length",
        type=lambda text: _length(text, positive=True),
        default=None,
        metavar="L",
        help="triangle edge length of surfaces from 3D stacks (default: the largest voxel size)",
    )
    common.add_argument("--method", default="auto", choices=CURVE_METHODS, help="the algorithm (default: auto)")
    closed = common.add_mutually_exclusive_group()
    closed.add_argument(
        "--closed", dest="closed", action="store_true", default=True, help="the curves are closed (the default)"
    )
    closed.add_argument("--open", dest="closed", action="store_false", help="the curves are open")
    common.add_argument(
        "--n", type=_positive, default=None, metavar="N", help="resample both curves to N equally spaced points first"
    )
    common.add_argument("--reverse", action="store_true", help="map C2 onto C1 and flip the vectors")
    common.add_argument(
        "--transform", action="store_true", help="move C1 close to C2 first (the paper's Appendix A), then map"
    )
    common.add_argument(
        "--no-split", dest="split", action="store_false", help="do not split the curves where they cross"
    )
    common.add_argument(
        "--contact-tolerance",
        type=_length,
        default=None,
        metavar="D",
        help="curves closer than D are in contact there: split and mapped to the closest point "
        "(default: 1%% of the finer median point spacing)",
    )
    common.add_argument(
        "--mesh-size",
        type=lambda text: _length(text, positive=True),
        default=None,
        metavar="H",
        help="the diffusion mesh size (default: from the gap between the curves)",
    )
    mapping = commands.add_parser(
        "map",
        parents=[common],
        help="map boundary C1 onto boundary C2 (curves, surfaces or masks) and write the displacement field",
        description="Map boundary C1 (time t) onto boundary C2 (time t + dt): curves (CSV files of x,y rows, "
        "with an optional header) or 2D masks (PNG, TIFF, .npy), or closed surfaces (STL, PLY, OBJ, "
        "OFF) or 3D stacks (TIFF, .npy). Prints the vector count and quality measures to stderr.",
    )
    mapping.add_argument(
        "-o",
        "--output",
        default="-",
        metavar="FIELD.csv",
        help="where to write the field: .csv (columns start_x,start_y,end_x,end_y,valid,method; 3D: "
        "with start_z, end_z and the faces), .vtu, .xdmf or a COMSOL .txt table; "
        "default: CSV to standard output",
    )
    mapping.add_argument(
        "--plot",
        metavar="FIELD.png",
        help="also draw the field into this image file (2D masks: y down, as the image looks)",
    )
    mapping.set_defaults(run=lambda args: _map(args, mapping))
    extend = commands.add_parser(
        "extend",
        parents=[common],
        help="map C1 onto C2 and extend the field into the domain C1 encloses (the solver's mesh motion)",
        description="Map boundary C1 onto C2 as `map` does, then extend the displacement (harmonic or elastic) into "
        "the domain C1 encloses: on the solver's own mesh (--mesh, triangles in 2D, tetrahedra in 3D, any "
        "file meshio reads) or on a mesh made by CGAL. Writes the interior displacement.",
    )
    extend.add_argument("--mesh", metavar="MESH", help="the solver's mesh of the domain (.xdmf, .vtu, .msh, ...)")
    extend.add_argument("--extend-mesh-size", type=lambda text: _length(text, positive=True), default=None,
                        metavar="H", help="without --mesh: the largest edge of the mesh made (default: graded in 2D, "
                                          "S1's mean edge in 3D)")
    extend.add_argument("--extension", choices=("harmonic", "elastic"), default="harmonic",
                        help="the interior problem: a vector Laplace equation or linear elasticity")
    extend.add_argument("--poisson-ratio", type=float, default=0.3, metavar="NU",
                        help="--extension elastic: the Poisson ratio, 0 <= NU < 0.5 (default 0.3)")
    extend.add_argument("--substeps", type=int, default=None, metavar="K",
                        help="move the mesh in K steps, each solved on the moved mesh (default: as many as "
                             "leave no cell inverted)")
    extend.add_argument("--untangle", action=argparse.BooleanOptionalAction, default=None,
                        help="then move the inner corners of the cells still inverted to untangle them (default: "
                             "where substeps leave inverted cells); with both --substeps and --[no-]untangle "
                             "the field is written as solved, inverted cells counted")
    extend.add_argument("--dt", type=lambda text: _length(text, positive=True), default=None, metavar="DT",
                        help="the time between the frames: also write the velocity")
    extend.add_argument("-o", "--output", required=True, metavar="U.xdmf",
                        help="where to write the interior displacement (.xdmf, .vtu or a COMSOL .txt)")
    extend.set_defaults(run=lambda args: _extend(args, extend))
    series = commands.add_parser(
        "series",
        help="map every consecutive pair of a time series and follow the first frame's points",
        description="Map frame k onto frame k + 1 for every k (curves, surfaces, masks or stacks, all of one kind) "
        "and carry the points of the first frame through the fields, with new points born where they "
        "spread apart; write the fields, the trajectories, the growth maps (stretch, normal speed), "
        "the quality per step, figures and an animation (GIF; MP4 when ffmpeg is there) into --out.",
    )
    series.add_argument("frames", nargs="+", metavar="FRAME")
    _share(common, series, ("--spacing", "--label", "--smooth", "--edge-length", "--method"))
    series.add_argument("--out", required=True, metavar="DIR", help="the folder to write into")
    series.add_argument(
        "--dt",
        type=lambda text: _length(text, positive=True),
        default=1.0,
        metavar="DT",
        help="the time between two frames, for the normal speeds (default 1)",
    )
    series.add_argument(
        "--reseed",
        type=_reseed,
        default=2.0,
        metavar="F",
        help="new points are born where neighbouring followed points get more than F times the "
        "first frame's spacing apart (default 2; 'none': follow only the first frame's points)",
    )
    series.add_argument("--no-progress", action="store_true", help="no progress bar (default: one on a terminal)")
    series.set_defaults(run=lambda args: _series(args, series))
    batch = commands.add_parser(
        "batch",
        help="map many pairs on Dask distributed (a local cluster, or --scheduler)",
        description="Map every pair listed in MANIFEST.csv (rows c1,c2[,method], paths relative to the manifest) as "
        "a Dask task; a failing task or a dying worker is reported and the others finish; fields are "
        "written atomically into --out, and a rerun skips the pairs already done.",
    )
    batch.add_argument("manifest", metavar="MANIFEST.csv")
    batch.add_argument("--out", required=True, metavar="DIR")
    batch.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler (default: a local cluster)")
    batch.add_argument(
        "--workers",
        type=_positive,
        default=None,
        metavar="N",
        help="worker processes of the local cluster (default: one per core)",
    )
    _share(common, batch, ("--spacing", "--smooth", "--method"))
    batch.add_argument("--no-progress", action="store_true", help="no progress bar (default: one on a terminal)")
    batch.set_defaults(run=lambda args: _batch(args, batch))
    args = parser.parse_args(argv)
    try:
        return args.run(args)
    except KeyboardInterrupt:
        print("morphomap: interrupted", file=sys.stderr)
        return 130


def _read_frame(path: str, args):
    """``(frame, from_image)`` for the command line: read_boundary with its options, the spacing
    used said on stderr."""
    from ..io.frames import read_boundary

    return read_boundary(
        path,
        spacing=args.spacing,
        label=args.label,
        smooth=args.smooth,
        edge_length=args.edge_length,
        report=lambda text: print(text, file=sys.stderr),
    )


def _spacing(text: str) -> tuple:
    values = tuple(_length(part, positive=True) for part in text.split(","))
    if len(values) not in (1, 2, 3):
        raise argparse.ArgumentTypeError(
            f"expected one length, or one per axis (rows,columns or sz,sy,sx), got {text!r}"
        )
    return values


def _reseed(text: str):
    if text.lower() == "none":
        return None
    value = _length(text, positive=True)
    if value <= 1:
        raise argparse.ArgumentTypeError(f"expected a factor > 1 or 'none', got {value}")
    return value


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value < 2:
        raise argparse.ArgumentTypeError(f"expected at least 2, got {value}")
    return value


def _length(text: str, positive: bool = False) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (value > 0 if positive else value >= 0) or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a finite length {'>' if positive else '>='} 0, got {value}")
    return value


if __name__ == "__main__":
    sys.exit(main())
