"""make_simple: contours as labs trace them (pixel necks and spurs, repeats, a seam glitch) made
simple, genuine self-intersections refused, simple curves passed through bit for bit."""

import time
import warnings

import numpy as np
import pytest
from skimage import measure

import morphomap as mm
from conftest import SHARED_CASES, require_cases
from conftest import circle, morphomap
from morphomap.simple import NECK_OPENING

LIMB = SHARED_CASES / "limb-bud" / "2d"
GLITCHES = (278, 279, 280, 338, 339, 340, 341, 342)

# Moore neighbourhood, clockwise on the screen (row down): N, NE, E, SE, S, SW, W, NW.
RING = ((-1, 0), (-1, 1), (0, 1), (1, 1), (1, 0), (1, -1), (0, -1), (-1, -1))


def moore_trace(mask):
    """Pixel centres (x = column, y = row) of the outer boundary of the 8-connected object holding
    the first foreground pixel in raster order: Moore neighbour tracing, one period of its walk."""
    grid = np.pad(np.asarray(mask, dtype=bool), 1)
    start = tuple(int(v) for v in np.argwhere(grid)[0])
    here, back = start, 6  # the pixel to the west of the first one is background
    seen, walk = {}, []
    while (here, back) not in seen:
        seen[(here, back)] = len(walk)
        walk.append(here)
        for turn in range(1, 9):
            d = (back + turn) % 8
            step = (here[0] + RING[d][0], here[1] + RING[d][1])
            if grid[step]:
                before = (here[0] + RING[(d - 1) % 8][0], here[1] + RING[(d - 1) % 8][1])
                back = RING.index((before[0] - step[0], before[1] - step[1]))
                here = step
                break
    loop = np.array(walk[seen[(here, back)]:], dtype=float) - 1.0
    return np.column_stack([loop[:, 1], loop[:, 0]])


def disk(shape, centre, radius):
    rows, cols = np.mgrid[0:shape[0], 0:shape[1]]
    return (rows - centre[0]) ** 2 + (cols - centre[1]) ** 2 <= radius ** 2


def necked():
    """Two disks joined by one pixel: an 8-connected trace passes through it twice."""
    mask = disk((40, 60), (20, 20), 8) | disk((40, 60), (20, 38), 8)
    mask[20, 29] = True
    return mask


def corner_touching():
    """Two squares meeting at a corner: the trace runs along the diagonal step and back."""
    mask = np.zeros((40, 40), dtype=bool)
    mask[5:15, 5:15] = True
    mask[15:25, 15:25] = True
    return mask


def corridor():
    """Two disks joined by a one-pixel-wide corridor five pixels long."""
    mask = disk((40, 70), (20, 18), 9) | disk((40, 70), (20, 50), 9)
    mask[20, 27:42] = True
    return mask


def spurred():
    """A disk with a one-pixel-wide line six pixels long sticking out of it and a diagonal hair
    of five pixels (where the trace starts: the first pixel in raster order)."""
    mask = disk((50, 50), (25, 25), 10)
    mask[25, 35:42] = True
    for k in range(5):
        mask[17 - k, 17 - k] = True
    return mask


def grown(mask, pixels=3):
    """The mask grown by `pixels` (its traced contour is simple)."""
    rows, cols = np.nonzero(mask)
    out = np.zeros_like(mask)
    for dr in range(-pixels, pixels + 1):
        for dc in range(-pixels, pixels + 1):
            if dr * dr + dc * dc <= pixels * pixels:
                out[np.clip(rows + dr, 0, mask.shape[0] - 1), np.clip(cols + dc, 0, mask.shape[1] - 1)] = True
    return out


def area(points):
    return abs(mm.signed_area(points))


