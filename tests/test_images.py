"""read_image: the data, axes, spacing, unit and frame interval each kind of file states, written by the libraries
labs use."""

import warnings

import numpy as np
import pytest

import morphomap as mm


@pytest.fixture
def stack():
    volume = np.zeros((5, 20, 30), np.uint8)
    volume[1:4, 5:15, 8:22] = 1
    return volume


def test_imagej_hyperstack(tmp_path, stack):
    import tifffile

    path = tmp_path / "stack.tif"
    tifffile.imwrite(path, stack, imagej=True, resolution=(1 / 0.65, 1 / 0.5),
                     metadata={"spacing": 2.0, "unit": "um", "axes": "ZYX"})
    image = mm.read_image(path)
    np.testing.assert_array_equal(image.data, stack)
    assert image.spacing == pytest.approx((2.0, 0.5, 0.65))
    assert (image.axes, image.unit, image.frame_interval) == ("ZYX", "um", None)


def test_ome_tiff(tmp_path, stack):
    import tifffile

    path = tmp_path / "stack.ome.tif"
    tifffile.imwrite(path, stack, ome=True, metadata={"axes": "ZYX", "PhysicalSizeX": 0.3, "PhysicalSizeY": 0.4,
                                                      "PhysicalSizeZ": 1.5})
    image = mm.read_image(path)
    np.testing.assert_array_equal(image.data, stack)
    assert image.spacing == pytest.approx((1.5, 0.4, 0.3))
    assert (image.axes, image.unit, image.frame_interval) == ("ZYX", "um", None)


def test_single_pages_png_and_npy(tmp_path, stack):
    import tifffile
    from PIL import Image

    page = stack[2] * 255
    # A TIFF page at 25400 / 0.8 pixels per inch: 0.8 um pixels; one without a size.
    tifffile.imwrite(tmp_path / "sized.tif", page, resolution=(25400 / 0.8, 25400 / 0.8), resolutionunit=2)
    image = mm.read_image(tmp_path / "sized.tif")
    np.testing.assert_array_equal(image.data, page)
    assert image.spacing == pytest.approx((0.8, 0.8))
    assert (image.axes, image.unit) == ("YX", "um")
    tifffile.imwrite(tmp_path / "plain.tif", page)
    plain = mm.read_image(tmp_path / "plain.tif")
    assert (plain.axes, plain.spacing, plain.unit, plain.frame_interval) == ("YX", None, None, None)
    Image.fromarray(page).save(tmp_path / "mask.png", dpi=(25400 / 0.5, 25400 / 0.25))
    image = mm.read_image(tmp_path / "mask.png")
    np.testing.assert_array_equal(image.data, page)
    assert image.spacing == pytest.approx((0.25, 0.5), rel=1e-3)  # (rows, columns)
    assert (image.axes, image.unit) == ("YX", "um")
    assert mm.read_image(tmp_path / "mask.png", unit="nm").spacing == pytest.approx((250, 500), rel=1e-3)
    Image.fromarray(page).save(tmp_path / "screen.png", dpi=(72, 72))
    assert mm.read_image(tmp_path / "screen.png").spacing is None
    np.save(tmp_path / "mask.npy", stack)
    image = mm.read_image(tmp_path / "mask.npy")
    np.testing.assert_array_equal(image.data, stack)
    assert (image.axes, image.spacing, image.unit, image.frame_interval) == ("ZYX", None, None, None)
    np.save(tmp_path / "page.npy", page)
    assert mm.read_image(tmp_path / "page.npy").axes == "YX"


def test_into_a_boundary(tmp_path):
    import tifffile

    rows, columns = np.indices((80, 80))
    mask = ((columns - 40) * 0.5) ** 2 + ((rows - 40) * 0.5) ** 2 <= 15**2
    tifffile.imwrite(tmp_path / "disc.tif", mask.astype(np.uint8), imagej=True, resolution=(2.0, 2.0),
                     metadata={"unit": "um"})
    image = mm.read_image(tmp_path / "disc.tif")
    curve = mm.boundary_from_mask(image.data, image.spacing)
    assert abs(mm.signed_area(curve) / (np.pi * 15**2) - 1) < 0.01


