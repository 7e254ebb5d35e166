"""Bad input gives a ValueError or TypeError that names the argument, never a crash."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import morphomap as mm

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])

# Every public function, called with one array argument replaced by the fuzzed value.
CALLS = {
    "resample": lambda x: mm.resample(x, 10),
    "resample_spline": lambda x: mm.resample(x, 10, method="spline"),
    "resample_pchip_open": lambda x: mm.resample(x, 10, method="pchip", closed=False),
    "arc_lengths": lambda x: mm.arc_lengths(x),
    "perimeter": lambda x: mm.perimeter(x, closed=False),
    "signed_area": lambda x: mm.signed_area(x),
    "orientation": lambda x: mm.orientation(x),
    "normals": lambda x: mm.normals(x),
    "is_self_intersecting": lambda x: mm.is_self_intersecting(x),
    "closest_points_queries": lambda x: mm.closest_points(x, SQUARE),
    "closest_points_curve": lambda x: mm.closest_points(SQUARE, x),
    "line_intersections_origins": lambda x: mm.line_intersections(x, np.ones_like(np.asarray(x, dtype=float)), SQUARE),
    "line_intersections_directions": lambda x: mm.line_intersections(
        np.zeros_like(np.asarray(x, dtype=float)), x, SQUARE
    ),
    "line_intersections_curve": lambda x: mm.line_intersections(SQUARE, SQUARE, x, closed=False),
    "curve_intersections_c1": lambda x: mm.curve_intersections(x, SQUARE),
    "curve_intersections_c2": lambda x: mm.curve_intersections(SQUARE + 0.5, x, closed=False),
    "crossing_pairs": lambda x: mm.crossing_pairs(x, np.asarray(x) * 0.5),
    "count_crossings": lambda x: mm.count_crossings(x, x),
    "overlap_area": lambda x: mm.overlap_area(x, SQUARE),
    "align_curves": lambda x: mm.align_curves(x, SQUARE * 2),
    "map_curves_normal": lambda x: mm.map_curves(x, SQUARE * 3 - 1, "normal"),
    "map_curves_uniform_open": lambda x: mm.map_curves(SQUARE, x, "uniform", closed=False),
    "map_curves_auto": lambda x: mm.map_curves(x, SQUARE * 3 - 1),
    "quality": lambda x: mm.quality(mm.map_curves(SQUARE, SQUARE * 3 - 1, "normal"), x, SQUARE * 3 - 1),
}

elements = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.sampled_from([0.0, 1.0, -1.0, 1e300, -1e300, 5e-324]),
)
arrays = st.one_of(
    hnp.arrays(np.float64, st.tuples(st.integers(0, 12), st.integers(1, 3)), elements=elements),
    hnp.arrays(np.float64, st.tuples(st.integers(0, 12), st.just(2)), elements=st.integers(-3, 3).map(float)),
    hnp.arrays(np.int64, st.tuples(st.integers(0, 8), st.just(2)), elements=st.integers(-3, 3)),
    hnp.arrays(np.float64, hnp.array_shapes(min_dims=0, max_dims=3, max_side=4)),
)


@pytest.mark.parametrize("name", sorted(CALLS))
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(value=arrays)
def test_random_arrays_never_crash(name, value):
    try:
        CALLS[name](value)
    except mm.GeometryError as error:
        # The default's contract: a pair without a crossing-free complete field is said, not mapped.
        assert name == "map_curves_auto" and str(error).startswith("map_curves: "), str(error)
    except (ValueError, TypeError) as error:
        assert str(error).split(":")[0] in {
            "points",
            "n",
            "queries",
            "curve",
            "origins",
            "directions",
            "c1",
            "c2",
            "starts",
            "ends",
            "a",
            "b",
            "field",
        }, str(error)


# Diffusion meshes the region between the curves: a second or so a call, so fewer examples.
DIFFUSION_CALLS = {
    "map_curves_diffusion": lambda x: mm.map_curves(SQUARE * 3 - 1, x, "diffusion", reverse=True),
    "solve_diffusion": lambda x: mm.solve_diffusion(x, SQUARE * 3 - 1, mesh_fraction=0.1),
}


@pytest.mark.parametrize("name", sorted(DIFFUSION_CALLS))
@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(value=arrays)
def test_random_arrays_never_crash_diffusion(name, value):
    try:
        DIFFUSION_CALLS[name](value)
    except (ValueError, TypeError, mm.GeometryError) as error:
        assert isinstance(error, mm.GeometryError) or str(error).split(":")[0] in {"c1", "c2"}, str(error)


@pytest.mark.parametrize(
    "value, kind, words",
    [
        ("abc", TypeError, "points: expected an array"),
        (None, TypeError, "points: expected an array"),
        (np.array([[True, False]] * 3), TypeError, "dtype bool"),
        (np.array([["a", "b"]] * 3), TypeError, "dtype"),
        (np.zeros((4, 3)), ValueError, "points: expected shape (N, 2)"),
        (np.zeros(8), ValueError, "points: expected shape (N, 2)"),
        ([[0, 0], [1]], ValueError, "points"),
        (np.array([[0.0, 0.0], [np.nan, 1.0], [1.0, 1.0]]), ValueError, "points: row 1 has a non-finite"),
        (np.array([[0.0, 0.0], [np.inf, 1.0], [1.0, 1.0]]), ValueError, "points: row 1 has a non-finite"),
        (np.array([[0.0, 0.0], [1.0, 1.0]]), ValueError, "points: a closed curve needs at least 3 points"),
        (np.ones((5, 2)), ValueError, "points: the curve has zero length"),
    ],
)
def test_bad_curves_are_named(value, kind, words):
    with pytest.raises(kind) as caught:
        mm.perimeter(value)
    assert words in str(caught.value)


def test_too_few_points_for_an_open_curve():
    with pytest.raises(ValueError, match="points: an open curve needs at least 2 points"):
        mm.arc_lengths([[0.0, 0.0]], closed=False)


def test_non_contiguous_and_integer_arrays_are_converted():
    big = np.zeros((8, 4))
    big[::2, ::2] = SQUARE * 3  # a strided view
    view = big[::2, ::2]
    assert not view.flags.c_contiguous
    assert mm.perimeter(view) == 12.0
    assert mm.perimeter(np.array([[0, 0], [3, 0], [3, 3], [0, 3]])) == 12.0


def test_flags_and_counts_are_checked():
    with pytest.raises(TypeError, match="closed: expected True or False"):
        mm.perimeter(SQUARE, closed="yes")
    with pytest.raises(TypeError, match="n: expected an integer"):
        mm.resample(SQUARE, 10.5)
    with pytest.raises(ValueError, match="n: resampling a closed curve needs at least 3"):
        mm.resample(SQUARE, 2)
    with pytest.raises(ValueError, match="method: expected one of"):
        mm.resample(SQUARE, 10, method="cubic")


def test_query_arguments_are_checked():
    with pytest.raises(ValueError, match="directions: row 0 is the zero vector"):
        mm.line_intersections([[0.5, 0.5]], [[0.0, 0.0]], SQUARE)
    with pytest.raises(ValueError, match="directions: has 2 rows but origins has 1"):
        mm.line_intersections([[0.5, 0.5]], [[1.0, 0.0], [0.0, 1.0]], SQUARE)
    with pytest.raises(ValueError, match="queries: row 0 has a non-finite"):
        mm.closest_points([[np.nan, 0.0]], SQUARE)
    with pytest.raises(ValueError, match="ends: expected shape"):
        mm.count_crossings(SQUARE, SQUARE[:3])


def test_invalid_input_is_a_value_error():
    assert issubclass(mm.InvalidInput, ValueError)
