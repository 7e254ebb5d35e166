"""morphomap: displacement fields between the boundaries of a growing organ.

Maps curve C1 (time t) onto curve C2 (time t + dt) in 2D, or one closed surface onto another in 3D,
with the algorithms of Schwaninger, Menshykau and Iber (minimal distance, normal, diffusion,
uniform) and their extensions and quality measures.
"""

from ._core import GeometryError, InvalidInput
from ._core import build_info as _build_info
from .components import split_components
from .crossings import count_crossings, crossing_pairs
from .curves import (
    arc_lengths,
    curve_intersections,
    is_self_intersecting,
    normals,
    orientation,
    perimeter,
    resample,
    signed_area,
)
from .diffusion import DiffusionSolution, solve_diffusion
from .diffusion3d import ShellDiffusionSolution, solve_diffusion_3d
from .extend import InteriorField, extend_field
from .field import DisplacementField
from .images import Image, boundary_from_mask, read_image, surface_from_mask
from .io import (
    load_example,
    read_curve,
    read_field,
    read_surface,
    write_curve,
    write_field,
    write_interior,
    write_surface,
)
from .mapping import map_curves
from .plot import plot_field, plot_field_3d
from .quality import CurveQuality, SurfaceQuality, quality
from .batch import Job, map_batch
from . import best  # noqa: F401  (registers method "best" with map_curves and map_surfaces)
from .series import Series, map_series
from .simple import make_simple
from .queries import CurveHits, CurveIndex, closest_points, line_intersections
from .prepared import PreparedCurve, PreparedSurface
from .surfaces import SurfaceHits, SurfaceIndex, map_surfaces, remesh_surface, surface_normals
from .transform import Similarity, align_curves, overlap_area

__version__ = _build_info()["version"]


def build_info() -> dict:
    """Versions of morphomap and of CGAL, Embree, Eigen and TBB it was built against, and threads."""
    return dict(_build_info())


__all__ = [
    "CurveHits",
    "CurveIndex",
    "CurveQuality",
    "DiffusionSolution",
    "DisplacementField",
    "GeometryError",
    "Image",
    "InteriorField",
    "InvalidInput",
    "Job",
    "Series",
    "ShellDiffusionSolution",
    "Similarity",
    "SurfaceHits",
    "SurfaceIndex",
    "PreparedCurve",
    "PreparedSurface",
    "SurfaceQuality",
    "align_curves",
    "arc_lengths",
    "boundary_from_mask",
    "build_info",
    "closest_points",
    "count_crossings",
    "crossing_pairs",
    "curve_intersections",
    "extend_field",
    "is_self_intersecting",
    "line_intersections",
    "load_example",
    "make_simple",
    "map_batch",
    "map_curves",
    "map_series",
    "map_surfaces",
    "normals",
    "orientation",
    "overlap_area",
    "perimeter",
    "plot_field",
    "plot_field_3d",
    "quality",
    "read_curve",
    "read_field",
    "read_image",
    "read_surface",
    "remesh_surface",
    "resample",
    "signed_area",
    "solve_diffusion",
    "solve_diffusion_3d",
    "split_components",
    "surface_from_mask",
    "surface_normals",
    "write_curve",
    "write_field",
    "write_interior",
    "write_surface",
]
