"""Growth kinematics against closed forms: scaling, a spheroid, a rotation, a budding circle, series."""

import numpy as np
import pytest
import trimesh

import morphomap as mm
from morphomap.examples.growing_frames import frames
from conftest import SHARED_CASES, require_cases


def _sphere(subdivisions=2):
    sphere = trimesh.creation.icosphere(subdivisions)
    return np.asarray(sphere.vertices), np.asarray(sphere.faces)


def _face_geometry(vertices, faces):
    corners = vertices[faces]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    return corners, normal


def test_uniform_scaling_is_isotropic_without_direction():
    vertices, faces = _sphere()
    scale, dt = 1.2, 2.0
    g = mm.growth(mm.DisplacementField(vertices, vertices * scale, "normal", faces), dt=dt)
    np.testing.assert_allclose(g.stretches, scale, rtol=1e-12)
    np.testing.assert_allclose(g.areal_growth, scale ** 2, rtol=1e-12)
    np.testing.assert_allclose(g.areal_growth_rate, np.log(scale ** 2) / dt, rtol=1e-12)
    np.testing.assert_allclose(g.anisotropy, 1.0, rtol=1e-12)
    assert np.isnan(g.directions).all()  # no preferred direction: reported as such, not noise
    corners, normal = _face_geometry(vertices, faces)
    velocity = (scale - 1) * corners.mean(axis=1) / dt
    np.testing.assert_allclose(g.normal_velocity, np.einsum("ij,ij->i", velocity, normal), rtol=1e-12)
    np.testing.assert_allclose(g.tangential_velocity, velocity - g.normal_velocity[:, None] * normal, atol=1e-14)
    assert (g.normal_velocity > 0).all()  # outward


