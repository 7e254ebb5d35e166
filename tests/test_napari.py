"""The napari plugin: its manifest, reader and widget in a real viewer (napari's make_napari_viewer,
pytest-qt), on labels movies made here. The layers it adds must hold morphomap's own results
converted to napari's (t, [plane,] row, column) pixel indices; bad input must end in a
notification, never an exception out of the viewer.

The picture in the README is this module's screenshot: ``python tests/test_napari.py docs/napari.png``
(under ``xvfb-run -a`` without a display).
"""

import os
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import PIL.Image
import pytest
import tifffile

import morphomap as mm
from conftest import require_client

try:
    import napari
    import pytestqt  # noqa: F401  (make_napari_viewer needs qtbot)
    from napari.utils.notifications import NotificationSeverity, notification_manager

    from morphomap.napari.widget import SeriesWidget
except ImportError:
    napari = None

ROOT = Path(__file__).resolve().parents[1]
SPACING_2D = (0.5, 0.25)  # (row, column) µm: unequal, so that a swapped axis shows
SPACING_3D = (1.0, 0.8, 0.8)  # (plane, row, column)
WAIT = 180_000  # ms: a 3D series on a loaded CI machine


def growing_bud(frames=4, size=96):
    """A disc (the organ) growing a bud on its right over ``frames`` frames: labels (T, rows, columns)."""
    rows, columns = np.mgrid[:size, :size]
    movie = np.zeros((frames, size, size), dtype=np.uint8)
    for t in range(frames):
        disc = (rows - 48) ** 2 + (columns - 44) ** 2 <= 22 ** 2
        bud = (rows - 48) ** 2 + (columns - 66) ** 2 <= (4 + 4 * t) ** 2
        movie[t][disc | bud] = 1
    return movie


def growing_ball(frames=3, size=36):
    """A ball growing a bud: labels (T, planes, rows, columns)."""
    planes, rows, columns = np.mgrid[:size, :size, :size]
    movie = np.zeros((frames, size, size, size), dtype=np.uint8)
    for t in range(frames):
        ball = (planes - 18) ** 2 + (rows - 18) ** 2 + (columns - 16) ** 2 <= 9 ** 2
        bud = (planes - 18) ** 2 + (rows - 18) ** 2 + (columns - 25) ** 2 <= (2 + 2 * t) ** 2
        movie[t][ball | bud] = 2
    return movie


@pytest.fixture
def viewer(request):
    require_client(napari is not None, "napari with pytest-qt (pip install '.[test]')")
    return request.getfixturevalue("make_napari_viewer")(show=True)


@pytest.fixture
def notifications():
    """The notifications napari shows during the test."""
    shown = []
    notification_manager.notification_ready.connect(shown.append)
    yield shown
    notification_manager.notification_ready.disconnect(shown.append)


def errors(shown):
    return [n.message for n in shown if n.severity == NotificationSeverity.ERROR]


def mapped(viewer, qtbot, data, scale, name="bud", **choices):
    """The widget docked in ``viewer``, run on a Labels layer of ``data``; waits for its worker."""
    viewer.add_labels(data, scale=scale, name=name)
    widget = SeriesWidget(viewer)
    viewer.window.add_dock_widget(widget, name="morphomap: map series")
    widget.labels.setCurrentText(name)
    for box, value in choices.items():
        getattr(widget, box).setCurrentText(value)
    widget.run()
    qtbot.waitUntil(lambda: not widget.busy, timeout=WAIT)
    return widget


def as_napari(points, spacing):
    """(x, y[, z]) physical -> (row, column) or (plane, row, column) pixels, written out by hand."""
    if points.shape[1] == 2:
        return np.column_stack([points[:, 1] / spacing[0], points[:, 0] / spacing[1]])
    return np.column_stack([points[:, 2] / spacing[0], points[:, 1] / spacing[1], points[:, 0] / spacing[2]])


def expected_vectors(series, spacing):
    rows = []
    for k, field in enumerate(series.fields):
        starts, moves = as_napari(field.starts[field.valid], spacing), as_napari(field.vectors[field.valid], spacing)
        time = np.full((len(starts), 1), k)
        rows.append(np.stack([np.hstack([time, starts]), np.hstack([0 * time, moves])], axis=1))
    return np.concatenate(rows)


