"""The paper's Algorithm 1 (``method="paper"``) as stated, and the default (``"auto"``), which never
returns crossings or misses and maps from C1's own points."""

import numpy as np

import morphomap as mm
from conftest import circle, ellipse


def test_paper_on_the_kidney_pair_removes_the_crossings_of_normal_mapping():
    c1, c2 = mm.load_example("kidney")
    normal = mm.map_curves(c1, c2, "normal")
    assert mm.count_crossings(normal.starts, normal.ends) > 0  # the case Algorithm 1 is for
    field = mm.map_curves(c1, c2, "paper")
    assert field.valid.all()
    assert mm.count_crossings(field.starts, field.ends) == 0
    assert set(field.method) == {"normal", "reverse_diffusion"}  # normal where it works, reverse diffusion elsewhere
    assert mm.closest_points(field.starts, c1).distances.max() < 1e-9  # starts on C1
    assert mm.closest_points(field.ends, c2).distances.max() < 1e-9  # ends on C2


def test_paper_keeps_normal_mapping_where_it_has_no_crossings_or_misses():
    c1, c2 = circle(100, 0.95), ellipse(100, 2.177, 1.0)
    field = mm.map_curves(c1, c2, "paper")
    expected = mm.map_curves(c1, c2, "normal")
    assert set(field.method) == {"normal"}
    assert np.array_equal(field.ends, expected.ends)


def test_paper_falls_back_to_reverse_diffusion_for_the_whole_pair_when_they_do_not_cross():
    t = 2 * np.pi * np.arange(300) / 300
    r = 1 + 0.35 * np.cos(6 * t)  # deep bays: its normals cross before they reach C2
    c1 = np.column_stack([r * np.cos(t), r * np.sin(t)])
    c2 = circle(300, 3.0)
    assert mm.count_crossings(*_vectors(mm.map_curves(c1, c2, "normal"))) > 0
    field = mm.map_curves(c1, c2, "paper")
    assert set(field.method) == {"reverse_diffusion"}
    assert len(field) == len(c2) and field.valid.all()
    assert mm.count_crossings(field.starts, field.ends) == 0


def _vectors(field):
    ok = field.valid
    return field.starts[ok], field.ends[ok]


def test_density_rule_tries_reverse_minimal_distance_on_dense_points():
    c1, c2 = circle(400, 1.0), circle(400, 2.0)  # 64 points per gap
    dense = mm.map_curves(c1, c2, "paper", density_threshold=5.0)
    assert set(dense.method) == {"reverse_minimal_distance"} and len(dense) == len(c2)
    # Radial, in order along C1 (which of the two ends of the order the vector at C1's first
    # point takes is up to rounding).
    shift = int(np.argmin(np.hypot(*(dense.ends - c2[0]).T)))
    assert np.allclose(np.roll(dense.ends, -shift, axis=0), c2)
    assert np.allclose(np.roll(dense.starts, -shift, axis=0), c1, atol=1e-12)
    sparse = mm.map_curves(c1, c2, "paper", density_threshold=100.0)
    assert set(sparse.method) == {"normal"} and np.allclose(sparse.starts, c1)


def test_density_threshold_is_checked():
    import pytest

    with pytest.raises(ValueError, match="density_threshold: must be a finite number >= 0"):
        mm.map_curves(circle(10), circle(10, 2.0), density_threshold=-1.0)
    with pytest.raises(TypeError, match="density_threshold: expected a number"):
        mm.map_curves(circle(10), circle(10, 2.0), density_threshold="high")


def check_default(field, c1, c2):
    """The default's contract: every point of C1 a start point, in order, valid, no crossings."""
    q = mm.quality(field, c1, c2)
    assert field.valid.all() and q.crossings == 0
    assert mm.closest_points(c1, field.starts).distances.max() < 1e-12
    assert mm.closest_points(field.ends, c2).distances.max() < 1e-9
    return q


def test_default_on_the_kidney_pair_beats_algorithm_1():
    c1, c2 = mm.load_example("kidney")
    field = mm.map_curves(c1, c2)
    q = check_default(field, c1, c2)
    paper = mm.quality(mm.map_curves(c1, c2, "paper"), c1, c2)
    # Algorithm 1's QM here is 39.9: its reverse diffusion vectors bunch up on the buds.
    assert q.qm < 0.05 * paper.qm
    # The cheap candidates sufficed: no diffusion problem was solved.
    assert set(field.method.tolist()) <= {"normal", "optimal", "minimal_distance", "reverse_minimal_distance",
                                          "reverse_optimal"}


def test_default_maps_from_c1_where_algorithm_1_maps_from_c2():
    t = 2 * np.pi * np.arange(300) / 300
    r = 1 + 0.35 * np.cos(6 * t)  # deep bays: normal mapping crosses
    c1 = np.column_stack([r * np.cos(t), r * np.sin(t)])
    c2 = circle(300, 3.0)
    field = mm.map_curves(c1, c2)
    check_default(field, c1, c2)
    assert len(field) == len(c1)
    np.testing.assert_array_equal(field.starts, c1)


def test_default_keeps_normal_mapping_where_it_is_best():
    # Concentric circles: normal mapping is radial (QM 0 up to rounding); optimal cannot beat it.
    c1, c2 = circle(100, 1.0), circle(100, 2.0)
    field = mm.map_curves(c1, c2)
    check_default(field, c1, c2)
    np.testing.assert_allclose(np.hypot(*field.ends.T), 2.0, rtol=1e-12)



def test_default_reversed_and_resampled_keep_the_contract():
    # reverse=True: one vector per point of C2 (found from C2), none crossing; n: the resampled
    # points. Neither takes the moved-C1 field, whose start points are C1's own rows.
    c1, c2 = mm.load_example("kidney")
    back = mm.map_curves(c1, c2, reverse=True)
    q = mm.quality(back, c1, c2)
    assert back.valid.all() and q.crossings == 0
    assert mm.closest_points(c2, back.ends).distances.max() < 1e-12
    resampled = mm.map_curves(c1, c2, n=120)
    q = mm.quality(resampled, c1, c2)
    assert resampled.valid.all() and q.crossings == 0 and len(resampled) >= 120
