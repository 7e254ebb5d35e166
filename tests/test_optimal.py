"""method="optimal": order-preserving, onto all of C2, no crossings; radial on concentric circles;
below the paper's Table 1 on its pair. The DP itself against a closed form: tests/cpp/test_optimal.cpp."""


import numpy as np
import pytest

import morphomap as mm
from conftest import SHARED_CASES, circle, ellipse, require_cases

import frames  # noqa: E402  (next to this file)

CASES = SHARED_CASES
#: QM1 of every row of the paper's Table 1 (circle onto ellipse; bench/paper_table1.py has the table).
TABLE1_QM1 = (13.4, 0.128, 1.69, 0.103, 56.1, 0.084, 0.494, 1.589, 0.224)


def winding_steps(field, c2):
    """Arc steps along C2 between consecutive ends, each taken forward (mod the perimeter)."""
    hits = mm.closest_points(field.ends, c2)
    length = np.linalg.norm(np.diff(np.vstack([c2, c2[:1]]), axis=0), axis=1).sum()
    steps = np.diff(np.append(hits.arc_lengths, hits.arc_lengths[0])) % length
    return steps, length


def check_order_preserving(field, c1, c2):
    """Every vector valid and on its curves, no crossings, the ends once round C2 in order."""
    assert field.valid.all()
    q = mm.quality(field, c1, c2)
    assert q.crossings == 0
    size = np.ptp(c2, axis=0).max()
    assert mm.closest_points(field.starts, c1).distances.max() < 1e-9 * size
    assert mm.closest_points(field.ends, c2).distances.max() < 1e-9 * size
    # Ends follow the starts' order round C2 exactly once: the forward steps add up to one
    # perimeter (a step backwards would add nearly a whole one more), so no part of C2 is skipped
    # over twice or missed.
    steps, length = winding_steps(field, c2)
    assert steps.sum() == pytest.approx(length, rel=1e-9)
    assert steps.max() < 0.5 * length
    # Every point of C1 is a start point (crossing points are added as their own).
    assert mm.closest_points(c1, field.starts).distances.max() < 1e-12 * size
    return q


@pytest.mark.parametrize("name", ["circle_ellipse", "kidney"])
def test_bundled_pairs(name):
    c1, c2 = mm.load_example(name)
    field = mm.map_curves(c1, c2, "optimal")
    check_order_preserving(field, c1, c2)
    assert set(field.method.tolist()) == {"optimal"}


def test_shared_frames():
    require_cases(CASES / "frame2.csv")
    c1, c2 = mm.read_curve(CASES / "frame2.csv"), mm.read_curve(CASES / "frame3.csv")
    field = mm.map_curves(c1, c2, "optimal")
    check_order_preserving(field, c1, c2)


# 16, 24, 31, 35: staircase contours whose vectors crossed one, two or three apart. 10: the first
# pass's anchor runs along a staircase edge of C2 (its region is not a simple polygon: that pass is
# counted). 52: a piece with no path inside its region at the sampling (the penalised path, counted).
@pytest.mark.parametrize("seed", [0, 1, 2, 4, 5, 6, 10, 16, 24, 31, 35, 52])
def test_fuzz_pairs(seed):
    pair = frames.curve_pair(seed, "careful")
    if pair.identical:
        pytest.skip("the two frames are the same curve")
    field = mm.map_curves(pair.c1, pair.c2, "optimal")
    check_order_preserving(field, pair.c1, pair.c2)


def budded(depth):
    """The unit circle (120 points) onto a circle of radius 1.5 with a finger `depth` long and 0.2
    radians wide at angle 0.3 (800 points)."""
    c1 = mm.resample(circle(400), 120)
    t = 2 * np.pi * np.arange(800) / 800
    r = 1.5 + depth * np.clip(1 - (np.abs(np.angle(np.exp(1j * (t - 0.3)))) / 0.1) ** 8, 0, 1)
    return c1, np.column_stack([r * np.cos(t), r * np.sin(t)])


def test_deep_narrow_bud_without_crossings():
    # The crossing penalty (three vectors back) left 2 crossing pairs here, vectors four or more
    # apart fanning into the finger; inside the region none can cross.
    c1, c2 = budded(2.0)
    check_order_preserving(mm.map_curves(c1, c2, "optimal"), c1, c2)


def test_fingers_up_to_six_long_map_without_crossings():
    # The finger's long edges make the target uneven, so it is sampled through its vertices too
    # (sample_arcs in optimal.cpp): the few start points facing it now reach its tip with vectors
    # inside the region. Equally spaced samples alone found no such path at 3 (12 crossing pairs).
    for depth in (3.0, 4.0, 5.0, 6.0):
        c1, c2 = budded(depth)
        check_order_preserving(mm.map_curves(c1, c2, "optimal"), c1, c2)


def test_fingers_of_any_length_map_through_a_forced_jump():
    # From 8 long, the few start points facing the finger cannot reach its tip within a step's
    # reach with vectors inside the region; where every vector inside it is out of reach, the DP
    # takes the jump from the furthest vectors of the row before (solve_level in optimal.cpp).
    for depth in (8.0, 20.0, 40.0):
        c1, c2 = budded(depth)
        check_order_preserving(mm.map_curves(c1, c2, "optimal"), c1, c2)


def test_no_crossing_free_matching_is_refused():
    # Open curves run opposite ways: their end vectors, fixed, cross each other.
    c1 = np.array([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0]])
    c2 = np.array([[1.0, 1.0], [0.5, 1.2], [0.0, 1.0]])
    with pytest.raises(mm.GeometryError, match="no crossing-free order-preserving matching"):
        mm.map_curves(c1, c2, "optimal", closed=False)


