"""Time-lapse files in: a movie of masks or labels as a series, objects through time, drift removed."""

import math
import subprocess
import sys
import warnings

import numpy as np
import pytest
import tifffile
from skimage.draw import polygon

import morphomap as mm
from morphomap.movie import movie_frames, register_frames

PIXEL = 0.65  # µm
INTERVAL = 300.0  # s


def write_movie(path, frames, axes="TYX"):
    tifffile.imwrite(path, np.asarray(frames, dtype=np.uint8), imagej=True, resolution=(1 / PIXEL, 1 / PIXEL),
                     metadata={"axes": axes, "unit": "um", "finterval": INTERVAL})


def disc(shape, centre, radius):
    rows, columns = np.mgrid[: shape[0], : shape[1]]
    return np.hypot(rows - centre[0], columns - centre[1]) < radius


def kidney_pixels():
    """The bundled kidney outline in pixel units (x = column, y = row), about 60 px across."""
    c1, _ = mm.load_example("kidney")
    c1 = c1 - c1.mean(axis=0)
    return c1 * (60.0 / np.ptp(c1, axis=0).max())


def drawn(outline, shape):
    """The mask of a closed outline (x, y) = (column, row)."""
    mask = np.zeros(shape, dtype=bool)
    rows, columns = polygon(outline[:, 1], outline[:, 0], shape)
    mask[rows, columns] = True
    return mask


def turned(points, angle, centre):
    c, s = math.cos(angle), math.sin(angle)
    return (points - centre) @ np.array([[c, -s], [s, c]]).T + centre


def test_a_2d_movie_maps_with_its_spacing_and_interval(tmp_path):
    shape = (120, 120)
    write_movie(tmp_path / "grow.tif", [disc(shape, (60, 60), 20 + 3 * t) for t in range(4)])
    series = mm.map_series(tmp_path / "grow.tif", progress=False)
    assert len(series.fields) == 3 and series.dt == INTERVAL and series.motion is None
    # Frames in µm: the discs' radii, 20 to 29 pixels.
    for t, frame in enumerate(series.frames):
        radius = np.linalg.norm(frame - frame.mean(axis=0), axis=1).mean()
        assert radius == pytest.approx((20 + 3 * t) * PIXEL, abs=0.5 * PIXEL)
    # Growth of 3 pixels a frame: the normal speed in µm per second.
    speeds = series.normal_speed[np.isfinite(series.normal_speed)]
    assert np.median(speeds) == pytest.approx(3 * PIXEL / INTERVAL, rel=0.15)


def test_a_3d_movie_gives_surfaces(tmp_path):
    z, y, x = np.mgrid[:24, :40, :40]
    frames = [np.hypot(np.hypot(z - 12, y - 20), x - 20) < 7 + 2 * t for t in range(3)]
    write_movie(tmp_path / "grow3d.tif", frames, axes="TZYX")
    series = mm.map_series(tmp_path / "grow3d.tif", progress=False)
    assert series.dim == 3 and len(series.fields) == 2 and series.dt == INTERVAL
    assert all(frame.is_watertight for frame in series.frames)


def test_a_drifting_3d_movie_is_registered(tmp_path):
    # An ellipsoid growing and drifting 2 voxels a frame along x: rigid registration (ICP) finds
    # the shift within a voxel and next to no rotation (under 2 degrees: about the ellipsoid's own
    # axes of symmetry a turn changes the distances only to second order, so growth sets it).
    z, y, x = np.mgrid[:24, :40, :56]
    frames = [((z - 12) / (6 + t)) ** 2 + ((y - 20) / (9 + t)) ** 2 + ((x - 20 - 2 * t) / (12 + t)) ** 2 < 1
              for t in range(3)]
    write_movie(tmp_path / "drift3d.tif", frames, axes="TZYX")
    series = mm.map_series(tmp_path / "drift3d.tif", register="rigid", progress=False)
    for t, matrix in enumerate(series.motion):
        angle = math.degrees(math.acos(np.clip((np.trace(matrix[:3, :3]) - 1) / 2, -1, 1)))
        assert angle < 2.0
        centre = np.array([20.0 + 2 * t, 20.0, 12.0]) * PIXEL  # (x, y, z) of the drifted centre
        moved = matrix[:3, :3] @ centre + matrix[:3, 3]
        assert np.linalg.norm(moved - np.array([20.0, 20.0, 12.0]) * PIXEL) < PIXEL


