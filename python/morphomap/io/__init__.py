"""Files in and out: curves and fields as CSV, surfaces as mesh files, fields and interior motion
as the files solvers read (COMSOL, VTK, XDMF), one frame of a series from any of them, atomic writes.
"""

from .csv_files import read_curve, read_field, write_curve
from .examples import EXAMPLES, example_path, load_example
from .formats import FORMATS, write_field, write_interior, write_interior_series
from .meshes import SURFACE_SUFFIXES, read_surface, write_surface

__all__ = ["EXAMPLES", "FORMATS", "SURFACE_SUFFIXES", "example_path", "load_example", "read_curve", "read_field",
           "read_surface", "write_curve", "write_field", "write_interior",
           "write_interior_series", "write_surface"]
