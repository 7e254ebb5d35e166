"""The interior displacement (harmonic extension) against exact answers."""

import numpy as np
import pytest
import trimesh
from scipy.spatial import Delaunay

import morphomap as mm
from conftest import circle

A2, B2 = np.array([[1.2, 0.3], [-0.1, 0.9]]), np.array([0.3, -0.2])
A3, B3 = np.array([[1.1, 0.2, 0.0], [-0.1, 0.9, 0.1], [0.3, 0.0, 1.2]]), np.array([0.1, 0.2, -0.3])


def rotation(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


def disc_mesh(c1, interior=300, seed=1):
    """A Delaunay mesh of the convex curve's vertices and random points inside: its boundary is C1."""
    rng = np.random.default_rng(seed)
    r, t = 0.95 * np.sqrt(rng.random(interior)), rng.uniform(0, 2 * np.pi, interior)
    points = np.vstack([c1, np.column_stack([r * np.cos(t), r * np.sin(t)])])
    return points, Delaunay(points).simplices


METHODS = [{"method": "harmonic"}, {"method": "elastic"}, {"method": "elastic", "poisson_ratio": 0.45}]


@pytest.mark.parametrize("options", METHODS)
@pytest.mark.parametrize("A, b", [(A2, B2), (1.7 * rotation(0.6), np.array([2.0, -1.0]))])
def test_affine_boundary_maps_extend_to_the_same_map_in_2d(A, b, options):
    c1 = circle(120)
    field = mm.DisplacementField(c1, c1 @ A.T + b, "normal", source=c1)
    for mesh in (None, disc_mesh(c1)):
        interior = mm.extend_field(field, mesh=mesh, **options)
        expected = interior.points @ A.T + b - interior.points
        assert np.abs(interior.displacement - expected).max() < 1e-10
        assert interior.inverted == 0 and interior.boundary_distance < 1e-12
        assert interior.min_jacobian == pytest.approx(np.linalg.det(A), rel=1e-9)


@pytest.mark.parametrize("options", METHODS)
def test_affine_boundary_maps_extend_to_the_same_map_in_3d(options):
    s1 = trimesh.creation.icosphere(2)
    rng = np.random.default_rng(2)
    inside = rng.normal(size=(400, 3))
    inside *= (0.9 * rng.random(400) ** (1 / 3) / np.linalg.norm(inside, axis=1))[:, None]
    points = np.vstack([s1.vertices, inside])
    cells = Delaunay(points).simplices
    field = mm.DisplacementField(s1.vertices, s1.vertices @ A3.T + B3, "normal", faces=s1.faces)
    interior = mm.extend_field(field, mesh=(points, cells), **options)
    assert np.abs(interior.displacement - (points @ A3.T + B3 - points)).max() < 1e-10
    assert interior.inverted == 0 and interior.boundary_distance < 1e-12


def test_concentric_circles_give_the_radial_field_inside():
    # Diffusion between r = 1 and r = 2: u = x on the boundary to the mapping's accuracy, and the
    # harmonic extension of u = x is u = x inside.
    c1 = circle(200)
    field = mm.map_curves(c1, 2 * c1, "diffusion")
    interior = mm.extend_field(field, mesh_size=0.05)
    boundary_error = np.abs(field.vectors - field.starts).max()
    assert np.abs(interior.displacement - interior.points).max() <= boundary_error + 1e-9
    assert interior.inverted == 0 and interior.min_jacobian > 3.9  # area x4
    assert np.allclose(interior.velocity(0.5), 2 * interior.displacement)


def test_concentric_spheres_give_the_radial_field_inside():
    s1 = trimesh.creation.icosphere(2)
    field = mm.map_surfaces(s1, s1.copy().apply_scale(2.0), "diffusion")
    boundary_error = np.abs(field.vectors - field.starts).max()
    rng = np.random.default_rng(3)
    inside = rng.normal(size=(300, 3))
    inside *= (0.9 * rng.random(300) ** (1 / 3) / np.linalg.norm(inside, axis=1))[:, None]
    points = np.vstack([s1.vertices, inside])
    interior = mm.extend_field(field, mesh=(points, Delaunay(points).simplices))
    assert np.abs(interior.displacement - interior.points).max() <= boundary_error + 1e-9
    assert interior.inverted == 0


@pytest.mark.parametrize("options", METHODS[:2])
def test_affine_boundary_maps_extend_to_the_same_map_on_the_default_3d_mesh(options):
    s1 = trimesh.creation.icosphere(2)
    field = mm.DisplacementField(s1.vertices, s1.vertices @ A3.T + B3, "normal", faces=s1.faces)
    interior = mm.extend_field(field, **options)
    points = interior.points
    assert len(points) > len(s1.vertices) and interior.cells.shape[1] == 4
    assert np.linalg.norm(points, axis=1).max() <= 1 + 1e-12  # S1 is inscribed in the unit sphere
    assert np.abs(interior.displacement - (points @ A3.T + B3 - points)).max() < 1e-10
    assert interior.inverted == 0 and interior.boundary_distance < 1e-12
    again = mm.extend_field(field, **options)  # the mesher's random choices are fixed
    assert np.array_equal(again.points, points) and np.array_equal(again.cells, interior.cells)


def test_every_tetrahedron_of_the_default_3d_mesh_has_a_free_node():
    # Tetrahedra with four corners on S1 would move with the boundary field alone: their longest
    # chord is split. The lung-like S1 (tubes, a crotch) has many such caps under Mesh_3.
    from morphomap.synthetic.lung import lung_pair

    s1, _ = lung_pair()
    field = mm.DisplacementField(s1.vertices, s1.vertices @ A3.T + B3, "normal", faces=s1.faces)
    interior = mm.extend_field(field)
    cells = interior.cells
    faces = np.sort(np.vstack([np.delete(cells, k, axis=1) for k in range(4)]), axis=1)
    unique, counts = np.unique(faces, axis=0, return_counts=True)
    on_surface = np.zeros(len(interior.points), bool)
    on_surface[unique[counts == 1].ravel()] = True
    assert not on_surface[cells].all(axis=1).any()
    assert np.abs(interior.displacement - (interior.points @ A3.T + B3 - interior.points)).max() < 1e-10
    assert interior.inverted == 0 and interior.boundary_distance < 1e-12


def test_concentric_spheres_give_the_radial_field_on_the_default_3d_mesh():
    # Diffusion between R1 = 1 and R2 = 1.5: u = (R2 / R1 - 1) x inside, to the boundary field's accuracy.
    s1 = trimesh.creation.icosphere(2)
    field = mm.map_surfaces(s1, s1.copy().apply_scale(1.5), "diffusion")
    boundary_error = np.abs(field.vectors - 0.5 * field.starts).max()
    interior = mm.extend_field(field, mesh_size=0.2)
    corners = interior.points[interior.cells]
    volume = np.abs(np.linalg.det(corners[:, 1:] - corners[:, :1])).sum() / 6
    assert 0.95 * s1.volume < volume <= s1.volume  # the tetrahedra fill S1 (their faces chords of it)
    assert np.abs(interior.displacement - 0.5 * interior.points).max() <= boundary_error + 1e-9
    assert interior.inverted == 0 and interior.min_jacobian > 1.5 ** 3 * 0.9


@pytest.mark.parametrize("options", METHODS[:2])
def test_substeps_keep_affine_maps_exact(options):
    # Each substep moves the boundary by an affine map of the moved mesh: exact again.
    c1 = circle(120)
    A = 1.7 * rotation(0.6)
    field = mm.DisplacementField(c1, c1 @ A.T + B2, "normal", source=c1)
    interior = mm.extend_field(field, substeps=5, **options)
    assert np.abs(interior.displacement - (interior.points @ A.T + B2 - interior.points)).max() < 1e-10
    s1 = trimesh.creation.icosphere(2)
    field3 = mm.DisplacementField(s1.vertices, s1.vertices @ A3.T + B3, "normal", faces=s1.faces)
    interior3 = mm.extend_field(field3, substeps=3, **options)
    assert np.abs(interior3.displacement - (interior3.points @ A3.T + B3 - interior3.points)).max() < 1e-10


def test_substeps_undo_the_inversions_of_the_kidney_bud():
    # A bud grows out of a few microns of C1: one solve turns triangles over there, substeps do not.
    field = mm.map_curves(*mm.load_example("kidney"), "diffusion")
    once = mm.extend_field(field, mesh_size=0.02, substeps=1, untangle=False)
    stepped = mm.extend_field(field, mesh=(once.points, once.cells), substeps=4)
    assert once.inverted >= 1 and once.min_jacobian < 0
    assert stepped.inverted == 0 and stepped.min_jacobian > 0.05
    cells = once.cells
    edges = np.sort(np.vstack([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    boundary = np.unique(unique[counts == 1])  # the steps add up to the field there
    assert np.abs(stepped.displacement[boundary] - field.at(once.points[boundary])).max() < 1e-12


def test_untangle_moves_only_inner_corners_of_the_inverted_cells():
    # The kidney bud's one-solve inversions, untangled instead of substepped: no cell stays
    # inverted, and only free corners of cells that were inverted move (at most a handful).
    field = mm.map_curves(*mm.load_example("kidney"), "diffusion")
    once = mm.extend_field(field, mesh_size=0.02, substeps=1, untangle=False)
    untangled = mm.extend_field(field, mesh=(once.points, once.cells), untangle=True)
    assert once.inverted >= 1 and untangled.inverted == 0 and untangled.min_jacobian > 0
    cells = once.cells
    edges = np.sort(np.vstack([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    boundary = np.unique(unique[counts == 1])
    moved = np.flatnonzero((untangled.displacement != once.displacement).any(axis=1))

    def areas(x):
        d1, d2 = x[cells[:, 1]] - x[cells[:, 0]], x[cells[:, 2]] - x[cells[:, 0]]
        return d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]

    turned = areas(once.points + once.displacement) / areas(once.points) <= 0
    assert 1 <= len(moved) <= 10
    assert np.isin(moved, cells[turned]).all() and not np.isin(moved, boundary).any()
    with pytest.raises(TypeError, match="untangle: expected True or False"):
        mm.extend_field(field, mesh=(once.points, once.cells), untangle=1)


def test_inversions_are_counted():
    # A boundary map that turns part of the disc inside out (a half turn of one side).
    c1 = circle(100)
    ends = c1.copy()
    right = c1[:, 0] > 0.5
    ends[right, 0] = 1.0 - 2.5 * (c1[right, 0] - 0.5)
    field = mm.DisplacementField(c1, ends, "normal", source=c1)
    interior = mm.extend_field(field, mesh_size=0.1, substeps=1, untangle=False)
    assert interior.inverted > 0 and interior.min_jacobian < 0
    assert (interior.substeps, interior.untangled, len(interior.attempts)) == (1, False, 1)


def test_bad_input_is_named():
    c1 = circle(40)
    field = mm.DisplacementField(c1, 2 * c1, "normal", source=c1)
    with pytest.raises(ValueError, match="method"):
        mm.extend_field(field, method="biharmonic")
    for nu in (-0.1, 0.5, 0.7, np.nan):
        with pytest.raises(ValueError, match="poisson_ratio: must be at least 0 and below 0.5"):
            mm.extend_field(field, method="elastic", poisson_ratio=nu)
    with pytest.raises(TypeError, match="poisson_ratio"):
        mm.extend_field(field, method="elastic", poisson_ratio="0.3")
    with pytest.raises(ValueError, match="substeps: must be at least 1"):
        mm.extend_field(field, substeps=0)
    with pytest.raises(ValueError, match="mesh cells"):
        mm.extend_field(field, mesh=(c1, np.zeros((3, 4), int)))
    with pytest.raises(ValueError, match="mesh: cell 0 refers to point 99"):
        mm.extend_field(field, mesh=(c1, np.array([[0, 1, 99]])))
    flat = np.vstack([c1, [[0.0, 0.0], [0.5, 0.0], [1.0, 0.0]]])
    cells = np.vstack([Delaunay(flat[:40]).simplices, [[40, 41, 42]]])
    with pytest.raises(ValueError, match=r"mesh: cell \d+ is flat \(zero area\)"):
        mm.extend_field(field, mesh=(flat, cells))
    missed = mm.DisplacementField(c1, np.full_like(c1, np.nan), "normal", source=c1)
    with pytest.raises(ValueError, match="field: has no displacement at"):
        mm.extend_field(missed)
    s1 = trimesh.creation.icosphere(1)
    field3 = mm.map_surfaces(s1, s1.copy().apply_scale(1.5), "normal")
    open_surface = mm.DisplacementField(s1.vertices, 1.5 * s1.vertices, "normal", faces=s1.faces[1:])
    with pytest.raises(ValueError, match="field: its triangles do not close a volume"):
        mm.extend_field(open_surface)
    with pytest.raises(ValueError, match="mesh_size"):
        mm.extend_field(field3, mesh_size=-1.0)
    with pytest.raises(ValueError, match="boundary: this field does not know"):
        mm.extend_field(mm.DisplacementField(c1, 2 * c1, "normal"))


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45])
def test_elastic_extension_converges_to_a_solution_of_navier_equations(nu):
    # u = (x^2 - (lambda + 2 mu) / mu y^2, 0) has mu lap u + (lambda + mu) grad div u = 0 and is not
    # harmonic: the elastic extension of its boundary values tends to it, the harmonic one does not.
    c = -(2 * nu / (1 - 2 * nu) + 2)  # -(lambda + 2 mu) / mu, as lambda / mu = 2 nu / (1 - 2 nu)

    def exact(x):
        return np.column_stack([x[:, 0] ** 2 + c * x[:, 1] ** 2, np.zeros(len(x))])

    c1 = circle(400)
    field = mm.DisplacementField(c1, c1 + exact(c1), "normal", source=c1)
    # One solve each: the solution of the linear problem (its motion inverts cells, which the
    # default would go on to clear).
    once = dict(substeps=1, untangle=False)
    elastic = mm.extend_field(field, method="elastic", poisson_ratio=nu, mesh_size=0.03, **once)
    harmonic = mm.extend_field(field, mesh=(elastic.points, elastic.cells), **once)
    scale = np.abs(exact(elastic.points)).max()
    error = np.abs(elastic.displacement - exact(elastic.points)).max()
    assert error < 5e-4 * scale
    assert np.abs(harmonic.displacement - exact(elastic.points)).max() > 100 * error
