"""The default on real outlines segmented by others: the mouse limb bud, hour by hour
(../shared/cases/limb-bud/2d, read its README). The default returns every start point of C1, each
vector valid, and no crossings, closed and open, on every consecutive, 4 h and 8 h pair and on the
long jumps (330 -> 381 h among them, where the paper's Algorithm 1 crosses).
"""

import warnings

import numpy as np
import pytest

import morphomap as mm
from conftest import SHARED_CASES, require_cases

LIMB = SHARED_CASES / "limb-bud" / "2d"
HOURS = range(248, 382)


def require_limb():
    require_cases(LIMB)


def outline(hour):
    return np.loadtxt(LIMB / f"limb_h{hour}.csv", delimiter=",", skiprows=1)


def pairs():
    out = [(h, h + 1) for h in range(248, 381)]
    out += [(h, h + 4) for h in range(248, 378, 4)] + [(h, h + 8) for h in range(248, 374, 8)]
    return out + [(250, 270), (330, 381)]


def check_default(c1, c2, closed):
    """The default's contract: C1's points each once, in order, valid, no crossings. The glitch
    outlines (a first point across the closing segment) are made simple first, as map_curves
    does itself with a warning (tests/test_make_simple.py), so that they are measured on the
    curves that were mapped."""
    c1, c2 = mm.make_simple(c1, closed=closed)[0], mm.make_simple(c2, closed=closed)[0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing left to repair
        field = mm.map_curves(c1, c2, closed=closed)
    q = mm.quality(field, c1, c2, closed=closed)
    assert field.valid.all()
    assert q.crossings == 0
    size = np.ptp(np.vstack([c1, c2]), axis=0).max()
    # Every point of C1 is a start point (a split point is one of its own), in the order along C1.
    assert mm.closest_points(c1, field.starts, closed=closed).distances.max() < 1e-12 * size
    assert mm.closest_points(field.ends, c2, closed=closed).distances.max() < 1e-9 * size
    return field, q


@pytest.mark.parametrize("closed", [True, False], ids=["closed", "open"])
def test_default_is_crossing_free_and_complete_on_every_pair(closed):
    require_limb()
    failures = []
    curves = {h: outline(h) for h in HOURS}
    for a, b in pairs():
        try:
            check_default(curves[a], curves[b], closed)
        except (AssertionError, ValueError, RuntimeError) as error:
            failures.append(f"{a}->{b}: {str(error).splitlines()[0][:200]}")
    assert not failures, f"{len(failures)} of {len(pairs())} pairs: " + "; ".join(failures[:10])


@pytest.mark.parametrize("closed", [True, False], ids=["closed", "open"])
def test_the_lobed_jump_the_paper_crosses_on(closed):
    # 330 h -> 381 h: digit lobes appear. The paper's Algorithm 1 gives reverse diffusion vectors
    # that cross where the streamlines fan into a lobe; the default does not.
    require_limb()
    c1, c2 = outline(330), outline(381)
    paper = mm.map_curves(c1, c2, "paper", closed=closed)
    assert mm.quality(paper, c1, c2, closed=closed).crossings > 0
    field, q = check_default(c1, c2, closed)
    assert len(field.starts) >= len(c1)
    assert q.qm < 1.0



@pytest.mark.parametrize("closed", [True, False], ids=["closed", "open"])
def test_optimal_maps_every_pair_without_crossings(closed):
    # Uneven outlines: the flank is one long edge beside points 0.01 apart, and where the curves
    # cross on it a piece holds a start a hair from its end; a traced tip's last point lies back
    # across the one before it (250 -> 270 h open). optimal maps every pair crossing-free.
    require_limb()
    failures = []
    curves = {h: mm.make_simple(outline(h), closed=closed)[0] for h in HOURS}
    for a, b in pairs():
        c1, c2 = curves[a], curves[b]
        try:
            field = mm.map_curves(c1, c2, "optimal", closed=closed)
            assert field.valid.all()
            assert mm.quality(field, c1, c2, closed=closed).crossings == 0
        except (AssertionError, ValueError, RuntimeError) as error:
            failures.append(f"{a}->{b}: {str(error).splitlines()[0][:200]}")
    assert not failures, f"{len(failures)} of {len(pairs())} pairs: " + "; ".join(failures[:10])


@pytest.mark.parametrize("closed", [True, False], ids=["closed", "open"])
def test_the_lobed_jump_resampled_to_10_4_points(closed):
    # 330 -> 381 h resampled evenly: where the source turns into a lobe, the part of C2 its points
    # see from inside the region jumps ahead by more than a step's reach, and the bands of the
    # finer levels must follow the coarse path's jumps; optimal raised from 10^3 points on. Now
    # optimal, its reverse and the default map crossing-free at every density (time:
    # bench/README.md "Real 2D outlines").
    require_limb()
    a, b = (mm.make_simple(outline(h), closed=closed)[0] for h in (330, 381))
    for n in (1000, 2000, 10_000):
        c1, c2 = mm.resample(a, n, closed=closed), mm.resample(b, n, closed=closed)
        for method, reverse in (("optimal", False), ("optimal", True), ("auto", False)):
            field = mm.map_curves(c1, c2, method, closed=closed, reverse=reverse)
            q = mm.quality(field, c1, c2, closed=closed)
            assert field.valid.all(), (n, method, reverse)
            assert q.crossings == 0, (n, method, reverse)
            size = np.ptp(np.vstack([c1, c2]), axis=0).max()
            assert mm.closest_points(field.starts, c1, closed=closed).distances.max() < 1e-9 * size
            assert mm.closest_points(field.ends, c2, closed=closed).distances.max() < 1e-9 * size
            if not reverse:  # every point of C1 a start
                assert mm.closest_points(c1, field.starts, closed=closed).distances.max() < 1e-12 * size


def test_optimal_on_the_flank_is_as_even_as_normal_mapping():
    # 300 -> 301 h closed: the curves cross on the flank segment; optimal's QM stays within twice
    # normal mapping's (its samples include the uniform map's position of every start).
    require_limb()
    c1, c2 = (mm.make_simple(outline(h))[0] for h in (300, 301))
    normal = mm.quality(mm.map_curves(c1, c2, "normal"), c1, c2)
    optimal = mm.quality(mm.map_curves(c1, c2, "optimal"), c1, c2)
    assert normal.crossings == optimal.crossings == 0
    assert optimal.qm <= 2 * normal.qm


def test_default_on_the_long_open_jump_is_within_1_5_of_best():
    # 250 -> 270 h open: the traced tip's last point doubles back, so only a field whose last
    # vectors share C2's end point is crossing-free; optimal finds it and the default takes it.
    require_limb()
    c1, c2 = (mm.make_simple(outline(h), closed=False)[0] for h in (250, 270))
    default = mm.quality(mm.map_curves(c1, c2, closed=False), c1, c2, closed=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        best = mm.quality(mm.map_curves(c1, c2, "best", closed=False), c1, c2, closed=False)
    assert default.crossings == best.crossings == 0
    assert default.qm <= 1.5 * best.qm
