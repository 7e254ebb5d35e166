"""Diffusion mapping in 3D against shapes with a known answer.

Between concentric spheres of radii 1 and 4 the potential is (1/r - 1/4) / (1 - 1/4) and the
streamlines are radial; a sphere inside an ellipsoid must map without losses or folds; between
crossing surfaces each piece of the symmetric difference maps its part of S1 onto its part of S2,
and the map back is the inverse.
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


def radial_default(inner, radius):
    """Diffusion at the default settings from `inner` onto the same triangulation scaled to `radius`:
    the solution (every streamline must arrive) and its RMS end error (angular_rms)."""
    outer = (inner[0] * radius, inner[1])
    solution = mm.solve_diffusion_3d(inner, outer)
    assert np.isfinite(solution.ends).all()
    return solution, angular_rms(inner[0], solution.ends, radius)


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
    field = mm.DisplacementField(inner[0], solution.ends, np.full(len(inner[0]), "diffusion"), faces=inner[1])
    assert mm.quality(field, inner, spheres[1]).folds == 0


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
    # Near S1 the default mesh is already graded from 2% of S1's diagonal, so a mesh_size of 0.35
    # changes nothing (149k tetrahedra either way): 0.2 refines (216k; RMS 9.2e-3 -> 7.6e-3).
    coarse = mm.solve_diffusion_3d(inner, outer, mesh_size=1.0)
    fine = mm.solve_diffusion_3d(inner, outer, mesh_size=0.2)
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


CROSSING_AXES, CROSSING_CENTRE = np.array([1.3, 1.0, 1.0]), np.array([0.6, 0.05, 0.03])


def crossing_pair():
    """The unit sphere and an ellipsoid through it: the symmetric difference has two pieces."""
    v, f = sphere(1.0)
    return (v, f), (v * CROSSING_AXES + CROSSING_CENTRE, f)


@pytest.fixture(scope="module")
def crossing():
    s1, s2 = crossing_pair()
    return s1, s2, mm.map_surfaces(s1, s2, "diffusion"), mm.map_surfaces(s2, s1, "diffusion")


def ellipsoid_radius(points):
    return np.linalg.norm((points - CROSSING_CENTRE) / CROSSING_AXES, axis=1)


def test_crossing_surfaces_each_piece_maps_across(crossing):
    s1, s2, field, _ = crossing
    ends = field.ends
    assert np.isfinite(ends).all()
    # On S2 (an inscribed polyhedron of the ellipsoid: its faces sag inside by about 1e-3).
    radius = ellipsoid_radius(ends)
    assert radius.max() <= 1 + 1e-12 and radius.min() > 1 - 0.002
    # A start outside S2 bounds the piece S1 \ S2, whose other side is the part of S2 inside S1:
    # its end lies inside S1, and the other way round (up to the mesh near the crossing curve).
    outside = ellipsoid_radius(s1[0]) > 1
    r = np.linalg.norm(ends, axis=1)
    assert outside.sum() > 1000 and (~outside).sum() > 500
    assert (r[outside] < 1 + 0.005).all() and (r[~outside] > 1 - 0.005).all()
    # The crossing curve lies on both surfaces: a start next to it moves hardly further than its
    # distance to S2 (by at most about the mesh size there).
    distance = np.linalg.norm(mm.SurfaceIndex(*s2).closest_points(s1[0]).points - s1[0], axis=1)
    near = distance < 0.02
    assert near.sum() > 20
    assert (np.linalg.norm(ends - s1[0], axis=1) - distance)[near].max() < 0.01
    assert mm.quality(field, s1, s2).folds == 0


def test_crossing_surfaces_reverse_is_inverse(crossing):
    # c' = 1 - c: the streamlines from S2 to S1 are those from S1 to S2 run backwards, so the map
    # S2 -> S1, interpolated on S2's triangles at the images of S1's vertices, gives them back.
    s1, s2, forward, backward = crossing
    hits = mm.SurfaceIndex(*s2).closest_points(forward.ends)
    corners = s2[0][s2[1][hits.faces]]
    images = backward.ends[s2[1][hits.faces]]
    e1, e2, d = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0], hits.points - corners[:, 0]
    gram = np.stack([np.einsum("ij,ij->i", e1, e1), np.einsum("ij,ij->i", e1, e2), np.einsum("ij,ij->i", e2, e2)], 1)
    rhs1, rhs2 = np.einsum("ij,ij->i", d, e1), np.einsum("ij,ij->i", d, e2)
    det = gram[:, 0] * gram[:, 2] - gram[:, 1] ** 2
    w1 = (gram[:, 2] * rhs1 - gram[:, 1] * rhs2) / det
    w2 = (gram[:, 0] * rhs2 - gram[:, 1] * rhs1) / det
    back = (1 - w1 - w2)[:, None] * images[:, 0] + w1[:, None] * images[:, 1] + w2[:, None] * images[:, 2]
    error = np.linalg.norm(back - s1[0], axis=1)
    mean_displacement = np.linalg.norm(forward.ends - s1[0], axis=1).mean()
    assert mean_displacement > 0.2
    # Exits interpolated from the mesh's corners: RMS 2.26e-3, max 9.2e-3 (one streamline per
    # vertex gave 2.51e-3 and 1.41e-2; bench/README.md, "Exits interpolated from the mesh's source
    # corners").
    assert np.sqrt(np.mean(error**2)) < 0.005 and error.max() < 0.012


def test_crossing_surfaces_bad_input():
    cube = trimesh.creation.box((1.0, 1.0, 1.0))
    shifted = trimesh.creation.box((1.0, 1.0, 1.0))
    shifted.apply_translation((0.5, 0.0, 0.0))
    with pytest.raises(ValueError, match="coincides with s1"):
        mm.solve_diffusion_3d(cube, shifted)  # their top, bottom, front and back faces overlap
    s1, s2 = crossing_pair()
    poked = s1[0].copy()
    poked[0] = -1.8 * poked[0]  # a spike through the sphere's far side and out of S2
    with pytest.raises(ValueError, match="s1: intersects itself"):
        mm.solve_diffusion_3d((poked, s1[1]), s2)
    with pytest.raises(ValueError, match="s2: intersects itself"):
        mm.solve_diffusion_3d(s2, (poked, s1[1]))


def test_bad_input():
    s1, s2 = sphere(1.0, 2), sphere(3.0, 2)
    apart = (s1[0] + [5.0, 0, 0], s1[1])
    with pytest.raises(ValueError, match="lie apart"):
        mm.solve_diffusion_3d(s1, apart)
    with pytest.raises(ValueError, match="s2"):
        mm.solve_diffusion_3d(s1, (s2[0], s2[1][:-1]))  # open
    with pytest.raises(ValueError, match="mesh_size"):
        mm.solve_diffusion_3d(s1, s2, mesh_size=-1)
    with pytest.raises(TypeError, match="mesh_size"):
        mm.solve_diffusion_3d(s1, s2, mesh_size="fine")
    with pytest.raises(TypeError, match="s1"):
        mm.solve_diffusion_3d("sphere", s2)
    with pytest.raises(TypeError, match="repeatable"):
        mm.solve_diffusion_3d(s1, s2, repeatable="no")
    with pytest.raises(TypeError, match="repeatable"):
        mm.map_surfaces(s1, s2, "diffusion", repeatable=None)
    bad = s1[0].copy()
    bad[0, 0] = np.nan
    with pytest.raises(ValueError, match="s1"):
        mm.solve_diffusion_3d((bad, s1[1]), s2)


def test_a_surface_enclosing_no_volume_is_named_whichever_way_diffusion_runs():
    # A closed tetrahedron 1e-13 high passes the closed-surface checks but leaves no region to mesh.
    flat = (np.array([[-2.0, -2, 0], [3, -2, 0], [-2, 3, 0], [0, 0, 1e-13]]),
            np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]))
    ball = sphere(1.0, 2)
    for reverse in (False, True):
        with pytest.raises(ValueError, match="^s2: encloses no volume"):
            mm.map_surfaces(ball, flat, "diffusion", reverse=reverse)
        with pytest.raises(ValueError, match="^s1: encloses no volume"):
            mm.map_surfaces(flat, ball, "diffusion", reverse=reverse)
    with pytest.raises(ValueError, match="^s1: encloses no volume"):
        mm.solve_diffusion_3d(flat, ball)
    # No diffusion to fall back on, and normal mapping and minimal distance fold: "auto" takes the
    # flat body's 4 vertices mapped onto the ball and carried onto the ball's vertices, which
    # folds nothing.
    field = mm.map_surfaces(ball, flat)
    assert field.valid.all() and set(field.method) == {"reverse_minimal_distance"}
    assert mm.quality(field, ball, flat).folds == 0


def test_a_coarse_inner_sphere_is_as_accurate_by_default():
    # 642 vertices (icosphere 3) inside and out: the mesh near S1 is sized from S1's extent, not
    # from its coarse triangles (at their size the RMS end error was 0.018).
    _, rms = radial_default(sphere(1.0, 3), 4.0)
    assert rms < 0.01


def test_finely_triangulated_spheres_mesh_to_their_shape_not_to_their_triangles():
    # 10242 vertices each (mean edges 0.038 and 0.15): the mesh near each surface stops at 1.5% of
    # its diagonal (0.052 and 0.21). At 1% it had 408k tetrahedra and an RMS end error of 4.9e-3;
    # now 228k and 5.9e-3, below the 2562-vertex default row's 7.9e-3 (bench/README.md, "The finest
    # element size").
    solution, rms = radial_default(sphere(1.0, 5), 4.0)
    assert len(solution.tetrahedra) < 300_000, len(solution.tetrahedra)
    assert rms < 7.0e-3


def test_exits_interpolated_from_the_mesh_corners_beat_a_streamline_per_vertex():
    # 10242 vertices on S1, about 3.3k corners on the mesh's source boundary: by default each
    # vertex's exit is interpolated from the corners' streamlines (measured RMS 5.02e-3); with
    # streamlines=True each vertex is traced itself (5.90e-3, bench/README.md, "Exits interpolated
    # from the mesh's source corners").
    inner = sphere(1.0, 5)
    outer = (inner[0] * 4.0, inner[1])
    interpolated = mm.solve_diffusion_3d(inner, outer)
    traced = mm.solve_diffusion_3d(inner, outer, streamlines=True)
    assert np.isfinite(interpolated.ends).all() and np.isfinite(traced.ends).all()
    rms_interpolated = angular_rms(inner[0], interpolated.ends, 4.0)
    rms_traced = angular_rms(inner[0], traced.ends, 4.0)
    assert rms_interpolated < 5.5e-3
    assert rms_interpolated < 0.95 * rms_traced, (rms_interpolated, rms_traced)
    # The same mesh and field: the two differ by the traced starts' scatter only (max 8.2e-3).
    assert np.linalg.norm(interpolated.ends - traced.ends, axis=1).max() < 0.015


def test_a_thin_shell_meshes_to_its_surfaces_spacing_not_to_a_quarter_of_its_gap():
    # Spheres of radii 1 and 1.1 with 642 vertices (mean edge 0.15-0.17, mean gap 0.1): a quarter
    # of the gap is six times finer than the triangles and gave ~380k tetrahedra; the default is
    # now half the gap (two elements across), and the streamlines stay radial to 1% of the gap.
    inner = sphere(1.0, 3)
    solution, rms = radial_default(inner, 1.1)
    assert len(solution.tetrahedra) < 100_000, len(solution.tetrahedra)
    assert rms < 1e-3
    field = mm.DisplacementField(inner[0], solution.ends, np.full(len(inner[0]), "diffusion"), faces=inner[1])
    assert mm.quality(field, inner, sphere(1.1, 3)).folds == 0


_REPEAT_SCRIPT = """
import hashlib, os, sys
import numpy as np, trimesh
if sys.argv[1] == "one":
    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})  # TBB then runs one thread
