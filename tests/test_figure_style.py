"""The rules every figure follows: colour scales an outlier cannot wash out, units, time stamps,
method names."""

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import matplotlib  # noqa: E402

matplotlib.use("Agg")

from matplotlib.colors import LogNorm, TwoSlopeNorm  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import morphomap as mm  # noqa: E402
from morphomap import figure_style as style  # noqa: E402
from conftest import circle, ellipse  # noqa: E402


@pytest.fixture(scope="module")
def outlier_series():
    """A series whose stretches spread around 1.5, one piece's accumulated stretch made 1,879."""
    series = mm.map_series([circle(80, 1.0), ellipse(80, 1.9, 1.2)], "normal", progress=False)
    values = series._accumulated[0]
    assert 1.2 < np.median(values) < 1.8
    values[7] = 1879.0
    return series


def test_one_outlier_leaves_the_stretch_colour_bar_to_the_percentiles(outlier_series):
    values = outlier_series.accumulated_stretch(0)
    ax = outlier_series.plot_growth("accumulated_stretch", 0, Figure().subplots())
    artist = ax.collections[-1]
    low, high = np.percentile(values, style.PERCENTILES)
    assert artist.norm.vmin == pytest.approx(low) and artist.norm.vmax == pytest.approx(high)
    assert high < 3 < 1879  # the outlier does not set the range
    # Most pieces get distinct colours rather than the bottom of the map.
    shown = artist.norm(np.delete(values, 7))
    assert np.ptp(shown) > 0.8
    bar = ax.figure.axes[-1]
    assert bar.get_ylabel() == "stretch since frame 0 (length ratio)"
    assert artist.colorbar.extend in ("max", "both")  # an arrow for the values beyond the scale
    # The full range on request, and a log scale.
    ax = outlier_series.plot_growth("accumulated_stretch", 0, Figure().subplots(), scale="linear")
    assert ax.collections[-1].norm.vmax == 1879.0
    ax = outlier_series.plot_growth("accumulated_stretch", 0, Figure().subplots(), scale="log")
    assert isinstance(ax.collections[-1].norm, LogNorm) and ax.collections[-1].norm.vmax < 3
    with pytest.raises(ValueError, match="scale: expected one of"):
        outlier_series.plot_growth("stretch", 0, Figure().subplots(), scale="percentile")


def test_colour_scale_rules():
    values = np.r_[np.linspace(1.0, 2.0, 99), 1879.0, np.nan]
    robust = style.colour_scale(values)
    assert robust.norm.vmin == pytest.approx(np.percentile(values[:-1], 2))
    assert robust.norm.vmax < 2.1 and robust.extend == "both" and robust.cmap == style.SEQUENTIAL_MAP
    assert style.colour_scale(values, "linear").norm.vmax == 1879.0
    assert style.colour_scale(values, "linear").extend == "neither"
    # Speeds either side of 0: a diverging map centred on 0; of one sign, a sequential one.
    speeds = style.colour_scale(np.linspace(-1.0, 3.0, 50), diverging=True)
    assert isinstance(speeds.norm, TwoSlopeNorm) and speeds.norm.vcenter == 0 and speeds.cmap == style.DIVERGING_MAP
    assert style.colour_scale(np.linspace(1.0, 3.0, 50), diverging=True).cmap == style.SEQUENTIAL_MAP
    # One value (a circle grown evenly) but for an outlier: a band around it, not up to the outlier.
    even = style.colour_scale(np.r_[np.full(60, 1.5), 1879.0])
    assert even.norm.vmin < 1.5 < even.norm.vmax < 3
    assert style.colour_scale([]).norm.vmax == 1.0
    with pytest.raises(ValueError, match="scale: 'log' needs positive values"):
        style.colour_scale([-1.0, 2.0], "log")


def test_units_and_time_stamps():
    assert style.unit_name("um") == "µm" and style.unit_name(None) == "units" and style.unit_name("mm") == "mm"
    assert style.unit_name("pixel") == "pixels"
    assert style.speed_unit("um", "s") == "µm/s" and style.speed_unit(None, None) == "units/time"
    # Seconds are given in the unit that suits the whole series.
    assert style.time_stamp(3, 3600.0, "s", 5) == "t = 3.0 h"
    assert style.time_stamp(2, 30.0, "s", 4) == "t = 1.0 min"
    assert style.time_stamp(1, 0.5, "s", 3) == "t = 0.5 s"
    assert style.time_stamp(4, 86400.0, "s", 10) == "t = 4.0 d"
    assert style.time_stamp(3, 0.5, "h", 5) == "t = 1.5 h"  # a unit the caller gave, as it is
    assert style.time_stamp(3, 1.0, None, 5) == "t = 3.0"  # no unit known: none made up
    assert style.time_stamp(250, 1.0, None, 300) == "t = 250"


def test_methods_are_named_never_numbered():
    codes = np.array([0, 0, 1, 2])
    names = style.method_names(codes)
    assert names.tolist() == [mm.field.METHOD_NAMES[c] for c in codes]
    assert style.method_summary(np.array(["normal", "normal", "diffusion"])) == "diffusion 1, normal 2"
    assert style.method_summary(codes) == ", ".join(
        f"{n} {c}" for n, c in zip(*np.unique(names, return_counts=True)))
    with pytest.raises(ValueError, match="methods: codes expected"):
        style.method_names(np.array([len(mm.field.METHOD_NAMES)]))


def test_orientation_is_decided_in_one_place():
    assert style.resolve_y_down(None, True) is True and style.resolve_y_down(None, False) is False
    assert style.resolve_y_down(False, True) is False
    with pytest.raises(TypeError, match="y_down: expected True or False"):
        style.resolve_y_down("yes", True)
    ax = Figure().subplots()
    style.orient_axes(ax, 2, y_down=True, unit="um")
    style.orient_axes(ax, 2, y_down=True, unit="um")  # twice: still y-down (not flipped back)
    assert ax.yaxis_inverted() and ax.get_xlabel() == "x (µm)"