def expected_tracks(series, spacing):
    rows = []
    for point in range(series.trajectories.shape[1]):
        for t, p in enumerate(series.trajectories[:, point]):
            if np.isfinite(p).all():
                rows.append([point, t, *as_napari(p[None], spacing)[0]])
    return np.array(rows)


def test_manifest_entry_point_and_light_import():
    require_client(napari is not None, "napari (pip install '.[test]')")
    from npe2 import PluginManifest

    manifest = PluginManifest.from_file(ROOT / "python" / "morphomap" / "napari" / "napari.yaml")
    assert manifest.name == "morphomap"
    for command in manifest.contributions.commands:
        assert callable(_resolve(command.python_name)), command.id
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["entry-points"]["napari.manifest"] == {"morphomap": "morphomap.napari:napari.yaml"}
    assert any(r.startswith("napari") for r in project["optional-dependencies"]["napari"])
    code = "import sys, morphomap, morphomap.napari; print('napari' in sys.modules, 'qtpy' in sys.modules)"
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert loaded.split() == ["False", "False"]


def _resolve(python_name):
    module, name = python_name.split(":")
    return getattr(__import__(module, fromlist=[name]), name)


def test_2d_widget_layers_are_morphomaps_results_in_row_column(viewer, qtbot, notifications, tmp_path):
    movie = growing_bud()
    widget = mapped(viewer, qtbot, movie, (1.0, *SPACING_2D))
    assert errors(notifications) == []
    series = mm.map_series([mm.boundary_from_mask(frame, SPACING_2D) for frame in movie])
    vectors, tracks = viewer.layers["bud displacement"], viewer.layers["bud trajectories"]
    assert vectors.data.shape == (sum(f.valid.sum() for f in series.fields), 2, 3)
    np.testing.assert_allclose(vectors.data, expected_vectors(series, SPACING_2D), atol=1e-9)
    np.testing.assert_allclose(vectors.features["length"],
                               np.concatenate([np.linalg.norm(f.vectors[f.valid], axis=1) for f in series.fields]))
    np.testing.assert_allclose(tracks.data, expected_tracks(series, SPACING_2D), atol=1e-9)
    for layer in (vectors, tracks, viewer.layers["bud boundaries"], viewer.layers["bud growth"]):
        np.testing.assert_allclose(layer.scale, (1.0, *SPACING_2D))
    outlines = viewer.layers["bud boundaries"].data
    assert len(outlines) == 4
    np.testing.assert_allclose(outlines[2][:, 1:], as_napari(series.frames[2], SPACING_2D), atol=1e-9)
    # The colouring of the last frame is the areal growth of its pieces since their birth.
    growth = viewer.layers["bud growth"]
    last = np.asarray(growth.features["growth"])[growth.data[:, 0] == 3]
    stretch = mm.growth(series).accumulated[2].areal_growth
    np.testing.assert_allclose(np.sort(last), np.sort(stretch[np.isfinite(stretch)]))
    assert last.max() > 1.3 and last.min() > 0.5
    # The quality table: one row per step, as series.quality says.
    assert widget.table.rowCount() == 3
    assert [widget.table.item(k, 3).text() for k in range(3)] == [f"{q.qm:.3f}" for q in series.quality]
    widget.write(tmp_path / "series")
    qtbot.waitUntil(lambda: not widget.busy, timeout=WAIT)
    assert errors(notifications) == []
    assert (tmp_path / "series" / "quality.csv").is_file() and (tmp_path / "series" / "trajectories.csv").is_file()


