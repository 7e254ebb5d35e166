"""``method="best"``: run every candidate mapping of a pair and keep, per subproblem, the
crossing-free, miss-free one with the lowest QM.

The candidates (2D, :func:`map_curves`): normal, minimal distance and diffusion mapping, each plain,
reversed (``reverse=True``), transformed (``transform=True``) and both; ``"optimal"``; and
``"auto"`` (the default, itself a per-piece choice among the cheap candidates). 3D
(:func:`map_surfaces`): normal, minimal distance and diffusion, plain and reversed, ``"optimal"`` and
``"auto"``.
Each candidate runs once on the whole pair with the same options (splitting at crossings and
contact stretches inside it as usual).

Subproblems (2D): the pieces between the split points at the curves' crossings and contact
stretches, as ``map_curves`` splits them (the core's ``split_curves``: one rule for both). On each
piece every candidate's vectors from that stretch of C1 are measured on their own, as a field
between the two open pieces with the split points' own vectors at both ends: QM1, QM2, QM,
crossings and misses (``field.piece_candidates``). A candidate whose vectors leave the piece (an
end on another piece of C2: the transformed candidates split their moved C1 at other points) does
not compete there; one without any vector from the piece's points of C1 counts them as missed
(``"no vectors"``). Each piece keeps its winner (the rule below); the winners' vectors, with the
split points' own (from a forward candidate: a crossing onto itself, a contact stretch's points to
their closest points), make the ``"per_piece"`` field, which is measured as a whole and competes
with the whole-pair candidates by the same rule, so that a crossing between two pieces' winners or
a QM that the pieces' choice does not lower never wins over a whole candidate. Curves that do not
meet are one piece (no ``"per_piece"`` row). With ``n`` the candidates split the resampled curves,
whose crossings are not on the given ones: the choice is then per pair. In 3D the pair is one
subproblem.

Choice: a candidate is admissible when it has no crossings (folds in 3D), no misses and a finite
QM; the admissible one with the lowest QM wins. When none is admissible, the one with the fewest
crossings (folds), then the fewest misses, then the lowest QM wins, so a field with crossings is
never returned while a crossing-free candidate exists. Ties go to the earlier row of the table
(the whole-pair candidates before ``"per_piece"``). ``auto`` is a candidate, so the winner's QM is
never above auto's when auto is admissible.

Skip rule: the candidates that solve a diffusion problem cost seconds where the others cost
milliseconds. The cheap ones run first; the diffusion candidates are skipped (``status`` says so)
when an admissible cheap one already has ``QM <= skip_below`` over the whole pair (default 1e-3: a
field that good is as good as the paper's best rows on its example by two orders of magnitude).
``skip_below=0`` never skips.

Candidates of one batch run in parallel threads (the core releases the GIL), ``workers`` at a time
(default: the number of CPUs).
"""

from __future__ import annotations

import math
import os
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from typing import NamedTuple

import numpy as np

from . import _core
from ._validate import as_count, as_flag, as_points
from .chooser import CHOOSERS
from .field import DisplacementField
from .mapping import as_contact_tolerance, map_curves
from .prepared import as_surface
from .quality import quality
from .queries import closest_points
from .surfaces import map_surfaces

#: Default of ``skip_below``: see the module's documentation.
SKIP_BELOW = 1e-3


class Candidate(NamedTuple):
    """One row of ``field.candidates``."""

    name: str       # "normal", "reverse_normal", "transformed_diffusion", "optimal", "auto", ..., "per_piece"
    qm1: float
    qm2: float
    qm: float
    defects: int    # crossings (2D) or folds (3D); -1 when not run
    misses: int     # vectors without a target; -1 when not run
    seconds: float  # mapping and quality
    status: str     # "won", "admissible", "crossings", "misses", "skipped", or "failed: <reason>"


class PieceCandidate(NamedTuple):
    """One row of ``field.piece_candidates``: one candidate on one piece (2D)."""

    piece: int      # index of the piece, in order along C1
    name: str
    qm1: float
    qm2: float
    qm: float
    defects: int    # crossings among the piece's vectors (with the split points' own)
    misses: int
    status: str     # "won", "admissible", "crossings", "misses", "no vectors", "leaves the piece",
                    # or "failed: <reason>"


def _name(method: str, reverse: bool, transform: bool) -> str:
    return ("transformed_" if transform else "") + ("reverse_" if reverse else "") + method


