"""The output formats: one registry from a file's suffix to its writer, and the public writers.

:data:`FORMATS` says, per suffix, what the format is and which of a boundary field, an interior
field and a series of interior fields it can hold; :func:`write_field`, :func:`write_interior` and
:func:`write_interior_series` look the writer up there, and a suffix it lacks is a ``ValueError``
listing the known ones. The writers themselves are in :mod:`morphomap.io.solver` and
:mod:`morphomap.io.csv_files`.
"""

from __future__ import annotations

import os

from ..extend import InteriorField
from ..field import DisplacementField
from . import solver
from .csv_files import write_field_csv


class Format:
    """One output format: a description and its writers (None where it cannot hold that kind).

    ``field(path, field, dt)``, ``interior(path, interior, dt)``, ``series(path, interiors, times)``.
    """

    __slots__ = ("description", "field", "interior", "series")

    def __init__(self, description, field=None, interior=None, series=None):
        self.description, self.field, self.interior, self.series = description, field, interior, series


_FIELD_HEADER = "morphomap displacement field: {count} vectors from C1 to C2 ({dim}D)"
_INTERIOR_HEADER = "morphomap interior displacement: {count} mesh nodes ({dim}D)"


def _comsol_field(path, field, dt):
    content = solver.field_content(field, dt)
    content.header = _FIELD_HEADER
    solver.write_comsol(path, content)


def _comsol_interior(path, interior, dt):
    content = solver.interior_content(interior, dt)
    content.header = _INTERIOR_HEADER
    solver.write_comsol(path, content)


def _series(write):
    return lambda path, interiors, times: write(path, [solver.interior_content(i) for i in interiors], times)


#: Suffix -> Format: every file morphomap writes fields into.
FORMATS = {
    ".csv": Format("CSV table of start and end points (3D: the faces in NAME.faces.csv beside)",
                   field=lambda path, field, dt: write_field_csv(path, field)),
    ".txt": Format("COMSOL interpolation table (spreadsheet format; velocity columns with dt)",
                   field=_comsol_field, interior=_comsol_interior),
    ".vtu": Format("VTK unstructured grid (ParaView)",
                   field=lambda path, field, dt: solver.write_vtu(path, solver.field_content(field, dt)),
                   interior=lambda path, interior, dt: solver.write_vtu(path, solver.interior_content(interior, dt))),
    ".vtp": Format("VTK PolyData, boundary fields (needs the optional vtk package)",
                   field=lambda path, field, dt: solver.write_poly_data(path, solver.field_content(field, dt))),
    ".xdmf": Format("XDMF with HDF5 (dolfinx, ParaView; series with time values)",
                    field=lambda path, field, dt: solver.write_xdmf_file(path, solver.field_content(field, dt)),
                    interior=lambda path, interior, dt: solver.write_xdmf_file(
                        path, solver.interior_content(interior, dt)),
                    series=_series(solver.write_xdmf_series)),
    ".pvd": Format("ParaView collection of .vtu files, series", series=_series(solver.write_pvd_series)),
}

_KINDS = {"field": "a displacement field", "interior": "an interior field", "series": "a series of interior fields"}


def suffixes(kind) -> tuple:
    """The suffixes that can hold ``kind`` ("field", "interior" or "series")."""
    return tuple(suffix for suffix, form in FORMATS.items() if getattr(form, kind) is not None)


def writer(path, kind):
    """The writer of ``kind`` for ``path``'s suffix; a ``ValueError`` listing the known ones if none."""
    suffix = os.path.splitext(os.fspath(path))[1].lower()
    form = FORMATS.get(suffix)
    if form is None or getattr(form, kind) is None:
        known = "; ".join(f"{s} ({FORMATS[s].description})" for s in suffixes(kind))
        raise ValueError(f"path: unknown format {suffix or '(no suffix)'!r} for {_KINDS[kind]}: use one of {known}")
    return getattr(form, kind)


def write_field(path, field, *, dt=None) -> None:
    """Write a displacement field; the format from the suffix (:data:`FORMATS`): ``.csv``
    (:func:`morphomap.io.csv_files.write_field_csv`), ``.txt`` (COMSOL table), ``.vtu``, ``.vtp``
    (optional ``vtk`` package) or ``.xdmf`` (:mod:`morphomap.io.solver`).

    Parameters
    ----------
    path : str, path or open text file
        An open text file gets CSV.
    field : DisplacementField
    dt : float, optional
        The time between the two boundaries: adds the velocity ``vectors / dt`` (not to CSV).
    """
    if not isinstance(field, DisplacementField):
        raise TypeError(f"field: expected a DisplacementField, got {type(field).__name__}")
    if hasattr(path, "write"):
        write_field_csv(path, field)
        return
    writer(path, "field")(path, field, dt)


def write_interior(path, interior, dt=None) -> None:
    """Write an :class:`~morphomap.extend.InteriorField`: ``.xdmf`` (grid ``mesh``, for dolfinx's
    ``read_mesh()``), ``.vtu`` (the mesh and ``displacement``, with ``velocity`` when ``dt`` is
    given) or a COMSOL ``.txt`` table (node, displacement[, velocity])."""
    if not isinstance(interior, InteriorField):
        raise TypeError(f"interior: expected an InteriorField, got {type(interior).__name__}")
    writer(path, "interior")(path, interior, dt)


def write_interior_series(path, interiors, times) -> None:
    """Interior fields of a series, each at its time: ``.xdmf`` (one moving mesh: every step with
    the same cells; dolfinx reads step k with ``read_function(path, time=times[k])``) or ``.pvd``
    (ParaView: one ``.vtu`` per step beside it, any meshes).

    Parameters
    ----------
    interiors : sequence of InteriorField
        Step k's nodes and the displacement that moves them to step k + 1.
    times : sequence of float
        One per step, increasing.
    """
    interiors = list(interiors)
    times = [float(t) for t in times]
    if not interiors or not all(isinstance(i, InteriorField) for i in interiors):
        raise TypeError("interiors: expected a non-empty sequence of InteriorField")
    if len(times) != len(interiors) or any(b <= a for a, b in zip(times, times[1:])):
        raise ValueError(f"times: expected {len(interiors)} increasing values, one per interior field, got {times}")
    writer(path, "series")(path, interiors, times)