def test_the_tracer_gives_lab_contours():
    # The point of these masks: the traces are not simple, marching squares' contours are.
    for mask in (necked(), corner_touching(), corridor(), spurred()):
        traced = moore_trace(mask)
        assert mm.is_self_intersecting(traced)
        contour = max(measure.find_contours(mask.astype(float), 0.5), key=len)[:-1]
        points = np.ascontiguousarray(contour[:, ::-1])
        assert not mm.is_self_intersecting(points)
        simple, changes = mm.make_simple(points)
        assert len(changes) == 0 and np.array_equal(simple, points)
    square = np.zeros((6, 6), dtype=bool)
    square[1:4, 2:5] = True
    np.testing.assert_array_equal(moore_trace(square), [[2, 1], [3, 1], [4, 1], [4, 2], [4, 3], [3, 3], [2, 3],
                                                        [2, 2]])


@pytest.mark.parametrize("make", [necked, corner_touching, corridor], ids=["neck", "corner", "corridor"])
def test_necks_are_opened_keeping_every_point_and_the_area(make):
    traced = moore_trace(make())
    simple, changes = mm.make_simple(traced)
    assert not mm.is_self_intersecting(simple)
    assert len(simple) == len(traced)  # every visit kept, none dropped
    assert {change.kind for change in changes} == {"neck"}
    moved = np.linalg.norm(simple - traced[changes.source_rows], axis=1)
    visits = sum(len(change.rows) for change in changes)
    assert np.count_nonzero(moved) == visits
    assert moved.max() <= NECK_OPENING * 1.0000001  # the pixel spacing is 1
    # Each moved copy changes the area by at most its opening times its two half segments.
    assert abs(area(simple) - area(traced)) <= visits * NECK_OPENING * np.sqrt(2)
    assert abs(area(simple) - area(traced)) <= 1e-7 * area(traced)
    assert "opened a neck" in str(changes) and "visited it 2 times" in str(changes)


def test_a_neck_is_reported_where_it_is():
    traced = moore_trace(necked())
    _, changes = mm.make_simple(traced)
    # The neck pixel and the two it joins are each passed twice (left to right, then back).
    assert [change.where for change in changes] == [(28.0, 20.0), (29.0, 20.0), (30.0, 20.0)]
    assert all(len(change.rows) == 2 for change in changes)
    np.testing.assert_array_equal(traced[list(changes[1].rows)], [[29, 20], [29, 20]])


def test_spurs_are_removed_without_losing_area():
    traced = moore_trace(spurred())
    simple, changes = mm.make_simple(traced)
    assert not mm.is_self_intersecting(simple)
    kinds = [change.kind for change in changes]
    assert kinds == ["spur", "spur"]
    # A spur of k pixels beyond the disk: out k points, back k (the base point is kept).
    assert sorted(len(change.rows) for change in changes) == [10, 12]
    assert len(simple) == len(traced) - 22
    assert area(simple) == pytest.approx(area(traced), rel=1e-12)
    tips = {tuple(traced[list(change.rows)][np.argmax(np.linalg.norm(traced[list(change.rows)] - change.where,
                                                                    axis=1))]) for change in changes}
    assert tips == {(41.0, 25.0), (13.0, 13.0)}
    assert "removed a spur of" in str(changes)


def test_repeated_points_are_removed():
    c = circle(50)
    given = np.insert(c, [7, 7, 30], c[[6, 6, 29]], axis=0)
    given = np.vstack([given, c[:1]])  # the first point again at the end
    simple, changes = mm.make_simple(given)
    np.testing.assert_array_equal(simple, c)
    assert len(changes) == 1 and changes[0].kind == "repeated"
    assert changes[0].rows == (7, 8, 32, 53)
    assert str(changes) == "removed 4 repeated points (rows 7, 8, 32, 53)"
    # Open: no closing segment, so the last point is one of its own.
    open_simple, open_changes = mm.make_simple(given[:-1], closed=False)
    np.testing.assert_array_equal(open_simple, c)
    assert open_changes[0].rows == (7, 8, 32)


