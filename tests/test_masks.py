"""Boundaries from masks against closed forms: discs and ellipses drawn on pixel grids."""

import numpy as np
import pytest

import morphomap as mm


def disc(shape, centre, radius, spacing=(1.0, 1.0)):
    """Pixels whose centres lie within `radius` (physical) of `centre` (x, y, physical)."""
    rows, columns = np.indices(shape)
    x, y = columns * spacing[1], rows * spacing[0]
    return (x - centre[0]) ** 2 + (y - centre[1]) ** 2 <= radius**2


def test_a_disc_gives_its_circle():
    # The bar: radius 50 px at 0.65 um/px, perimeter and area within 0.5%, every point
    # within half a pixel of the circle.
    s, r = 0.65, 50 * 0.65
    centre = (70 * s, 64 * s)
    mask = disc((130, 140), centre, r, (s, s))
    for curve in (mm.boundary_from_mask(mask, s, smooth=0), mm.boundary_from_mask(mask, s)):
        assert curve.shape[1] == 2 and not np.allclose(curve[0], curve[-1])
        assert mm.signed_area(curve) > 0  # counter-clockwise in (x, y)
        assert abs(mm.signed_area(curve) / (np.pi * r**2) - 1) < 0.005
        assert np.abs(np.linalg.norm(curve - centre, axis=1) - r).max() <= 0.5 * s + 1e-9
    # Unsmoothed, the contour follows the pixels' staircase (measured: 5.6% longer than the
    # circle); at the default (about one pixel) and smoothed by one pixel it is the circle's length.
    raw = mm.boundary_from_mask(mask, s, smooth=0)
    assert 0.04 < mm.perimeter(raw) / (2 * np.pi * r) - 1 < 0.07
    assert abs(mm.perimeter(curve) / (2 * np.pi * r) - 1) < 0.005  # measured: +0.14%
    smoothed = mm.boundary_from_mask(mask, s, smooth=s)
    assert abs(mm.perimeter(smoothed) / (2 * np.pi * r) - 1) < 0.005
    assert abs(mm.signed_area(smoothed) / (np.pi * r**2) - 1) < 0.005
    assert np.abs(np.linalg.norm(smoothed - centre, axis=1) - r).max() <= 0.5 * s + 1e-9


def test_anisotropic_pixels_and_axes():
    # Rows 0.5 apart, columns 1.0 apart: a disc of radius 20 in physical units; x is the column.
    spacing = (0.5, 1.0)
    centre, r = (30.0, 25.0), 20.0
    curve = mm.boundary_from_mask(disc((100, 60), centre, r, spacing), spacing)
    assert abs(mm.signed_area(curve) / (np.pi * r**2) - 1) < 0.01
    assert np.abs(np.linalg.norm(curve - centre, axis=1) - r).max() <= 0.5 * max(spacing) + 1e-9
    # A wide rectangle: columns 10..49, rows 5..14 -> x spans about 10..49, y about 2.5..7.
    mask = np.zeros((20, 60), bool)
    mask[5:15, 10:50] = True
    box = mm.boundary_from_mask(mask, spacing, smooth=0)
    assert box[:, 0].min() == pytest.approx(9.5) and box[:, 0].max() == pytest.approx(49.5)
    assert box[:, 1].min() == pytest.approx(4.5 * 0.5) and box[:, 1].max() == pytest.approx(14.5 * 0.5)


