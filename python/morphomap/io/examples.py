"""The example curve pairs bundled with the package (``morphomap/data/NAME_c1.csv``, ``NAME_c2.csv``;
made by :mod:`morphomap.synthetic.examples`)."""

from __future__ import annotations

from importlib import resources

from .csv_files import read_curve

#: The example pairs shipped in ``morphomap/data``.
EXAMPLES = ("circle_ellipse", "kidney")


def example_path(name: str, curve: str):
    """Path of one bundled curve file: ``curve`` is ``"c1"`` or ``"c2"``."""
    if name not in EXAMPLES:
        raise ValueError(f"name: expected one of {', '.join(map(repr, EXAMPLES))}, got {name!r}")
    if curve not in ("c1", "c2"):
        raise ValueError(f"curve: expected 'c1' or 'c2', got {curve!r}")
    return resources.files("morphomap").joinpath("data", f"{name}_{curve}.csv")


def load_example(name: str):
    """The bundled example pair ``name`` as ``(c1, c2)``, two closed counter-clockwise curves.

    ``"circle_ellipse"``: the paper's Table 1 case, a circle of radius 0.95 (100 points) inside the
    concentric ellipse with semi-axes 2.177 and 1 (100 points equally spaced in arc length, from
    angle 0). ``"kidney"``: a synthetic branching-organ pair, a blob with shallow buds and a later
    stage whose buds have grown and one has branched; the curves cross, and plain normal mapping
    gives crossing vectors in the concave regions of C1.
    """
    with resources.as_file(example_path(name, "c1")) as c1, resources.as_file(example_path(name, "c2")) as c2:
        return read_curve(c1), read_curve(c2)