def test_3d_widget_gives_a_surface_per_frame(viewer, qtbot, notifications):
    movie = growing_ball()
    mapped(viewer, qtbot, movie, (1.0, *SPACING_3D), name="ball")
    assert errors(notifications) == []
    series = mm.map_series([mm.surface_from_mask(frame, SPACING_3D) for frame in movie])
    np.testing.assert_allclose(viewer.layers["ball displacement"].data, expected_vectors(series, SPACING_3D), atol=1e-9)
    np.testing.assert_allclose(viewer.layers["ball trajectories"].data, expected_tracks(series, SPACING_3D), atol=1e-9)
    surface = viewer.layers["ball growth"]
    assert isinstance(surface, napari.layers.Surface)
    vertices, faces, values = surface.data
    assert vertices.shape[1] == 4 and set(np.unique(vertices[:, 0])) == {0.0, 1.0, 2.0}
    # Frame 0's surface is the first frame's mesh, in (plane, row, column) pixels.
    first = vertices[:, 0] == 0
    np.testing.assert_allclose(np.sort(vertices[first, 1:], axis=0),
                               np.sort(as_napari(series.frames[0].vertices, SPACING_3D), axis=0), atol=1e-9)
    assert len(values) == len(vertices) and np.isfinite(values).all()
    assert (faces < len(vertices)).all() and (vertices[faces, 0] == vertices[faces[:, :1], 0]).all()


def test_with_drift_removed_the_layers_lie_on_the_image(viewer, qtbot, notifications):
    movie = growing_bud()
    movie = np.stack([np.roll(frame, (3 * t, -2 * t), axis=(0, 1)) for t, frame in enumerate(movie)])  # drifting
    mapped(viewer, qtbot, movie, (1.0, *SPACING_2D), drift="translation")
    assert errors(notifications) == []
    tracks = viewer.layers["bud trajectories"].data
    starts = viewer.layers["bud displacement"].data[:, 0]
    for t, frame in enumerate(movie):
        outline = mm.boundary_from_mask(frame, SPACING_2D)  # where the organ is imaged, drift and all
        # The followed points of frame t, and the start points of step t, on frame t's outline.
        for on in (tracks[tracks[:, 1] == t, 2:], starts[starts[:, 0] == t, 1:]):
            physical = np.column_stack([on[:, 1] * SPACING_2D[1], on[:, 0] * SPACING_2D[0]])
            if len(physical):
                assert mm.closest_points(physical, outline).distances.max() < 1e-6, t


def test_bad_input_is_a_notification_not_an_exception(viewer, qtbot, notifications):
    widget = SeriesWidget(viewer)
    viewer.window.add_dock_widget(widget)
    assert widget.run() is None  # no Labels layer
    assert "no Labels layer" in errors(notifications)[-1]
    viewer.add_image(np.zeros((3, 20, 20)), name="grey")  # an image is not offered
    assert widget.labels.count() == 0
    empty = growing_bud()
    empty[2] = 0
    viewer.add_labels(empty, name="empty")
    assert widget.labels.currentText() == "empty"
    widget.run()
    qtbot.waitUntil(lambda: not widget.busy, timeout=WAIT)
    assert "frame 2: has no object" in errors(notifications)[-1]
    widget.objects.setCurrentText("label")
    widget.label.setValue(7)  # a label no frame holds
    widget.run()
    qtbot.waitUntil(lambda: not widget.busy, timeout=WAIT)
    assert "no pixel has the value 7" in errors(notifications)[-1]
    viewer.add_labels(np.ones((20, 20), dtype=np.uint8), name="still")  # one frame, no time axis
    widget.labels.setCurrentText("still")
    assert widget.run() is None and "expected a movie" in errors(notifications)[-1]
    assert not [name for name in (layer.name for layer in viewer.layers) if "displacement" in name]


def disc_and_ellipse(size=96):
    """Two single frames (rows, columns): a disc, and an ellipse around it (the later, grown organ)."""
    rows, columns = np.mgrid[:size, :size]
    disc = (rows - 48) ** 2 + (columns - 44) ** 2 <= 20 ** 2
    ellipse = ((rows - 48) / 26) ** 2 + ((columns - 46) / 30) ** 2 <= 1
    return disc.astype(np.uint8), 2 * ellipse.astype(np.uint8)


