"""Contours as labs trace them made simple: repeated points, pixel spurs and necks, a seam glitch.

A contour traced round the pixels of a mask (8-connected tracing through pixel centres) is often
not a simple curve although it bounds one object: it repeats points, runs out and back along a
one-pixel-wide spur, and passes twice through the pixel of a one-pixel neck between two lobes.
An open outline closed by a straight segment may have its first point a little across that
segment. :func:`make_simple` repairs exactly these, says what it changed, and refuses everything
else that meets itself (a figure-eight, a loop with area) with a ``ValueError``.

The rule
--------
Repairs, in this order (rows are those of the input):

1. **Repeated points**: a point equal to the one before it (closed curves: also a last point equal
   to the first) is removed.
2. **Spurs**: where the curve turns back on itself — the point after a vertex equals the point
   before it, or lies on the line of the last segment, going back (to 1e-12 of the two segments'
   lengths) — the vertex is the tip of an out-and-back run; it is removed, and so on down to the
   spur's base. A spur encloses no area, so none is lost.
3. **Necks**: a point the curve still visits more than once (the pixel of a one-pixel neck, or
   both ends of a one-pixel-wide corridor traversed both ways) is kept for each visit, each copy
   moved by ``1e-6`` of the median point spacing along the bisector of its own outside angle
   (the side away from the region for a closed curve; for an open curve whichever of the two
   consistent choices gives a simple curve). The visits come apart, the neck becomes a channel of
   that width and every lobe stays: the enclosed area changes by less than ``1e-6`` of a point
   spacing squared per moved copy. A corridor segment traversed both ways that is longer than
   three median spacings is not a neck but the jump between two objects' contours stacked into
   one array: ``ValueError`` (``morphomap.split_components`` separates them).
4. **First point across the closing segment** (closed curves only): where the only segments that
   still meet are the closing segment and the second one (``points[1]``-``points[2]``), the first
   point lies beyond the second as the outline runs, across the closing segment (an open outline
   closed by a straight segment, its first point a little off that line). The two are swapped,
   if they lie within two median spacings, the swapped curve is simple and the sliver between the
   two orders is a hair (at most 1% of the area): no point moves or is lost, and the enclosed area
   changes by that sliver (``Change.area``).
   The same for the last point and the one before it.

Whatever is left meeting itself is genuine: the curve crosses itself, or touches itself along a
segment, or a visit crosses another at a shared point. ``ValueError`` naming the argument, where
and the remedy. The result is checked with the core's exact self-intersection test.

A simple curve (no repeated consecutive points, no self-intersection by exact predicates) comes
back unchanged, bit for bit, with no changes, at the cost of one check.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from . import _core
from ._validate import as_flag, as_points
from .crossings import count_crossings
from .curves import signed_area
from .field import DisplacementField
from .queries import closest_points

#: How far each visit of a neck point is moved, relative to the median point spacing.
NECK_OPENING = 1e-6
#: A segment traversed both ways and longer than this many median spacings joins two objects.
LONGEST_CORRIDOR_STEP = 3.0
#: A turn back whose sine is below this is a spur (exactly back along the last segment).
TURN_BACK_SINE = 1e-12


class Change(NamedTuple):
    """One repair made by :func:`make_simple`.

    Attributes
    ----------
    kind : str
        ``"repeated"``, ``"spur"``, ``"neck"`` or ``"first point"`` / ``"last point"`` (across
        the closing segment).
    rows : tuple of int
        Rows of the input concerned: removed (``"repeated"``, ``"spur"``), moved (``"neck"``:
        each visit) or swapped (the point across the closing segment and its neighbour).
    where : (float, float)
        A point of the input where it happened: the first repeat, the spur's base, the neck
        point, the point across the closing segment.
    distance : float
        How far each visit of a neck was moved; how far apart the swapped points lie; 0 for
        removals.
    area : float
        How much the enclosed area changed (closed curves; 0 for removals, which bound none).
    """

    kind: str
    rows: tuple
    where: tuple
    distance: float = 0.0
    area: float = 0.0

    def __str__(self) -> str:
        at = f"({self.where[0]:.6g}, {self.where[1]:.6g})"
        rows = _rows(self.rows)
        if self.kind == "repeated":
            count = len(self.rows)
            return f"removed {count} repeated point{'s' if count > 1 else ''} ({rows})"
        if self.kind == "spur":
            return (f"removed a spur of {len(self.rows)} points ({rows}): the curve ran out from {at} and back "
                    "along the same points")
        if self.kind == "neck":
            return (f"opened a neck at {at}: the curve visited it {len(self.rows)} times ({rows}); each visit was "
                    f"moved {self.distance:.3g} apart")
        which, other = ("first", "second") if self.kind == "first point" else ("last", "one before it")
        return (f"swapped the {which} point (at {at}) and the {other} ({rows}): the {which} point lay "
                f"{self.distance:.3g} beyond it, across the closing segment, which crossed the curve there; "
                f"the enclosed area changed by {self.area:.3g}")


def _rows(rows) -> str:
    listed = ", ".join(str(r) for r in rows[:6])
    more = f", ... ({len(rows)} in all)" if len(rows) > 6 else ""
    return f"row{'s' if len(rows) > 1 else ''} {listed}{more}"


class Changes(tuple):
    """What :func:`make_simple` changed: a tuple of :class:`Change`, empty when nothing.

    ``str(changes)`` is one sentence per change, for a warning. ``changes.source_rows`` is a
    ``(M,)`` int array: the input row of each output point.
    """

    def __new__(cls, items=(), source_rows=None):
        self = super().__new__(cls, items)
        self.source_rows = np.asarray(source_rows if source_rows is not None else [], dtype=np.int64)
        return self

    def __str__(self) -> str:
        return "; ".join(str(change) for change in self) if self else "no changes"

    def __repr__(self) -> str:
        return f"Changes({tuple.__repr__(self)})"


def make_simple(points, *, closed=True):
    """Make a contour as labs trace it simple, and say what was changed.

    Repairs repeated points, one-pixel spurs and necks, and a first (or last) point lying across
    the closing segment; refuses genuine self-intersections. The rule is in the module's
    docstring (:mod:`morphomap.simple`).

    Parameters
    ----------
    points : (N, 2) float
        The curve.
    closed : bool
        Whether it is closed (by the segment from the last point to the first). Open curves have
        no closing segment, so only repeats, spurs and necks apply.

    Returns
    -------
    points : (M, 2) float
        A simple curve, ``M <= N``; the input unchanged (a copy) when it was simple already.
    changes : Changes
        A tuple of :class:`Change`, empty when nothing was changed; its ``str`` is a readable
        account, and ``changes.source_rows`` the input row of each output point.

    Raises
    ------
    ValueError
        The curve crosses itself or touches itself other than at isolated points (a figure-eight,
        a loop with area, a jump between two objects' contours), or too few points are left.
    """
    return simple_curve(points, as_flag(closed, "closed"), "points")


def simple_curve(points, closed: bool, name: str):
    """:func:`make_simple` with the argument named ``name`` in messages."""
    p = as_points(points, name)
    needed = 3 if closed else 2
    if len(p) < needed:
        raise ValueError(f"{name}: a {'closed' if closed else 'open'} curve needs at least {needed} points, "
                         f"got {len(p)}")
    repeats = np.all(p[1:] == p[:-1], axis=1)
    if not repeats.any() and not (closed and np.array_equal(p[0], p[-1])):
        if not _core.is_self_intersecting(p, closed):
            return p.copy(), Changes((), np.arange(len(p)))
    return _Repair(p, closed, name).run()


def _turns_back(u, v, q) -> bool:
    """Whether the path u -> v -> q goes back along the segment it came by."""
    d1x, d1y, d2x, d2y = v[0] - u[0], v[1] - u[1], q[0] - v[0], q[1] - v[1]
    if d1x * d2x + d1y * d2y >= 0:
        return False
    return abs(d1x * d2y - d1y * d2x) <= TURN_BACK_SINE * math.hypot(d1x, d1y) * math.hypot(d2x, d2y)


class _Repair:
    """The repairs of the module's rule on one curve, in order; ``run`` returns (points, changes)."""

    def __init__(self, p: np.ndarray, closed: bool, name: str):
        self.input, self.closed, self.name = p, closed, name
        self.changes: list[Change] = []

    def run(self):
        rows = self.drop_repeats(np.arange(len(self.input)))
        rows = self.drop_spurs(rows)
        p = self.input[rows]
        spacing = self.spacing(p)
        p = self.open_necks(p, rows, spacing)
        if self.closed and _core.is_self_intersecting(p, True):
            p = self.fix_seam(p, rows, spacing)
        if _core.is_self_intersecting(p, self.closed):
            self.refuse(p, rows)
        if self.closed and signed_area(p) == 0.0:
            raise ValueError(f"{self.name}: the closed curve encloses zero area once its repeated points and spurs "
                             "are removed; pass the boundary of a region")
        return p, Changes(self.changes, rows)

    def too_few(self, count: int, what: str):
        needed = 3 if self.closed else 2
        if count < needed:
            zero = "the closed curve encloses zero area: " if self.closed else ""
            raise ValueError(f"{self.name}: {zero}after removing {what} the curve has {count} distinct points, "
                             f"fewer than the {needed} it needs; pass the boundary of a region")

    def drop_repeats(self, rows: np.ndarray) -> np.ndarray:
        p = self.input
        keep = np.ones(len(p), dtype=bool)
        keep[1:] = np.any(p[1:] != p[:-1], axis=1)
        if self.closed:
            # A closed curve's last points equal to its first repeat it across the closing segment.
            last = len(p) - 1
            while last > 0 and (not keep[last] or np.array_equal(p[last], p[0])):
                keep[last] = False
                last -= 1
        if not keep.all():
            removed = tuple(int(r) for r in np.flatnonzero(~keep))
            self.changes.append(Change("repeated", removed, tuple(p[removed[0]].tolist())))
        self.too_few(int(keep.sum()), "repeated points")
        return rows[keep]

    def drop_spurs(self, rows: np.ndarray) -> np.ndarray:
        p = self.input
        xy = [tuple(row) for row in p[rows].tolist()]
        stack: list[int] = []  # positions in `rows`
        removed: list[int] = []
        for k, q in enumerate(xy):
            while len(stack) >= 2 and _turns_back(xy[stack[-2]], xy[stack[-1]], q):
                removed.append(stack.pop())
            if stack and xy[stack[-1]] == q:
                removed.append(k)
                continue
            stack.append(k)
        if self.closed:
            # The same across the closing segment, where the walk's two ends meet.
            while len(stack) >= 3:
                if xy[stack[-1]] == xy[stack[0]] or _turns_back(xy[stack[-2]], xy[stack[-1]], xy[stack[0]]):
                    removed.append(stack.pop())
                elif _turns_back(xy[stack[-1]], xy[stack[0]], xy[stack[1]]):
                    removed.append(stack.pop(0))
                else:
                    break
        if removed:
            self.record_spurs(sorted(removed), rows, len(xy))
        self.too_few(len(stack), "spurs (runs out and back along the same points)")
        return rows[stack]

    def record_spurs(self, removed: list[int], rows: np.ndarray, count: int):
        # Runs of consecutive removed positions (wrapping round on a closed curve) are one spur each.
        runs = [[removed[0]]]
        for k in removed[1:]:
            if k == runs[-1][-1] + 1:
                runs[-1].append(k)
            else:
                runs.append([k])
        if self.closed and len(runs) > 1 and runs[0][0] == 0 and runs[-1][-1] == count - 1:
            runs[0] = runs.pop() + runs[0]
        for run in runs:
            base = rows[(run[0] - 1) % count]
            self.changes.append(Change("spur", tuple(int(rows[k]) for k in run), tuple(self.input[base].tolist())))

    @staticmethod
    def spacing(p: np.ndarray) -> float:
        steps = np.linalg.norm(np.diff(p, axis=0), axis=1)
        return float(np.median(steps))

    def open_necks(self, p: np.ndarray, rows: np.ndarray, spacing: float) -> np.ndarray:
        _, inverse, counts = np.unique(p, axis=0, return_inverse=True, return_counts=True)
        inverse = inverse.reshape(-1)
        visits = np.flatnonzero(counts[inverse] > 1)
        if len(visits) == 0:
            return p
        self.refuse_long_corridors(p, rows, visits, spacing)
        step = NECK_OPENING * spacing
        if self.closed:
            sides = (1.0 if signed_area(p) > 0 else -1.0,)
        else:
            sides = (1.0, -1.0)
        for side in sides:
            q = p.copy()
            q[visits] += step * self.outside_directions(p, visits, side)
            if len(sides) == 1 or not _core.is_self_intersecting(q, self.closed):
                break
        groups: dict[int, list[int]] = {}
        for k in visits:
            groups.setdefault(int(inverse[k]), []).append(int(k))
        for group in sorted(groups.values()):
            moved = np.linalg.norm(q[group] - p[group], axis=1).max()
            self.changes.append(Change("neck", tuple(int(rows[k]) for k in group), tuple(p[group[0]].tolist()),
                                       distance=float(moved), area=abs(signed_area(q) - signed_area(p)) / len(groups)
                                       if self.closed else 0.0))
        return q

    def outside_directions(self, p: np.ndarray, visits: np.ndarray, side: float) -> np.ndarray:
        """Unit vectors along the bisector of each visit's outside angle (on the right of the
        direction of travel for ``side`` +1, as outside a counter-clockwise curve)."""
        n = len(p)
        out = np.empty((len(visits), 2))
        for i, k in enumerate(visits):
            here = p[k]
            before = p[k - 1] if (k > 0 or self.closed) else None
            after = p[(k + 1) % n] if (k < n - 1 or self.closed) else None
            if before is None or after is None:
                # An open curve's end: draw it back along its own segment.
                towards = (after if before is None else before) - here
                out[i] = towards / np.linalg.norm(towards)
                continue
            a = math.atan2(*(before - here)[::-1])
            b = math.atan2(*(after - here)[::-1])
            start, end = (a, b) if side > 0 else (b, a)
            angle = (end - start) % (2 * math.pi) or 2 * math.pi
            middle = start + angle / 2
            out[i] = (math.cos(middle), math.sin(middle))
        return out

    def refuse_long_corridors(self, p, rows, visits, spacing):
        n = len(p)
        segments = {}
        last = n if self.closed else n - 1
        repeated = set(int(k) for k in visits)
        for k in range(last):
            j = (k + 1) % n
            if k in repeated and j in repeated:
                segments[(tuple(p[k]), tuple(p[j]))] = k
        for (a, b), k in segments.items():
            if (b, a) in segments and math.dist(a, b) > LONGEST_CORRIDOR_STEP * spacing:
                raise ValueError(
                    f"{self.name}: the curve runs from ({a[0]:.6g}, {a[1]:.6g}) to ({b[0]:.6g}, {b[1]:.6g}) and back "
                    f"(rows {int(rows[k])} and {int(rows[segments[(b, a)]])}), a jump of {math.dist(a, b):.3g} "
                    f"against a median point spacing of {spacing:.3g}: the contours of several objects joined into "
                    "one array, which make_simple does not join; pass one object's curve "
                    "(morphomap.split_components(points) separates them)")

    def fix_seam(self, p: np.ndarray, rows: np.ndarray, spacing: float) -> np.ndarray:
        n = len(p)
        pairs = {tuple(pair) for pair in _core.crossing_pairs(p, np.roll(p, -1, axis=0)).tolist()}
        if n < 5 or pairs not in ({(1, n - 1)}, {(n - 3, n - 1)}):
            return p
        first = pairs == {(1, n - 1)}
        # The first point lies beyond the second as the outline runs (or the last before the one
        # before it): in the other order the two need not cross the closing segment.
        k, j = (0, 1) if first else (n - 1, n - 2)
        if not np.linalg.norm(p[k] - p[j]) <= 2 * spacing:
            return p
        order = np.arange(n)
        order[[k, j]] = order[[j, k]]
        q = p[order]
        # A hair across, not a loop: the sliver between the two orders is a small part of the area
        # (the limb outlines': 1e-4 to 1.4e-3; else the crossing is genuine and refused).
        sliver = abs(signed_area(q) - signed_area(p))
        if sliver > 1e-2 * abs(signed_area(q)) or _core.is_self_intersecting(q, True):
            return p
        rows[:] = rows[order]
        self.changes.append(Change("first point" if first else "last point", (int(rows[j]), int(rows[k])),
                                   tuple(p[k].tolist()), distance=float(np.linalg.norm(p[k] - p[j])),
                                   area=abs(signed_area(q) - signed_area(p))))
        return q

    def refuse(self, p: np.ndarray, rows: np.ndarray):
        n = len(p)
        pairs = _core.crossing_pairs(p, np.roll(p, -1, axis=0))
        if not self.closed:
            pairs = pairs[(pairs < n - 1).all(axis=1)]
        where = ""
        if len(pairs):
            i, j = (int(v) for v in pairs[0])
            where = (f": {len(pairs)} pair{'s' if len(pairs) > 1 else ''} of its segments meet, the first the "
                     f"segments from row {int(rows[i])} ({p[i, 0]:.6g}, {p[i, 1]:.6g}) and from row {int(rows[j])} "
                     f"({p[j, 0]:.6g}, {p[j, 1]:.6g})")
        raise ValueError(
            f"{self.name}: the curve crosses itself or runs along itself{where}. That is a genuine "
            "self-intersection (a figure-eight, a loop with area), which morphomap.make_simple does not repair: it "
            "repairs only repeated points, one-pixel spurs and necks (the curve touching itself at isolated points) "
            "and a first point across the closing segment. Pass the boundary of one region without self-crossings "
            "(check the segmentation; morphomap.split_components separates stacked contours)")


def put_back(field, c1, c2, repaired, changes, closed: bool):
    """The ``field`` mapped between the ``repaired`` curves (``(r1, r2)``, as :func:`make_simple`
    made ``c1`` and ``c2``, with their ``changes``, ``None`` for a curve left as it was) put back
    onto the curves as given, unless that adds crossings: start points the repair had moved (a
    neck's visits, a first point across the closing segment) where ``c1`` has them, and split
    points inserted on a segment that the seam repair moved (farther from ``c1`` than a neck's
    opening: not points of ``c1``) dropped; ends at their closest point of ``c2`` (they move by
    at most what the repair moved ``c2``)."""
    (r1, r2), (changes1, changes2) = repaired, changes
    starts, ends, method = np.array(field.starts), np.array(field.ends), field.method
    source = r1
    if changes1 is not None:
        source = as_points(c1, "c1")[changes1.source_rows]
        keep = _back_onto(starts, r1, source, as_points(c1, "c1"), closed)
        starts, ends, method = starts[keep], ends[keep], method[keep]
    if changes2 is not None:
        valid = np.isfinite(ends).all(axis=1)
        target = as_points(c2, "c2")
        onto = ends[valid]
        _back_onto(onto, r2, target[changes2.source_rows], target, closed, snap=True)
        ends[valid] = onto
    if count_crossings(starts, ends) > count_crossings(field.starts, field.ends):
        return DisplacementField(field.starts, field.ends, field.method, source=r1, closed=closed)
    return DisplacementField(starts, ends, method, source=source, closed=closed)


def _back_onto(points, repaired, kept, given, closed, *, snap=False):
    """Puts ``points`` found on the ``repaired`` curve back onto the curve as ``given``, in place:
    a point equal to a repaired vertex that moved goes where that vertex was (``kept``: the given
    rows the repair kept); the others go to their closest point of ``given``: all with ``snap``,
    else those within a neck's opening of it. Returns which points are on ``given`` now."""
    moved = np.zeros(len(points), dtype=bool)
    for k in np.flatnonzero(np.any(kept != repaired, axis=1)):
        at = np.all(points == repaired[k], axis=1)
        points[at], moved[at] = kept[k], True
    hits = closest_points(points, given, closed=closed)
    near = ~moved & (hits.distances <= 2 * NECK_OPENING * _Repair.spacing(repaired))
    off = ~moved if snap else near
    points[off] = hits.points[off]
    return moved | off