import morphomap as mm
a, b = trimesh.creation.icosphere(2), trimesh.creation.icosphere(2)
s1 = (np.array(a.vertices), np.array(a.faces))
s2 = (np.array(b.vertices) * [2.0, 1.5, 1.2] + [0.1, 0.0, 0.0], np.array(b.faces))
for _ in range(2 if sys.argv[1] == "all" else 1):  # twice in one process, once in the other
    solved = mm.solve_diffusion_3d(s1, s2)
    digest = hashlib.sha256()
    for array in (solved.vertices, solved.tetrahedra, solved.potential, solved.ends):
        digest.update(np.ascontiguousarray(array).tobytes())
    print(len(solved.tetrahedra), digest.hexdigest())
"""


@pytest.mark.skipif(not hasattr(__import__("os"), "sched_setaffinity"), reason="needs sched_setaffinity")
def test_same_input_same_mesh_and_field_in_other_processes_and_thread_counts():
    # Mesh_3 used to stop exudation after a wall-clock time, so that the mesh (and the ends, by up
    # to 4e-3) changed with the machine's load from call to call.
    import subprocess
    import sys

    runs = [subprocess.run([sys.executable, "-c", _REPEAT_SCRIPT, threads], capture_output=True, text=True, check=True)
            for threads in ("all", "one")]
    lines = [line for run in runs for line in run.stdout.split()]
    assert len(lines) == 6 and int(lines[0]) > 1000
    assert len(set(lines[1::2])) == 1, lines


_THREADS_SCRIPT = """
import hashlib, sys, threading
import numpy as np, scipy.linalg, trimesh  # SciPy's OpenBLAS brings a fork handler of its own
import morphomap as mm
repeatable = sys.argv[1] == "repeatable"
a = trimesh.creation.icosphere(2 if repeatable else 3)
s1 = (np.array(a.vertices), np.array(a.faces))
s2 = (np.array(a.vertices) * [2.0, 1.5, 1.2], np.array(a.faces))
digests, lost = [], []
def diffusion():
    for _ in range(4 if repeatable else 3):
        ends = mm.solve_diffusion_3d(s1, s2, mesh_size=0.5 if repeatable else None, repeatable=repeatable).ends
        digests.append(hashlib.sha256(ends.tobytes()).hexdigest())
        lost.append(int((~np.isfinite(ends)).sum()))
