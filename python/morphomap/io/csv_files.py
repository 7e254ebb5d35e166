"""Curves and displacement fields as CSV files.

Curve files hold one point per row, ``x,y``, with an optional header row (``x,y``). Field files have
the header ``start_x,start_y,end_x,end_y,valid,method`` (``start_z`` and ``end_z`` after the ``y``
columns of a 3D field); rows without a target hold ``nan`` and ``valid`` 0: one table, as
``pandas.read_csv`` and spreadsheets read it. A 3D field's faces (the triangles of its start
points, which its quality measures need) go into a second file beside it, ``NAME.faces.csv``
(:func:`faces_path`), headed ``face_a,face_b,face_c``, of row indices into the vectors. Files that
hold the faces as a second table after the vectors, in that header, are read too.

Blank lines and lines starting with ``#`` are skipped. Values are separated by commas; a file
without commas may separate them by tabs or spaces instead. Numbers are written with ``repr`` so
that they read back exactly.
"""

from __future__ import annotations

import contextlib
import math
import os
import warnings

import numpy as np

from .._validate import as_points
from ..field import DisplacementField
from .atomic import atomic_text

_FIELD_2D = ("start_x", "start_y", "end_x", "end_y", "valid", "method")
_FIELD_3D = ("start_x", "start_y", "start_z", "end_x", "end_y", "end_z", "valid", "method")
_FACES = ("face_a", "face_b", "face_c")


