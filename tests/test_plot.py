"""Pictures of displacement fields (artists counted; no images compared)."""

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import matplotlib  # noqa: E402

matplotlib.use("Agg")

from matplotlib.collections import LineCollection, PathCollection  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import morphomap as mm  # noqa: E402
from conftest import circle  # noqa: E402


def axes():
    return Figure().subplots()


def test_clean_field_draws_two_curves_vectors_and_end_dots():
    c1, c2 = circle(40, 1.0), circle(60, 2.0)
    field = mm.map_curves(c1, c2, "normal")
    ax = mm.plot_field(field, c1, c2, ax=axes(), title="normal")
    assert isinstance(ax, matplotlib.axes.Axes)
    assert len(ax.lines) == 2 and len(ax.collections) == 2
    green, blue = ax.lines
    assert len(green.get_xdata()) == 41 and len(blue.get_xdata()) == 61  # drawn closed
    vectors, dots = ax.collections
    assert isinstance(vectors, LineCollection) and len(vectors.get_segments()) == 40
    assert isinstance(dots, PathCollection) and len(dots.get_offsets()) == 40
    assert ax.get_title() == "normal"
    assert ax.get_aspect() == 1.0
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["$C_1$", "$C_2$", "vectors (40)"]


def test_crossings_and_misses_get_their_own_artists():
    c1 = circle(8, 1.0)
    ends = 2 * c1
    ends[[0, 1]] = ends[[1, 0]]  # vectors 0 and 1 cross
    ends[5] = np.nan  # a miss
    field = mm.DisplacementField(c1, ends, "normal")
    assert mm.count_crossings(field.starts, field.ends) == 1
    ax = mm.plot_field(field, c1, circle(50, 2.0), ax=axes())
    assert len(ax.lines) == 2 and len(ax.collections) == 4
    vectors, dots, crossing, misses = ax.collections
    assert len(vectors.get_segments()) == 5  # 8 minus 2 crossing minus 1 miss
    assert len(crossing.get_segments()) == 2
    assert len(dots.get_offsets()) == 7
    assert np.allclose(misses.get_offsets(), c1[5:6])  # marked at the start point
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["$C_1$", "$C_2$", "vectors (7)", "crossing (1 pairs)", "no target (1)"]


def test_reverse_misses_are_marked_on_c2_and_open_curves_stay_open():
    x = np.linspace(0, 1, 5)
    c1 = np.column_stack([x, np.zeros(5)])
    c2 = np.column_stack([x, np.ones(5)])
    starts = c1.copy()
    starts[2] = np.nan
    field = mm.DisplacementField(starts, c2, "normal")
    ax = mm.plot_field(field, c1, c2, ax=axes(), closed=False)
    assert len(ax.lines[0].get_xdata()) == 5
    assert np.allclose(ax.collections[-1].get_offsets(), c2[2:3])


def test_new_figure_when_no_axes_and_bad_arguments():
    c1, c2 = circle(20), circle(20, 2.0)
    field = mm.map_curves(c1, c2, "minimal_distance")
    ax = mm.plot_field(field, c1, c2)
    assert isinstance(ax, matplotlib.axes.Axes)
    import matplotlib.pyplot as plt

    plt.close(ax.figure)
    with pytest.raises(TypeError, match="field: expected a DisplacementField"):
        mm.plot_field((c1, c2), c1, c2)
    with pytest.raises(ValueError, match="c2: expected shape"):
        mm.plot_field(field, c1, np.zeros((4, 3)))


def test_y_down_draws_the_image_way_up():
    c1, c2 = circle(40, 1.0), circle(60, 2.0)
    field = mm.map_curves(c1, c2, "normal")
    assert not mm.plot_field(field, c1, c2, ax=axes()).yaxis_inverted()
    assert mm.plot_field(field, c1, c2, ax=axes(), y_down=True).yaxis_inverted()


def test_3d_field_draws_two_surfaces_and_coloured_vectors():
    import trimesh
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    s1 = trimesh.creation.icosphere(2)
    s2 = s1.copy().apply_scale(1.5)
    field = mm.map_surfaces(s1, s2, "normal")
    ax = mm.plot_field(field, s1, s2, ax=Figure().add_subplot(projection="3d"), title="normal")
    assert sum(isinstance(c, Poly3DCollection) for c in ax.collections) == 2
    [lines] = [c for c in ax.collections if isinstance(c, Line3DCollection)]
    assert len(lines.get_array()) == len(field)
    assert np.allclose(lines.get_array(), 0.5, atol=0.01)  # unit icosphere to radius 1.5
    # Many vectors are thinned to keep the surfaces visible; a 2D axes is refused.
    big = trimesh.creation.icosphere(5)
    field = mm.map_surfaces(big, big.copy().apply_scale(1.2), "normal")
    ax = mm.plot_field_3d(field, big, big.copy().apply_scale(1.2), ax=Figure().add_subplot(projection="3d"))
    [lines] = [c for c in ax.collections if isinstance(c, Line3DCollection)]
    assert len(lines.get_array()) == mm.plot.MAX_VECTORS_3D < len(field)
    with pytest.raises(TypeError, match="ax: expected a 3D axes"):
        mm.plot_field_3d(field, big, big, ax=axes())
