"""The morphomap command line."""

from __future__ import annotations

import argparse
import sys
from importlib import import_module

from .. import build_info
from ..mapping import CURVE_METHODS


def _info(args) -> int:
    info = build_info()
    print(f"morphomap {info['version']}")
    print(f"CGAL      {info['cgal']}")
    print(f"Embree    {info['embree']}")
    print(f"Eigen     {info['eigen']}")
    print(f"TBB       {info['tbb']}")
    print(f"threads   {info['threads']}")
    return 0


def _command(module: str, name: str, parser):
    """The subcommand: ``name`` of this package's ``module``, called with the arguments and the
    subcommand's ``parser`` (for its error messages)."""
    def run(args) -> int:
        # Imported when the subcommand runs: its module imports what it maps, reads, draws or
        # distributes with (trimesh, scipy, matplotlib, distributed: about a second), which --help
        # and info do without.
        return getattr(import_module(f".{module}", __package__), name)(args, parser)

    return run


def _share(common, parser, options) -> None:
    """Give ``parser`` the same ``options`` as ``common`` (one definition of each option's rules)."""
    for option in options:
        parser._add_action(next(a for a in common._actions if option in a.option_strings))


def main(argv=None) -> int:
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
    demo.set_defaults(run=_command("demo", "command", demo))
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
        help="also draw the field into this image file (masks: as the image looks, y down; axes in the image's unit)",
    )
    mapping.set_defaults(run=_command("pair", "run_map", mapping))
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
    extend.set_defaults(run=_command("pair", "run_extend", extend))
    series = commands.add_parser(
        "series",
        help="map every consecutive pair of a time series and follow the first frame's points",
        description="Map frame k onto frame k + 1 for every k (curves, surfaces, masks or stacks, all of one kind; "
        "or one movie file, an ImageJ hyperstack or OME-TIFF with a T axis, 2D or 3D) "
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
        default=None,
        metavar="DT",
        help="the time between two frames, for the normal speeds (default: a movie's frame interval in seconds, "
        "else 1)",
    )
    series.add_argument("--objects", choices=("union", "largest", "follow"), default=None,
                        help="one movie file of labels not linked across frames: every label (union, the default "
                        "without --label), the largest in each frame, or the object followed by overlap from "
                        "--label (or the largest) in the first frame")
    series.add_argument("--register", choices=("translation", "rigid"), default=None,
                        help="remove the sample's drift: move (rigid: and turn) each frame onto the previous one; "
                        "the motion is printed and written to motion.csv")
    series.add_argument(
        "--reseed",
        type=_reseed,
        default=2.0,
        metavar="F",
        help="new points are born where neighbouring followed points get more than F times the "
        "first frame's spacing apart (default 2; 'none': follow only the first frame's points)",
    )
    series.add_argument("--interior", action="store_true",
                        help="also carry a mesh of the first frame's domain through the frames (the solver's "
                        "mesh motion, no cell inverted): interior.xdmf for dolfinx, interior.pvd for ParaView, and "
                        "the mesh quality per step in quality.csv")
    series.add_argument("--mesh", metavar="MESH", help="with --interior: the solver's own mesh of the first frame's "
                        "domain (.xdmf, .vtu, .msh, ...; default: one made by CGAL)")
    series.add_argument("--no-progress", action="store_true", help="no progress bar (default: one on a terminal)")
    series.set_defaults(run=_command("series", "run", series))
    batch = commands.add_parser(
        "batch",
        help="map many pairs on Dask distributed (a local cluster, or --scheduler)",
        description="Map every pair listed in MANIFEST.csv as a Dask task: a header names the columns c1,c2 and "
        "optionally label,method,spacing,smooth (an empty cell: the option's value below), or rows are "
        "c1,c2[,method]; paths relative to the manifest. A failing job is reported and the others finish; a dying "
        "worker fails the job it ran, its waiting jobs run elsewhere. Fields (LABEL.csv, else NNN_C1_C2.csv), "
        "each with a sidecar of what made it, and summary.csv (quality of every row) are written atomically into "
        "--out; a rerun skips a row only when its input files' contents and options are unchanged.",
    )
    batch.add_argument("manifest", metavar="MANIFEST.csv")
    batch.add_argument("--out", required=True, metavar="DIR")
    batch.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler (default: a local cluster)")
    batch.add_argument(
        "--workers",
        type=_workers,
        default=None,
        metavar="N",
        help="worker processes of the local cluster, 1 or more (default: one per core)",
    )
    _share(common, batch, ("--spacing", "--smooth", "--method"))
    batch.add_argument("--no-progress", action="store_true", help="no progress bar (default: one on a terminal)")
    batch.set_defaults(run=_command("batch", "run", batch))
    args = parser.parse_args(argv)
    try:
        return args.run(args)
    except KeyboardInterrupt:
        print("morphomap: interrupted", file=sys.stderr)
        return 130


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


def _whole(least: int):
    """An argument type: a whole number of at least ``least``."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
        if value < least:
            raise argparse.ArgumentTypeError(f"expected at least {least}, got {value}")
        return value

    return parse


_positive = _whole(2)  # points of a resampled curve
_workers = _whole(1)


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