def _rows(path):
    """Yield ``(line_number, cells)`` for the non-blank, non-comment lines of a text file."""
    name = os.fspath(path)
    try:
        with open(name, encoding="utf-8-sig", newline="") as handle:
            text = handle.read()
    except UnicodeDecodeError:
        raise ValueError(f"{name}: not a text (UTF-8) CSV file") from None
    for number, line in enumerate(text.splitlines(), start=1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        cells = line.split(",") if "," in line else line.split()
        yield number, [cell.strip().strip('"').strip() for cell in cells]


def _number(cell: str, name: str, number: int, column: str) -> float:
    try:
        return float(cell)
    except ValueError:
        raise ValueError(f"{name}: line {number}, column {column}: {cell!r} is not a number") from None


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def read_curve(path) -> np.ndarray:
    """Read a curve from a CSV file of ``x,y`` rows (a header row is optional): ``(N, 2)`` float.

    With a header, the columns named ``x`` and ``y`` (any case) are used and any others ignored;
    without one, every row must have exactly two values. Raises ``ValueError`` naming the file and
    line for a wrong number of columns, a value that is not a number or a non-finite coordinate,
    and ``OSError`` (``FileNotFoundError``, ...) when the file cannot be opened.
    """
    name = os.fspath(path)
    rows = list(_rows(path))
    if not rows:
        raise ValueError(f"{name}: no points (the file is empty)")
    columns = (0, 1)
    width = None
    first_number, first = rows[0]
    if not all(_is_number(cell) for cell in first):
        header = [cell.lower() for cell in first]
        if "x" in header and "y" in header:
            columns = (header.index("x"), header.index("y"))
        elif len(header) == 2:
            columns = (0, 1)
        else:
            raise ValueError(
                f"{name}: line {first_number}: expected a header with columns x and y, got {','.join(first)}"
            )
        width = len(header)
        rows = rows[1:]
        if not rows:
            raise ValueError(f"{name}: no points after the header")
    points = np.empty((len(rows), 2))
    for i, (number, cells) in enumerate(rows):
        if width is None and len(cells) != 2:
            raise ValueError(f"{name}: line {number}: expected 2 values (x,y), got {len(cells)}")
        if width is not None and len(cells) != width:
            raise ValueError(f"{name}: line {number}: expected {width} values like the header, got {len(cells)}")
        for j, column in enumerate(columns):
            value = _number(cells[column], name, number, "xy"[j])
            if not math.isfinite(value):
                raise ValueError(f"{name}: line {number}, column {'xy'[j]}: {cells[column]!r} is not a finite number")
            points[i, j] = value
    return points


def _output(path):
    """An open text file for ``path`` (written atomically), or ``path`` itself when it is already
    writable (not closed)."""
    if hasattr(path, "write"):
        return contextlib.nullcontext(path)
    return atomic_text(path)


def write_curve(path, points, *, header=True) -> None:
    """Write a curve as ``x,y`` rows, with the header ``x,y`` unless ``header=False``.

    ``path``: a file name or an open text file.
    """
    points = as_points(points, "points")
    with _output(path) as handle:
        if header:
            handle.write("x,y\n")
        for x, y in points.tolist():
            handle.write(f"{x!r},{y!r}\n")


def faces_path(path) -> str:
    """Where a 3D field's faces go beside its CSV file: ``NAME.faces.csv`` for ``NAME.csv``."""
    name = os.fspath(path)
    stem = name[:-4] if name.lower().endswith(".csv") else name
    return stem + ".faces.csv"


def write_field_csv(path, field: DisplacementField) -> list:
    """Write a displacement field as CSV: ``start_x,start_y,end_x,end_y,valid,method`` per vector
    (:func:`morphomap.write_field` picks this writer for ``.csv`` and open files), and return the
    paths written.

    Missing coordinates are written as ``nan``; ``valid`` is 1 or 0. 3D fields get ``start_z`` and
    ``end_z`` columns, and their faces go into ``NAME.faces.csv`` beside (:func:`faces_path`), so
    that :func:`read_field` and :func:`morphomap.quality` round-trip. ``path``: a file name (written
    atomically, with its faces file) or an open text file, which gets the vectors alone (a
    ``UserWarning`` says where the faces of a 3D field did not go).
    """
    if not isinstance(field, DisplacementField):
        raise TypeError(f"field: expected a DisplacementField, got {type(field).__name__}")
    header = _FIELD_2D if field.dim == 2 else _FIELD_3D
    with _output(path) as handle:
        handle.write(",".join(header) + "\n")
        for start, end, valid, method in zip(
            field.starts.tolist(), field.ends.tolist(), field.valid.tolist(), field.method.tolist()
        ):
            values = ",".join(repr(float(v)) for v in (*start, *end))
            handle.write(f"{values},{int(valid)},{method}\n")
    if hasattr(path, "write"):
        if field.faces is not None:
            warnings.warn("field: the faces of a 3D field are not written to an open file (a table of their own "
                          "would follow the vectors); write to a .csv file to get NAME.faces.csv beside it",
                          UserWarning, stacklevel=3)
        return []
    written = [os.fspath(path)]
    if field.faces is not None:
        with atomic_text(faces_path(path)) as handle:
            handle.write(",".join(_FACES) + "\n")
            handle.writelines(f"{a},{b},{c}\n" for a, b, c in field.faces.tolist())
        written.append(faces_path(path))
    return written


def read_field(path) -> DisplacementField:
    """Read a displacement field written by :func:`write_field_csv`, with the faces in
    ``NAME.faces.csv`` beside a 3D one where that file exists.

    The header is required; columns may come in any order. ``valid`` is recomputed from the
    coordinates (a row is valid when none of them is NaN), so the column is only checked.
    """
    name = os.fspath(path)
    rows = list(_rows(path))
    if not rows:
        raise ValueError(f"{name}: empty file, expected the header {','.join(_FIELD_2D)}")
    number, header = rows[0]
    header = [cell.lower() for cell in header]
    wanted = _FIELD_3D if "start_z" in header else _FIELD_2D
    missing = [column for column in wanted if column not in header]
    if missing:
        raise ValueError(f"{name}: line {number}: the header lacks the column(s) {', '.join(missing)}")
    index = {column: header.index(column) for column in wanted}
    coordinates = [column for column in wanted if column not in ("valid", "method")]
    dim = len(coordinates) // 2
    face_rows, face_source = [], name
    split = next((k for k, (_, cells) in enumerate(rows) if [c.lower() for c in cells] == list(_FACES)), None)
    beside = faces_path(name)
    if dim == 3 and os.path.isfile(beside):
        if split is not None:
            raise ValueError(f"{name}: holds its faces itself, and {beside} holds faces too: remove one")
        face_file = list(_rows(beside))
        if not face_file or [cell.lower() for cell in face_file[0][1]] != list(_FACES):
            raise ValueError(f"{beside}: expected the header {','.join(_FACES)}")
        split, face_rows, face_source = len(rows), face_file[1:], beside
    elif split is not None:
        if dim != 3:
            raise ValueError(f"{name}: line {rows[split][0]}: a 2D field has no faces")
        rows, face_rows = rows[:split], rows[split + 1 :]
    values = np.empty((len(rows) - 1, 2 * dim))
    methods = []
    for i, (number, cells) in enumerate(rows[1:]):
        if len(cells) != len(header):
            raise ValueError(f"{name}: line {number}: expected {len(header)} values like the header, got {len(cells)}")
        for j, column in enumerate(coordinates):
            values[i, j] = _number(cells[index[column]], name, number, column)
        valid = cells[index["valid"]].lower()
        if valid not in ("0", "1", "true", "false"):
            raise ValueError(f"{name}: line {number}, column valid: expected 1 or 0, got {cells[index['valid']]!r}")
        if (valid in ("1", "true")) != bool(np.isfinite(values[i]).all()):
            raise ValueError(
                f"{name}: line {number}: valid is {cells[index['valid']]} but the coordinates say otherwise"
            )
        methods.append(cells[index["method"]])
    faces = None
    if split is not None:
        faces = np.empty((len(face_rows), 3), dtype=np.int64)
        for i, (number, cells) in enumerate(face_rows):
            if len(cells) != 3 or not all(cell.lstrip("-").isdigit() for cell in cells):
                raise ValueError(f"{face_source}: line {number}: expected three vector indices face_a,face_b,face_c")
            faces[i] = [int(cell) for cell in cells]
    try:
        return DisplacementField(values[:, :dim], values[:, dim:], np.asarray(methods, dtype=str).reshape(-1), faces)
    except ValueError as error:
        raise ValueError(f"{name}: {error}") from None
