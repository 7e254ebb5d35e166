"""A frame for the command line: a curve, a surface or a mask read with the options given."""

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