def ball_and_ellipsoid(size=32):
    """Two single frames (planes, rows, columns): a ball, and an ellipsoid around it."""
    planes, rows, columns = np.mgrid[:size, :size, :size]
    ball = (planes - 16) ** 2 + (rows - 16) ** 2 + (columns - 15) ** 2 <= 8 ** 2
    ellipsoid = ((planes - 16) / 9) ** 2 + ((rows - 16) / 9) ** 2 + ((columns - 17) / 11) ** 2 <= 1
    return 3 * ball.astype(np.uint8), 5 * ellipsoid.astype(np.uint8)


def paired(viewer, qtbot, earlier, later, scale, names=("early", "late")):
    """The widget docked in ``viewer`` in two-layer mode on Labels layers of ``earlier`` and
    ``later`` (one frame each); waits for its worker."""
    for data, name in zip((earlier, later), names):
        viewer.add_labels(data, scale=scale, name=name)
    widget = SeriesWidget(viewer)
    viewer.window.add_dock_widget(widget, name="morphomap: map series")
    widget.labels.setCurrentText(names[0])
    widget.later.setCurrentText(names[1])
    widget.run()
    qtbot.waitUntil(lambda: not widget.busy, timeout=WAIT)
    return widget


def expected_pair_vectors(field, spacing):
    """A field of morphomap's as the Vectors layer of the pair holds it: at time index 0."""
    starts, moves = as_napari(field.starts[field.valid], spacing), as_napari(field.vectors[field.valid], spacing)
    time = np.zeros((len(starts), 1))
    return np.stack([np.hstack([time, starts]), np.hstack([time, moves])], axis=1)


def check_pair_tracks(tracks, field, spacing):
    """The Tracks layer of a pair: every start point at time 0, carried by its vector at time 1
    (points born on the later frame, where the followed ones spread apart, have ids after them)."""
    assert isinstance(tracks, napari.layers.Tracks)
    data = tracks.data
    first = data[data[:, 1] == 0]
    np.testing.assert_array_equal(first[:, 0], np.arange(len(field.starts)))
    np.testing.assert_allclose(first[:, 2:], as_napari(field.starts, spacing), atol=1e-9)
    carried = data[(data[:, 1] == 1) & (data[:, 0] < len(field.starts))]
    np.testing.assert_allclose(carried[:, 2:], as_napari(field.starts + field.vectors, spacing), atol=1e-9)


def test_two_2d_layers_give_map_curves_field(viewer, qtbot, notifications):
    disc, ellipse = disc_and_ellipse()
    widget = paired(viewer, qtbot, disc, ellipse, SPACING_2D)
    assert errors(notifications) == []
    assert widget.run_button.text() == "Map pair" and "uniform" in [widget.method.itemText(k)
                                                                   for k in range(widget.method.count())]
    field = mm.map_curves(mm.boundary_from_mask(disc, SPACING_2D), mm.boundary_from_mask(ellipse, SPACING_2D))
    assert field.valid.all()
    vectors = viewer.layers["early to late displacement"]
    assert isinstance(vectors, napari.layers.Vectors)
    np.testing.assert_allclose(vectors.data, expected_pair_vectors(field, SPACING_2D), atol=1e-9)
    np.testing.assert_allclose(vectors.features["length"], np.linalg.norm(field.vectors, axis=1))
    check_pair_tracks(viewer.layers["early to late trajectories"], field, SPACING_2D)
    outlines = viewer.layers["early to late boundaries"].data
    assert len(outlines) == 2
    np.testing.assert_allclose(outlines[0][:, 1:], as_napari(field.starts, SPACING_2D), atol=1e-9)
    for name in ("displacement", "trajectories", "boundaries", "growth"):
        np.testing.assert_allclose(viewer.layers[f"early to late {name}"].scale, (1.0, *SPACING_2D))
    assert widget.table.rowCount() == 1 and widget.series is not None and len(widget.series.frames) == 2
    # Back to one layer: the first is a single frame, not a movie, and is refused as such.
    widget.later.setCurrentText("none")
    assert widget.run_button.text() == "Map series"
    assert widget.run() is None and "expected a movie" in errors(notifications)[-1]


