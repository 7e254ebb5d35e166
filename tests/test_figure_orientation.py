"""Figures of image data look as the image does: a mask's top-left corner stays top-left, read off
the rendered pixels; axes carry the image's unit; animation frames carry their time."""

import numpy as np
import pytest
import tifffile

pytest.importorskip("matplotlib")

import matplotlib  # noqa: E402

matplotlib.use("Agg")

from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from mpl_toolkits.mplot3d import proj3d  # noqa: E402

import morphomap as mm  # noqa: E402
from morphomap import series_plot  # noqa: E402
from conftest import circle  # noqa: E402

PIXEL = 0.5  # µm
INTERVAL = 1800.0  # seconds between frames
LEGS = (24, 32, 40)  # pixels: the object grows away from its corner


def triangle_mask(leg, shape=(64, 64), corner=8):
    """A right triangle whose right angle is at the top-left (row 8, column 8) of the image: most of
    its outline lies near that corner."""
    rows, columns = np.indices(shape)
    inside = (rows >= corner) & (columns >= corner) & ((rows - corner) + (columns - corner) < leg)
    return inside.astype(np.uint8) * 255


@pytest.fixture(scope="module")
def movie_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("figures") / "triangle.tif"
    frames = np.stack([triangle_mask(leg) for leg in LEGS])
    tifffile.imwrite(path, frames, imagej=True, resolution=(1 / PIXEL, 1 / PIXEL),
                     metadata={"axes": "TYX", "unit": "um", "finterval": INTERVAL})
    return path


@pytest.fixture(scope="module")
def series(movie_path):
    return mm.map_series(movie_path, "normal", progress=False)


def axes(projection=None):
    figure = Figure(figsize=(5, 5), dpi=80)
    FigureCanvasAgg(figure)
    return figure.add_subplot(projection=projection)


def ink_position(ax):
    """Where the drawing inside ``ax`` lies in its own bounding box, from the rendered pixels:
    ``(from the left, from the top)``, each 0..1; the outline of a triangle whose right angle is
    at its top-left gives about (0.35, 0.35), drawn upside down about (0.35, 0.65)."""
    if ax.get_legend() is not None:
        ax.get_legend().remove()
    ax.figure.canvas.draw()
    pixels = np.asarray(ax.figure.canvas.buffer_rgba())[..., :3].astype(int)
    box = ax.get_window_extent()
    height = pixels.shape[0]
    # Inside the axes' frame, a few pixels in from the spines; image row 0 is the top.
    top, bottom = int(height - box.y1) + 4, int(height - box.y0) - 4
    left, right = int(box.x0) + 4, int(box.x1) - 4
    inked = (pixels[top:bottom, left:right] < 200).any(axis=2)
    rows, columns = np.nonzero(inked)
    assert len(rows) > 100, "nothing drawn"
    across = (columns.mean() - columns.min()) / (columns.max() - columns.min())
    down = (rows.mean() - rows.min()) / (rows.max() - rows.min())
    return across, down


def assert_top_left(ax):
    across, down = ink_position(ax)
    assert across < 0.45 and down < 0.45, f"the corner is drawn at {across:.2f} across, {down:.2f} down"


def test_series_from_a_movie_knows_its_unit_orientation_and_time(series):
    assert series.unit == "um" and series.y_down is True
    assert series.time_unit == "s" and series.dt == pytest.approx(INTERVAL)
    # A list of curves carries no mark of an image; the figures then draw y-up in "units".
    plain = mm.map_series([circle(40, r) for r in (1.0, 1.5)], "normal", progress=False)
    assert plain.unit is None and plain.y_down is False and plain.time_unit is None


def test_map_figure_of_masks_keeps_the_corner_top_left(movie_path):
    masks = tifffile.imread(movie_path)
    c1, c2 = (mm.boundary_from_mask(m, PIXEL) for m in masks[:2])
    field = mm.map_curves(c1, c2, "normal")
    assert_top_left(mm.plot_field(field, c1, c2, ax=axes(), y_down=True, unit="um"))
    # The check itself tells the two apart: drawn y-up, the corner is at the bottom.
    across, down = ink_position(mm.plot_field(field, c1, c2, ax=axes(), y_down=False))
    assert across < 0.45 and down > 0.55


