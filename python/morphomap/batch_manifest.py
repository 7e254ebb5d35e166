"""A batch's manifest: a CSV file with one pair a row, read into :class:`morphomap.batch.Job` s.

With a header, the columns are named: ``c1`` and ``c2`` (required: the frame files, relative to
the manifest's folder unless absolute), and optionally ``label`` (the row's name: its field is
``LABEL.csv`` in the output folder, and the summary table names the row by it), ``method``,
``spacing`` (one length, or one per axis separated by spaces or semicolons) and ``smooth``. An
empty cell takes the batch's default. Without a header, or under the header ``c1,c2``, a row is
``c1,c2[,method]``. Lines that begin with ``#`` and empty lines are skipped.
"""

from __future__ import annotations

import csv
import math
import os
import re

from .batch import Job

COLUMNS = ("c1", "c2", "label", "method", "spacing", "smooth")
# The summary table's file name in the output folder: no row may take it.
SUMMARY_NAME = "summary.csv"
_LABEL = re.compile(r"[A-Za-z0-9][A-Za-z0-9._+-]*")


def _number(text: str, where: str, what: str, positive: bool) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{where}: expected {what}, got {text!r}") from None
    if not (value > 0 if positive else value >= 0) or value == math.inf:
        raise ValueError(f"{where}: expected {what}, got {text!r}")
    return value


def _spacing(text: str, where: str) -> tuple:
    parts = [p for p in re.split(r"[\s;,]+", text.strip()) if p]
    if len(parts) not in (1, 2, 3):
        raise ValueError(f"{where}: expected one length, or one per axis separated by spaces or ';', got {text!r}")
    return tuple(_number(p, where, "lengths > 0", True) for p in parts)


def read_manifest(path, out, *, method="auto", spacing=None, smooth=None, methods=None) -> list:
    """The jobs of the manifest ``path``, their fields written into the folder ``out``.

    Parameters
    ----------
    path : path
        The manifest CSV file (see the module's description).
    out : path
        The output folder: a row's field is ``LABEL.csv`` there, or, without a label,
        ``NNN_C1_C2.csv`` (its row number and the frames' names).
    method, spacing, smooth
        The defaults of rows that leave these columns out or empty.
    methods : collection of str, optional
        The methods a row may name; another is refused with the row and column.

    Raises
    ------
    ValueError
        A row that is malformed, names an unknown column, repeats a label, or holds a value that
        is not valid: the message names the file, the row (counted from 1 after the header) and
        the column.
    """
    path = os.fspath(path)
    with open(path, newline="", encoding="utf-8") as handle:
        rows = [row for row in csv.reader(handle) if row and any(row) and not row[0].lstrip().startswith("#")]
    header = None
    if rows and {cell.strip().lower() for cell in rows[0]} >= {"c1", "c2"}:
        header = [cell.strip().lower() for cell in rows.pop(0)]
        unknown = [name for name in header if name not in COLUMNS]
        if unknown:
            raise ValueError(f"{path}: unknown column {unknown[0]!r}; the columns are {', '.join(COLUMNS)}")
        if len(set(header)) != len(header):
            raise ValueError(f"{path}: a column is named twice in the header {','.join(header)}")
        if header == ["c1", "c2"]:  # the plain header of rows c1,c2[,method]
            header = None
    base = os.path.dirname(os.path.abspath(path))
    jobs, labels = [], {}
    for number, row in enumerate(rows, start=1):
        where = f"{path}: row {number}"
        if header is None:
            if len(row) not in (2, 3):
                raise ValueError(f"{where}: expected c1,c2[,method] (or a header naming the columns), "
                                 f"got {len(row)} values")
            cells = dict(zip(("c1", "c2", "method"), (cell.strip() for cell in row)))
        else:
            if len(row) > len(header):
                raise ValueError(f"{where}: {len(row)} values for the {len(header)} columns {','.join(header)}")
            cells = {name: cell.strip() for name, cell in zip(header, row)}
        for name in ("c1", "c2"):
            if not cells.get(name):
                raise ValueError(f"{where}, column {name}: the frame file is missing")
        c1, c2 = (p if os.path.isabs(p) else os.path.join(base, p) for p in (cells["c1"], cells["c2"]))
        row_method = cells.get("method") or method
        if methods is not None and row_method not in methods:
            raise ValueError(f"{where}, column method: expected one of {', '.join(methods)}, got {row_method!r}")
        row_spacing = _spacing(cells["spacing"], f"{where}, column spacing") if cells.get("spacing") else spacing
        row_smooth = _number(cells["smooth"], f"{where}, column smooth", "a width >= 0", False) \
            if cells.get("smooth") else smooth
        label = cells.get("label", "")
        if label:
            if not _LABEL.fullmatch(label) or f"{label}.csv" == SUMMARY_NAME:
                raise ValueError(f"{where}, column label: expected a file-name-safe name (letters, digits, "
                                 f"'.', '_', '+', '-'; not 'summary'), got {label!r}")
            if label in labels:
                raise ValueError(f"{where}, column label: {label!r} is row {labels[label]}'s label too")
            labels[label] = number
            stem = label
        else:
            stem = f"{number:03d}_{_stem(c1)}_{_stem(c2)}"
        jobs.append(Job(c1, c2, os.path.join(os.fspath(out), stem + ".csv"), row_method, row_spacing, row_smooth,
                        label))
    return jobs


def _stem(path: str) -> str:
    return os.path.splitext(os.path.basename(path))[0]
