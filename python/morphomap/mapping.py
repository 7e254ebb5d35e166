"""Displacement fields between two curves (2D): the paper's algorithms and extensions."""

from __future__ import annotations

from . import _core
from ._validate import as_choice, as_flag, as_integer, as_point, as_real
from .chooser import BEST, CHOOSERS
from .field import DisplacementField
from .prepared import PreparedCurve, as_curve, repaired_curves
from .simple import put_back

#: What ``method`` takes: the core's registry (``kMapMethods``), then ``"best"``, which is Python's.
CURVE_METHODS = tuple(_core.MAP_METHODS) + (BEST,)


def as_contact_tolerance(value) -> float:
    """``contact_tolerance`` as the core takes it: None is the core's default (any negative
    number there); a negative number passed here is refused rather than read as the default, the
    one rule of Python's own. Finiteness is the core's rule."""
    if value is None:
        return -1.0
    value = as_real(value, "contact_tolerance", 0.0)
    if value < 0:
        raise ValueError(f"contact_tolerance: must be a length >= 0 (None for the default), got {value}")
    return value


def _core_options(n, anchor, density_threshold, contact_tolerance, mesh_size, mesh_fraction, stretch_weight):
    """The options as the core takes them. Only their types are checked here: the core checks the
    values (``validate_options`` in ``morphomap/mapping.hpp``) and its messages are the ones users
    see; ``contact_tolerance`` has one rule of Python's own (:func:`as_contact_tolerance`)."""
    return dict(
        n=as_integer(n, "n", 0),
        anchor=None if anchor is None else as_point(anchor, "anchor", allow_nan=True),
        density_threshold=as_real(density_threshold, "density_threshold", 0.0),
        contact_tolerance=as_contact_tolerance(contact_tolerance),
        mesh_size=as_real(mesh_size, "mesh_size", 0.0),
        mesh_fraction=as_real(mesh_fraction, "mesh_fraction", 0.02),
        stretch_weight=as_real(stretch_weight, "stretch_weight", _core.DEFAULT_STRETCH_WEIGHT),
    )


