"""Diffusion mapping in 3D against shapes with a known answer.

Between concentric spheres of radii 1 and 4 the potential is (1/r - 1/4) / (1 - 1/4) and the
streamlines are radial; a sphere inside an ellipsoid must map without losses or folds.
"""

import numpy as np
import pytest

import morphomap as mm

trimesh = pytest.importorskip("trimesh")


def sphere(radius=1.0, subdivisions=4, axes=None):
    mesh = trimesh.creation.icosphere(subdivisions=subdivisions)
    vertices = np.array(mesh.vertices) * (radius if axes is None else np.asarray(axes, float))
    return vertices, np.array(mesh.faces)


def angular_rms(starts, ends, radius):
    """RMS angle between start and end directions, times the radius of the end sphere."""
    a = starts / np.linalg.norm(starts, axis=1, keepdims=True)
    b = ends / np.linalg.norm(ends, axis=1, keepdims=True)
    angles = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
    return radius * np.sqrt(np.mean(angles**2))


@pytest.fixture(scope="module")
def spheres():
    inner, outer = sphere(1.0), sphere(4.0)
    return inner, outer, mm.solve_diffusion_3d(inner, outer, streamlines=True)


def test_concentric_spheres_radial(spheres):
    inner, _, solution = spheres
    assert solution.ends.shape == inner[0].shape
    assert np.isfinite(solution.ends).all()
    error = angular_rms(inner[0], solution.ends, 4.0)
    assert error < 0.01, error
    # The ends lie on the target (a polyhedron inscribed in the sphere of radius 4).
    radii = np.linalg.norm(solution.ends, axis=1)
    assert (radii <= 4.0 + 1e-9).all() and (radii > 3.98).all()


def test_concentric_spheres_potential(spheres):
    _, _, solution = spheres
    r = np.linalg.norm(solution.vertices, axis=1)
    exact = np.clip((1 / r - 0.25) / 0.75, 0, 1)
    assert np.abs(solution.potential - exact).max() < 0.01
    assert solution.potential.min() >= -1e-9 and solution.potential.max() <= 1 + 1e-9


def test_result_arrays(spheres):
    inner, _, solution = spheres
    assert solution.vertices.shape[1] == 3 and solution.vertices.dtype == np.float64
    assert solution.tetrahedra.shape[1] == 4 and solution.tetrahedra.dtype == np.int64
    assert solution.potential.shape == (len(solution.vertices),)
    p = solution.vertices[solution.tetrahedra]
    volumes = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6
    assert (volumes > 0).all()
    assert volumes.sum() == pytest.approx(4 / 3 * np.pi * 63, rel=0.02)
    assert len(solution.streamlines) == len(inner[0])
    for i in (0, 17, len(inner[0]) - 1):
        line = solution.streamlines[i]
        assert line.shape[1] == 3 and len(line) >= 3
        np.testing.assert_array_equal(line[0], inner[0][i])
        np.testing.assert_array_equal(line[-1], solution.ends[i])
        r = np.linalg.norm(line[1:-1], axis=1)
        assert (np.diff(r) > -1e-6).all()  # outwards all the way
    assert set(solution.seconds) == {"mesh", "solve", "trace"}
    with pytest.raises(Exception):
        solution.ends = None  # frozen


def test_refinement_reduces_error():
    inner, outer = sphere(1.0, 3), sphere(4.0, 3)
    coarse = mm.solve_diffusion_3d(inner, outer, mesh_size=1.0)
    fine = mm.solve_diffusion_3d(inner, outer, mesh_size=0.35)
    assert len(fine.tetrahedra) > len(coarse.tetrahedra)
    assert angular_rms(inner[0], fine.ends, 4) < angular_rms(inner[0], coarse.ends, 4)


def test_outer_to_inner_and_trimesh_input():
    outer = trimesh.creation.icosphere(subdivisions=3)
    outer.apply_scale(3.0)
    inner = sphere(1.0, 3)
    inner = (inner[0], inner[1][:, ::-1])  # inwards-facing faces are accepted too
    solution = mm.solve_diffusion_3d(outer, inner)
    assert np.isfinite(solution.ends).all()
    assert angular_rms(np.array(outer.vertices), solution.ends, 1.0) < 0.01
    assert (np.linalg.norm(solution.ends, axis=1) < 1 + 1e-9).all()


def test_sphere_to_ellipsoid_no_losses_no_folds():
    axes = np.array([2.0, 1.5, 1.2])
    s1, s2 = sphere(1.0), sphere(axes=axes)
    solution = mm.solve_diffusion_3d(s1, s2)
    ends = solution.ends
    assert np.isfinite(ends).all()
    np.testing.assert_allclose(np.linalg.norm(ends / axes, axis=1), 1.0, atol=0.01)
    # Image triangles keep their orientation: their normals point out of the ellipsoid.
    faces = s1[1]
    a, b, c = ends[faces[:, 0]], ends[faces[:, 1]], ends[faces[:, 2]]
    normals = np.cross(b - a, c - a)
    centres = (a + b + c) / 3
    outward = centres / axes**2
    assert (np.einsum("ij,ij->i", normals, outward) > 0).all()


def test_bad_input():
    s1, s2 = sphere(1.0, 2), sphere(3.0, 2)
    apart = (s1[0] + [5.0, 0, 0], s1[1])
    with pytest.raises(ValueError, match="inside the other"):
        mm.solve_diffusion_3d(s1, apart)
    crossing = (s1[0] + [0.5, 0, 0], s1[1])
    with pytest.raises(ValueError, match="crossing surfaces is not supported"):
        mm.solve_diffusion_3d(s1, crossing)
    with pytest.raises(ValueError, match="s2"):
        mm.solve_diffusion_3d(s1, (s2[0], s2[1][:-1]))  # open
    with pytest.raises(ValueError, match="mesh_size"):
        mm.solve_diffusion_3d(s1, s2, mesh_size=-1)
    with pytest.raises(TypeError, match="mesh_size"):
        mm.solve_diffusion_3d(s1, s2, mesh_size="fine")
    with pytest.raises(TypeError, match="s1"):
        mm.solve_diffusion_3d("sphere", s2)
    bad = s1[0].copy()
    bad[0, 0] = np.nan
    with pytest.raises(ValueError, match="s1"):
        mm.solve_diffusion_3d((bad, s1[1]), s2)