# The core's method table has no column for what a candidate costs or for which one leads a tie,
# so these are the only method names written here; every other choice below reads the table.
#: The candidate that comes first in its batch, so that ties go to it: the paper's first choice
#: (normal mapping leads its Algorithm 1).
_LEADS = "normal"
#: The algorithm that solves a Laplace problem: seconds, where the others take milliseconds.
_SOLVES_PDE = "diffusion"


def _plan(form: str, transforms):
    """best's candidates for ``form`` (``"curves"``, ``"surfaces"``) from the core's method table,
    as ``(cheap, expensive)``, each ``[(name, method, reverse, transform)]`` in the order of the
    candidate table: the paper's basic algorithms that both forms have, each plain and, having a
    reversed form, reversed, for each of ``transforms`` (normal mapping first); then the form's basic
    algorithms beyond the paper, plain; then its workflows beyond the paper (the default). The
    ones that solve a Laplace problem are the expensive batch."""
    rows = [row for row in _core.METHODS if getattr(row, form)]
    common = sorted((row for row in rows if row.basic and row.from_paper and row.curves and row.surfaces),
                    key=lambda row: row.name != _LEADS)

    def variants(group):
        return [(_name(row.name, reverse, transform), row.name, reverse, transform)
                for transform in transforms for row in group
                for reverse in ((False, True) if row.backward else (False,))]

    beyond = [row for row in rows if not row.from_paper]
    plain = [(row.name, row.name, False, False) for row in beyond if row.basic]
    plain += [(row.name, row.name, False, False) for row in beyond if not row.basic]
    return (variants([row for row in common if row.name != _SOLVES_PDE]) + plain,
            variants([row for row in common if row.name == _SOLVES_PDE]))


#: The candidates of each dimension: 2D with and without Appendix A's transform, 3D without.
_CURVE_PLAN = _plan("curves", (False, True))
_SURFACE_PLAN = _plan("surfaces", (False,))
#: The options that only some candidates are given: ``density_threshold`` the workflows (the
#: paper's density rule), ``stretch_weight`` the basic algorithms beyond the paper (the
#: order-preserving matching's weight; the default's own matching keeps its default).
_TAKES = {row.name: {"density_threshold": not row.basic, "stretch_weight": row.basic and not row.from_paper}
          for row in _core.METHODS}


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
    status = ("crossings" if defects else "misses" if misses
              else "admissible" if math.isfinite(q.qm) else "failed: QM is NaN")
    return field, Candidate(name, float(q.qm1), float(q.qm2), float(q.qm), defects, misses,
                            time.perf_counter() - begin, status)


def _key(candidate: Candidate):
    qm = candidate.qm if math.isfinite(candidate.qm) else math.inf
    return (candidate.defects, candidate.misses, qm)


def _run_all(cheap, expensive, skip_below, workers):
    """Runs the batches and applies the skip rule: [(field or None, Candidate)] in table order."""
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
    return results


def _pick(results, piece_rows=None):
    """The winning field of [(field or None, Candidate)], carrying the table."""
    ran = [(field, c) for field, c in results if field is not None]
    if not ran:
        reasons = "; ".join(f"{c.name}: {c.status}" for _, c in results)
        raise ValueError(f"method 'best': no candidate could map this pair ({reasons})")
    best = min(ran, key=lambda fc: _key(fc[1]))[1]
    winner = best.name
    if best.defects or best.misses:
        # Every candidate has defects: the least bad is returned, but never silently.
        warnings.warn(f"method 'best': every candidate has defects (crossing pairs in 2D, folded triangles in "
                      f"3D) or misses; {winner} has {best.defects} and {best.misses} (see field.candidates)",
                      UserWarning, stacklevel=4)
    table = [c._replace(status="won") if c.name == winner else c for _, c in results]
    field = next(f for f, c in ran if c.name == winner)
    return field._with_candidates(table, piece_rows)


def _choose(cheap, expensive, skip_below, workers):
    """Runs the batches, applies the skip rule, returns the winning field with the table."""
    return _pick(_run_all(cheap, expensive, skip_below, workers))


#: Forward, untransformed cheap candidates: their vectors at the split points are the split's own.
_FIXED_FROM = frozenset(name for name, _, reverse, transform in _CURVE_PLAN[0] if not (reverse or transform))