def test_two_3d_layers_give_map_surfaces_field_and_a_surface(viewer, qtbot, notifications):
    ball, ellipsoid = ball_and_ellipsoid()
    widget = paired(viewer, qtbot, ball, ellipsoid, SPACING_3D, names=("ball", "grown"))
    assert errors(notifications) == []
    offered = [widget.method.itemText(k) for k in range(widget.method.count())]
    assert "uniform" not in offered and "diffusion" in offered  # three axes, one frame: surfaces
    field = mm.map_surfaces(mm.surface_from_mask(ball, SPACING_3D), mm.surface_from_mask(ellipsoid, SPACING_3D))
    assert field.valid.all()
    vectors = viewer.layers["ball to grown displacement"]
    assert vectors.data.shape == (len(field.starts), 2, 4)
    np.testing.assert_allclose(vectors.data, expected_pair_vectors(field, SPACING_3D), atol=1e-9)
    check_pair_tracks(viewer.layers["ball to grown trajectories"], field, SPACING_3D)
    surface = viewer.layers["ball to grown growth"]
    assert isinstance(surface, napari.layers.Surface)
    vertices, faces, values = surface.data
    assert set(np.unique(vertices[:, 0])) == {0.0, 1.0} and np.isfinite(values).all()
    np.testing.assert_allclose(np.sort(vertices[vertices[:, 0] == 0, 1:], axis=0),
                               np.sort(as_napari(field.starts, SPACING_3D), axis=0), atol=1e-9)
    np.testing.assert_allclose(surface.scale, (1.0, *SPACING_3D))


def test_two_layers_that_differ_are_a_notification_naming_both(viewer, qtbot, notifications):
    disc, ellipse = disc_and_ellipse()
    viewer.add_labels(disc, scale=SPACING_2D, name="early")
    viewer.add_labels(ellipse[:90], scale=SPACING_2D, name="cropped")
    viewer.add_labels(ellipse, scale=(0.5, 0.5), name="coarse")
    viewer.add_labels(ellipse, scale=SPACING_2D, translate=(4.0, 0.0), name="moved")
    viewer.add_labels(growing_bud(), scale=(1.0, *SPACING_2D), name="movie")  # as napari's own reader opens it
    viewer.add_labels(growing_bud(), scale=(1.0, *SPACING_2D), name="read", metadata={"axes": "TYX"})  # as ours
    viewer.add_labels(ellipse, scale=SPACING_2D, name="late")
    widget = SeriesWidget(viewer)
    viewer.window.add_dock_widget(widget)
    assert widget.later.currentText() == "none" and widget.later.itemText(0) == "none"
    widget.labels.setCurrentText("early")
    for later, said in (("cropped", "differ in shape, (96, 96) and (90, 96)"),
                        ("coarse", "differ in scale (pixel size), (0.5, 0.25) and (0.5, 0.5)"),
                        ("moved", "differ in translate"),
                        ("movie", "'movie' has one axis more than 'early', (4, 96, 96) and (96, 96)"),
                        ("read", "labels 'read': a movie (axes TYX, shape (4, 96, 96))")):
        widget.later.setCurrentText(later)
        assert widget.run() is None and not widget.busy, later
        message = errors(notifications)[-1]
        assert said in message and f"'{later}'" in message, message
        if later in ("movie", "read"):
            assert "takes one frame per layer: choose 'none' as the later layer" in message, message
        else:
            assert "'early'" in message and ("set the same" in message or "crop" in message), message
    widget.labels.setCurrentText("read")  # a movie as the earlier layer, too
    widget.later.setCurrentText("late")
    assert widget.run() is None and "labels 'read': a movie" in errors(notifications)[-1]
    assert not [layer.name for layer in viewer.layers if "displacement" in layer.name]
    # The viewer and the widget go on: the good pair maps.
    widget.labels.setCurrentText("early")
    widget.run()
    qtbot.waitUntil(lambda: not widget.busy, timeout=WAIT)
    assert isinstance(viewer.layers["early to late displacement"], napari.layers.Vectors)
    assert len(errors(notifications)) == 6