def test_labels_holes_and_the_border():
    labels = np.zeros((60, 60), np.int32)
    labels[disc((60, 60), (20, 20), 10)] = 3
    labels[disc((60, 60), (45, 45), 8)] = 7
    with pytest.raises(ValueError, match=r"mask: a label image with 2 labels \(3, 7\): pass label="):
        mm.boundary_from_mask(labels)
    seven = mm.boundary_from_mask(labels, label=7)
    assert np.abs(np.linalg.norm(seven - (45, 45), axis=1) - 8).max() < 0.75
    with pytest.raises(ValueError, match="label: no pixel of mask has the value 5"):
        mm.boundary_from_mask(labels, label=5)
    # Two objects in a binary mask: named with their sizes.
    with pytest.raises(ValueError, match=r"mask: 2 separate objects \(\d+, \d+ pixels\)"):
        mm.boundary_from_mask(labels > 0)
    # A hole is ignored: the outer boundary.
    ring = disc((60, 60), (30, 30), 20) & ~disc((60, 60), (30, 30), 8)
    outer = mm.boundary_from_mask(ring)
    assert abs(mm.signed_area(outer) / (np.pi * 20**2) - 1) < 0.02
    # An object cut by the image border is closed along the border.
    edge = np.zeros((30, 30), bool)
    edge[:10, 5:25] = True
    closed = mm.boundary_from_mask(edge, smooth=0)
    assert closed[:, 1].min() == pytest.approx(-0.5)
    assert mm.signed_area(closed) == pytest.approx(10 * 20, rel=0.01)
    # The default rounds the four corners (measured: area -2.6%); the border side stays put.
    rounded = mm.boundary_from_mask(edge)
    assert rounded[:, 1].min() == pytest.approx(-0.5)
    assert mm.signed_area(rounded) == pytest.approx(10 * 20, rel=0.03)


def ellipse_distance(points, centre, a, b):
    """Distance from each point to the ellipse with semi-axes a (along x) and b (along y)."""
    from scipy.spatial import cKDTree

    t = np.linspace(0, 2 * np.pi, 40000, endpoint=False)
    dense = np.column_stack([centre[0] + a * np.cos(t), centre[1] + b * np.sin(t)])
    return cKDTree(dense).query(points)[0], mm.perimeter(dense)


@pytest.mark.parametrize("spacing", [(0.65, 0.65), (0.65, 0.5), (0.5, 0.65)])
def test_the_default_outline_is_sub_pixel(spacing):
    # Discs and ellipses at random sub-pixel centres, radii 20 to 50 pixels: perimeter and area
    # within 0.5% and 2%, every point within half a pixel (the digitisation's own error, which
    # no outline of the pixels can beat). Measured worst over these: perimeter +0.5%, area
    # -1.6% (the 12-pixel ends of the 20 x 12 ellipse), 0.50 pixels.
    rng = np.random.default_rng(7)
    pixel = max(spacing)
    for radius, ratio in ((50, 1.0), (50, 0.6), (20, 1.0), (20, 0.6)):
        for _ in range(4):
            a, b = radius * 0.65, radius * 0.65 * ratio
            centre = (a + 5 + rng.uniform(0, 1), b + 4 + rng.uniform(0, 1))
            rows, columns = np.indices((int(2 * b / spacing[0]) + 30, int(2 * a / spacing[1]) + 30))
            x, y = columns * spacing[1], rows * spacing[0]
            mask = ((x - centre[0]) / a) ** 2 + ((y - centre[1]) / b) ** 2 <= 1
            curve = mm.boundary_from_mask(mask, spacing)
            distances, perimeter = ellipse_distance(curve, centre, a, b)
            raw = mm.boundary_from_mask(mask, spacing, smooth=0)
            assert mm.perimeter(raw) / perimeter - 1 > 0.04  # the staircase
            assert abs(mm.perimeter(curve) / perimeter - 1) < 0.005
            assert abs(mm.signed_area(curve) / (np.pi * a * b) - 1) < (0.02 if radius < 50 else 0.005)
            assert distances.max() <= 0.5 * pixel + 1e-9


@pytest.mark.parametrize("radius", [1, 2, 3, 4, 5])
def test_small_objects_keep_their_outline(radius):
    # Radius 3 to 5 pixels: a narrower Gaussian, every point within half a pixel of the circle.
    spacing = (0.65, 0.5)
    centre = (10.3 * 0.5, 9.8 * 0.65)
    rows, columns = np.indices((20, 22))
    mask = (columns * 0.5 - centre[0]) ** 2 + (rows * 0.65 - centre[1]) ** 2 <= (radius * 0.6) ** 2
    curve = mm.boundary_from_mask(mask, spacing)
    assert len(curve) >= 4 and mm.signed_area(curve) > 0.5 * mask.sum() * 0.65 * 0.5
    if radius >= 3:
        assert np.abs(np.linalg.norm(curve - centre, axis=1) - radius * 0.6).max() <= 0.5 * 0.65 + 1e-9


