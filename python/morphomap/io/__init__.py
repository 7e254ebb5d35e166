"""Files in and out: curves and fields as CSV, surfaces as mesh files, fields and interior motion
as the files solvers read (COMSOL, VTK, XDMF), one frame of a series from any of them, atomic writes.
"""

from .._lazy import lazy_names

# Imported on first use: the mesh and solver formats import trimesh, meshio and h5py (about 0.6 s),
# which reading a curve or loading an example does without.
__getattr__, __dir__ = lazy_names(__name__, globals(), {
    "csv_files": ("read_curve", "read_field", "write_curve"),
    "examples": ("EXAMPLES", "example_path", "load_example"),
    "formats": ("FORMATS", "write_field", "write_interior", "write_interior_series"),
    "meshes": ("read_surface", "write_surface"),
    "suffixes": ("SURFACE_SUFFIXES",),
})

__all__ = ["EXAMPLES", "FORMATS", "SURFACE_SUFFIXES", "example_path", "load_example", "read_curve", "read_field",
           "read_surface", "write_curve", "write_field", "write_interior",
           "write_interior_series", "write_surface"]