@pytest.mark.parametrize("figure", ["trajectories", "stretch", "normal_speed", "animation frame"])
def test_series_figures_keep_the_corner_top_left(series, figure):
    draw = {
        "trajectories": lambda ax: series.plot_trajectories(ax),
        "stretch": lambda ax: series.plot_growth("accumulated_stretch", -1, ax),
        "normal_speed": lambda ax: series.plot_growth("normal_speed", 0, ax),
        "animation frame": lambda ax: series_plot.plot_frame(series, 2, ax),
    }[figure]
    ax = draw(axes())
    assert ax.yaxis_inverted()
    assert_top_left(ax)
    # Asked to draw y-up instead, the same figure puts the corner at the bottom.
    flipped = {
        "trajectories": lambda ax: series.plot_trajectories(ax, y_down=False),
        "stretch": lambda ax: series.plot_growth("accumulated_stretch", -1, ax, y_down=False),
        "normal_speed": lambda ax: series.plot_growth("normal_speed", 0, ax, y_down=False),
        "animation frame": lambda ax: series_plot.plot_frame(series, 2, ax, y_down=False),
    }[figure](axes())
    assert ink_position(flipped)[1] > 0.55


def test_axis_labels_carry_the_unit(series):
    for ax in (series.plot_trajectories(axes()), series.plot_growth("stretch", 0, axes()),
               series_plot.plot_frame(series, 1, axes())):
        assert (ax.get_xlabel(), ax.get_ylabel()) == ("x (µm)", "y (µm)")
    c1, c2 = circle(30, 1.0), circle(30, 2.0)
    ax = mm.plot_field(mm.map_curves(c1, c2, "normal"), c1, c2, ax=axes())
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x (units)", "y (units)")
    assert not ax.yaxis_inverted()
    # Speeds are labelled per the frame interval's unit, stretches as ratios.
    bar = series.plot_growth("normal_speed", 0, axes()).figure.axes[-1]
    assert bar.get_ylabel() == "normal speed (µm/s)"
    bar = series.plot_growth("stretch", 0, axes()).figure.axes[-1]
    assert bar.get_ylabel() == "stretch over the step (length ratio)"
    with pytest.raises(TypeError, match="unit: expected a string"):
        series.plot_trajectories(axes(), unit=3)


def test_animation_frames_carry_time_stamps(series, tmp_path, monkeypatch):
    titles = []
    drawn = series_plot.plot_frame

    def recording(*args, **kwargs):
        ax = drawn(*args, **kwargs)
        titles.append(ax.get_title())
        return ax

    monkeypatch.setattr(series_plot, "plot_frame", recording)
    series.animate(tmp_path / "movie.gif")
    # 1800 s apart over 3 frames: one hour, stamped in minutes.
    assert [title.split(" (")[0] for title in titles] == ["t = 0.0 min", "t = 30.0 min", "t = 60.0 min"]
    assert titles[1].startswith("t = 30.0 min (frame 1 of 2): ")
    with pytest.raises(ValueError, match="t: expected a frame 0..2"):
        drawn(series, 3, axes())


def test_3d_image_data_is_seen_as_the_slices_look():
    s1 = mm.surface_from_mask(np.pad(np.ones((4, 6, 6), np.uint8), 2), (1.0, 1.0, 1.0))
    s2 = mm.surface_from_mask(np.pad(np.ones((6, 8, 8), np.uint8), 2), (1.0, 1.0, 1.0))
    field = mm.map_surfaces(s1, s2, "normal")
    ax = mm.plot_field(field, s1, s2, ax=axes("3d"), y_down=True, unit="um")
    assert (ax.get_xlabel(), ax.get_ylabel(), ax.get_zlabel()) == ("x (µm)", "y (µm)", "z (µm)")
    ax.figure.canvas.draw()

    def on_screen(point):
        return ax.transData.transform(proj3d.proj_transform(*point, ax.get_proj())[:2])

    origin, right, down = on_screen((5, 5, 5)), on_screen((8, 5, 5)), on_screen((5, 8, 5))
    assert right[0] > origin[0] + 10 and abs(right[1] - origin[1]) < 2  # x to the right
    assert down[1] < origin[1] - 10 and abs(down[0] - origin[0]) < 2  # y down the screen


def test_a_frame_read_from_a_file_says_its_unit(movie_path, tmp_path):
    from PIL import Image

    from morphomap.io.frames import read_boundary, read_sourced_boundary

    mask = tifffile.imread(movie_path)[0]
    tifffile.imwrite(tmp_path / "frame.tif", mask, imagej=True, resolution=(1 / PIXEL, 1 / PIXEL),
                     metadata={"unit": "um"})
    Image.fromarray(mask).save(tmp_path / "frame.png")
    curve, from_image, unit = read_sourced_boundary(tmp_path / "frame.tif")
    assert from_image and unit == "um" and curve[:, 0].max() < 64 * PIXEL
    assert read_sourced_boundary(tmp_path / "frame.png").unit == "pixel"  # no size in the file
    assert read_sourced_boundary(tmp_path / "frame.tif", spacing=2.0).unit is None  # the caller's unit
    mm.write_curve(tmp_path / "curve.csv", curve)
    assert read_sourced_boundary(tmp_path / "curve.csv")[1:] == (False, None)
    assert len(read_boundary(tmp_path / "frame.tif")) == 2
