"""The automatic workflow (the paper's Algorithm 1) is the default."""

import numpy as np

import morphomap as mm
from conftest import circle, ellipse


def test_auto_on_the_kidney_pair_removes_the_crossings_of_normal_mapping():
    c1, c2 = mm.load_example("kidney")
    normal = mm.map_curves(c1, c2, "normal")
    assert mm.count_crossings(normal.starts, normal.ends) > 0  # the case Algorithm 1 is for
    field = mm.map_curves(c1, c2)
    assert field.valid.all()
    assert mm.count_crossings(field.starts, field.ends) == 0
    assert set(field.method) == {"normal", "reverse_diffusion"}  # normal where it works, reverse diffusion elsewhere
    assert mm.closest_points(field.starts, c1).distances.max() < 1e-9  # starts on C1
    assert mm.closest_points(field.ends, c2).distances.max() < 1e-9  # ends on C2


def test_auto_keeps_normal_mapping_where_it_has_no_crossings_or_misses():
    c1, c2 = circle(100, 0.95), ellipse(100, 2.177, 1.0)
    field = mm.map_curves(c1, c2)
    expected = mm.map_curves(c1, c2, "normal")
    assert set(field.method) == {"normal"}
    assert np.array_equal(field.ends, expected.ends)


def test_auto_falls_back_to_reverse_diffusion_for_the_whole_pair_when_they_do_not_cross():
    t = 2 * np.pi * np.arange(300) / 300
    r = 1 + 0.35 * np.cos(6 * t)  # deep bays: its normals cross before they reach C2
    c1 = np.column_stack([r * np.cos(t), r * np.sin(t)])
    c2 = circle(300, 3.0)
    assert mm.count_crossings(*_vectors(mm.map_curves(c1, c2, "normal"))) > 0
    field = mm.map_curves(c1, c2, "auto")
    assert set(field.method) == {"reverse_diffusion"}
    assert len(field) == len(c2) and field.valid.all()
    assert mm.count_crossings(field.starts, field.ends) == 0


def _vectors(field):
    ok = field.valid
    return field.starts[ok], field.ends[ok]


def test_density_rule_tries_reverse_minimal_distance_on_dense_points():
    c1, c2 = circle(400, 1.0), circle(400, 2.0)  # 64 points per gap
    dense = mm.map_curves(c1, c2, density_threshold=5.0)
    assert set(dense.method) == {"reverse_minimal_distance"} and len(dense) == len(c2)
    # Radial, in order along C1 (which of the two ends of the order the vector at C1's first
    # point takes is up to rounding).
    shift = int(np.argmin(np.hypot(*(dense.ends - c2[0]).T)))
    assert np.allclose(np.roll(dense.ends, -shift, axis=0), c2)
    assert np.allclose(np.roll(dense.starts, -shift, axis=0), c1, atol=1e-12)
    sparse = mm.map_curves(c1, c2, density_threshold=100.0)
    assert set(sparse.method) == {"normal"} and np.allclose(sparse.starts, c1)


def test_density_threshold_is_checked():
    import pytest

    with pytest.raises(ValueError, match="density_threshold: must be a finite number >= 0"):
        mm.map_curves(circle(10), circle(10, 2.0), density_threshold=-1.0)
    with pytest.raises(TypeError, match="density_threshold: expected a number"):
        mm.map_curves(circle(10), circle(10, 2.0), density_threshold="high")
