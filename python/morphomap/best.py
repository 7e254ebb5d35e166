"""``method="best"``: run every candidate mapping of a pair and keep the crossing-free, miss-free one
with the lowest QM.

The candidates (2D, :func:`map_curves`): normal, minimal distance and diffusion mapping, each plain,
reversed (``reverse=True``), transformed (``transform=True``) and both; ``"optimal"``; and
``"auto"`` (the paper's Algorithm 1), so that the winner's QM is never above auto's when auto is
admissible. 3D (:func:`map_surfaces`): normal, minimal distance and diffusion, plain and reversed,
and ``"auto"``. Each candidate runs on the whole pair with the same options (splitting at
crossings and contact stretches inside each candidate as usual); the choice is made per pair,
not per pair of segments.

Choice: a candidate is admissible when it has no crossings (folds in 3D), no misses and a finite
QM; the admissible one with the lowest QM wins. When none is admissible, the one with the fewest
crossings (folds), then the fewest misses, then the lowest QM wins, so a field with crossings is
never returned while a crossing-free candidate exists.

Skip rule: the candidates that solve a diffusion problem cost seconds where the others cost
milliseconds. The cheap ones run first; the diffusion candidates are skipped (``status`` says so)
when an admissible cheap one already has ``QM <= skip_below`` (default 1e-3: a field that good is
as good as the paper's best rows on its example by two orders of magnitude). ``skip_below=0``
never skips.

Candidates of one batch run in parallel threads (the core releases the GIL), ``workers`` at a time
(default: the number of CPUs).
"""

from __future__ import annotations

import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from typing import NamedTuple

import numpy as np

from ._validate import as_count

#: Default of ``skip_below``: see the module's documentation.
SKIP_BELOW = 1e-3


class Candidate(NamedTuple):
    """One row of ``field.candidates``."""

    name: str       # "normal", "reverse_normal", "transformed_diffusion", "optimal", "auto", ...
    qm1: float
    qm2: float
    qm: float
    defects: int    # crossings (2D) or folds (3D); -1 when not run
    misses: int     # vectors without a target; -1 when not run
    seconds: float  # mapping and quality
    status: str     # "won", "admissible", "crossings", "misses", "skipped", or "failed: <reason>"


def _name(method: str, reverse: bool, transform: bool) -> str:
    return ("transformed_" if transform else "") + ("reverse_" if reverse else "") + method


def _plan(methods, transforms):
    """[(name, method, reverse, transform)] in the order of the table."""
    plan = []
    for transform in transforms:
        for method in methods:
            for reverse in (False, True):
                plan.append((_name(method, reverse, transform), method, reverse, transform))
    return plan


def _run(job):
    """Maps one candidate and measures it: (field or None, Candidate)."""
    name, map_one, measure = job
    begin = time.perf_counter()
    try:
        field = map_one()
        q = measure(field)
    except (ValueError, RuntimeError) as error:  # a candidate that cannot map this pair
        reason = str(error).splitlines()[0] if str(error) else type(error).__name__
        return None, Candidate(name, math.nan, math.nan, math.nan, -1, -1, time.perf_counter() - begin,
                               f"failed: {reason}")
    defects = int(q.crossings if hasattr(q, "crossings") else q.folds)
    misses = int((~field.valid).sum())
    status = "crossings" if defects else "misses" if misses else "admissible" if math.isfinite(q.qm) else "failed: QM is NaN"
    return field, Candidate(name, float(q.qm1), float(q.qm2), float(q.qm), defects, misses,
                            time.perf_counter() - begin, status)


def _key(candidate: Candidate):
    qm = candidate.qm if math.isfinite(candidate.qm) else math.inf
    return (candidate.defects, candidate.misses, qm)