def test_a_spheroid_stretches_along_its_axis():
    vertices, faces = _sphere()
    a = 1.5
    stretch = np.diag([1.0, 1.0, a])
    g = mm.growth(mm.DisplacementField(vertices, vertices @ stretch.T, "normal", faces))
    # Truth per triangle: the singular values and right singular vectors of the linear map on the
    # triangle's plane (an orthonormal basis Q of it), by numpy's SVD.
    corners, normal = _face_geometry(vertices, faces)
    for f in range(len(faces)):
        q = np.linalg.qr(np.column_stack([corners[f, 1] - corners[f, 0], corners[f, 2] - corners[f, 0]]))[0]
        _, s, vt = np.linalg.svd(stretch @ q)
        np.testing.assert_allclose(g.stretches[f], s, rtol=1e-12)
        if s[0] - s[1] > 1e-6 * s[0]:
            major = q @ vt[0]
            assert abs(abs(g.directions[f, 0] @ major) - 1) < 1e-9
    # A triangle in the plane x = 1 (its normal on the equator): stretched by a along z, 1 across.
    triangle = np.array([[1.0, 0.0, -0.1], [1.0, 0.1, 0.05], [1.0, -0.1, 0.08]])
    one = mm.growth(mm.DisplacementField(triangle, triangle @ stretch.T, "normal", np.array([[0, 1, 2]])))
    np.testing.assert_allclose(one.stretches[0], [a, 1.0], rtol=1e-12)
    assert one.anisotropy[0] == pytest.approx(a, rel=1e-12)
    np.testing.assert_allclose(np.abs(one.directions[0, 0]), [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(np.abs(one.directions[0, 1]), [0, 1, 0], atol=1e-12)


def test_a_rotation_grows_nothing():
    vertices, faces = _sphere()
    angle = 0.7
    rotation = np.array([[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]])
    g = mm.growth(mm.DisplacementField(vertices, vertices @ rotation.T, "normal", faces))
    np.testing.assert_allclose(g.stretches, 1.0, rtol=1e-12)
    np.testing.assert_allclose(g.areal_growth_rate, 0.0, atol=1e-12)
    assert np.isnan(g.directions).all()


def test_a_circle_growing_a_bud_grows_at_the_bud():
    shapes = frames(2, points=400)
    t = 2 * np.pi * np.arange(400) / 400
    g = mm.growth(mm.DisplacementField(shapes[0], shapes[1], "normal", source=shapes[0]), dt=0.5)
    # Truth: the length ratio of each segment, brute force.
    after = np.linalg.norm(np.roll(shapes[1], -1, axis=0) - shapes[1], axis=1)
    before = np.linalg.norm(np.roll(shapes[0], -1, axis=0) - shapes[0], axis=1)
    np.testing.assert_allclose(g.areal_growth, after / before, rtol=1e-12)
    assert g.stretches.shape == (400, 1) and g.directions.shape == (400, 1, 2) and np.isnan(g.anisotropy).all()
    middle = t + np.pi / 400
    bud = np.abs(np.angle(np.exp(1j * (middle - 0.5)))) < 0.2
    far = np.abs(np.angle(np.exp(1j * (middle - 0.5 - np.pi)))) < 0.5
    assert g.areal_growth[bud].min() > 1.25 and np.abs(g.areal_growth[far] - 1.08).max() < 0.01
    # Outward normal velocity: the corners' mean radial growth over dt (the segment's normal is
    # radial to cos(pi / 400)), largest at the bud.
    radial = np.linalg.norm(shapes[1], axis=1) - np.linalg.norm(shapes[0], axis=1)
    np.testing.assert_allclose(g.normal_velocity, 0.5 * (radial + np.roll(radial, -1)) / 0.5, rtol=1e-3)
    assert g.normal_velocity[bud].min() > 3 * g.normal_velocity[far].max()
    # The same curve clockwise: the same outward velocities.
    reverse = mm.growth(mm.DisplacementField(shapes[0][::-1], shapes[1][::-1], "normal", source=shapes[0][::-1]),
                        dt=0.5)
    np.testing.assert_allclose(np.sort(reverse.normal_velocity), np.sort(g.normal_velocity), rtol=1e-12)


def test_series_growth_accumulates_from_each_birth():
    series = mm.map_series(frames(5, points=120))
    sg = mm.growth(series)
    assert len(sg.steps) == len(sg.accumulated) == 4 and sg.dt == series.dt
    assert (series.born > 0).any()  # points born: elements that start later
    x = series.trajectories
    for k, cells in enumerate(series.cells[:4]):
        start = series.born[cells].max(axis=1)
        for e in range(0, len(cells), 7):
            a, b = cells[e]
            s = start[e]
            truth = np.linalg.norm(x[k + 1, b] - x[k + 1, a]) / np.linalg.norm(x[s, b] - x[s, a])
            assert sg.accumulated[k].areal_growth[e] == pytest.approx(truth, rel=1e-12)
            assert sg.accumulated[k].elapsed[e] == (k + 1 - s) * series.dt
            step = np.linalg.norm(x[k + 1, b] - x[k + 1, a]) / np.linalg.norm(x[k, b] - x[k, a])
            assert sg.steps[k].areal_growth[e] == pytest.approx(step, rel=1e-12)
    # The stretch map the series already had is the same quantity per step.
    np.testing.assert_allclose(sg.steps[2].areal_growth, series.stretch(2), rtol=1e-12)


def test_regions_average_by_length_and_bands_by_distance():
    shapes = frames(2, points=400)
    g = mm.growth(mm.DisplacementField(shapes[0], shapes[1], "normal", source=shapes[0]))
    tip = shapes[0][np.argmin(np.abs(np.angle(np.exp(1j * (2 * np.pi * np.arange(400) / 400 - 0.5)))))]
    bands = mm.distance_bands(shapes[0], tip, 0.5)
    assert bands.min() == 0 and bands.max() == 3  # the far side is 2 away
    table = g.by_region(bands, per="points")
    # Band 0 round the bud grows most; a region's areal growth is its length after over before.
    assert table["areal_growth"][0] == np.nanmax(table["areal_growth"])
    element = g._element_labels(bands, "points")
    inside = element == 2
    corners = g.cells[inside]
    truth = (np.linalg.norm(shapes[1][corners[:, 1]] - shapes[1][corners[:, 0]], axis=1).sum()
             / np.linalg.norm(shapes[0][corners[:, 1]] - shapes[0][corners[:, 0]], axis=1).sum())
    assert table["areal_growth"][2] == pytest.approx(truth, rel=1e-12)
    assert table["elements"].sum() == len(g.cells)
    with pytest.raises(ValueError, match="per='elements' or per='points'"):
        g.by_region(bands)  # 400 segments and 400 points
    with pytest.raises(ValueError, match="expected 400"):
        g.by_region(bands[:10], per="points")
    with pytest.raises(TypeError, match="labels"):
        g.by_region(bands.astype(float), per="points")
    with pytest.raises(TypeError, match="field_or_series"):
        mm.growth(shapes[0])
    with pytest.raises(ValueError, match="dt"):
        mm.growth(mm.DisplacementField(shapes[0], shapes[1], "normal", source=shapes[0]), dt=0)


def test_limb_bud_grows_at_the_tip_and_not_at_the_flank():
    limb = SHARED_CASES / "limb-bud" / "2d"
    require_cases(limb)
    hours = range(300, 341, 4)
    series = mm.map_series([mm.read_curve(limb / f"limb_h{h}.csv") for h in hours], dt=4.0)
    last = mm.growth(series).accumulated[-1]
    x = series.trajectories[-1]
    centre = x[series.cells[len(series.fields) - 1]].mean(axis=1)
    distal = centre[:, 0] > 0.8 * np.nanmax(x[:, 0])
    flank = centre[:, 0] < 0.05 * np.nanmax(x[:, 0])
    assert np.nanmedian(last.areal_growth[distal]) > 1.5 * np.nanmedian(last.areal_growth[flank])
