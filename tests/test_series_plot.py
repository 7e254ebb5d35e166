"""Pictures of a time series: trajectories, growth maps and the animation, read back from disk."""

import shutil

import numpy as np
import pytest
import trimesh

pytest.importorskip("matplotlib")

import matplotlib  # noqa: E402

matplotlib.use("Agg")

from matplotlib.figure import Figure  # noqa: E402
from PIL import Image  # noqa: E402

import morphomap as mm  # noqa: E402
from morphomap.figure_style import TIME_MAP  # noqa: E402
from conftest import circle  # noqa: E402


@pytest.fixture(scope="module")
def curves():
    return mm.map_series([circle(60, r) for r in (1.0, 1.4, 2.6, 3.0)], "normal", progress=False)


@pytest.fixture(scope="module")
def spheres():
    return mm.map_series([trimesh.creation.icosphere(1).apply_scale(r) for r in (1.0, 1.5, 2.2)], "normal",
                         progress=False)


def test_trajectories_are_coloured_by_frame(curves):
    ax = curves.plot_trajectories(Figure().subplots())
    alive = np.isfinite(curves.trajectories).all(axis=2)
    # The frames (4), then one line per step: a piece per point alive at both ends (pieces apart
    # by NaN), coloured by the step's end on the colour bar's scale.
    assert len(ax.lines) == 4 + 3
    bar = ax.figure.axes[-1]
    assert bar.get_ylabel() == "frame"
    for t, line in zip(range(1, 4), ax.lines[4:]):
        x, y = line.get_data()
        pieces = np.isfinite(np.asarray(x, dtype=float)).reshape(-1, 3)[:, :2].all(axis=1)
        assert pieces.sum() == int((alive[t - 1] & alive[t]).sum())
        assert line.get_color() == tuple(matplotlib.colormaps[TIME_MAP](t / 3))



def test_growth_maps_colour_the_boundary(curves, spheres):
    ax = curves.plot_growth("accumulated_stretch", -1, Figure().subplots())
    colours = ax.collections[-1]
    assert len(colours.get_segments()) == len(curves.cells[2])
    assert np.allclose(colours.get_array(), 3.0)  # every piece grew from radius 1 to 3
    ax = curves.plot_growth("normal_speed", 0, Figure().subplots())
    assert np.allclose(ax.collections[-1].get_array(), 0.4)
    ax = spheres.plot_growth("stretch", 1, Figure().add_subplot(projection="3d"))
    triangles = ax.collections[-1]
    assert len(triangles.get_array()) == len(spheres.cells[1])
    assert np.allclose(triangles.get_array(), spheres.stretch(1))
    with pytest.raises(ValueError, match="quantity: expected one of"):
        curves.plot_growth("speed")
    with pytest.raises(TypeError, match="ax: expected a 3D axes"):
        spheres.plot_growth("stretch", 0, Figure().subplots())


@pytest.mark.parametrize("kind", ["curves", "spheres"])
def test_write_draws_figures_and_an_animation(kind, request, tmp_path):
    series = request.getfixturevalue(kind)
    paths = series.write(tmp_path / kind)
    names = [p.split("/")[-1] for p in paths]
    movies = ["series.gif", "series.mp4"] if shutil.which("ffmpeg") else ["series.gif"]
    assert names[names.index("trajectories.png"):] == ["trajectories.png", "stretch.png", "normal_speed.png", *movies]
    for name in ("trajectories.png", "stretch.png", "normal_speed.png"):
        with Image.open(tmp_path / kind / name) as image:
            assert image.format == "PNG" and image.size[0] > 300
    with Image.open(tmp_path / kind / "series.gif") as gif:
        assert gif.format == "GIF" and gif.n_frames == len(series.frames)
    if shutil.which("ffmpeg"):
        assert (tmp_path / kind / "series.mp4").stat().st_size > 0


def test_animate_names_a_bad_path(curves, tmp_path):
    with pytest.raises(ValueError, match="path: expected a .gif or .mp4 file"):
        curves.animate(tmp_path / "movie.avi")
    if not shutil.which("ffmpeg"):
        with pytest.raises(ValueError, match="needs ffmpeg"):
            curves.animate(tmp_path / "movie.mp4")
        assert not (tmp_path / "movie.mp4").exists()