def test_thin_objects_and_parts_are_kept():
    # A one-pixel line vanishes under a Gaussian of one pixel: the default contours it as it is.
    line = np.zeros((20, 60), bool)
    line[10, 5:55] = True
    np.testing.assert_array_equal(mm.boundary_from_mask(line), mm.boundary_from_mask(line, smooth=0))
    with pytest.raises(ValueError, match="mask: the object vanishes when smoothed by 1.0"):
        mm.boundary_from_mask(line, smooth=1.0)
    # A one-pixel neck would be cut, a one-pixel spur erased: the default keeps both.
    dumbbell = disc((40, 80), (20, 20), 12) | disc((40, 80), (60, 20), 12)
    dumbbell[20, 20:60] = True
    curve = mm.boundary_from_mask(dumbbell)
    assert curve[:, 0].min() < 9 and curve[:, 0].max() > 71
    assert abs(mm.signed_area(curve) / mm.signed_area(mm.boundary_from_mask(dumbbell, smooth=0)) - 1) < 0.02
    spur = disc((80, 80), (40, 40), 20)
    spur[40, 60:75] = True
    assert mm.boundary_from_mask(spur)[:, 0].max() > 74
    # A single pixel and a pixel-wide diagonal staircase.
    single = np.zeros((5, 5), bool)
    single[2, 2] = True
    assert mm.signed_area(mm.boundary_from_mask(single)) == pytest.approx(0.5)
    stair = np.zeros((30, 30), bool)
    for i in range(25):
        stair[i + 2, i + 2 : i + 4] = True
    assert mm.signed_area(mm.boundary_from_mask(stair)) > 0.9 * stair.sum()


def test_smoothing_in_physical_units():
    # A square's corners round off under smoothing, by the same amount whatever the pixel size.
    areas = []
    for s in (1.0, 0.5):
        n = int(40 / s)
        mask = np.zeros((n + 20, n + 20), bool)
        mask[10:10 + n, 10:10 + n] = True
        areas.append(mm.signed_area(mm.boundary_from_mask(mask, s, smooth=3.0)))
    assert areas[0] < 40 * 40 and abs(areas[0] / areas[1] - 1) < 0.01
    # A neck thinner than the Gaussian is cut: said, not silently dropped.
    dumbbell = disc((40, 80), (20, 20), 12) | disc((40, 80), (60, 20), 12)
    dumbbell[19:21, 20:60] = True
    with pytest.raises(ValueError, match="smooth: a Gaussian of width 3.0 splits the object into 2 pieces"):
        mm.boundary_from_mask(dumbbell, smooth=3.0)


def test_the_curve_maps():
    # Two frames of a growing disc, straight from masks into map_curves.
    c1 = mm.boundary_from_mask(disc((120, 120), (60, 60), 30), 0.5)
    c2 = mm.boundary_from_mask(disc((120, 120), (60, 60), 40), 0.5)
    field = mm.map_curves(c1, c2, method="auto")
    assert np.all(field.valid) and mm.quality(field, c1, c2).crossings == 0


def test_bad_input():
    with pytest.raises(ValueError, match=r"mask: expected a 2D image, got shape \(4, 4, 4\)"):
        mm.boundary_from_mask(np.ones((4, 4, 4), bool))
    with pytest.raises(TypeError, match="mask: expected a boolean mask or an integer label image"):
        mm.boundary_from_mask(np.ones((4, 4)))
    with pytest.raises(ValueError, match="mask: has no foreground pixel"):
        mm.boundary_from_mask(np.zeros((4, 4), bool))
    with pytest.raises(ValueError, match="spacing"):
        mm.boundary_from_mask(np.ones((4, 4), bool), spacing=-1)
    with pytest.raises(ValueError, match="spacing"):
        mm.boundary_from_mask(np.ones((4, 4), bool), spacing=(1, 2, 3))
    with pytest.raises(TypeError, match="label"):
        mm.boundary_from_mask(np.ones((4, 4), np.uint8), label="a")
    with pytest.raises(ValueError, match="smooth"):
        mm.boundary_from_mask(np.ones((4, 4), bool), smooth=-1)
