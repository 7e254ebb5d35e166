"""What a batch keeps beside each output: the fingerprint of the inputs and options that made it,
its quality and time; and the summary table over a batch's rows.

A field ``OUTPUT`` gets a sidecar ``OUTPUT.morphomap.json``. A rerun skips a row only when the
sidecar's fingerprint equals the row's: the SHA-256 of each input file's content (a file touched
but not changed still matches; one rewritten with other content does not) and the options the job
carries (method, spacing, smoothing, the task). An output without a sidecar is recomputed: nothing
says what made it.
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
import os

from ._core import build_info
from .io.atomic import atomic_text

SIDECAR = ".morphomap.json"
# Columns of the summary table, in order; a missing value is left empty.
SUMMARY_COLUMNS = ("label", "c1", "c2", "output", "method", "status", "qm1", "qm2", "qm", "defects", "defect_kind",
                   "missed", "vectors", "seconds", "attempts", "message")


def sidecar_path(output: str) -> str:
    """The metadata file written beside ``output``."""
    return os.fspath(output) + SIDECAR


def file_digest(path: str, cache: dict | None = None) -> str:
    """The SHA-256 of ``path``'s content, hex; ``cache`` (path -> digest) spares a second read of a
    file that several rows share."""
    path = os.path.abspath(os.fspath(path))
    if cache is not None and path in cache:
        return cache[path]
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    if cache is not None:
        cache[path] = digest.hexdigest()
    return digest.hexdigest()


def fingerprint(job, task_name: str, cache: dict | None = None) -> dict:
    """What decides a job's output: its inputs' contents and its options (JSON-ready).

    An input that cannot be read gets ``None``: the job runs and reports the error itself.
    """
    inputs = []
    for path in (job.c1, job.c2):
        try:
            inputs.append(file_digest(path, cache))
        except OSError:
            inputs.append(None)
    spacing = None if job.spacing is None else [float(s) for s in job.spacing]
    smooth = None if job.smooth is None else float(job.smooth)
    return {"inputs": inputs, "method": job.method, "spacing": spacing, "smooth": smooth, "task": task_name}


def read_sidecar(output: str) -> dict | None:
    """The metadata beside ``output``, or None when there is none or it cannot be read."""
    try:
        with open(sidecar_path(output), encoding="utf-8") as handle:
            data = json.load(handle)
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def up_to_date(job, print_: dict) -> dict | None:
    """The sidecar of ``job.output`` when the output exists and was made from ``print_``, else None."""
    if not os.path.exists(job.output):
        return None
    data = read_sidecar(job.output)
    if data is None or data.get("fingerprint") != print_:
        return None
    return data


def write_sidecar(output: str, print_: dict, report: dict) -> None:
    """Record, atomically, that ``output`` was made from ``print_``, with the job's ``report``."""
    data = {"morphomap": build_info()["version"], "fingerprint": print_, **report}
    with atomic_text(sidecar_path(output)) as handle:
        json.dump(data, handle, indent=1, sort_keys=True)
        handle.write("\n")


def remove_sidecar(output: str) -> None:
    """Forget what made ``output`` before it is rewritten: a job that dies half-way must not leave
    an older fingerprint beside a newer output."""
    try:
        os.unlink(sidecar_path(output))
    except FileNotFoundError:
        pass


def _cell(value):
    if value is None:
        return ""
    if isinstance(value, float):
        return "" if math.isnan(value) else f"{value:.6g}"
    return value


def write_summary(path, results) -> None:
    """Write the summary table of a batch's ``results`` (a list of JobResult) to the CSV ``path``,
    atomically: one row per job, its quality (QM1, QM2, QM; crossings of a 2D field or folds of a
    3D one in ``defects``, named by ``defect_kind``), missed vectors, seconds, attempts and its
    message (the error of a failed job)."""
    with atomic_text(path) as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(SUMMARY_COLUMNS)
        for r in results:
            q = r.quality or {}
            row = {"label": r.job.label, "c1": r.job.c1, "c2": r.job.c2, "output": r.job.output,
                   "method": r.job.method, "status": r.status, "seconds": r.seconds, "attempts": r.attempts,
                   "message": r.message, **{k: q.get(k) for k in SUMMARY_COLUMNS if k in q}}
            writer.writerow([_cell(row.get(column)) for column in SUMMARY_COLUMNS])