def normals():  # TBB and Embree work in this process while the meshers fork
    for _ in range(40):
        mm.map_surfaces(s1, s2, "normal")
threads = [threading.Thread(target=f) for f in ([diffusion] * 3 if repeatable else [diffusion, diffusion, normals])]
for t in threads: t.start()
for t in threads: t.join()
print(len(digests), len(set(digests)), sum(lost))
"""


def run_threads_script(mode):
    """(diffusions, distinct fields, lost points) of _THREADS_SCRIPT in a child process."""
    import subprocess
    import sys

    run = subprocess.run([sys.executable, "-c", _THREADS_SCRIPT, mode], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    return [int(word) for word in run.stdout.split()]


def test_threads_meshing_at_once_neither_hang_nor_differ():
    # Each mesh is made in a forked child. Two threads forking at once ran OpenBLAS's fork handler
    # twice at once, and it joined one of its threads twice: the process hung (about one run in two).
    assert run_threads_script("repeatable") == [12, 1, 0]


def test_meshing_on_all_cores_is_as_accurate():
    # repeatable=False: Mesh_3's parallel mode, in a child with TBB workers of its own; the mesh
    # follows the threads, the accuracy bounds are those of the repeatable mesh above.
    inner, outer = sphere(1.0), sphere(4.0)
    solution = mm.solve_diffusion_3d(inner, outer, repeatable=False)
    assert np.isfinite(solution.ends).all()
    assert angular_rms(inner[0], solution.ends, 4.0) < 0.01
    r = np.linalg.norm(solution.vertices, axis=1)
    assert np.abs(solution.potential - np.clip((1 / r - 0.25) / 0.75, 0, 1)).max() < 0.01
    field = mm.DisplacementField(inner[0], solution.ends, np.full(len(inner[0]), "diffusion"), faces=inner[1])
    assert mm.quality(field, inner, outer).folds == 0
    ellipsoid = sphere(axes=(2.0, 1.5, 1.2), subdivisions=3)
    mapped = mm.map_surfaces(sphere(1.0, 3), ellipsoid, "diffusion", repeatable=False)
    assert mapped.valid.all() and mm.quality(mapped, sphere(1.0, 3), ellipsoid).folds == 0


def test_meshing_on_all_cores_beside_other_threads_neither_hangs_nor_loses_points():
    # Each fork stops this process's TBB workers first; a thread that enters TBB between that and
    # the fork could leave the child waiting on a lock: it is then replaced by a one-thread child.
    diffusions, _, lost = run_threads_script("all-cores")
    assert (diffusions, lost) == (6, 0)


def test_progress_reports_the_stages(capsys):
    s1, s2 = sphere(1.0, 2), sphere(axes=(2.0, 1.5, 1.2), subdivisions=2)
    quiet = mm.solve_diffusion_3d(s1, s2, progress=False)
    assert capsys.readouterr().err == ""
    shown = mm.solve_diffusion_3d(s1, s2, progress=True)
    err = capsys.readouterr().err
    assert "solve_diffusion_3d" in err and "3/3" in err and "trace" in err, err
    np.testing.assert_array_equal(shown.ends, quiet.ends)  # the report changes nothing
    with pytest.raises(TypeError, match="progress"):
        mm.solve_diffusion_3d(s1, s2, progress="yes")