def _per_piece(results, split, c1, c2, closed):
    """The per-piece choice: ((field, Candidate "per_piece") or None, [PieceCandidate])."""
    begin = time.perf_counter()
    ran = [(field, c) for field, c in results if field is not None]
    labels = []
    for field, _ in ran:
        at_start = _core.piece_labels(split, field.starts, True)
        at_end = _core.piece_labels(split, field.ends, False)
        labels.append((np.asarray(at_start["piece"]), at_start["along"], np.asarray(at_end["piece"]), at_end["along"],
                       np.isfinite(field.starts).all(axis=1), np.isfinite(field.ends).all(axis=1)))
    rows, chosen = [], []
    for p, piece in enumerate(split.pieces):
        scores = []
        for (field, c), (sp, sa, ep, ea, has_start, has_end) in zip(ran, labels):
            own = (sp == p) | (~has_start & (ep == p))
            if (own & has_start & has_end & (ep != p) & (ep != -1)).any():
                rows.append(PieceCandidate(p, c.name, math.nan, math.nan, math.nan, -1, -1, "leaves the piece"))
                continue
            members = np.flatnonzero(own)
            # No vector from a stretch of C1 that has points (a reverse candidate whose points of C2
            # all land elsewhere): the piece is not mapped, its points count as missed. (The two
            # split points' own vectors alone would measure as a perfect field.)
            unmapped = len(piece.source) - piece.begin_meeting - piece.end_meeting
            if len(members) == 0 and unmapped > 0:
                rows.append(PieceCandidate(p, c.name, math.nan, math.nan, math.nan, 0, unmapped, "no vectors"))
                continue
            # Along the piece (a reverse miss by its point on C2, scaled to C1's piece).
            along = np.where(has_start[members], sa[members],
                             ea[members] * piece.source_length / max(piece.target_length, 1e-300))
            members = members[np.argsort(along, kind="stable")]
            starts, ends = [field.starts[members]], [field.ends[members]]
            if piece.begin_meeting:
                starts.insert(0, piece.source[:1]), ends.insert(0, piece.target[:1])
            if piece.end_meeting:
                starts.append(piece.source[-1:]), ends.append(piece.target[-1:])
            sub = DisplacementField(np.vstack(starts), np.vstack(ends), "uniform")
            try:
                q = quality(sub, piece.source, piece.target, closed=False)
            except ValueError as error:
                rows.append(PieceCandidate(p, c.name, math.nan, math.nan, math.nan, -1, -1,
                                           f"failed: {str(error).splitlines()[0]}"))
                continue
            misses = int((~field.valid[members]).sum())
            status = ("crossings" if q.crossings else "misses" if misses else
                      "admissible" if math.isfinite(q.qm) else "failed: QM is NaN")
            row = PieceCandidate(p, c.name, float(q.qm1), float(q.qm2), float(q.qm), int(q.crossings), misses, status)
            rows.append(row)
            scores.append((row, field, members))
        if not scores:
            return None, rows
        row, field, members = min(scores, key=lambda s: _key(s[0]))
        rows[rows.index(row)] = row._replace(status="won")
        chosen.append((row.name, field, members))

    # The split points' own vectors are the same in every forward, untransformed candidate: from
    # the one that won the most pieces (the first on a tie).
    forward = [(f, c.name) for f, c in ran if c.name in _FIXED_FROM]
    if not forward:
        return None, rows
    wins = [name for name, _, _ in chosen]
    fixed_field = max(forward, key=lambda fc: wins.count(fc[1]))[0]
    sp = labels[[f for f, _ in ran].index(fixed_field)][0]
    fixed = np.flatnonzero((sp == -1) & np.isfinite(fixed_field.starts).all(axis=1))
    parts = [(fixed_field, fixed)] + [(field, members) for _, field, members in chosen]
    starts = np.vstack([f.starts[m] for f, m in parts])
    ends = np.vstack([f.ends[m] for f, m in parts])
    method = np.concatenate([f.method[m] for f, m in parts])
    # In the order of the start points along C1, as map_curves gives them (misses with no start last).
    key = np.full(len(starts), np.inf)
    found = np.isfinite(starts).all(axis=1)
    key[found] = closest_points(starts[found], c1, closed=closed).arc_lengths
    order = np.argsort(key, kind="stable")
    field = DisplacementField(starts[order], ends[order], method[order], source=c1, closed=closed)
    q = quality(field, c1, c2, closed=closed)
    misses = int((~field.valid).sum())
    status = ("crossings" if q.crossings else "misses" if misses else
              "admissible" if math.isfinite(q.qm) else "failed: QM is NaN")
    candidate = Candidate("per_piece", float(q.qm1), float(q.qm2), float(q.qm), int(q.crossings), misses,
                          time.perf_counter() - begin, status)
    return (field, candidate), rows