def test_drift_is_removed(tmp_path):
    # A kidney growing 4% a frame about its centroid, the sample drifting (6, -4) pixels and
    # turning 3 degrees a frame: the registered series recovers the motion within a pixel and
    # half a degree, and its growth maps are those of the same movie without drift.
    shape, frames = (220, 260), 5
    centre = np.array([100.0, 110.0])
    still, drifting, truth = [], [], []
    for t in range(frames):
        outline = kidney_pixels() * 1.04**t + centre
        still.append(drawn(outline, shape))
        angle, shift = math.radians(3.0 * t), np.array([6.0, -4.0]) * t
        drifting.append(drawn(turned(outline, angle, centre) + shift, shape))
        truth.append((angle, shift))
    write_movie(tmp_path / "still.tif", still)
    write_movie(tmp_path / "drift.tif", drifting)
    plain = mm.map_series(tmp_path / "still.tif", progress=False)
    series = mm.map_series(tmp_path / "drift.tif", register="rigid", progress=False)
    for matrix, (angle, shift) in zip(series.motion, truth):
        # The motion undoes the drift: turned back by the angle, and the drifted centre (a
        # point that the drift took to centre + shift) back onto the centre.
        assert math.degrees(math.atan2(matrix[1, 0], matrix[0, 0])) == pytest.approx(-math.degrees(angle), abs=0.5)
        moved = matrix[:2, :2] @ ((centre + shift) * PIXEL) + matrix[:2, 2]
        assert np.linalg.norm(moved - centre * PIXEL) < PIXEL
    # The same points of frame 0 followed: the normal speeds agree within the outlines' pixel
    # error (a pixel a frame at most, a fifth of one typically).
    a, b = plain.normal_speed, series.normal_speed
    both = np.isfinite(a) & np.isfinite(b)
    both[:, len(plain.frames[0]):] = False  # points born later differ between the two
    difference = np.abs(a[both] - b[both]) * INTERVAL / PIXEL
    assert difference.max() < 1.0 and np.median(difference) < 0.2
    # Without registering, the drift shows as growth.
    drifted = mm.map_series(tmp_path / "drift.tif", progress=False).normal_speed
    assert np.nanmax(np.abs(drifted[:, : len(plain.frames[0])] - a[:, : len(plain.frames[0])])) * INTERVAL / PIXEL > 3


def test_translation_only_and_the_motion_file(tmp_path):
    shape = (100, 140)
    write_movie(tmp_path / "move.tif", [disc(shape, (50, 40 + 8 * t), 18 + t) for t in range(4)])
    series = mm.map_series(tmp_path / "move.tif", register="translation", progress=False)
    for t, matrix in enumerate(series.motion):
        np.testing.assert_allclose(matrix[:2, :2], np.eye(2))
        assert matrix[0, 2] == pytest.approx(-8 * t * PIXEL, abs=0.2 * PIXEL)
        assert abs(matrix[1, 2]) < 0.2 * PIXEL
    written = series.write(tmp_path / "out", figures=False)
    assert str(tmp_path / "out" / "motion.csv") in written
    rows = (tmp_path / "out" / "motion.csv").read_text().splitlines()
    assert len(rows) == 5 and rows[0].startswith("frame,m00,m01,m02")


def two_halves(shape, centre, radius, left, right, split_right=None):
    """A disc of tissue made of two cells, its left half labelled `left`, its right `right`; with
    split_right = (upper, lower), the right cell has divided into an upper and a lower one."""
    rows, columns = np.mgrid[: shape[0], : shape[1]]
    inside = np.hypot(rows - centre[0], columns - centre[1]) < radius
    image = np.zeros(shape, dtype=np.uint8)
    image[inside & (columns < centre[1])] = left
    if split_right is None:
        image[inside & (columns >= centre[1])] = right
    else:
        image[inside & (columns >= centre[1]) & (rows < centre[0])] = split_right[0]
        image[inside & (columns >= centre[1]) & (rows >= centre[0])] = split_right[1]
    return image


def test_objects_through_unlinked_labels(tmp_path):
    # Labels renumbered every frame, the right cell dividing at frame 2, the left one growing.
    shape = (90, 90)
    frames = [two_halves(shape, (45, 45), 30, 5, 9), two_halves(shape, (45, 45), 31, 2, 7),
              two_halves(shape, (45, 45), 32, 8, 3, split_right=(4, 6))]
    write_movie(tmp_path / "cells.tif", frames)
    area = [np.abs(mm.signed_area(f)) / PIXEL**2 for f in movie_frames(tmp_path / "cells.tif").frames]
    assert area == pytest.approx([math.pi * r * r for r in (30, 31, 32)], rel=0.03)  # the tissue
    largest = movie_frames(tmp_path / "cells.tif", objects="largest").frames
    # The left cell is the largest once the right one has divided; before, the halves tie and
    # either is the largest.
    assert np.mean(largest[2][:, 0]) < 45 * PIXEL
    followed = movie_frames(tmp_path / "cells.tif", objects="follow", label=9).frames
    for t, frame in enumerate(followed):  # the right cell, then its larger daughter (a tie: one of them)
        assert np.mean(frame[:, 0]) > 45 * PIXEL
        half = math.pi * (30 + t) ** 2 / 2
        assert np.abs(mm.signed_area(frame)) / PIXEL**2 == pytest.approx(half if t < 2 else half / 2, rel=0.06)
    left = movie_frames(tmp_path / "cells.tif", objects="follow", label=5).frames
    assert all(np.mean(frame[:, 0]) < 45 * PIXEL for frame in left)