def test_pair_movie_stacks_two_frames_and_names_both_layers():
    from morphomap.napari.compute import Frame, pair_movie, spatial_dim

    disc, ellipse = disc_and_ellipse()
    data, spacing, unit = pair_movie(Frame("a", disc, SPACING_2D, (0.0, 0.0), None, "um"),
                                     Frame("b", ellipse, SPACING_2D, (0.0, 0.0)))
    assert data.shape == (2, 96, 96) and spacing == SPACING_2D and unit == "um"
    np.testing.assert_array_equal(data[1], ellipse)
    with pytest.raises(ValueError, match="labels 'a': a movie \\(axes TYX"):
        pair_movie(Frame("a", growing_bud(), (1.0, *SPACING_2D), (0.0,) * 3, "TYX"),
                   Frame("b", growing_bud(), (1.0, *SPACING_2D), (0.0,) * 3, "TYX"))
    with pytest.raises(ValueError, match="labels 'a' and 'b': differ in unit"):
        pair_movie(Frame("a", disc, SPACING_2D, (0.0, 0.0), None, "um"),
                   Frame("b", ellipse, SPACING_2D, (0.0, 0.0), None, "nm"))
    with pytest.raises(TypeError, match="labels: expected integer labels"):
        pair_movie(Frame("a", disc * 1.0, SPACING_2D, (0.0, 0.0)), Frame("b", ellipse * 1.0, SPACING_2D, (0.0, 0.0)))
    assert (spatial_dim(3), spatial_dim(4), spatial_dim(3, single_frame=True),
            spatial_dim(3, "TYX", single_frame=True), spatial_dim(2, single_frame=True)) == (2, 3, 3, 2, 2)