def map_curves(c1, c2, method="auto", *, closed=True, n=None, reverse=False, transform=False,
               split=True, anchor=None, density_threshold=None, contact_tolerance=None,
               mesh_size=None, mesh_fraction=0.02, stretch_weight=None, skip_below=None,
               workers=None) -> DisplacementField:
    """Map curve ``c1`` (time t) onto curve ``c2`` (time t + dt).

    Parameters
    ----------
    c1, c2 : (N, 2) float or PreparedCurve
        The curves, both closed unless ``closed=False`` (open curves are expected to run the same
        way: start maps towards start). Two :class:`PreparedCurve` skip the checks and index
        building they have done once (prepared as ``closed`` says); one alone is used as its
        points.
    method : {"auto", "minimal_distance", "normal", "diffusion", "uniform", "optimal", "paper", "best"}
        ``"minimal_distance"``: each start point to its closest point on C2.
        ``"normal"``: the line through each start point along its normal, both directions, to its
        nearest intersection with C2; NaN where it meets nothing.
        ``"uniform"``: the arc-length fraction of each start point from an anchor on C1 to the
        same fraction from the corresponding anchor on C2. Anchors: the ends of open curves; an
        intersection point of closed curves; else ``anchor``; else the cyclic shift of C2 that
        minimises the sum of squared displacements of equally spaced points.
        ``"diffusion"``: streamlines of Laplace's equation between the curves (c = 1 on C1, 0 on C2;
        see :func:`solve_diffusion`) from each start point to C2.
        ``"auto"`` (the default): on each pair of segments between split points (or the whole
        pair), the candidate without crossings (counted with the split points' own vectors) or
        misses and of lowest QM on that pair, among normal mapping, ``"optimal"``, minimal
        distance, and reverse minimal distance and reverse optimal carried onto the segment's
        start points (each end the same fraction of the way along C2 between the reverse vectors
        either side; milliseconds); where none of these qualifies with QM <= 1, also diffusion and
        reverse diffusion carried so (tenths of a second). Every candidate maps the segment's own
        start points, so the field has one vector per point of C1 (and per
        crossing), in order along C1. Where no candidate qualifies on a pair, or the pairs' fields
        cross each other, :class:`GeometryError` says how many start points and where: the
        default never returns a crossing or incomplete field. Without ``n`` or ``reverse`` it
        also maps C1 moved near C2 by
        Appendix A's similarity without its greedy search (open curves: ends onto ends; closed:
        scaled to C2's area, centroid onto centroid), carried back onto C1's points, and keeps
        that field where it has no crossings on the curves as given and a lower QM. With
        ``transform=True`` it maps the transformed C1 only, and raises where the field carried
        back crosses. Why not Algorithm 1: on real outlines its reverse diffusion vectors cross
        where the streamlines fan into a lobe, and they start from C2's points (bench/README.md,
        "Real 2D outlines").
        ``"paper"``: the paper's Algorithm 1 as stated (Tables 1 and 2 and its figures): split at
        intersections, normal mapping on each pair of segments, and reverse diffusion for a pair
        where normal mapping gives crossings or misses. Where reverse diffusion fails on a pair
        (its region cannot be meshed, streamlines stall), it still answers: diffusion (also
        crossing-free streamlines), else the normal mapping if it missed nothing (crossings and
        all), else minimal distance. ``field.method`` tells which algorithm made each vector
        (``"reverse_diffusion"`` and so on for vectors found from C2).
        ``"optimal"`` (beyond the paper): an order-preserving matching of each pair of segments
        between split points (crossings and contact stretches, as above), or of the whole closed
        curves cut open where the best cyclic shift puts C1's first point: the ends follow C2 in
        the order of the start points and reach all of it, found by dynamic programming to
        minimise ``sum |p_i - P_i|^2 / g^2 + stretch_weight * sum (L_i / (alpha l_i) - 1)^2``
        (g^2: the mean squared distance from the start points to C2; the second sum is the
        paper's QM1 term over consecutive vectors). The ends are chosen among 4 to 8 equally
        spaced positions on C2 per start point (the matching's resolution); coarse to fine, so
        that 10^4 points per curve take well under a second. Guaranteed: the order (the ends run
        along C2 in the order of the start points, every part of it reached) and no crossings
        within a pair of segments. Each vector must lie inside the region between its two
        segments (bounded by them and the vectors joining their ends; whole closed curves: the
        ring between them cut along the first vector); where that region is a simple polygon no
        two such vectors can cross, by construction. Where it is not (the segments or the joining
        vectors meet elsewhere), or no such path exists at the matching's resolution (a deep
        narrow bud that few start points face), the field is kept only if an exact count finds no
        crossing; otherwise ``GeometryError`` ("no crossing-free order-preserving matching"):
        ``"optimal"`` never returns crossings within a pair of segments (pairs whose regions
        overlap are not checked against each other). See ``monotone_match`` in the C++ header
        ``morphomap/optimal.hpp``.
        ``"best"`` (beyond the paper): runs every candidate — normal, minimal distance, diffusion,
        each plain, reversed, transformed and both, ``"optimal"`` and ``"auto"`` — and keeps, on
        each piece between the split points (as above), the one without crossings or misses of
        lowest QM there; the pieces' winners together (``"per_piece"``) compete with the whole
        candidates, and the field without crossings or misses of lowest QM is returned (see
        :mod:`morphomap.best`). ``field.candidates`` is the table of the whole candidates,
        ``field.piece_candidates`` that per piece, ``field.method`` names the algorithm of each
        vector.
    n : int, optional
        Resample both curves to ``n`` equally spaced points first (linear, the paper's
        preprocessing); by default the given points of the source curve are the start points.
        The points found on the resampled curves are then put onto ``c1`` and ``c2`` as given
        (their closest points: the resampled polylines cut the corners), so that
        ``quality(field, c1, c2)`` measures the field on the curves you passed.
    reverse : bool
        Map C2 -> C1 with the chosen algorithm and flip the vectors: starts lie on C1, ends on
        C2, in the order of C2's points.
    transform : bool
        Appendix A: scale C1 about its centroid to the area of C2 and align it rigidly to maximise
        the overlap (open curves: the similarity that takes C1's ends onto C2's), map, then carry
        the start points back onto the original C1.
    split : bool
        Where the curves cross, split both at the intersection points and map each pair of
        segments on its own; the intersection points are inserted as start points that map onto
        themselves. No effect when they do not cross.
    anchor : (2,) float, optional
        Uniform mapping of closed curves that do not cross: the point of C1 nearest to ``anchor``
        maps onto the point of C2 nearest to it.
    density_threshold : float, optional
        ``"paper"`` only, off by default: the paper's density rule. Where the start points of a pair
        of segments are denser than this — the mean distance from them to C2 over their mean
        spacing along C1, i.e. start points per gap — reverse minimal distance is tried before
        normal mapping (reverse diffusion still replaces it if it crosses or misses). The paper
        gives no number; 5 (five points per gap) is a reasonable start.
    contact_tolerance : float, optional
        Where the curves touch or run together closer than this — consecutive frames segmented
        on one pixel grid share whole stretches where the tissue did not move — they are split
        there, as at an intersection (whatever ``split`` says), and the start points on the
        stretch map to their closest point on C2 (``field.method`` says ``"minimal_distance"``).
        Default: 1% of the finer of the two curves' median point spacings; 0: exact contact only.
    mesh_size, mesh_fraction : float, optional
        The diffusion mesh (also within ``"auto"`` and ``"paper"``), as in :func:`solve_diffusion`.
    stretch_weight : float, optional
        ``"optimal"`` (also within ``"best"``): the weight of the stretch term against the
        squared displacements, default 10 (``_core.DEFAULT_STRETCH_WEIGHT``); 0 gives the
        nearest order-preserving matching, large values the piecewise uniform one.
    skip_below, workers : optional
        ``"best"`` only: see :func:`morphomap.best.map_best`.

    Both curves must be simple: one loop each, not meeting itself (``ValueError`` naming the
    curve otherwise, with the count; :func:`split_components` separates the loops of several
    objects joined into one array). A contour as labs trace it — repeated points, one-pixel spurs
    and necks, a first point across the closing segment — is mapped as :func:`make_simple`
    repairs it, with one ``UserWarning`` saying what was changed; start points the repair moved
    are put back on ``c1``'s own points, removed ones have no vector.

    Returns
    -------
    DisplacementField
    """
    closed = as_flag(closed, "closed")
    method = as_choice(method, "method", CURVE_METHODS)
    if method == BEST:
        if as_flag(reverse, "reverse") or as_flag(transform, "transform"):
            raise ValueError(f"reverse/transform: method {BEST!r} tries the reversed and transformed forms itself; "
                             "leave both False")
        # Checked here, as a candidate that refuses an option would only drop out of the choice.
        _core.validate_options(closed, **_core_options(n, anchor, density_threshold, contact_tolerance, mesh_size,
                                                        mesh_fraction, stretch_weight))
        (c1, c2), _ = repaired_curves(c1, c2, closed, stacklevel=2)
        return CHOOSERS["curves"](as_curve(c1, "c1"), as_curve(c2, "c2"), closed=closed, n=n, split=split,
                                  anchor=anchor, density_threshold=density_threshold,
                                  contact_tolerance=contact_tolerance, mesh_size=mesh_size,
                                  mesh_fraction=mesh_fraction, stretch_weight=stretch_weight, skip_below=skip_below,
                                  workers=workers)
    if skip_below is not None or workers is not None:
        raise ValueError(f"skip_below/workers: only for method {BEST!r}")
    options = _core_options(n, anchor, density_threshold, contact_tolerance, mesh_size, mesh_fraction, stretch_weight)
    # Finiteness is the core's rule (require_curve, the same message): converted only here.
    source = as_curve(c1, "c1", allow_nan=True)
    if isinstance(c1, PreparedCurve) and isinstance(c2, PreparedCurve):
        core, curves = _core.map_prepared_curves, (c1._prepared, c2._prepared)
    else:
        core, curves = _core.map_curves, (source, as_curve(c2, "c2", allow_nan=True))
    flags = dict(reverse=as_flag(reverse, "reverse"), transform=as_flag(transform, "transform"),
                 split=as_flag(split, "split"), **options)
    try:
        record = core(*curves, method, closed, **flags)
    except ValueError as error:
        # Not simple: a contour as traced (necks, spurs, repeats) is mapped as make_simple repairs
        # it, with a warning; anything else raises. Simple curves pay nothing for this.
        return _map_repaired(error, c1, c2, closed, lambda a, b: DisplacementField._from_core(
            _core.map_curves(a, b, method, closed, **flags), source=a, closed=closed))
    return DisplacementField._from_core(record, source=source, closed=closed)


def _map_repaired(error: ValueError, c1, c2, closed: bool, run):
    """After the core refused ``c1`` or ``c2`` with ``error``: map them as :func:`make_simple`
    makes them with ``run(c1, c2)`` (a :class:`DisplacementField` from arrays) and put the field
    back onto the curves as given (:func:`morphomap.simple.put_back`), or raise ``error`` again
    where neither changes."""
    try:
        repaired, changes = repaired_curves(c1, c2, closed, stacklevel=3)
    except ValueError as refusal:
        # The core's message first (it counts the loops or the meeting pairs), then why the repair
        # does not apply, where that says more (a curve of too few points is refused alike).
        if str(refusal) == str(error):
            raise error from None
        raise ValueError(f"{error} (morphomap.make_simple does not repair it either: {refusal})") from None
    if all(change is None for change in changes):
        raise error
    return put_back(run(*repaired), c1, c2, repaired, changes, closed)
