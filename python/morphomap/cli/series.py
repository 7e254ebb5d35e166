"""``morphomap series``: every consecutive pair of frames mapped, the first frame's points followed."""

from __future__ import annotations

import sys

from .._core import GeometryError, InvalidInput
from ..series import map_series
from .frames import read_frame


def run(args, parser) -> int:
    frames = []
    for path in args.frames:
        try:
            frames.append(read_frame(path, args)[0])
        except OSError as error:
            parser.error(f"cannot read {path}: {error.strerror or error}")
        except (ValueError, TypeError) as error:
            parser.error(f"{path}: {error}")
    try:
        series = map_series(frames, args.method, dt=args.dt, reseed=args.reseed,
                                      progress=False if args.no_progress else None)
    except (ValueError, TypeError, InvalidInput, GeometryError) as error:
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