def _choose(cheap, expensive, skip_below, workers):
    """Runs the batches, applies the skip rule, returns the winning field with the table."""
    skip_below = SKIP_BELOW if skip_below is None else float(skip_below)
    if not (skip_below >= 0 and math.isfinite(skip_below)):
        raise ValueError(f"skip_below: must be a finite number >= 0, got {skip_below}")
    workers = (os.cpu_count() or 1) if workers is None else as_count(workers, "workers", 1)
    # The first candidate runs here, alone: first calls into the core from several threads at once
    # deadlocked on the one-time set-up of its array conversions (a function-local static waiting
    # for a thread that waits for the GIL; seen with a module built against an older pybind11).
    results = [_run(cheap[0])]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        results += list(pool.map(_run, cheap[1:]))
        good = [c.qm for _, c in results if c.status == "admissible"]
        if skip_below > 0 and good and min(good) <= skip_below:
            results += [(None, Candidate(name, math.nan, math.nan, math.nan, -1, -1, 0.0,
                                         f"skipped: a cheap candidate has QM <= {skip_below:g}"))
                        for name, _, _ in expensive]
        else:
            results += list(pool.map(_run, expensive))
    ran = [(field, c) for field, c in results if field is not None]
    if not ran:
        reasons = "; ".join(f"{c.name}: {c.status}" for _, c in results)
        raise ValueError(f"method 'best': no candidate could map this pair ({reasons})")
    winner = min(ran, key=lambda fc: _key(fc[1]))[1].name
    table = [c._replace(status="won") if c.name == winner else c for _, c in results]
    field = next(f for f, c in ran if c.name == winner)
    return field._with_candidates(table)


def map_best(c1, c2, *, closed=True, n=None, split=True, anchor=None, density_threshold=None,
             contact_tolerance=None, mesh_size=None, mesh_fraction=0.02, stretch_weight=None,
             skip_below=None, workers=None):
    """2D ``method="best"``: see the module's documentation. Called by :func:`map_curves`."""
    from .mapping import map_curves
    from .quality import quality

    options = dict(closed=closed, n=n, split=split, anchor=anchor, contact_tolerance=contact_tolerance,
                   mesh_size=mesh_size, mesh_fraction=mesh_fraction)

    def job(name, method, reverse=False, transform=False):
        extra = {"density_threshold": density_threshold} if method == "auto" else {}
        if method == "optimal":
            extra["stretch_weight"] = stretch_weight
        return (name, lambda: map_curves(c1, c2, method, reverse=reverse, transform=transform, **options, **extra),
                lambda field: quality(field, c1, c2, closed=closed))

    cheap = [job(*row) for row in _plan(("normal", "minimal_distance"), (False, True))]
    cheap += [job("optimal", "optimal"), job("auto", "auto")]
    expensive = [job(*row) for row in _plan(("diffusion",), (False, True))]
    return _choose(cheap, expensive, skip_below, workers)


def map_best_surfaces(s1, s2, *, mesh_size=None, skip_below=None, workers=None):
    """3D ``method="best"``: see the module's documentation. Called by :func:`map_surfaces`."""
    from .quality import quality
    from .surfaces import as_surface, map_surfaces

    s1, s2 = as_surface(s1, "s1"), as_surface(s2, "s2")

    def job(name, method, reverse=False, transform=False):
        return (name, lambda: map_surfaces(s1, s2, method, reverse=reverse, mesh_size=mesh_size),
                lambda field: quality(field, s1, s2))

    cheap = [job(*row) for row in _plan(("normal", "minimal_distance"), (False,))] + [job("auto", "auto")]
    expensive = [job(*row) for row in _plan(("diffusion",), (False,))]
    return _choose(cheap, expensive, skip_below, workers)


def candidate_table(field) -> str:
    """``field.candidates`` as an aligned text table (one line per candidate)."""
    if field.candidates is None:
        raise ValueError("field: has no candidates (made by a method other than 'best')")
    rows = [("candidate", "QM1", "QM2", "QM", "defects", "misses", "seconds", "status")]
    for c in field.candidates:
        rows.append((c.name, f"{c.qm1:.4g}", f"{c.qm2:.4g}", f"{c.qm:.4g}", str(c.defects), str(c.misses),
                     f"{c.seconds:.3f}", c.status))
    widths = np.max([[len(x) for x in row] for row in rows], axis=0)
    return "\n".join("  ".join(x.ljust(w) for x, w in zip(row, widths)).rstrip() for row in rows)
