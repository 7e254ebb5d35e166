"""Time series: chained fields and trajectories against closed forms."""

import numpy as np
import pytest
import trimesh

import morphomap as mm
from conftest import circle


def test_circles_keep_their_angle_and_reach_each_radius():
    # Normal mapping between concentric circles is radial: a followed point keeps its angle and
    # lies on every frame's circle; the stretch of each step is the radius ratio.
    radii = [1.0, 1.5, 2.0, 2.5]
    frames = [circle(200, r) for r in radii]
    series = mm.map_series(frames, "normal", progress=False)
    assert len(series.fields) == 3 and series.trajectories.shape == (4, 200, 2)
    for t, r in enumerate(radii):
        assert np.abs(np.linalg.norm(series.trajectories[t], axis=1) - r).max() < 1e-12
    angles = np.arctan2(series.trajectories[:, :, 1], series.trajectories[:, :, 0])
    assert np.abs(angles - angles[0]).max() < 1e-12
    assert np.allclose(series.stretch(1), 2.0 / 1.5)
    assert [q.defects for q in series.quality] == [0, 0, 0] and all(q.misses == 0 for q in series.quality)


def test_spheres_and_writing(tmp_path):
    frames = [trimesh.creation.icosphere(2).apply_scale(1 + 0.2 * k) for k in range(3)]
    series = mm.map_series(frames, "normal", progress=False)
    assert np.abs(np.linalg.norm(series.trajectories[-1], axis=1) - 1.4).max() < 2e-3  # faceted spheres
    assert series.stretch(1).mean() == pytest.approx((1.4 / 1.2) ** 2, rel=1e-2)
    paths = series.write(tmp_path / "out")
    assert [p.split("/")[-1] for p in paths] == ["field_00.csv", "field_01.csv", "trajectories.csv", "quality.csv"]
    back = mm.read_field(paths[1])
    assert back.faces is not None and np.allclose(back.vectors, series.fields[1].vectors)
    table = np.loadtxt(paths[2], delimiter=",", skiprows=1)
    assert table.shape == (3 * len(frames[0].vertices), 5)
    assert (tmp_path / "out" / "quality.csv").read_text().splitlines()[0].startswith("step,qm1,qm2,qm,folds")


def test_bad_frames_are_named():
    c1 = circle(100)
    with pytest.raises(ValueError, match="frames: expected at least 2"):
        mm.map_series([c1])
    with pytest.raises(ValueError, match="frames: mix curves and surfaces"):
        mm.map_series([c1, trimesh.creation.icosphere(1)])
    with pytest.raises(ValueError, match=r"frames\[1\] -> frames\[2\]"):
        mm.map_series([c1, 2 * c1, np.vstack([c1, c1 + 5])])
