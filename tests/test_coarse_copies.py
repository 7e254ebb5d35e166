"""The 3D default through coarse copies: a surface contoured from a voxel mask, too large and too
rough for the whole-resolution candidates, mapped on remeshed copies and carried back onto its own
vertices (cpp/src/mapping/coarse_field.hpp), against the closed form of concentric spheres."""

import numpy as np
import pytest
from skimage import measure

import morphomap as mm
from morphomap import _progress
from surface_shapes import icosphere, signed_volume


def voxel_ball(radius):
    """The marching-cubes surface of a ball of `radius` voxels centred at the origin, as a lab
    contours a thresholded stack: staircase facets, outward."""
    size = int(2 * radius + 8)
    centre = (size - 1) / 2
    zz, yy, xx = np.indices((size, size, size))
    mask = (xx - centre) ** 2 + (yy - centre) ** 2 + (zz - centre) ** 2 < radius**2
    vertices, faces, _, _ = measure.marching_cubes(np.pad(mask, 1).astype(float), 0.5)
    vertices = vertices - 1 - centre
    return vertices, (faces if signed_volume(vertices, faces) > 0 else faces[:, ::-1]).astype(np.int64)


@pytest.fixture
def stages(monkeypatch):
    """The stages the core reports to the progress bar, in order."""
    seen = []
    report = _progress.StageBar._on_stage

    def recording(self, stage):
        seen.append(stage)
        report(self, stage)

    monkeypatch.setattr(_progress.StageBar, "_on_stage", recording)
    return seen


def test_a_large_voxel_ball_maps_through_coarse_copies_along_the_radii(stages):
    # A ball of radius 30 voxels (16,968 vertices, more than the 10,000 above which the copies are
    # made) onto the sphere of radius 45 around it. Normal mapping folds on the staircase, so the
    # default maps copies remeshed at about 5,000 vertices and carries that field back.
    v1, f1 = voxel_ball(30)
    v2, f2 = icosphere(4, radius=45.0)
    assert len(v1) > 10_000
    field = mm.map_surfaces((v1, f1), (v2, f2), progress=True)
    assert "coarse copies" in stages
    np.testing.assert_array_equal(field.starts, v1)
    assert field.valid.all()
    assert mm.quality(field, (v1, f1), (v2, f2)).folds == 0
    assert mm.SurfaceIndex(v2, f2).closest_points(field.ends).distances.max() < 1e-9
    # Between concentric spheres the field is radial. The staircase (at most a voxel off the
    # sphere) turns a streamline aside by about a voxel before it runs radially: 1/45 = 0.022 in
    # direction (0.0095 measured, RMS 0.0021). Ends carried from the wrong coarse triangle would
    # be off by a coarse edge (1.6 voxels, 0.036) and more.
    along = v1 / np.linalg.norm(v1, axis=1, keepdims=True)
    reached = field.ends / np.linalg.norm(field.ends, axis=1, keepdims=True)
    deviation = np.linalg.norm(along - reached, axis=1)
    assert deviation.max() < 0.022
    assert np.sqrt(np.mean(deviation**2)) < 0.005


def test_a_small_voxel_ball_is_mapped_as_it_is(stages):
    # 4,000-odd vertices: below the rule, no copies.
    v1, f1 = voxel_ball(15)
    v2, f2 = icosphere(4, radius=22.0)
    assert len(v1) < 10_000
    field = mm.map_surfaces((v1, f1), (v2, f2), progress=True)
    assert "coarse copies" not in stages
    assert field.valid.all() and mm.quality(field, (v1, f1), (v2, f2)).folds == 0
