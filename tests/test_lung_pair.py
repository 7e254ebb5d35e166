"""A branching lung-like pair in 3D: plain normal mapping folds, "auto" must not.

The pair (morphomap.synthetic.lung): S1 is a trunk tube that splits into two daughters; by S2 the
daughters have grown on and each has budded a side branch, and the whole is dilated, so that S1
lies strictly inside S2 (3D diffusion needs nested surfaces). Both are meshed from implicit
functions with marching cubes.
"""

import numpy as np
import pytest

import morphomap as mm

trimesh = pytest.importorskip("trimesh")
pytest.importorskip("skimage")

from morphomap.synthetic.lung import DILATION, lung_pair  # noqa: E402

LONG_BUDS = 1.0  # growth at which reverse diffusion's images of the buds tilt past 90 degrees


@pytest.fixture(scope="module")
def pair():
    return lung_pair()


@pytest.fixture(scope="module")
def auto(pair):
    return mm.map_surfaces(*pair, "auto")


@pytest.fixture(scope="module")
def long_buds():
    s1, s2 = lung_pair(resolution=8, growth=LONG_BUDS)
    return s1, s2, mm.map_surfaces(s1, s2, "auto")


def diagonal(mesh):
    return float(np.linalg.norm(np.ptp(mesh.vertices, axis=0)))


def distances_to(points, mesh):
    return mm.SurfaceIndex(mesh.vertices, mesh.faces).closest_points(points).distances


def turned_over(field, s1, s2):
    """Image triangles turned over relative to the surfaces themselves: the start triangle against
    the normal of the face of S1 under its centroid, the end triangle against that of S2; a
    triangle counts when exactly one of the two disagrees. The idea of ``quality(...).folds``,
    written independently here with the centroid's face alone; neither counts a triangle whose
    image is merely tilted by more than 90 degrees, as on the side of a bud that grew out
    sideways."""
    faces = field.faces[field.valid[field.faces].all(axis=1)]
    flips = np.zeros(len(faces), int)
    for points, mesh in ((field.starts, s1), (field.ends, s2)):
        corners = points[faces]
        normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        under = mm.SurfaceIndex(mesh.vertices, mesh.faces).closest_points(corners.mean(axis=1)).faces
        flips += np.einsum("ij,ij->i", normal, mesh.face_normals[under]) < 0
    return int((flips == 1).sum())


def test_the_pair_is_closed_oriented_nested_and_deterministic(pair):
    s1, s2 = pair
    for mesh in pair:
        assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
        assert mesh.euler_number == 2  # a sphere: the tubes join into one closed surface
        assert (mesh.area_faces > 1e-6).all()
        assert len(mesh.faces) == len(np.unique(np.sort(mesh.faces, axis=1), axis=0))
        assert 1000 < len(mesh.faces) < 8000
    assert s2.volume > 2 * s1.volume and s2.area > 1.5 * s1.area
    # S1 strictly inside S2: every vertex of S1 inside S2 (by the face normal at its closest point)
    # and at least about DILATION from it.
    hits = mm.SurfaceIndex(s2.vertices, s2.faces).closest_points(s1.vertices)
    outward = np.einsum("ij,ij->i", s1.vertices - hits.points, s2.face_normals[hits.faces])
    assert (outward < 0).all()
    assert hits.distances.min() > 0.8 * DILATION
    again = lung_pair()
    for mesh, same in zip(pair, again):
        np.testing.assert_array_equal(mesh.vertices, same.vertices)
        np.testing.assert_array_equal(mesh.faces, same.faces)


def test_normal_mapping_folds_at_the_branch_points(pair):
    s1, s2 = pair
    field = mm.map_surfaces(s1, s2, "normal")
    q = mm.quality(field, s1, s2)
    print(f"normal: {q.folds} folds, {int((~field.valid).sum())} misses")
    # The normals of S1 on either side of its concave crotch and saddles cross before they reach S2.
    assert q.folds > 0 or not field.valid.all()
    assert turned_over(field, s1, s2) > 0