def test_bad_input(tmp_path):
    with pytest.raises(ValueError, match="path: no such file"):
        mm.read_image(tmp_path / "missing.tif")
    (tmp_path / "field.csv").write_text("x,y\n")
    with pytest.raises(ValueError, match=r"path: .*field.csv: expected a .png, .tif, .tiff or .npy image"):
        mm.read_image(tmp_path / "field.csv")
    with pytest.raises(TypeError, match="path"):
        mm.read_image(3)
    with pytest.raises(ValueError, match="unit: expected one of um, nm, mm, cm, m, got 'furlong'"):
        mm.read_image(tmp_path / "missing.tif", unit="furlong")
    np.save(tmp_path / "movie.npy", np.zeros((2, 3, 4, 5), np.uint8))
    with pytest.raises(ValueError, match=r"movie.npy: a 4D array: a .npy states no axes"):
        mm.read_image(tmp_path / "movie.npy")


@pytest.fixture
def movies():
    """A growing rectangle: 5 frames of (20, 30) pixels, and 4 time points of a (3, 20, 30) stack."""
    frames = np.zeros((5, 20, 30), np.uint8)
    for t in range(5):
        frames[t, 5:10 + t, 8:14 + 2 * t] = 1
    stacks = np.zeros((4, 3, 20, 30), np.uint8)
    for t in range(4):
        stacks[t, 1, 5:10 + t, 8:14 + 2 * t] = 1
    return {"TYX": frames, "TZYX": stacks}


@pytest.mark.parametrize("axes", ["TYX", "TZYX"])
@pytest.mark.parametrize("length, unit", [(0.65, "um"), (650.0, "nm")])
def test_imagej_movie(tmp_path, movies, axes, length, unit):
    # Fiji's hyperstack: pixels per unit in the resolution tags, z spacing and frame interval
    # (in its time unit) in the description; a file in nm reads as um (650 nm -> 0.65 um).
    import tifffile

    movie, path = movies[axes], tmp_path / f"{axes}_{unit}.tif"
    tifffile.imwrite(path, movie, imagej=True, resolution=(1 / length, 1 / length),
                     metadata={"axes": axes, "unit": unit, "spacing": 3 * length, "finterval": 2.5, "tunit": "min"})
    image = mm.read_image(path)
    np.testing.assert_array_equal(image.data, movie)
    assert (image.axes, image.unit) == (axes, "um")
    expected = (1.95, 0.65, 0.65) if axes == "TZYX" else (0.65, 0.65)
    assert image.spacing == pytest.approx(expected)
    assert image.frame_interval == pytest.approx(150.0)
    in_nm = mm.read_image(path, unit="nm")
    assert in_nm.unit == "nm" and in_nm.spacing == pytest.approx(tuple(1000 * v for v in expected))
    # The interval in ImageJ's default unit, seconds; an uncalibrated file (unit "pixel") has no size.
    tifffile.imwrite(path, movie, imagej=True, metadata={"axes": axes, "unit": "pixel", "finterval": 30})
    image = mm.read_image(path)
    assert (image.axes, image.spacing, image.unit, image.frame_interval) == (axes, None, None, 30.0)


@pytest.mark.parametrize("axes", ["TYX", "TZYX"])
@pytest.mark.parametrize("length, unit", [(0.65, "µm"), (650.0, "nm")])
def test_ome_movie(tmp_path, movies, axes, length, unit):
    import tifffile

    movie, path = movies[axes], tmp_path / f"{axes}_{unit}.ome.tif"
    metadata = {"axes": axes, "PhysicalSizeX": length, "PhysicalSizeXUnit": unit, "PhysicalSizeY": length,
                "PhysicalSizeYUnit": unit, "PhysicalSizeZ": 2.0, "PhysicalSizeZUnit": "µm",
                "TimeIncrement": 1500, "TimeIncrementUnit": "ms"}
    tifffile.imwrite(path, movie, ome=True, metadata=metadata)
    image = mm.read_image(path)
    np.testing.assert_array_equal(image.data, movie)
    assert (image.axes, image.unit) == (axes, "um")
    assert image.spacing == pytest.approx((2.0, 0.65, 0.65) if axes == "TZYX" else (0.65, 0.65))
    assert image.frame_interval == pytest.approx(1.5)
    # Without units, OME's defaults: micrometres and seconds.
    tifffile.imwrite(path, movie, ome=True, metadata={"axes": axes, "PhysicalSizeX": 0.5, "PhysicalSizeY": 0.5,
                                                      "TimeIncrement": 20})
    image = mm.read_image(path, unit="mm")
    assert (image.axes, image.unit, image.frame_interval) == (axes, "mm", 20.0)
    assert image.spacing[-2:] == pytest.approx((5e-4, 5e-4))