def test_bad_movies_are_refused(tmp_path):
    with pytest.raises(ValueError, match="objects: expected one of"):
        mm.map_series(tmp_path / "x.tif", objects="all")
    write_movie(tmp_path / "empty.tif", [np.zeros((20, 20)), np.zeros((20, 20))])
    with pytest.raises(ValueError, match="frame 0: has no object"):
        mm.map_series(tmp_path / "empty.tif")
    with pytest.raises(ValueError, match="label/objects: only for a movie file"):
        mm.map_series([np.eye(2), np.eye(2)], objects="union")
    with pytest.raises(ValueError, match="register: expected one of"):
        register_frames([np.eye(2)], "affine")
    # Far apart frames: the followed object is lost, and said so.
    shape = (60, 120)
    write_movie(tmp_path / "jump.tif", [disc(shape, (30, 20), 10) * 3, disc(shape, (30, 95), 10) * 4])
    with pytest.raises(ValueError, match="no object overlaps"):
        movie_frames(tmp_path / "jump.tif", objects="follow")


def test_border_touching_object_is_warned_about(tmp_path):
    shape = (60, 60)
    write_movie(tmp_path / "edge.tif", [disc(shape, (30, 5), 12), disc(shape, (30, 5), 14)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        movie_frames(tmp_path / "edge.tif")
    assert any(str(w.message).startswith("frame 0: mask: the object touches the image border") for w in caught)
    # One mask or stack on its own, the same; an object inside the image says nothing.
    with pytest.warns(UserWarning, match="mask: the object touches the image border"):
        mm.boundary_from_mask(disc(shape, (30, 5), 12))
    with pytest.warns(UserWarning, match="volume: the object touches the image border"):
        mm.surface_from_mask(np.ones((8, 8, 8), dtype=bool))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mm.boundary_from_mask(disc(shape, (30, 30), 12))


def test_cli_series_from_a_movie(tmp_path):
    shape = (100, 140)
    write_movie(tmp_path / "move.tif", [disc(shape, (50, 40 + 8 * t), 18 + t) for t in range(3)])
    done = subprocess.run([sys.executable, "-m", "morphomap", "series", str(tmp_path / "move.tif"), "--out",
                           str(tmp_path / "out"), "--register", "translation", "--no-progress"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "frame interval 300 s" in done.stderr and "frame 2: moved by" in done.stderr
    assert (tmp_path / "out" / "motion.csv").exists() and (tmp_path / "out" / "field_01.csv").exists()


@pytest.mark.parametrize("kind", ["imagej", "ome"])
@pytest.mark.parametrize("axes", ["TYX", "TZYX"])
@pytest.mark.parametrize("length, unit", [(0.65, "um"), (650.0, "nm")])
def test_series_from_imagej_and_ome_movies(tmp_path, kind, axes, length, unit):
    # A growing disc or ball, written as Fiji or an OME pipeline would, calibrated in µm or nm:
    # the series' frames come out in µm and dt in seconds, whichever way the file says them.
    if axes == "TYX":
        rows, columns = np.mgrid[:60, :60]
        movie = np.array([np.hypot(rows - 30, columns - 30) < 12 + 3 * t for t in range(3)], dtype=np.uint8)
    else:
        z, y, x = np.mgrid[:24, :36, :36]
        movie = np.array([np.hypot(np.hypot(z - 12, y - 18), x - 18) < 6 + 2 * t for t in range(3)], dtype=np.uint8)
    path = tmp_path / f"movie.{kind}.tif"
    if kind == "imagej":
        tifffile.imwrite(path, movie, imagej=True, resolution=(1 / length, 1 / length),
                         metadata={"axes": axes, "unit": unit, "spacing": length, "finterval": 2.5, "tunit": "min"})
    else:
        tifffile.imwrite(path, movie, ome=True, metadata={
            "axes": axes, "PhysicalSizeX": length, "PhysicalSizeXUnit": "µm" if unit == "um" else unit,
            "PhysicalSizeY": length, "PhysicalSizeYUnit": "µm" if unit == "um" else unit, "PhysicalSizeZ": length,
            "PhysicalSizeZUnit": "µm" if unit == "um" else unit, "TimeIncrement": 150, "TimeIncrementUnit": "s"})
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # inside the image: nothing to warn about
        series = mm.map_series(path, progress=False)
    assert series.dt == pytest.approx(150.0) and len(series.fields) == 2
    first = series.frames[0] if axes == "TYX" else series.frames[0].vertices
    radius = np.linalg.norm(first - first.mean(axis=0), axis=1).mean()
    assert radius == pytest.approx((12 if axes == "TYX" else 6) * PIXEL, abs=0.6 * PIXEL)