def test_auto_gives_no_folds(pair, auto):
    s1, s2 = pair
    q = mm.quality(auto, s1, s2)
    methods = sorted(map(str, set(auto.method)))
    print(f"auto: methods {methods}, folds {q.folds}, QM1 {q.qm1:.4g}, QM2 {q.qm2:.4g}, QM {q.qm:.4g}")
    assert q.folds == 0
    assert auto.valid.all()
    # Normal mapping folds at the branch points only, so "auto" keeps it elsewhere and takes
    # diffusion near them: the vectors run from the vertices of S1, in S1's order, with S1's faces.
    assert methods == ["diffusion", "normal"]
    np.testing.assert_array_equal(auto.starts, s1.vertices)
    np.testing.assert_array_equal(auto.faces, s1.faces)
    kept = auto.method == "normal"
    np.testing.assert_array_equal(auto.ends[kept], mm.map_surfaces(s1, s2, "normal").ends[kept])
    assert kept.mean() > 0.5
    assert distances_to(auto.ends, s2).max() < 1e-6 * diagonal(s2)
    assert turned_over(auto, s1, s2) == 0


def test_reverse_diffusion_gives_no_folds(pair):
    # Mapped from S2's vertices onto S1, then carried onto S1's vertices: S1's order and faces.
    s1, s2 = pair
    field = mm.map_surfaces(s1, s2, "diffusion", reverse=True)
    assert field.valid.all() and set(field.method) == {"reverse_diffusion"}
    np.testing.assert_array_equal(field.starts, s1.vertices)
    np.testing.assert_array_equal(field.faces, s1.faces)
    assert distances_to(field.ends, s2).max() < 1e-6 * diagonal(s2)
    assert mm.quality(field, s1, s2).folds == 0
    assert turned_over(field, s1, s2) == 0


def test_quality_table(pair, auto):
    s1, s2 = pair
    fields = {
        "normal": mm.map_surfaces(s1, s2, "normal"),
        "reverse normal": mm.map_surfaces(s1, s2, "normal", reverse=True),
        "minimal distance": mm.map_surfaces(s1, s2, "minimal_distance"),
        "auto": auto,
    }
    print(f"\nlung pair: S1 {len(s1.faces)} faces, S2 {len(s2.faces)} faces")
    print(f"{'method':18s}{'valid':>8s}{'folds':>7s}{'QM1':>11s}{'QM2':>11s}{'QM':>11s}")
    table = {}
    for name, field in fields.items():
        q = table[name] = mm.quality(field, s1, s2)
        print(f"{name:18s}{field.valid.mean():8.3f}{q.folds:7d}{q.qm1:11.4g}{q.qm2:11.4g}{q.qm:11.4g}")
    assert table["auto"].folds == 0
    for name in ("normal", "reverse normal", "minimal distance"):
        assert table[name].folds > 0 or not fields[name].valid.all(), name


def test_long_buds_auto_turns_no_triangle_over(long_buds):
    # With longer buds the field of "auto" (normal, diffusion near the branch points) is still
    # orientation-preserving on the surfaces: no image triangle is turned over relative to S1 or S2.
    s1, s2, field = long_buds
    assert field.valid.all() and set(field.method) == {"normal", "diffusion"}
    assert turned_over(field, s1, s2) == 0
    assert mm.quality(field, s1, s2).folds == 0


def test_long_buds_reverse_diffusion_carried_onto_s1_folds_none(long_buds):
    s1, s2, _ = long_buds
    field = mm.map_surfaces(s1, s2, "diffusion", reverse=True)
    q = mm.quality(field, s1, s2)
    # The centroid-only count (turned_over) finds 1 triangle here that quality's fold test, which
    # also looks at the faces under the corners, does not count: carrying onto S1 puts a vertex's
    # end where the image of S2's triangles crosses a crease of S2.
    print(f"long buds, reverse diffusion carried onto S1: {q.folds} folds, QM {q.qm:.4g}, "
          f"{turned_over(field, s1, s2)} turned over by the centroid's face alone")
    assert field.valid.all() and len(field) == len(s1.vertices)
    assert q.folds == 0
