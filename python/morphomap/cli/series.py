"""``morphomap series``: every consecutive pair of frames mapped, the first frame's points followed."""

from __future__ import annotations

import sys

from .._core import GeometryError, InvalidInput
from ..movie import describe_motion, movie_frames
from ..series import map_series
from .frames import read_frame, read_solver_mesh


def _movie(path: str, args):
    """One file given: a movie, its frames read with the options given."""
    movie = movie_frames(path, label=args.label, objects=args.objects, smooth=args.smooth,
                         edge_length=args.edge_length, spacing=args.spacing)
    unit = movie.unit or "pixel"
    interval = "no frame interval in the file" if movie.dt is None else f"frame interval {movie.dt:g} s"
    print(f"{path}: {len(movie.frames)} time points, spacing {' x '.join(f'{v:g}' for v in movie.spacing)} "
          f"{unit}, {interval}", file=sys.stderr)
    return movie


def run(args, parser) -> int:
    frames, sources = [], []
    if len(args.frames) == 1:
        try:
            frames = _movie(args.frames[0], args)
        except OSError as error:
            parser.error(f"cannot read {args.frames[0]}: {error.strerror or error}")
        except (ValueError, TypeError) as error:
            parser.error(f"{args.frames[0]}: {error}")
    elif args.objects is not None:
        parser.error("--objects: only with one movie file")
    for path in args.frames if len(args.frames) > 1 else ():
        try:
            frame, from_image, unit = read_frame(path, args)
            frames.append(frame)
            sources.append((from_image, unit))
        except OSError as error:
            parser.error(f"cannot read {path}: {error.strerror or error}")
        except (ValueError, TypeError) as error:
            parser.error(f"{path}: {error}")
    if args.mesh and not args.interior:
        parser.error("--mesh: only with --interior")
    interior = None
    if args.interior:
        first = frames.frames[0] if hasattr(frames, "frames") else frames[0]
        dim = 2 if getattr(first, "ndim", 0) == 2 and first.shape[1] == 2 else 3
        interior = read_solver_mesh(args.mesh, dim, parser) if args.mesh else True
    try:
        series = map_series(frames, args.method, dt=args.dt, reseed=args.reseed, register=args.register,
                            interior=interior, progress=False if args.no_progress else None)
    except (ValueError, TypeError, InvalidInput, GeometryError) as error:
        parser.error(str(error))
    if sources and sources[0][0]:  # frames traced from masks: the figures drawn as the images look
        series.y_down, series.unit = True, sources[0][1]
    if series.motion is not None:
        for line in describe_motion(series.motion):
            print(line, file=sys.stderr)
    try:
        written = series.write(args.out)
    except OSError as error:
        parser.error(f"cannot write {error.filename}: {error.strerror or error}")
    for q in series.quality:
        kind = "crossings" if series.dim == 2 else "folds"
        mesh = "" if q.mesh is None else (f"  mesh: {q.mesh.inverted} inverted, smallest angle "
                                          f"{q.mesh.min_angle:.3g} deg, {q.mesh.substeps} substeps")
        print(f"step {q.step}: QM1 {q.qm1:.4g}  QM2 {q.qm2:.4g}  QM {q.qm:.4g}  {kind} {q.defects}  misses {q.misses}  "
              f"{q.seconds:.2f} s{mesh}", file=sys.stderr)
    print(f"{series!r}; {len(written)} files written to {args.out}", file=sys.stderr)
    return 0
