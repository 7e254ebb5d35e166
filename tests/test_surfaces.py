"""Surface mapping in 3D: the paper's methods on spheres and ellipsoids against closed forms, the
quality measures and folds, "auto", and what every surface entry does with bad input."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import morphomap as mm
from surface_shapes import AXES, ellipsoid, face_areas, icosphere, subdivide_onto_sphere


@pytest.fixture(scope="module")
def sphere():
    return icosphere(4)  # radius 1, 5120 faces


@pytest.fixture(scope="module")
def fine_ellipsoid():
    return ellipsoid(6)  # 81920 faces


def test_surface_normals_of_a_sphere(sphere):
    v, f = sphere
    normals = mm.surface_normals(v, f)
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-15)
    assert np.linalg.norm(normals - v, axis=1).max() < 1e-2  # nearly radial on a regular mesh


def test_normal_mapping_hits_the_analytic_ellipsoid(sphere, fine_ellipsoid):
    v1, f1 = sphere
    v2, f2 = fine_ellipsoid
    field = mm.map_surfaces((v1, f1), (v2, f2), "normal")
    assert field.dim == 3 and len(field) == len(v1) and field.valid.all()
    np.testing.assert_array_equal(field.faces, f1)
    assert set(field.method) == {"normal"}
    # The same lines against the exact ellipsoid x^T D x = 1: the nearer root of the quadratic.
    o, u = v1, mm.surface_normals(v1, f1)
    w = 1 / AXES**2
    qa, qb, qc = (u * u) @ w, 2 * (o * u) @ w, (o * o) @ w - 1
    roots = np.stack([(-qb + s * np.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa) for s in (1, -1)], axis=1)
    t = roots[np.arange(len(o)), np.argmin(np.abs(roots), axis=1)]
    exact = o + t[:, None] * u
    error = np.linalg.norm(field.ends - exact, axis=1)
    # Bound: every vertex lies on the ellipsoid, so a triangle of circumradius R deviates from it by
    # at most the sagitta kappa R^2 / 2 (to first order; kappa = the largest principal curvature,
    # a / c^2 at the tips of the long axis). Along a line at angle theta to the ellipsoid's normal
    # this distance becomes sagitta / cos(theta). Factor 1.2 for the second-order terms.
    a, b, c = (v2[f2[:, k]] for k in range(3))
    la, lb, lc = (np.linalg.norm(x - y, axis=1) for x, y in ((b, c), (c, a), (a, b)))
    circumradius = (la * lb * lc / (4 * face_areas(v2, f2))).max()
    kappa = AXES.max() / AXES.min() ** 2
    normal = exact * w
    cos = np.abs(np.einsum("ij,ij->i", normal / np.linalg.norm(normal, axis=1)[:, None], u))
    bound = 1.2 * kappa * circumradius**2 / 2 / cos
    assert (error <= bound).all(), (error.max(), bound.min())
    assert error.max() < 2e-3  # 81920 faces: R ~ 0.02 on the long axis


def unreached_fraction(ends, v2, f2):
    """Area fraction of S2 that no end point reaches: faces with no end point on a face of their
    1-ring (the faces sharing a vertex with them)."""
    on = mm.SurfaceIndex(v2, f2).closest_points(ends[np.isfinite(ends).all(axis=1)]).faces
    hit_vertex = np.zeros(len(v2), bool)
    hit_vertex[f2[on].ravel()] = True  # vertices of faces holding an end point
    reached = hit_vertex[f2].any(axis=1)
    areas = face_areas(v2, f2)
    return areas[~reached].sum() / areas.sum()


def test_sphere_onto_ellipsoid_minimal_distance_leaves_regions_unreached(sphere):
    v1, f1 = sphere
    v2, f2 = ellipsoid(4)
    md = mm.map_surfaces((v1, f1), (v2, f2), "minimal_distance")
    normal = mm.map_surfaces((v1, f1), (v2, f2), "normal")
    diffusion = mm.map_surfaces((v1, f1), (v2, f2), "diffusion")
    lost_md = unreached_fraction(md.ends, v2, f2)
    lost_normal = unreached_fraction(normal.ends, v2, f2)
    lost_diffusion = unreached_fraction(diffusion.ends, v2, f2)
    print(f"unreached area: minimal distance {lost_md:.3f}, normal {lost_normal:.4f}, diffusion {lost_diffusion:.4f}")
    assert lost_md > 0.15
    assert lost_normal < 0.01
    assert lost_diffusion < 0.01
    qn = mm.quality(normal, (v1, f1), (v2, f2))
    qmd = mm.quality(md, (v1, f1), (v2, f2))
    assert isinstance(qn, mm.SurfaceQuality)
    assert qn.folds == 0
    assert qn.qm1 < qmd.qm1


def test_minimal_distance_ends_on_the_target(sphere):
    v1, f1 = sphere
    v2, f2 = ellipsoid(3)
    field = mm.map_surfaces((v1, f1), (v2, f2), "minimal_distance")
    hits = mm.SurfaceIndex(v2, f2).closest_points(v1)
    np.testing.assert_array_equal(field.ends, hits.points)


def test_reverse_is_carried_onto_the_vertices_of_s1(sphere):
    v1, f1 = sphere
    v2, f2 = ellipsoid(3)
    field = mm.map_surfaces((v1, f1), (v2, f2), "normal", reverse=True)
    np.testing.assert_array_equal(field.starts, v1)
    np.testing.assert_array_equal(field.faces, f1)
    assert field.valid.all() and set(field.method) == {"reverse_normal"}
    on_s2 = mm.SurfaceIndex(v2, f2).closest_points(field.ends).distances
    assert on_s2.max() < 1e-9
    # Concentric spheres of radius 1 and 2 (one mesh scaled): reverse normal mapping takes 2p to
    # about p, so carried back each vertex p goes to about 2p (the normals are nearly radial; at
    # 5,120 faces the largest miss is 0.0044, the faceting).
    big = mm.map_surfaces((v1, f1), (2 * v1, f1), "normal", reverse=True)
    assert np.abs(big.ends - 2 * v1).max() < 0.008


def test_quality_of_the_identity_and_a_scaling(sphere):
    v, f = sphere
    same = mm.map_surfaces((v, f), (v, f), "minimal_distance")
    q = mm.quality(same, (v, f), (v, f))
    assert q.qm1 == pytest.approx(0.0, abs=1e-24) and q.folds == 0 and np.isnan(q.qm2)
    # Normal mapping onto a concentric sphere of radius 2 scales every triangle by 4 = alpha.
    big = mm.map_surfaces((v, f), (2 * v, f), "normal")
    q = mm.quality(big, (v, f), (2 * v, f))
    # (The vertex normals are not exactly radial, so the images are not exactly 2 p.)
    assert q.qm1 < 1e-3 and q.folds == 0
    # With images exactly 2 p the solid is a frustum of the cone from the centre (planar sides, so
    # the three tetrahedra fill it exactly): V_j = (8 - 1) |det(p0, p1, p2)| / 6.
    exact = mm.quality(mm.DisplacementField(v, 2 * v, "normal", f), (v, f), (2 * v, f))
    volume = 7 * np.abs(np.linalg.det(v[f])) / 6
    assert exact.qm1 == pytest.approx(0.0, abs=1e-24) and exact.folds == 0
    assert exact.qm2 == pytest.approx(np.mean((volume / volume.mean() - 1) ** 2), rel=1e-9)
    assert exact.qm == 0.0


def octasphere(levels):
    """An octahedron subdivided ``levels`` times onto the unit sphere; outward faces. Its equator
    z = 0 runs along edges, so every face lies in one half, and it is symmetric in z exactly."""
    vertices = [np.array(p, float) for p in
                ([1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1])]
    faces = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    return subdivide_onto_sphere(vertices, faces, levels)


def normals_in_space(starts, ends, f):
    """n_j . N_j of the start triangles and their images: negative where an image is merely
    tilted by more than 90 degrees in space (what folds used to count)."""
    n = np.cross(starts[f[:, 1]] - starts[f[:, 0]], starts[f[:, 2]] - starts[f[:, 0]])
    image = np.cross(ends[f[:, 1]] - ends[f[:, 0]], ends[f[:, 2]] - ends[f[:, 0]])
    return np.einsum("ij,ij->i", n, image)


def test_folds_count_every_triangle_of_a_mirror_image(sphere):
    v, f = sphere
    field = mm.map_surfaces((v, f), (v, f), "minimal_distance")
    ends = field.ends * [1, 1, -1]  # a mirror: the map reverses orientation everywhere
    mirrored = mm.DisplacementField(field.starts, ends, field.method, f)
    # The mirrored sphere with its faces reversed, so that they face out again.
    assert mm.quality(mirrored, (v, f), (v * [1, 1, -1], f[:, ::-1])).folds == len(f)


def test_no_folds_under_an_affine_map(sphere):
    # The sphere onto a rotated, translated ellipsoid by the exact affine map: no image is turned
    # over, although many are tilted by more than 90 degrees in space.
    v, f = sphere
    angle, axis = 2.5, np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rotation = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
    a = rotation @ np.diag(AXES)
    ends = v @ a.T + [5.0, -1.0, 2.0]
    field = mm.DisplacementField(v, ends, "normal", f)
    assert (normals_in_space(v, ends, f) < 0).sum() > len(f) // 10
    assert mm.quality(field, (v, f), (ends, f)).folds == 0
    # The same ellipsoid mirrored (faces reversed to face out): every image is turned over.
    mirrored = ends * [-1, 1, 1]
    field = mm.DisplacementField(v, mirrored, "normal", f)
    assert mm.quality(field, (v, f), (mirrored, f[:, ::-1])).folds == len(f)


def test_folds_of_a_hemisphere_folded_down():
    # z -> -|z|: the upper half is mirrored onto the lower, the lower half stays. Exactly the upper
    # faces are turned over, whether or not they tilt by more than 90 degrees in space.
    v, f = octasphere(4)
    ends = v * [1, 1, 1]
    ends[:, 2] = -np.abs(v[:, 2])
    upper = v[f, 2].max(axis=1) > 0
    assert upper.sum() == len(f) // 2
    tilted = normals_in_space(v, ends, f) < 0
    assert 0 < tilted.sum() < upper.sum()
    field = mm.DisplacementField(v, ends, "normal", f)
    assert mm.quality(field, (v, f), (v, f)).folds == upper.sum()
    # A miss is not a fold: NaN at the north pole takes its four faces out of the count.
    pole = int(np.flatnonzero(v[:, 2] == 1)[0])
    ends[pole] = np.nan
    field = mm.DisplacementField(v, ends, "normal", f)
    assert (f == pole).any(axis=1).sum() == 4
    assert mm.quality(field, (v, f), (v, f)).folds == upper.sum() - 4


def test_trimesh_input(sphere):
    trimesh = pytest.importorskip("trimesh")
    s1 = trimesh.creation.icosphere(subdivisions=3)
    s2 = trimesh.Trimesh(*ellipsoid(3))
    field = mm.map_surfaces(s1, s2)
    assert field.valid.all() and len(field) == len(s1.vertices)
    q = mm.quality(field, s1, s2)
    assert q.folds == 0


def test_auto_is_normal_when_it_works(sphere):
    v1, f1 = sphere
    field = mm.map_surfaces((v1, f1), ellipsoid(3), "auto")
    assert set(field.method) == {"normal"}


def test_auto_falls_back_to_reverse_diffusion_where_normals_miss(sphere):
    # Most normals of a big sphere miss a small one off its centre; "auto" then takes reverse
    # diffusion (streamlines from the small sphere's vertices back to the big one), carried onto
    # the big sphere's vertices: one vector each, every one valid, no fold.
    v1, f1 = icosphere(2, radius=3.0)
    v2, f2 = icosphere(2, radius=0.5)
    v2 = v2 + [1.0, 0, 0]
    assert not mm.map_surfaces((v1, f1), (v2, f2), "normal").valid.all()
    field = mm.map_surfaces((v1, f1), (v2, f2))
    assert set(field.method) == {"reverse_diffusion"}
    np.testing.assert_array_equal(field.starts, v1)
    np.testing.assert_array_equal(field.faces, f1)
    assert field.valid.all()
    assert mm.quality(field, (v1, f1), (v2, f2)).folds == 0
    assert mm.SurfaceIndex(v2, f2).closest_points(field.ends).distances.max() < 1e-9


def test_auto_diffuses_only_near_a_new_bud_where_normal_mapping_folds():
    # S1: a sphere with a pit; S2: 1.15 times the sphere with a bud over the pit. The normals of
    # the pit cross (72 folds), elsewhere they are sound: "auto" keeps the normal field there and
    # takes forward diffusion near the pit, from S1's vertices, blended into the normal field
    # across a band a gap wide.
    from scipy.spatial import cKDTree

    trimesh = pytest.importorskip("trimesh")
    u, faces = icosphere(4)
    angle = np.arccos(np.clip(u[:, 2], -1, 1))
    v1 = u * (1 - 0.25 * np.exp(-0.5 * (angle / 0.15) ** 2))[:, None]
    v2 = u * (1.15 + 0.6 * np.exp(-0.5 * (angle / 0.35) ** 2))[:, None]
    s1, s2 = trimesh.Trimesh(v1, faces), trimesh.Trimesh(v2, faces)
    gap = (s2.volume - s1.volume) / (0.5 * (s1.area + s2.area))
    normal = mm.map_surfaces(s1, s2, "normal")
    assert mm.quality(normal, s1, s2).folds > 0
    field = mm.map_surfaces(s1, s2, "auto")
    assert set(field.method) == {"normal", "diffusion"}
    np.testing.assert_array_equal(field.starts, v1)
    np.testing.assert_array_equal(field.faces, faces)
    assert field.valid.all() and mm.quality(field, s1, s2).folds == 0
    assert mm.SurfaceIndex(v2, faces).closest_points(field.ends).distances.max() < 1e-9
    redone = field.method == "diffusion"
    np.testing.assert_array_equal(field.ends[~redone], normal.ends[~redone])
    # Only around the pit (its normals fold within ~20 degrees of the axis), an eighth of S1.
    assert redone.mean() < 0.125 and np.degrees(angle[redone]).max() < 45
    # A gap or more inside the redone part the ends are diffusion's (the mesh coarser away from
    # it): as close to diffusion over the whole region as two meshes of it are to each other.
    inner = redone.copy()
    inner[redone] = cKDTree(v1[~redone]).query(v1[redone])[0] >= gap
    assert inner.sum() > 100
    apart = np.linalg.norm(field.ends[inner] - mm.map_surfaces(s1, s2, "diffusion").ends[inner], axis=1)
    assert np.sqrt(np.mean(apart**2)) < 0.05 * gap and apart.max() < 0.25 * gap


def test_prepared_surfaces_give_the_same_fields_and_quality(sphere):
    s1, s2 = mm.PreparedSurface(sphere, "frame 1"), mm.PreparedSurface(ellipsoid(3), "frame 2")
    for method, reverse in (("normal", False), ("minimal_distance", False), ("auto", False), ("normal", True)):
        plain = mm.map_surfaces(sphere, ellipsoid(3), method, reverse=reverse)
        prepared = mm.map_surfaces(s1, s2, method, reverse=reverse)
        np.testing.assert_array_equal(prepared.starts, plain.starts)
        np.testing.assert_array_equal(prepared.ends, plain.ends)
        np.testing.assert_array_equal(prepared.faces, plain.faces)
        assert list(prepared.method) == list(plain.method)
        assert mm.quality(prepared, s1, s2) == mm.quality(plain, sphere, ellipsoid(3))
    mixed = mm.map_surfaces(s1, ellipsoid(3), "normal")  # one prepared: used as a plain surface
    np.testing.assert_array_equal(mixed.ends, mm.map_surfaces(sphere, ellipsoid(3), "normal").ends)
    v, f = sphere
    with pytest.raises(ValueError, match=r"frames\[3\]: .*closed"):
        mm.PreparedSurface((v, f[:-1]), "frames[3]")


# ---- progress ---------------------------------------------------------------------------------


def test_progress_names_the_stages_and_changes_nothing(capsys):
    v1, f1 = icosphere(2)
    quiet = mm.map_surfaces((v1, f1), ellipsoid(2), "diffusion", progress=False)
    assert capsys.readouterr().err == ""
    shown = mm.map_surfaces((v1, f1), ellipsoid(2), "diffusion", progress=True)
    err = capsys.readouterr().err
    assert "map_surfaces" in err and "3/3" in err and "trace" in err, err
    np.testing.assert_array_equal(shown.ends, quiet.ends)
    # auto: the normal mapping, here all it needs (tests/cpp/test_surfaces.cpp follows a fallback).
    mm.map_surfaces((v1, f1), ellipsoid(2), "auto", progress=True)
    err = capsys.readouterr().err
    assert "map_surfaces" in err and "4/4" in err and "normal" in err, err
    mm.map_surfaces((v1, f1), ellipsoid(2), "auto")  # by default only on a terminal
    assert capsys.readouterr().err == ""
    with pytest.raises(TypeError, match="progress: expected True, False or None"):
        mm.map_surfaces((v1, f1), ellipsoid(2), "diffusion", progress="yes")
    with pytest.raises(ValueError, match="progress: method 'best'"):
        mm.map_surfaces((v1, f1), ellipsoid(2), "best", progress=True)


def test_a_raising_progress_callback_leaves_the_call_cleanly(monkeypatch):
    from morphomap import _core
    from morphomap._progress import StageBar

    v1, f1 = icosphere(2)
    v2, f2 = ellipsoid(2)

    def stop(stage):
        raise RuntimeError(f"stopped at {stage}")

    with pytest.raises(RuntimeError, match="stopped at mesh"):
        _core.map_surfaces(v1, f1, v2, f2, "diffusion", False, 0.0, True, stop)
    closed = []
    monkeypatch.setattr(StageBar, "_on_stage", lambda self, stage: (_ for _ in ()).throw(KeyboardInterrupt()))
    monkeypatch.setattr(StageBar, "close", lambda self: closed.append(self.bar.n))
    with pytest.raises(KeyboardInterrupt):
        mm.map_surfaces((v1, f1), (v2, f2), "diffusion", progress=True)
    assert closed == [0]
    monkeypatch.undo()
    assert mm.map_surfaces((v1, f1), (v2, f2), "diffusion", progress=False).valid.all()


# ---- bad input ------------------------------------------------------------------------------


def test_open_flipped_nan_and_out_of_range(sphere):
    v, f = sphere
    good = (v, f)
    with pytest.raises(ValueError, match=r"^s1: .*not closed"):
        mm.map_surfaces((v, f[:-1]), good)
    flipped = f.copy()
    flipped[5] = flipped[5, ::-1]
    with pytest.raises(ValueError, match=r"^s2: .*same direction"):
        mm.map_surfaces(good, (v, flipped))
    bad = v.copy()
    bad[7, 2] = np.nan
    with pytest.raises(ValueError, match=r"^s1 vertices: row 7"):
        mm.map_surfaces((bad, f), good)
    out = f.copy()
    out[3, 1] = len(v)
    with pytest.raises(ValueError, match=r"^s2 faces: vertex index"):
        mm.map_surfaces(good, (v, out))
    with pytest.raises(ValueError, match=r"^s2 faces: vertex index -1"):
        mm.map_surfaces(good, (v, f - 1))
    zero = v.copy()
    zero[f[0, 1]] = zero[f[0, 0]]
    with pytest.raises(ValueError, match=r"^s1: "):
        mm.map_surfaces((zero, f), good)


@pytest.mark.parametrize("entry", ["map_surfaces", "quality", "solve_diffusion_3d", "PreparedSurface"])
def test_every_surface_entry_names_bad_arrays_alike(sphere, entry):
    # Finite vertices and face indices in range are the core's rules (check_closed_surface), checked
    # once on the way; every entry that takes a closed surface names the array the same way.
    v, f = sphere
    bad = v.copy()
    bad[7, 2] = np.inf
    out = f.copy()
    out[3, 1] = len(v) + 5
    field = mm.map_surfaces((v, f), (1.5 * v, f))
    entries = {
        "map_surfaces": lambda s: mm.map_surfaces((v, f), s),
        "quality": lambda s: mm.quality(field, (v, f), s),
        "solve_diffusion_3d": lambda s: mm.solve_diffusion_3d((v, f), s),
        "PreparedSurface": lambda s: mm.PreparedSurface(s, "s2"),
    }
    call = entries[entry]
    with pytest.raises(ValueError, match=r"^s2 vertices: row 7 has a non-finite coordinate"):
        call((bad, f))
    with pytest.raises(ValueError, match=rf"^s2 faces: vertex index {len(v) + 5} is outside 0\.\.{len(v) - 1}"):
        call((v, out))
    with pytest.raises(ValueError, match=r"^s2 faces: vertex index -1 "):
        call((v, f - 1))


def test_wrong_types_and_shapes(sphere):
    v, f = sphere
    good = (v, f)
    with pytest.raises(TypeError, match="^s1: "):
        mm.map_surfaces(v, good)
    with pytest.raises(TypeError, match="^s2 faces: "):
        mm.map_surfaces(good, (v, f.astype(float)))
    with pytest.raises(ValueError, match=r"^s1 vertices: expected shape \(N, 3\)"):
        mm.map_surfaces((v[:, :2], f), good)
    with pytest.raises(ValueError, match=r"^s1 faces: expected shape \(F, 3\)"):
        mm.map_surfaces((v, f[:, :2]), good)
    with pytest.raises(ValueError, match="^method: "):
        mm.map_surfaces(good, good, "uniform")
    with pytest.raises(TypeError, match="^reverse: "):
        mm.map_surfaces(good, good, reverse=1)
    with pytest.raises(ValueError, match="^directions: row 1 is the zero vector"):
        mm.SurfaceIndex(v, f).line_intersections(np.zeros((2, 3)), np.array([[1.0, 0, 0], [0, 0, 0]]))
    with pytest.raises(ValueError, match="^faces: the surface has no face"):
        mm.SurfaceIndex(v, np.zeros((0, 3), np.int64))
    with pytest.raises(ValueError, match="^queries: "):
        mm.SurfaceIndex(v, f).closest_points(np.full((1, 3), np.inf))
    with pytest.raises(ValueError, match="^field: "):
        mm.quality(mm.DisplacementField(v, v, "normal"), good, good)


finite = st.floats(-1e3, 1e3, allow_nan=False, width=64)
anything = st.floats(allow_nan=True, allow_infinity=True, width=64)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    vertices=hnp.arrays(np.float64, st.tuples(st.integers(0, 12), st.integers(2, 4)), elements=anything),
    faces=hnp.arrays(np.int64, st.tuples(st.integers(0, 12), st.integers(2, 4)), elements=st.integers(-2, 14)),
    queries=hnp.arrays(np.float64, st.tuples(st.integers(0, 5), st.just(3)), elements=finite),
)
def test_random_arrays_never_crash(child, vertices, faces, queries):
    # In a child process: an abort fails this test with its input (and hypothesis shrinks it).
    for call in (
        "mm.map_surfaces((vertices, faces), (vertices, faces))",
        "mm.map_surfaces((vertices, faces), (vertices, faces), 'minimal_distance')",
        "mm.SurfaceIndex(vertices, faces).closest_points(queries)",
        "mm.SurfaceIndex(vertices, faces).line_intersections(queries, queries + 1)",
        "mm.surface_normals(vertices, faces)",
    ):
        child.run(call, "(ValueError, TypeError)", vertices=vertices, faces=faces, queries=queries)


@st.composite
def well_formed_soups(draw):
    """Triangle soups that pass the array checks (shape (N, 3), indices in range), so that the C++
    checks and kernels see them: degenerate, open, non-manifold, inward or tangled."""
    n = draw(st.integers(3, 10))
    vertices = draw(hnp.arrays(np.float64, (n, 3), elements=st.sampled_from([-1.0, 0.0, 0.5, 1.0]) | finite))
    faces = draw(hnp.arrays(np.int64, st.tuples(st.integers(1, 14), st.just(3)), elements=st.integers(0, n - 1)))
    return vertices, faces


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(soup=well_formed_soups(), other=well_formed_soups(),
       queries=hnp.arrays(np.float64, st.tuples(st.integers(1, 5), st.just(3)), elements=finite))
def test_well_formed_soups_reach_the_core_and_never_crash(soup, other, queries):
    for call in (
        lambda: mm.map_surfaces(soup, other),
        lambda: mm.map_surfaces(soup, other, "minimal_distance"),
        lambda: mm.SurfaceIndex(*soup).closest_points(queries),
        lambda: mm.SurfaceIndex(*soup).line_intersections(queries, queries + 1),
        lambda: mm.surface_normals(*soup),
    ):
        try:
            call()
        except (ValueError, mm.GeometryError):
            pass


@pytest.mark.parametrize("method", ["auto", "diffusion"])
def test_a_crossing_ellipsoid_is_mapped_complete_and_fold_free(method):
    # A unit sphere and an ellipsoid (1.4, 0.8, 0.8) cross along two circles: the poles of S1 lie
    # inside S2, its waist outside. Each region between them is mapped on its own; the field is
    # one of S1's vertices with every vertex mapped, ends on S2, no fold, and (diffusion) the
    # poles move outwards along x, the waist inwards.
    v1, f1 = icosphere(3, radius=1.0)
    v2, f2 = icosphere(3, radius=1.0)
    v2 = v2 * [1.4, 0.8, 0.8]
    field = mm.map_surfaces((v1, f1), (v2, f2), method)
    np.testing.assert_array_equal(field.starts, v1)
    assert field.valid.all()
    assert mm.quality(field, (v1, f1), (v2, f2)).folds == 0
    assert mm.SurfaceIndex(v2, f2).closest_points(field.ends).distances.max() < 1e-9
    radial = np.einsum("ij,ij->i", field.vectors, v1)
    poles, waist = np.abs(v1[:, 0]) > 0.95, np.abs(v1[:, 0]) < 0.05
    assert (radial[poles] > 0).all() and (radial[waist] < 0).all()


def flat_cone(radius, n=24, height=0.4):
    """Apex on +z; the base a fan from rim vertex 1, so every corner of a base triangle lies on
    the rim's sharp crease; the side faces first, so that each rim vertex's lowest face (the one a
    closest-point query returns there) is a side face, whose normal leans against the base's."""
    angle = 2 * np.pi * np.arange(n) / n
    rim = np.c_[radius * np.cos(angle), radius * np.sin(angle), np.zeros(n)]
    side = [[0, 1 + k, 1 + (k + 1) % n] for k in range(n)]
    base = [[1, 2 + k, 1 + k] for k in range(1, n - 1)]
    return np.vstack([[0.0, 0.0, height], rim]), np.array(side + base), np.array(base)


def test_a_triangle_lying_on_its_surface_takes_that_surface_s_orientation_at_a_crease():
    # The base of a flat cone shrunk into the inside of a wider cone's flat base: an
    # orientation-preserving map (closed form: a scaling by 1/2 in the plane), so no fold. Asked
    # at their corners alone, the rim's side faces would outvote the base and call all 22 folded.
    v1, f1, base = flat_cone(1.0)
    v2, f2, _ = flat_cone(2.0)
    ends = v1 * [0.5, 0.5, 1.0]
    ends[0] = v2[0]
    field = mm.DisplacementField(v1, ends, "minimal_distance", base)
    assert mm.quality(field, (v1, f1), (v2, f2)).folds == 0
    # Mirrored in the plane (x -> -x), the same triangles are turned over: every one is a fold.
    mirrored = mm.DisplacementField(v1, ends * [-1.0, 1.0, 1.0], "minimal_distance", base)
    assert mm.quality(mirrored, (v1, f1), (v2, f2)).folds == len(base)