def test_a_start_a_hair_from_a_long_edge_end_lands_beside_it():
    # Open pieces whose target is one long edge: the start 0.001 from the end maps to the uniform
    # map's point, not a whole sample step (1/16 of the edge) away from it.
    c1 = np.array([[0.0, 0.0], [0.0, 0.999], [0.0, 1.0]])
    c2 = np.array([[1.0, 0.0], [1.0, 1.0]])
    field = mm.map_curves(c1, c2, "optimal", closed=False)
    assert np.abs(field.ends[1] - [1.0, 0.999]).max() < 1e-12
    assert mm.quality(field, c1, c2, closed=False).crossings == 0


def test_an_end_doubling_back_shares_the_target_end():
    # C1's last point lies back across the one before it (as a traced tip): the last vector
    # separates C1's third point from all of C2 but C2's end, so the only crossing-free
    # order-preserving field sends both there.
    c1 = np.array([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [0.98, 0.01]])
    c2 = np.column_stack([np.linspace(0.0, 1.0, 9), np.full(9, -1.0)])
    field = mm.map_curves(c1, c2, "optimal", closed=False)
    assert field.valid.all()
    assert mm.quality(field, c1, c2, closed=False).crossings == 0
    np.testing.assert_array_equal(field.ends[2], c2[-1])
    np.testing.assert_array_equal(field.ends[3], c2[-1])
    # The rest keeps strict order along C2.
    assert np.all(np.diff(field.ends[:3, 0]) > 0)


@pytest.mark.parametrize("n, m, phase", [(100, 1000, 0.0), (100, 2570, 0.3), (400, 1500, 1.0)])
def test_concentric_circles_give_the_radial_map(n, m, phase):
    t1 = 2 * np.pi * np.arange(n) / n + phase
    c1 = np.column_stack([np.cos(t1), np.sin(t1)])
    # C2 finer than the matching's samples, so that its polygon is the circle: on a coarse polygon
    # the nearest points are not the radial ones (its corners stand out).
    c2 = circle(m, radius=2.0)
    field = mm.map_curves(c1, c2, "optimal")
    radial = mm.line_intersections(c1, c1, c2).points
    # The ends are chosen among M + 1 equally spaced positions on C2 (optimal.hpp): the radial
    # map rounded to those is the sampling's accuracy, half a step.
    samples = max(4 * (n + 1), min(m, 8 * (n + 1)))
    step = 2 * np.pi * 2.0 / samples
    error = np.linalg.norm(field.ends - radial, axis=1)
    assert error.max() < 0.51 * step
    assert error.mean() < 0.3 * step


def test_table1_pair_below_every_row_of_the_paper():
    c1, c2 = mm.load_example("circle_ellipse")
    q = mm.quality(mm.map_curves(c1, c2, "optimal"), c1, c2)
    assert q.crossings == 0
    assert q.qm1 < min(TABLE1_QM1)


def test_stretch_weight_trades_displacement_for_stretch():
    c1, c2 = mm.load_example("circle_ellipse")
    near = mm.map_curves(c1, c2, "optimal", stretch_weight=0.0)
    even = mm.map_curves(c1, c2, "optimal", stretch_weight=100.0)
    assert mm.quality(even, c1, c2).qm1 < mm.quality(near, c1, c2).qm1
    assert (np.linalg.norm(near.vectors, axis=1) ** 2).sum() < (np.linalg.norm(even.vectors, axis=1) ** 2).sum()


def test_reverse_transform_and_resampling():
    c1, c2 = ellipse(120, 1.0, 0.6), circle(90, radius=1.3)
    back = mm.map_curves(c1, c2, "optimal", reverse=True)
    assert set(back.method.tolist()) == {"reverse_optimal"}
    assert back.valid.all() and mm.quality(back, c1, c2).crossings == 0
    moved = mm.map_curves(c1 + [0.1, 0.05], c2, "optimal", transform=True, n=200)
    assert len(moved) >= 200 and moved.valid.all()  # (and the crossing points)
    assert mm.quality(moved, c1 + [0.1, 0.05], c2).crossings == 0


def test_open_curves_map_end_to_end():
    x = np.linspace(0.0, 1.0, 60)
    c1 = np.column_stack([x, 0.1 * np.sin(3 * x)])
    c2 = np.column_stack([1.5 * np.linspace(0.0, 1.0, 85), 0.5 + 0.2 * np.cos(2 * x[0] + np.linspace(0, 2, 85))])
    field = mm.map_curves(c1, c2, "optimal", closed=False)
    assert field.valid.all() and mm.quality(field, c1, c2, closed=False).crossings == 0
    np.testing.assert_allclose(field.ends[0], c2[0], atol=1e-12)
    np.testing.assert_allclose(field.ends[-1], c2[-1], atol=1e-12)
    arcs = mm.closest_points(field.ends, c2, closed=False).arc_lengths
    assert (np.diff(arcs) > 0).all()


def test_bad_input():
    c1, c2 = mm.load_example("circle_ellipse")
    with pytest.raises(ValueError, match="stretch_weight"):
        mm.map_curves(c1, c2, "optimal", stretch_weight=-1.0)
    with pytest.raises(TypeError, match="stretch_weight"):
        mm.map_curves(c1, c2, "optimal", stretch_weight="ten")
    with pytest.raises(ValueError, match="skip_below"):
        mm.map_curves(c1, c2, "optimal", skip_below=0.1)
    with pytest.raises(ValueError, match="c2"):
        mm.map_curves(c1, np.full((5, 2), np.nan), "optimal")