def test_screenshot_shows_the_results(tmp_path):
    """The README's picture made afresh and checked not blank. In a process of its own on the X
    display (pytest-xvfb's Xvfb in CI): napari's canvas is OpenGL, which Qt's offscreen platform
    leaves black."""
    require_client(napari is not None, "napari (pip install '.[test]')")
    require_client(bool(os.environ.get("DISPLAY")), "an X display for napari's OpenGL canvas (Debian's xvfb, "
                   "which pytest-xvfb starts)")
    where = os.path.dirname(os.path.dirname(os.path.abspath(mm.__file__)))
    env = {k: v for k, v in os.environ.items() if k != "QT_QPA_PLATFORM"}
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [where, os.environ.get("PYTHONPATH")]))
    path = tmp_path / "napari.png"
    subprocess.run([sys.executable, __file__, str(path)], env=env, check=True, timeout=600)
    image = np.asarray(PIL.Image.open(path).convert("RGB"))
    assert image.shape[0] >= 400 and image.shape[1] >= 600
    # The canvas (the middle third) shows the labels, outlines, vectors and growth colours.
    canvas = image[:, image.shape[1] // 3: 2 * image.shape[1] // 3]
    colours = np.unique(canvas.reshape(-1, 3) // 32, axis=0)
    assert len(colours) >= 8, f"a blank canvas ({len(colours)} colours)"


def picture(viewer, qtbot, path):
    """The README's picture: the bud movie mapped, at its last step, saved to ``path``."""
    viewer.window._qt_window.resize(1100, 620)
    mapped(viewer, qtbot, growing_bud(), (1.0, 0.5, 0.5))
    viewer.layers["bud"].opacity = 0.35
    viewer.dims.set_current_step(0, 2)
    viewer.reset_view()
    viewer.camera.zoom *= 1.4
    qtbot.wait(300)
    viewer.screenshot(path=str(path), canvas_only=False)


def test_settings_and_arrays_are_checked_naming_the_argument():
    from morphomap.napari.compute import Options, map_labels
    from morphomap.napari.layers import to_pixels

    with pytest.raises(TypeError, match="labels: expected integer labels"):
        map_labels(np.zeros((3, 10, 10)), (1.0, 1.0))
    with pytest.raises(ValueError, match="spacing: expected 2 positive sizes"):
        map_labels(growing_bud(), (1.0, 0.0))
    with pytest.raises(ValueError, match="method: 'uniform' does not map surfaces"):
        map_labels(growing_ball(), SPACING_3D, Options(method="uniform"))
    with pytest.raises(ValueError, match="label: choose"):
        map_labels(growing_bud(), SPACING_2D, Options(objects="label"))
    with pytest.raises(ValueError, match="spacing: expected one size per coordinate"):
        to_pixels(np.zeros((4, 2)), (1.0, 1.0, 1.0))
    np.testing.assert_allclose(to_pixels([[3.0, 2.0]], (0.5, 0.25)), [[4.0, 12.0]])  # (x, y) -> (row, column)


def test_reader_gives_labels_and_surfaces_at_the_files_scale(tmp_path):
    require_client(napari is not None, "napari (pip install '.[test]')")
    from morphomap.napari.reader import get_reader

    path = tmp_path / "bud.tif"
    tifffile.imwrite(path, growing_bud(), imagej=True, resolution=(1 / 0.65, 1 / 0.65),
                     metadata={"axes": "TYX", "unit": "um", "finterval": 300.0})
    [(data, options, kind)] = get_reader(str(path))(str(path))
    assert kind == "labels" and data.shape == (4, 96, 96) and options["name"] == "bud"
    np.testing.assert_allclose(options["scale"], (1.0, 0.65, 0.65))
    assert options["metadata"] == {"axes": "TYX", "unit": "um", "frame_interval": 300.0}
    mesh = mm.surface_from_mask(growing_ball()[0], SPACING_3D)
    mm.write_surface(tmp_path / "ball.ply", mesh)
    [((vertices, faces), options, kind)] = get_reader(str(tmp_path / "ball.ply"))(str(tmp_path / "ball.ply"))
    assert kind == "surface" and options["name"] == "ball"
    np.testing.assert_allclose(vertices, mesh.vertices[:, ::-1])
    np.testing.assert_array_equal(faces, mesh.faces)
    assert get_reader(str(tmp_path / "notes.txt")) is None


@pytest.fixture
def plugin(request):
    """napari's plugin manager holding only this plugin, from its manifest (npe2's own test
    manager, which discovers nothing: installed or run from the source tree, morphomap is there
    once). Asked for before the viewer, which hands the plugin's commands to napari."""
    require_client(napari is not None, "napari (pip install '.[test]')")
    manager = request.getfixturevalue("npe2pm")
    with manager.tmp_plugin(manifest=str(ROOT / "python" / "morphomap" / "napari" / "napari.yaml")):
        yield manager


def test_napari_opens_files_and_docks_the_widget_through_the_manifest(plugin, viewer, qtbot, tmp_path):
    path = tmp_path / "bud.tif"
    tifffile.imwrite(path, growing_bud(), imagej=True, resolution=(1 / 0.65, 1 / 0.65),
                     metadata={"axes": "TYX", "unit": "um", "finterval": 300.0})
    [layer] = viewer.open(str(path), plugin="morphomap")
    assert isinstance(layer, napari.layers.Labels) and layer.data.shape == (4, 96, 96)
    np.testing.assert_allclose(layer.scale, (1.0, 0.65, 0.65))
    _, widget = viewer.window.add_plugin_dock_widget("morphomap", "Map series")
    assert isinstance(widget, SeriesWidget) and widget.layer() is layer
    widget.run()
    qtbot.waitUntil(lambda: not widget.busy, timeout=WAIT)
    assert widget.series is not None and widget.series.dt == 300.0 and widget.series.unit == "um"
    np.testing.assert_allclose(viewer.layers["bud displacement"].scale, (1.0, 0.65, 0.65))


class _Events:
    """qtbot's waiting, for the picture made outside pytest."""

    def waitUntil(self, done, timeout):
        import time

        from qtpy.QtWidgets import QApplication

        end = time.monotonic() + timeout / 1000
        while not done() and time.monotonic() < end:
            QApplication.processEvents()
            time.sleep(0.01)

    def wait(self, ms):
        self.waitUntil(lambda: False, ms)


if __name__ == "__main__":  # the README's picture, in a viewer of its own
    window = napari.Viewer(show=True)
    picture(window, _Events(), Path(sys.argv[1]))
    window.close()
