"""morphomap: displacement fields between the boundaries of a growing organ.

Maps curve C1 (time t) onto curve C2 (time t + dt) in 2D, or one closed surface onto another in 3D,
with the algorithms of Schwaninger, Menshykau and Iber (minimal distance, normal, diffusion,
uniform) and their extensions and quality measures.
"""

from . import best  # noqa: F401  (registers method "best" with map_curves and map_surfaces)
from ._core import GeometryError, InvalidInput
from ._core import build_info as _build_info
from ._lazy import lazy_names
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
from .growth import Growth, SeriesGrowth, distance_bands, growth
from .mapping import map_curves
from .prepared import PreparedCurve, PreparedSurface
from .quality import CurveQuality, SurfaceQuality, quality
from .queries import CurveHits, CurveIndex, closest_points, line_intersections
from .simple import make_simple
from .surfaces import SurfaceHits, SurfaceIndex, map_surfaces, surface_normals
from .transform import Similarity, align_curves, overlap_area

# Imported on first use: these modules import trimesh, matplotlib, scipy.ndimage, meshio, h5py or
# distributed at their tops (about 1.5 s together), which the mapping core above does without.
__getattr__, __dir__ = lazy_names(__name__, globals(), {
    "batch": ("Job", "map_batch"),
    "components": ("split_components",),
    "images": ("Image", "boundary_from_mask", "read_image", "surface_from_mask"),
    "moving_mesh": ("MovingMesh", "extend_series"),
    "io": ("load_example", "read_curve", "read_field", "read_surface", "write_curve", "write_field",
           "write_interior", "write_surface"),
    "plot": ("plot_field", "plot_field_3d"),
    "remesh": ("remesh_surface",),
    "series": ("Series", "map_series"),
})

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
    "Growth",
    "Image",
    "InteriorField",
    "InvalidInput",
    "Job",
    "MovingMesh",
    "Series",
    "SeriesGrowth",
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
    "distance_bands",
    "extend_field",
    "extend_series",
    "growth",
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
