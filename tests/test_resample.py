"""mm.resample: equal-arc-length resampling (the paper's interparc).

Spline and pchip spacing is measured along an independent scipy interpolant on the same
chord-length parameter, with scipy.integrate.quad for the arc length.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.interpolate import CubicHermiteSpline, CubicSpline, PchipInterpolator

import morphomap as mm

METHODS = ["linear", "spline", "pchip"]


def chord_parameter(points, closed):
    """Knots (cumulative chord length) and the points, with the first repeated when closed."""
    pts = np.vstack([points, points[:1]]) if closed else np.asarray(points, float)
    t = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
    return t, pts


def periodic_pchip(points):
    """Fritsch-Carlson slopes (scipy's inside formula) with the wrap taken as an inside point."""
    t, pts = chord_parameter(points, closed=True)
    h = np.diff(t)
    delta = np.diff(pts, axis=0) / h[:, None]
    h_left, h_right = np.roll(h, 1)[:, None], h[:, None]
    m_left, m_right = np.roll(delta, 1, axis=0), delta
    w1, w2 = 2 * h_right + h_left, h_right + 2 * h_left
    extremum = (np.sign(m_left) != np.sign(m_right)) | (m_left == 0) | (m_right == 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        slopes = np.where(extremum, 0.0, (w1 + w2) / (w1 / m_left + w2 / m_right))
    return CubicHermiteSpline(t, pts, np.vstack([slopes, slopes[:1]]))


def reference(points, closed, method):
    t, pts = chord_parameter(points, closed)
    if method == "spline":
        return t, CubicSpline(t, pts, bc_type="periodic" if closed else "natural")
    if method == "pchip":
        return t, periodic_pchip(points) if closed else PchipInterpolator(t, pts)
    raise ValueError(method)


def parameters_on(curve, t_end, q):
    """Parameter of each point q on the parametric curve: nearest dense sample, then Newton on
    the squared distance."""
    dense = np.linspace(0.0, t_end, 100001)
    samples = curve(dense)
    d2 = ((q[:, None, :] - samples[None, :, :]) ** 2).sum(axis=2)
    s = dense[np.argmin(d2, axis=1)]
    d1, dd = curve.derivative(1), curve.derivative(2)
    for _ in range(8):
        e, v, a = curve(s) - q, d1(s), dd(s)
        step = (e * v).sum(1) / ((v * v).sum(1) + (e * a).sum(1))
        s = np.clip(s - step, 0.0, t_end)
    return s


def spline_arcs(curve, s):
    """Arc length of the piecewise cubic curve between consecutive parameters s, integrating
    piece by piece (the second derivative jumps at the knots)."""
    d1 = curve.derivative(1)

    def speed(x):
        return np.hypot(*d1(x))

    def arc(a, b):
        cuts = np.concatenate([[a], curve.x[(curve.x > a) & (curve.x < b)], [b]])
        return sum(quad(speed, lo, hi, epsabs=0.0, epsrel=1e-13, limit=200)[0]
                   for lo, hi in zip(cuts[:-1], cuts[1:]))

    return np.array([arc(a, b) for a, b in zip(s[:-1], s[1:])])


def check_spacing(points, n, closed, method, rtol):
    """Resample, then measure the output along the scipy curve: on it, and equally spaced."""
    out = mm.resample(points, n, closed=closed, method=method)
    assert out.shape == (n, 2)
    t, curve = reference(points, closed, method)
    s = parameters_on(curve, t[-1], out)
    s[0] = 0.0
    if closed:
        s = np.append(s, t[-1])
    else:
        s[-1] = t[-1]
    scale = np.ptp(points, axis=0).max()
    assert np.abs(curve(s[: len(out)]) - out).max() < 1e-10 * scale
    arcs = spline_arcs(curve, s)
    total = spline_arcs(curve, np.array([0.0, t[-1]]))[0]
    err = np.abs(arcs / (total / len(arcs)) - 1).max()
    assert err < rtol, err
    return out


def blob(m, seed=0):
    """An irregular star-shaped closed curve with unevenly spread points."""
    rng = np.random.default_rng(seed)
    angle = np.sort(rng.uniform(0, 2 * np.pi, m))
    radius = 1 + 0.3 * np.sin(3 * angle) + 0.1 * rng.uniform(size=m)
    return np.c_[radius * np.cos(angle), radius * np.sin(angle)]


def zigzag():
    return np.array([[0.0, 0.0], [1.0, 2.0], [1.5, 2.1], [3.0, -1.0], [3.2, 0.5], [5.0, 0.4]])


# --- linear ------------------------------------------------------------------------------------


def polyline_positions(points, closed, q):
    """Arc-length position of points q that lie on the polyline."""
    pts = np.vstack([points, points[:1]]) if closed else np.asarray(points, float)
    a, b = pts[:-1], pts[1:]
    lengths = np.hypot(*(b - a).T)
    start = np.concatenate([[0.0], np.cumsum(lengths)])
    t = ((q[:, None] - a[None]) * (b - a)[None]).sum(2) / lengths**2
    t = np.clip(t, 0, 1)
    d = np.hypot(*(a[None] + t[..., None] * (b - a)[None] - q[:, None]).transpose(2, 0, 1))
    seg = np.argmin(d, axis=1)
    rows = np.arange(len(q))
    assert d[rows, seg].max() < 1e-12 * lengths.sum()
    return start[seg] + t[rows, seg] * lengths[seg], start[-1]


@pytest.mark.parametrize("closed", [True, False])
def test_linear_equal_spacing(closed):
    points = blob(40) if closed else zigzag()
    n = 157
    out = mm.resample(points, n, closed=closed)
    pos, total = polyline_positions(points, closed, out)
    expected = np.arange(n) * total / (n if closed else n - 1)
    assert np.abs(pos - expected).max() < 1e-12 * total / n
    assert np.array_equal(out[0], points[0])
    if not closed:
        assert np.array_equal(out[-1], points[-1])


@settings(max_examples=50, deadline=None)
@given(
    st.lists(st.floats(0.1, 100), min_size=3, max_size=30),
    st.lists(st.integers(0, 359), min_size=3, max_size=30, unique=True),
    st.integers(3, 300),
)
def test_linear_spacing_property(radii, angles, n):
    """Any star-shaped polygon: simple, so that a point's position on it is well defined."""
    m = min(len(radii), len(angles))
    angle = np.radians(np.sort(angles[:m]))
    points = np.array(radii[:m])[:, None] * np.c_[np.cos(angle), np.sin(angle)]
    out = mm.resample(points, n, closed=True)
    pos, total = polyline_positions(points, True, out)
    gap = np.abs(pos - np.arange(n) * total / n)
    assert np.minimum(gap, total - gap).max() <= 1e-11 * total


def test_linear_regular_polygon():
    angle = 2 * np.pi * np.arange(12) / 12
    polygon = 3 * np.c_[np.cos(angle), np.sin(angle)]
    np.testing.assert_allclose(mm.resample(polygon, 12), polygon, atol=1e-14)
    np.testing.assert_allclose(mm.resample(polygon, 3), polygon[::4], atol=1e-14)
    fine = mm.resample(polygon, 36)
    sides = np.hypot(*(np.roll(fine, -1, axis=0) - fine).T)
    np.testing.assert_allclose(sides, np.hypot(*(polygon[1] - polygon[0])) / 3, rtol=1e-13)


@pytest.mark.parametrize("method", METHODS)
def test_straight_line_idempotent(method):
    t = np.array([0.0, 0.3, 0.35, 1.7, 2.0, 4.0])
    line = np.c_[2 + 0.6 * t, -1 + 0.8 * t]
    once = mm.resample(line, 41, closed=False, method=method)
    np.testing.assert_allclose(np.hypot(*np.diff(once, axis=0).T), 0.1, rtol=1e-12)
    twice = mm.resample(once, 41, closed=False, method=method)
    np.testing.assert_allclose(twice, once, atol=1e-13)


# --- spline and pchip --------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["spline", "pchip"])
@pytest.mark.parametrize("closed", [True, False])
def test_smooth_equal_spacing(method, closed):
    points = blob(12, seed=3) if closed else zigzag()
    out = check_spacing(points, 45, closed, method, rtol=1e-8)
    assert np.array_equal(out[0], points[0])
    if not closed:
        assert np.array_equal(out[-1], points[-1])


def test_pchip_matches_scipy_open():
    rng = np.random.default_rng(7)
    points = np.c_[np.cumsum(rng.uniform(0.1, 1.0, 15)), rng.normal(size=15)]
    check_spacing(points, 200, False, "pchip", rtol=1e-8)


def test_spline_circle():
    angle = 2 * np.pi * np.arange(64) / 64
    circle = np.c_[np.cos(angle), np.sin(angle)]
    out = mm.resample(circle, 10000, method="spline")
    assert np.abs(np.hypot(*out.T) - 1).max() < 1e-6
    check_spacing(circle, 50, True, "spline", rtol=1e-8)


def test_pchip_square_corners():
    """Pchip through a square's corners is the square, walked with zero speed at the corners."""
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    out = mm.resample(square, 20, method="pchip")
    step = np.arange(5)[:, None] / 5
    expected = np.vstack([(1 - step) * square[i] + step * square[(i + 1) % 4] for i in range(4)])
    np.testing.assert_allclose(out, expected, atol=1e-12)


# --- shared behaviour --------------------------------------------------------------------------


@pytest.mark.parametrize("method", METHODS)
def test_repeats_are_dropped(method):
    points = blob(10, seed=5)
    messy = np.vstack([points[:3], points[2:3], points[3:], points[:1]])  # a repeat, a closing one
    np.testing.assert_array_equal(
        mm.resample(messy, 33, method=method), mm.resample(points, 33, method=method)
    )


@pytest.mark.parametrize("method", METHODS)
def test_large_n(method):
    """Many output points (the parallel path) land where fewer would."""
    points = blob(30, seed=1)
    out = mm.resample(points, 200_000, method=method)
    assert out.shape == (200_000, 2) and np.isfinite(out).all()
    np.testing.assert_allclose(out[::1000], mm.resample(points, 200, method=method), atol=1e-12)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize(
    "points, n, closed, argument",
    [
        ([[0, 0], [1, 0], [np.nan, 1]], 10, True, "points"),
        ([[0, 0], [1, np.inf]], 10, False, "points"),
        ([[0, 0]], 10, False, "points"),
        ([[0, 0], [1, 0]], 10, True, "points"),
        ([[0, 0], [1, 0], [0, 0]], 10, True, "points"),
        ([[2, 3], [2, 3], [2, 3]], 10, True, "points"),
        ([[2, 3], [2, 3]], 10, False, "points"),
        ([[0, 0], [1, 0]], 1, False, "n"),
        ([[0, 0], [1, 0]], 0, False, "n"),
        ([[0, 0], [1, 0]], -3, False, "n"),
        ([[0, 0], [1, 0], [0, 1]], 2, True, "n"),
        ([[0, 0], [1, 0], [0, 1]], 10**12, True, "n"),
    ],
)
def test_invalid_input(method, points, n, closed, argument):
    with pytest.raises(ValueError, match=f"^{argument}"):
        mm.resample(np.array(points, float), n, closed=closed, method=method)


@pytest.mark.parametrize("method", ["linear", "spline", "pchip"])
@pytest.mark.parametrize("points", [
    [[5e-324, 0.0], [0.0, 0.0]],
    [[-2.5e-292, 0.0], [0.0, 0.0]],
    [[0.0, 0.0], [5e-324, 0.0], [1.0, 0.0]],
], ids=["subnormal", "tiny", "one-subnormal-piece"])
def test_subnormal_pieces_give_an_answer_or_a_clear_error(points, method):
    # These once sent the adaptive arc-length quadrature into 2^30 bisections (a hang).
    try:
        out = mm.resample(np.array(points), 10, method=method, closed=False)
    except ValueError as error:
        assert str(error).startswith("points:")
    else:
        assert np.isfinite(out).all()