def map_best(c1, c2, *, closed=True, n=None, split=True, anchor=None, density_threshold=None,
             contact_tolerance=None, mesh_size=None, mesh_fraction=0.02, stretch_weight=None,
             skip_below=None, workers=None):
    """2D ``method="best"``: see the module's documentation. Called by :func:`map_curves`."""
    options = dict(closed=closed, n=n, split=split, anchor=anchor, contact_tolerance=contact_tolerance,
                   mesh_size=mesh_size, mesh_fraction=mesh_fraction)

    given = {"density_threshold": density_threshold, "stretch_weight": stretch_weight}

    def job(name, method, reverse=False, transform=False):
        extra = {option: value for option, value in given.items() if _TAKES[method][option]}
        return (name, lambda: map_curves(c1, c2, method, reverse=reverse, transform=transform, **options, **extra),
                lambda field: quality(field, c1, c2, closed=closed))

    cheap, expensive = ([job(*row) for row in batch] for batch in _CURVE_PLAN)
    results = _run_all(cheap, expensive, skip_below, workers)
    # With n the candidates split the resampled curves: per pair (see above). Without any field
    # _pick says why each candidate failed.
    if n is not None or all(field is None for field, _ in results):
        return _pick(results, ())
    c1, c2 = as_points(c1, "c1"), as_points(c2, "c2")
    split_at = _core.split_curves(c1, c2, closed, as_flag(split, "split"),
                                  as_contact_tolerance(contact_tolerance))
    if len(split_at.pieces) < 2:
        return _pick(results, ())
    assembled, piece_rows = _per_piece(results, split_at, c1, c2, closed)
    return _pick(results + ([assembled] if assembled else []), tuple(piece_rows))


def map_best_surfaces(s1, s2, *, mesh_size=None, repeatable=True, skip_below=None, workers=None):
    """3D ``method="best"``: see the module's documentation; the pair is one subproblem (no
    per-piece choice, no ``piece_candidates``). Called by :func:`map_surfaces`."""
    s1, s2 = as_surface(s1, "s1"), as_surface(s2, "s2")

    def job(name, method, reverse=False, transform=False):
        return (name, lambda: map_surfaces(s1, s2, method, reverse=reverse, mesh_size=mesh_size,
                                           repeatable=repeatable, progress=False),
                lambda field: quality(field, s1, s2))

    cheap, expensive = ([job(*row) for row in batch] for batch in _SURFACE_PLAN)
    return _choose(cheap, expensive, skip_below, workers)


def candidate_table(field, *, pieces=False) -> str:
    """``field.candidates`` as an aligned text table (one line per candidate); with ``pieces=True``
    ``field.piece_candidates`` (one line per candidate and piece)."""
    if field.candidates is None:
        raise ValueError("field: has no candidates (made by a method other than 'best')")
    if pieces:
        rows = [("piece", "candidate", "QM1", "QM2", "QM", "defects", "misses", "status")]
        for c in field.piece_candidates or ():
            rows.append((str(c.piece), c.name, f"{c.qm1:.4g}", f"{c.qm2:.4g}", f"{c.qm:.4g}", str(c.defects),
                         str(c.misses), c.status))
    else:
        rows = [("candidate", "QM1", "QM2", "QM", "defects", "misses", "seconds", "status")]
        for c in field.candidates:
            rows.append((c.name, f"{c.qm1:.4g}", f"{c.qm2:.4g}", f"{c.qm:.4g}", str(c.defects), str(c.misses),
                         f"{c.seconds:.3f}", c.status))
    widths = np.max([[len(x) for x in row] for row in rows], axis=0)
    return "\n".join("  ".join(x.ljust(w) for x, w in zip(row, widths)).rstrip() for row in rows)


CHOOSERS.update(curves=map_best, surfaces=map_best_surfaces)