def test_stated_time_and_unknown_units(tmp_path, movies):
    import tifffile

    # tifffile's own metadata stating a T axis: time, no warning.
    tifffile.imwrite(tmp_path / "shaped.tif", movies["TYX"], metadata={"axes": "TYX"})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert mm.read_image(tmp_path / "shaped.tif").axes == "TYX"
    tifffile.imwrite(tmp_path / "odd.tif", movies["TYX"], imagej=True, resolution=(2.0, 2.0),
                     metadata={"axes": "TYX", "unit": "furlong"})
    with pytest.raises(ValueError, match=r"odd.tif: unknown length unit 'furlong'"):
        mm.read_image(tmp_path / "odd.tif")
    tifffile.imwrite(tmp_path / "odd.tif", movies["TYX"], imagej=True,
                     metadata={"axes": "TYX", "finterval": 2, "tunit": "fortnight"})
    with pytest.raises(ValueError, match=r"odd.tif: unknown time unit 'fortnight'"):
        mm.read_image(tmp_path / "odd.tif")


@pytest.mark.parametrize("shaped", [False, True])
def test_pages_without_axes_are_a_z_stack_with_a_warning(tmp_path, movies, shaped):
    # Pages that do not say what they are: tifffile's generic I (plain pages) or Q (its shaped
    # metadata without axes) axis, read as Z and said so, never silently.
    import tifffile

    path = tmp_path / "pages.tif"
    tifffile.imwrite(path, movies["TYX"], **({} if shaped else {"metadata": None}))
    with pytest.warns(UserWarning, match=r"pages.tif: .*assumed a z-stack of 5 pages.*imagej=True.*'TYX'"):
        image = mm.read_image(path)
    np.testing.assert_array_equal(image.data, movies["TYX"])
    assert (image.axes, image.spacing, image.frame_interval) == ("ZYX", None, None)


def test_rgb_png_and_movies_are_not_masks(tmp_path, movies):
    import tifffile
    from PIL import Image

    from morphomap.io.frames import read_boundary

    picture = np.zeros((20, 30, 3), np.uint8)
    picture[5:15, 8:22] = (200, 40, 40)
    Image.fromarray(picture).save(tmp_path / "photo.png")
    image = mm.read_image(tmp_path / "photo.png")
    assert image.axes == "YXC" and image.data.shape == (20, 30, 3)
    Image.fromarray(np.dstack([picture, np.full((20, 30), 255, np.uint8)])).save(tmp_path / "rgba.png")
    assert mm.read_image(tmp_path / "rgba.png").axes == "YXC"
    with pytest.raises(ValueError, match=r"an RGB/multichannel image, not a mask: .*photo.png.*segment it first"):
        read_boundary(tmp_path / "photo.png")
    tifffile.imwrite(tmp_path / "movie.tif", movies["TYX"], imagej=True, metadata={"axes": "TYX"})
    with pytest.raises(ValueError, match=r"movie.tif: a movie \(axes TYX, 5 time points\).*morphomap series"):
        read_boundary(tmp_path / "movie.tif")
    # A mask's boundary, with the unit the spacing is in.
    tifffile.imwrite(tmp_path / "frame.tif", movies["TYX"][4], imagej=True, resolution=(1 / 0.65, 1 / 0.65),
                     metadata={"unit": "micron"})
    lines = []
    curve, from_image = read_boundary(tmp_path / "frame.tif", smooth=0, report=lines.append)
    assert from_image and lines == [f"{tmp_path / 'frame.tif'}: pixel spacing 0.65 x 0.65 (the file), in um"]
    # 9 x 14 pixels less the four corners marching squares cuts (1/8 pixel each), in um^2.
    assert abs(mm.signed_area(curve)) == pytest.approx((9 * 14 - 0.5) * 0.65**2, rel=1e-6)