@pytest.mark.parametrize("make", [necked, spurred, corridor], ids=["neck", "spur", "corridor"])
def test_open_curves_with_necks_and_spurs(make):
    traced = np.roll(moore_trace(make()), 5, axis=0)
    simple, changes = mm.make_simple(traced, closed=False)
    assert not mm.is_self_intersecting(simple, closed=False)
    assert len(changes) >= 1
    # The ends stay, but where one is also passed elsewhere it is drawn back along its segment.
    assert np.abs(simple[[0, -1]] - traced[[0, -1]]).max() <= NECK_OPENING * 1.0001
    assert np.abs(simple - traced[changes.source_rows]).max() <= NECK_OPENING * 1.0001


@pytest.mark.parametrize("make", [necked, corner_touching, corridor, spurred],
                         ids=["neck", "corner", "corridor", "spur"])
@pytest.mark.parametrize("forward", [True, False], ids=["c1", "c2"])
def test_the_default_maps_traced_contours(make, forward):
    traced = moore_trace(make())
    other = moore_trace(grown(make()))
    assert not mm.is_self_intersecting(other)
    c1, c2 = (traced, other) if forward else (other, traced)
    with pytest.warns(UserWarning, match="c1: " if forward else "c2: ") as told:
        field = mm.map_curves(c1, c2)
    assert len(told) == 1
    assert "make_simple" in str(told[0].message)
    q = mm.quality(field, c1, c2)
    assert field.valid.all()
    assert q.crossings == 0
    # The field starts on C1's own points: every point of C1 that the repair kept.
    kept = mm.make_simple(c1)[1].source_rows
    assert mm.closest_points(c1[kept], field.starts).distances.max() < 1e-12
    assert mm.closest_points(field.ends, c2).distances.max() < 1e-9


def test_prepared_curves_are_repaired_the_same_way():
    traced = moore_trace(necked())
    with pytest.warns(UserWarning, match="opened a neck"):
        prepared = mm.PreparedCurve(traced, "c1")
    np.testing.assert_array_equal(prepared.points, mm.make_simple(traced)[0])
    other = mm.PreparedCurve(moore_trace(grown(necked())), "c2")
    field = mm.map_curves(prepared, other)
    assert field.valid.all() and mm.quality(field, prepared, other).crossings == 0


def figure_eight(n=200):
    t = 2 * np.pi * np.arange(n) / n
    return np.column_stack([np.sin(t), np.sin(t) * np.cos(t)])


def test_a_figure_eight_is_refused():
    with pytest.raises(ValueError, match=r"points: the curve crosses itself.*make_simple does not repair"):
        mm.make_simple(figure_eight())
    # The core's message (with its count) first, then why the repair does not apply.
    with pytest.raises(ValueError, match=r"^c1: the curve intersects itself: 1 pair.*make_simple does not repair"):
        mm.map_curves(figure_eight(), circle(100, 2.0))


def test_crossing_at_a_shared_vertex_is_refused():
    # The two loops pass through (0, 0) crossing each other there: no nudge separates them.
    eight = np.array([[0, 0], [1, 1], [2, 0], [1, -1], [0, 0], [-1, 1], [-2, 0], [-1, -1]], dtype=float)
    with pytest.raises(ValueError, match="crosses itself"):
        mm.make_simple(eight)


def test_a_loop_with_area_is_refused():
    # A closed curve whose end overlaps its start: the overlap has area.
    t = np.linspace(0, 2.3 * np.pi, 230, endpoint=False)
    with pytest.raises(ValueError, match="crosses itself"):
        mm.make_simple(np.column_stack([np.cos(t) * (1 + 0.05 * t), np.sin(t) * (1 + 0.05 * t)]))


def test_stacked_contours_are_not_joined():
    a, b = circle(40), circle(40, centre=(5.0, 0.0))
    stacked = np.vstack([a, a[:1], b, b[:1]])
    with pytest.raises(ValueError, match="split_components"):
        mm.make_simple(stacked)


