"""read_image: the data and the spacing each kind of file states, written by the libraries labs use."""

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
    data, spacing = mm.read_image(path)
    np.testing.assert_array_equal(data, stack)
    assert spacing == pytest.approx((2.0, 0.5, 0.65))


def test_ome_tiff(tmp_path, stack):
    import tifffile

    path = tmp_path / "stack.ome.tif"
    tifffile.imwrite(path, stack, ome=True, metadata={"axes": "ZYX", "PhysicalSizeX": 0.3, "PhysicalSizeY": 0.4,
                                                      "PhysicalSizeZ": 1.5})
    data, spacing = mm.read_image(path)
    np.testing.assert_array_equal(data, stack)
    assert spacing == pytest.approx((1.5, 0.4, 0.3))


def test_single_pages_png_and_npy(tmp_path, stack):
    import tifffile
    from PIL import Image

    page = stack[2] * 255
    # A TIFF page at 25400 / 0.8 pixels per inch: 0.8 um pixels; one without a size.
    tifffile.imwrite(tmp_path / "sized.tif", page, resolution=(25400 / 0.8, 25400 / 0.8), resolutionunit=2)
    data, spacing = mm.read_image(tmp_path / "sized.tif")
    np.testing.assert_array_equal(data, page)
    assert spacing == pytest.approx((0.8, 0.8))
    tifffile.imwrite(tmp_path / "plain.tif", page)
    assert mm.read_image(tmp_path / "plain.tif").spacing is None
    Image.fromarray(page).save(tmp_path / "mask.png", dpi=(25400 / 0.5, 25400 / 0.25))
    data, spacing = mm.read_image(tmp_path / "mask.png")
    np.testing.assert_array_equal(data, page)
    assert spacing == pytest.approx((0.25, 0.5), rel=1e-3)  # (rows, columns)
    Image.fromarray(page).save(tmp_path / "screen.png", dpi=(72, 72))
    assert mm.read_image(tmp_path / "screen.png").spacing is None
    np.save(tmp_path / "mask.npy", stack)
    data, spacing = mm.read_image(tmp_path / "mask.npy")
    np.testing.assert_array_equal(data, stack)
    assert spacing is None


def test_into_a_boundary(tmp_path):
    import tifffile

    rows, columns = np.indices((80, 80))
    mask = ((columns - 40) * 0.5) ** 2 + ((rows - 40) * 0.5) ** 2 <= 15**2
    tifffile.imwrite(tmp_path / "disc.tif", mask.astype(np.uint8), imagej=True, resolution=(2.0, 2.0),
                     metadata={"unit": "um"})
    data, spacing = mm.read_image(tmp_path / "disc.tif")
    curve = mm.boundary_from_mask(data, spacing)
    assert abs(mm.signed_area(curve) / (np.pi * 15**2) - 1) < 0.01


def test_bad_input(tmp_path):
    with pytest.raises(ValueError, match="path: no such file"):
        mm.read_image(tmp_path / "missing.tif")
    (tmp_path / "field.csv").write_text("x,y\n")
    with pytest.raises(ValueError, match=r"path: .*field.csv: expected a .png, .tif, .tiff or .npy image"):
        mm.read_image(tmp_path / "field.csv")
    with pytest.raises(TypeError, match="path"):
        mm.read_image(3)