def test_simple_curves_pass_bit_for_bit_and_fast(wobbly):
    for closed in (True, False):
        simple, changes = mm.make_simple(wobbly, closed=closed)
        assert simple.tobytes() == wobbly.tobytes() and simple is not wobbly
        assert len(changes) == 0 and str(changes) == "no changes"
        np.testing.assert_array_equal(changes.source_rows, np.arange(len(wobbly)))
    big = mm.resample(wobbly, 10_000)
    mm.make_simple(big)
    spent = min(_timed(lambda: mm.make_simple(big)) for _ in range(5))
    assert spent < 0.05  # a few milliseconds measured; generous for loaded machines


def _timed(call):
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def test_bad_arguments():
    with pytest.raises(TypeError, match="points"):
        mm.make_simple("no")
    with pytest.raises(ValueError, match="points: expected shape"):
        mm.make_simple(np.zeros((4, 3)))
    with pytest.raises(ValueError, match="at least 3 points"):
        mm.make_simple(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="fewer than the 3"):
        mm.make_simple(np.array([[0, 0], [1, 0], [2, 0], [1, 0]], dtype=float))
    with pytest.raises(TypeError, match="closed"):
        mm.make_simple(circle(10), closed=1)


def require_limb():
    require_cases(LIMB)


def outline(hour):
    return np.loadtxt(LIMB / f"limb_h{hour}.csv", delimiter=",", skiprows=1)


def test_limb_outlines_with_the_first_point_across_the_closing_segment():
    require_limb()
    for hour in GLITCHES:
        given = outline(hour)
        assert mm.is_self_intersecting(given)
        simple, changes = mm.make_simple(given)
        assert not mm.is_self_intersecting(simple)
        assert len(changes) == 1 and changes[0].kind == "first point"
        np.testing.assert_array_equal(simple, given[[1, 0, *range(2, len(given))]])
        assert 0 < changes[0].area < 2e-3 * area(given)
        assert changes[0].area == pytest.approx(abs(area(simple) - area(given)), rel=1e-9)
        # Open, there is no closing segment: nothing to repair.
        opened, none = mm.make_simple(given, closed=False)
        assert len(none) == 0 and np.array_equal(opened, given)


def test_other_limb_outlines_pass_unchanged():
    require_limb()
    for hour in sorted(set(range(243, 382)) - set(GLITCHES)):
        given = outline(hour)
        simple, changes = mm.make_simple(given)
        assert len(changes) == 0 and np.array_equal(simple, given), hour


def test_limb_glitch_maps_by_default_with_one_warning():
    require_limb()
    c1, c2 = outline(278), outline(279)
    with warnings.catch_warnings(record=True) as told:
        warnings.simplefilter("always")
        field = mm.map_curves(c1, c2)
    messages = [str(w.message) for w in told if issubclass(w.category, UserWarning)]
    assert len(messages) == 1 and "c1: swapped the first point" in messages[0] and "c2: swapped" in messages[0]
    q = mm.quality(field, c1, c2)
    assert field.valid.all() and q.crossings == 0
    assert mm.closest_points(c1, field.starts).distances.max() == 0.0  # every point of C1 starts a vector


def test_the_command_line_repairs_and_says_so(tmp_path):
    c1, c2 = moore_trace(necked()), moore_trace(grown(necked()))
    mm.write_curve(tmp_path / "c1.csv", c1)
    mm.write_curve(tmp_path / "c2.csv", c2)
    done = morphomap("map", tmp_path / "c1.csv", tmp_path / "c2.csv", "-o", tmp_path / "field.csv")
    assert done.returncode == 0, done.stderr
    assert "warning" in done.stderr and "opened a neck" in done.stderr
    assert "crossings 0" in done.stderr
    eight = tmp_path / "eight.csv"
    mm.write_curve(eight, figure_eight())
    refused = morphomap("map", eight, tmp_path / "c2.csv", "-o", tmp_path / "no.csv")
    assert refused.returncode != 0 and "make_simple" in refused.stderr
