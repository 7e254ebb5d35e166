"""Regression tests of the real-segmentations issue: frames that touch, coincide or come in pieces."""

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import trimesh
from skimage import measure

import morphomap as mm
from conftest import SHARED_CASES, circle, ellipse, require_cases

CASES = SHARED_CASES


def shared_frames():
    require_cases(CASES / "frame2.csv")
    return mm.read_curve(CASES / "frame2.csv"), mm.read_curve(CASES / "frame3.csv")


def distance_to(points, curve):
    return mm.closest_points(points, curve).distances


@pytest.mark.parametrize("method", ["auto", "diffusion"])
@pytest.mark.parametrize("reverse", [False, True])
def test_the_shared_frames_map_without_crossings(method, reverse):
    # A tenth of these two contours did not move: they share pixel stretches (this segfaulted).
    c1, c2 = shared_frames()
    field = mm.map_curves(c1, c2, method, reverse=reverse)
    assert field.valid.all()
    q = mm.quality(field, c1, c2)
    assert q.crossings == 0
    size = np.ptp(c2, axis=0).max()
    assert distance_to(field.ends, c2).max() < 1e-9 * size
    assert distance_to(field.starts, c1).max() < 1e-9 * size
    # The shared stretches are contact: their points stay (the longest vector there is tiny).
    on_stretch = field.method == ("reverse_minimal_distance" if reverse else "minimal_distance")
    assert on_stretch.sum() > 0.05 * len(c1)
    assert np.linalg.norm(field.vectors[on_stretch], axis=1).max() < 0.05 * np.median(
        np.linalg.norm(np.diff(c1, axis=0), axis=1))


def masks_sharing_a_stretch(spacing=(0.7, 1.0)):
    """Two blobs on one pixel grid, the second grown on its right half only, contoured."""
    rows, cols = np.mgrid[0:120, 0:120]
    first = (rows - 60) ** 2 / 30 ** 2 + (cols - 60) ** 2 / 26 ** 2 <= 1
    second = first | (((rows - 60) ** 2 / 34 ** 2 + (cols - 60) ** 2 / 36 ** 2 <= 1) & (cols > 64))
    curves = []
    for mask in (first, second):
        contour = max(measure.find_contours(mask.astype(float), 0.5), key=len)[:-1]
        curves.append(np.column_stack([contour[:, 1] * spacing[1], contour[:, 0] * spacing[0]]))
    return curves


@pytest.mark.parametrize("method", ["auto", "normal", "minimal_distance", "diffusion", "uniform"])
def test_a_shared_stretch_is_split_and_maps_onto_itself(method):
    c1, c2 = masks_sharing_a_stretch()
    field = mm.map_curves(c1, c2, method)
    assert field.valid.all()
    shared = distance_to(c1, c2) == 0.0  # the left half did not move
    assert shared.sum() > 0.3 * len(c1)
    # Every start on the shared stretch maps onto itself.
    rows = np.flatnonzero(distance_to(field.starts, c2) == 0.0)
    np.testing.assert_allclose(field.ends[rows], field.starts[rows], atol=1e-12)
    if method in ("auto", "diffusion", "uniform"):
        assert mm.quality(field, c1, c2).crossings == 0


def test_contact_tolerance_is_checked_and_zero_means_exact_contact():
    c1, c2 = masks_sharing_a_stretch()
    exact = mm.map_curves(c1, c2, "diffusion", contact_tolerance=0.0)
    assert exact.valid.all() and mm.quality(exact, c1, c2).crossings == 0
    with pytest.raises(ValueError, match="contact_tolerance"):
        mm.map_curves(c1, c2, contact_tolerance=-1.0)
    with pytest.raises(ValueError, match="^contact_tolerance: must be finite"):  # the core's rule
        mm.map_curves(c1, c2, contact_tolerance=float("nan"))
    with pytest.raises(TypeError, match="contact_tolerance"):
        mm.map_curves(c1, c2, contact_tolerance="small")


def test_touching_at_one_point_is_a_split():
    # A circle inside another, touching it at (1, 0) from the inside.
    c1 = circle(200, 0.5, centre=(0.5, 0.0))
    c2 = circle(200, 1.0)
    for method in ("auto", "diffusion"):
        field = mm.map_curves(c1, c2, method)
        assert field.valid.all() and mm.quality(field, c1, c2).crossings == 0
        assert distance_to(field.ends, c2).max() < 1e-9
        # Not all onto the touching point (a piece from the point round to itself did that).
        assert len(np.unique(field.ends, axis=0)) == len(field)


def test_resampled_fields_lie_on_the_given_curves():
    c1, c2 = mm.load_example("kidney")
    for reverse in (False, True):
        field = mm.map_curves(c1, c2, n=300, reverse=reverse)
        assert distance_to(field.starts[field.valid], c1).max() < 1e-9
        assert distance_to(field.ends[field.valid], c2).max() < 1e-9
        mm.quality(field, c1, c2)  # accepted


def test_the_cli_writes_a_resampled_field(tmp_path):
    c1, c2 = mm.load_example("kidney")
    mm.write_curve(tmp_path / "c1.csv", c1)
    mm.write_curve(tmp_path / "c2.csv", c2)
    run = subprocess.run([sys.executable, "-m", "morphomap", "map", tmp_path / "c1.csv", tmp_path / "c2.csv",
                          "--n", "250", "-o", tmp_path / "f.csv"], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert len(mm.read_field(tmp_path / "f.csv")) >= 250
    assert "missed" in run.stderr


@pytest.mark.parametrize("method", ["auto", "normal", "minimal_distance", "diffusion", "uniform"])
def test_two_objects_in_one_curve_are_refused_with_the_count(method):
    a = np.vstack([circle(50, 1.0), circle(1, 1.0)])  # a contour repeats its first point
    b = np.vstack([circle(40, 0.3, centre=(3, 0)), circle(1, 0.3, centre=(3, 0))])
    both = np.vstack([a, b])
    with pytest.raises(ValueError, match=r"c1: the points form 2 loops"):
        mm.map_curves(both, circle(80, 2.0), method)
    parts = mm.split_components(both)
    assert [len(p) for p in parts] == [50, 40]
    mm.map_curves(parts[0], circle(80, 2.0), method)


@pytest.mark.parametrize("method", ["auto", "normal", "minimal_distance", "diffusion", "uniform"])
def test_self_intersecting_curves_are_refused_for_every_method(method):
    t = 2 * np.pi * np.arange(200) / 200
    eight = np.column_stack([np.sin(t), np.sin(t) * np.cos(t)])  # encloses zero signed area
    with pytest.raises(ValueError, match=r"c1: the curve intersects itself: 1 pair"):
        mm.map_curves(eight, circle(100, 3.0), method)
    with pytest.raises(ValueError, match=r"c2: the curve intersects itself"):
        mm.map_curves(circle(100, 3.0), eight, method)


def test_misses_keep_their_known_point():
    c1, c2 = circle(200, 0.3, centre=(1.5, 0.0)), circle(200, 3.0)
    field = mm.map_curves(c1, c2, "normal", reverse=True)  # most normals of the big circle miss
    missed = ~field.valid
    assert missed.any()
    assert np.isfinite(field.ends[missed]).all() and np.isnan(field.starts[missed]).all()
    assert f"{missed.sum()} missed" in repr(field)


def icosphere(radius=1.0, centre=(0.0, 0.0, 0.0), subdivisions=3):
    mesh = trimesh.creation.icosphere(subdivisions, radius=radius)
    mesh.apply_translation(centre)
    return mesh


@pytest.mark.parametrize("method", ["normal", "minimal_distance", "diffusion", "auto"])
def test_debris_in_a_surface_is_refused_with_the_count(method):
    organ = trimesh.util.concatenate([icosphere(10.0), icosphere(1.0, (20.0, 0, 0), 1)])
    with pytest.raises(ValueError, match=r"s1: the surface has 2 separate components \(1280, 80 faces\)"):
        mm.map_surfaces(organ, icosphere(12.0), method)
    parts = mm.split_components(organ)
    assert [len(p.faces) for p in parts] == [1280, 80]
    mm.map_surfaces(parts[0], icosphere(12.0), method)


def test_inward_and_unused_vertex_surfaces_are_refused():
    inward = icosphere(1.0)
    inward.invert()
    with pytest.raises(ValueError, match="s1: the faces are oriented inwards"):
        mm.map_surfaces(inward, icosphere(2.0), "normal")
    with pytest.raises(ValueError, match="s2: the faces are oriented inwards"):
        mm.quality(mm.map_surfaces(icosphere(1.0), icosphere(2.0)), icosphere(1.0), inward)
    sphere = icosphere(1.0)
    extra = (np.vstack([sphere.vertices, [[5.0, 5.0, 5.0]]]), sphere.faces)
    with pytest.raises(ValueError, match="s1: vertex 642 .* is used by no face"):
        mm.map_surfaces(extra, icosphere(2.0), "normal")


def voxel_surfaces():
    """Two marching-cubes surfaces on one voxel grid: the second grew a bud on one side only, so
    the far side's faces are shared exactly."""
    z, y, x = np.mgrid[0:40, 0:40, 0:40]
    first = (x - 20) ** 2 + (y - 20) ** 2 + (z - 20) ** 2 <= 11 ** 2
    second = first | ((x - 29) ** 2 + (y - 20) ** 2 + (z - 20) ** 2 <= 6 ** 2)
    meshes = []
    for volume in (first, second):
        vertices, faces, _, _ = measure.marching_cubes(np.pad(volume, 1).astype(float), 0.5,
                                                       spacing=(2.0, 1.0, 1.0))
        mesh = trimesh.Trimesh(vertices[:, ::-1], faces, process=True)
        if mesh.volume < 0:
            mesh.invert()
        meshes.append(mesh)
    return meshes


def test_surfaces_sharing_faces_still_map_with_auto():
    s1, s2 = voxel_surfaces()
    shared = mm.SurfaceIndex(s2.vertices, s2.faces).closest_points(s1.vertices).distances == 0
    assert shared.mean() > 0.3
    field = mm.map_surfaces(s1, s2, "auto")
    assert field.valid.all()
    on_s2 = mm.SurfaceIndex(s2.vertices, s2.faces).closest_points(field.ends).distances
    assert on_s2.max() < 1e-6 * np.ptp(s2.vertices, axis=0).max()


@pytest.mark.parametrize("reverse", [False, True])
def test_surfaces_sharing_faces_map_with_diffusion_and_the_shared_patch_stays(reverse):
    """A bud grown on one side of a voxel ball: the far side's faces are shared exactly. Diffusion
    cuts that patch out: its vertices map onto themselves, the rest follows streamlines."""
    s1, s2 = voxel_surfaces()
    field = mm.map_surfaces(s1, s2, "diffusion", reverse=reverse)
    assert field.valid.all()
    # Either way round, the field is one of S1's vertices (reverse: carried onto them).
    np.testing.assert_array_equal(field.starts, s1.vertices)
    np.testing.assert_array_equal(field.faces, s1.faces)
    shared = mm.SurfaceIndex(s2.vertices, s2.faces).closest_points(s1.vertices).distances == 0
    assert shared.mean() > 0.3
    patch = np.asarray(field.method) == ("reverse_minimal_distance" if reverse else "minimal_distance")
    if reverse:  # a vertex next to the patch's rim may take its nearest corner's label
        assert patch[shared].mean() > 0.95 and not patch[~shared].any()
    else:
        assert np.array_equal(patch, shared)
    assert np.abs(field.ends[shared] - field.starts[shared]).max() < 1e-9
    on_target = mm.SurfaceIndex(s2.vertices, s2.faces).closest_points(field.ends).distances
    assert on_target.max() < 1e-6 * np.ptp(s2.vertices, axis=0).max()
    assert mm.quality(field, s1, s2).folds == 0
    # The bud's tip (S2's farthest point along +x, 36.5) is reached within a voxel; on reverse, it
    # comes from S1's cap under the bud (S1: a ball of radius 11 about x = 21).
    tip = s2.vertices[:, 0].max()
    ends = np.asarray(field.ends)
    assert tip - ends[:, 0].max() < 1.0
    assert np.asarray(field.starts)[np.argmax(ends[:, 0]), 0] > 28.0


def test_bodies_that_only_touch_from_outside_are_refused_by_diffusion():
    """Two boxes sharing a face: the surfaces meet, so they count as crossing until the contact is
    cleared, after which they lie apart; diffusion says so instead of meshing two bodies, and
    "auto", which has no fold-free field of them, says how each way failed."""
    left = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    right = trimesh.creation.box(bounds=[[1, 0, 0], [2, 1, 1]])
    with pytest.raises(ValueError, match="s2: only touches s1 from outside"):
        mm.map_surfaces(left, right, "diffusion")
    with pytest.raises(mm.GeometryError, match=r"no complete, fold-free field from the 8 vertices of s1 .*"
                                               r"normal: 0 vertices unmapped, \d+ triangles folded around"):
        mm.map_surfaces(left, right)


def test_ctrl_c_stops_a_long_mapping_within_a_second(tmp_path):
    if os.name != "posix":
        pytest.skip("signals")
    # Diffusion at 2e5 points per curve: about 7 s meshing, 2 s solving (the one phase that
    # cannot stop early: a sparse factorisation), 5 s tracing.
    c1, c2 = ellipse(200_000, 1.0, 0.6), ellipse(200_000, 2.0, 1.6)
    mm.write_curve(tmp_path / "c1.csv", c1)
    mm.write_curve(tmp_path / "c2.csv", c2)
    (tmp_path / "f.csv").write_text("previous\n")
    process = subprocess.Popen([sys.executable, "-m", "morphomap", "map", tmp_path / "c1.csv", tmp_path / "c2.csv",
                                "--method", "diffusion", "-o", tmp_path / "f.csv"],
                               stderr=subprocess.PIPE, text=True)
    time.sleep(4.0)  # reading the curves takes a second or two; then it is meshing
    assert process.poll() is None, "finished before the interrupt: make the case bigger"
    sent = time.monotonic()
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=30)
    took = time.monotonic() - sent
    assert process.returncode == 130
    assert stderr.strip() == "morphomap: interrupted"
    assert took < 1.5, took
    assert (tmp_path / "f.csv").read_text() == "previous\n"  # the old field is still there


def test_an_interrupted_write_leaves_the_old_file(tmp_path):
    target = tmp_path / "field.csv"
    target.write_text("previous\n")
    field = mm.map_curves(circle(50, 1.0), circle(50, 2.0), "normal")

    class Broken:
        def __iter__(self):
            raise KeyboardInterrupt

    from morphomap.io.atomic import atomic_text
    with pytest.raises(KeyboardInterrupt):
        with atomic_text(target) as handle:
            handle.write("start_x,start_y\n")
            list(Broken())
    assert target.read_text() == "previous\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["field.csv"]
    mm.write_field(target, field)
    assert len(mm.read_field(target)) == 50


@pytest.mark.parametrize("method", ["auto", "normal", "minimal_distance", "diffusion", "uniform"])
def test_curves_that_lie_apart_are_refused(method):
    with pytest.raises(ValueError, match="c2: lies apart from c1"):
        mm.map_curves(circle(100, 1.0), circle(100, 1.0, centre=(5.0, 0.0)), method)


@pytest.mark.parametrize("method", ["normal", "minimal_distance", "diffusion", "auto"])
def test_surfaces_that_lie_apart_are_refused(method):
    with pytest.raises(ValueError, match="s2: lies apart from s1"):
        mm.map_surfaces(icosphere(1.0), icosphere(1.0, (5.0, 0.0, 0.0)), method)


@pytest.mark.parametrize("seed, reverse, mesh_size",
                         [(732004074, False, None), (732004074, True, None), (5060, False, None), (6022, True, None),
                          (827098517, False, 0.5)])
def test_diffusion_repairs_the_triangles_it_folds(seed, reverse, mesh_size):
    """Fuzz seeds whose diffusion fields folded triangles: 732004074 (smoothed marching cubes,
    voxels 2 x 1 x 1) a sliver 0.02 wide, narrower than the tetrahedral mesh's distance to the
    surfaces (0.05); 5060 (a swell pair, unsmoothed) a triangle across a crease of S2; 6022
    (reverse) one next to a lost streamline; 827098517 (a swell pair, unsmoothed) a triangle
    whose image lay across a right-angled edge of S2, where no tangent plane holds a kernel for
    its corners (at the default mesh size it meshes for a minute; 0.5 folds the same way in 4 s)."""
    import frames

    made = frames.pair(3, seed, None)
    field = mm.map_surfaces(made.s1, made.s2, method="diffusion", reverse=reverse, mesh_size=mesh_size)
    valid = np.asarray(field.valid)
    assert valid.mean() > 0.99
    assert mm.quality(field, made.s1, made.s2).folds == 0
    # The repaired ends still lie on S2 (the starts, on reverse).
    on = np.asarray(field.starts if reverse else field.ends)[valid]
    vertices, faces = made.arrays(made.s1 if reverse else made.s2)
    distance = mm.SurfaceIndex(vertices, faces).closest_points(on).distances
    assert distance.max() < 1e-9 * np.ptp(vertices, axis=0).max()


@pytest.mark.parametrize("seed", [5002, 5022])
def test_surfaces_touching_over_a_patch_map_with_diffusion(seed):
    """Fuzz seeds whose frames are the same mask outside a growing cap (one unsmoothed, one
    smoothed): the surfaces share or nearly share faces there. Diffusion crashed inside Mesh_3
    (5022) or spent minutes (a sibling pair took 218 s), later refused them; now the patch is cut
    out (its vertices map to their closest point) and the rest of the region is meshed."""
    import frames

    made = frames.pair(3, seed, None)
    (v1, f1), (v2, f2) = made.arrays(made.s1), made.arrays(made.s2)
    for reverse in (False, True):
        field = mm.map_surfaces(made.s1, made.s2, method="diffusion", reverse=reverse)
        assert np.asarray(field.valid).mean() > 0.99
        assert mm.quality(field, made.s1, made.s2).folds == 0
        valid = np.asarray(field.valid)
        on_s2 = mm.SurfaceIndex(v2, f2).closest_points(np.asarray(field.ends)[valid]).distances
        on_s1 = mm.SurfaceIndex(v1, f1).closest_points(np.asarray(field.starts)[valid]).distances
        assert max(on_s2.max(), on_s1.max()) < 1e-9 * np.ptp(v2, axis=0).max()
        assert any("minimal_distance" in name for name in set(np.asarray(field.method).tolist()))
    assert np.all(mm.map_surfaces(made.s1, made.s2, method="auto").valid)


def test_auto_on_segmented_lung_stacks_diffuses_near_the_branch_points_only():
    """The lung-like pair as voxel stacks (2 x 1 x 1 um), contoured and smoothed as a lab would:
    normal mapping folds about 70 triangles at the branch points, and "auto" redoes only the
    vertices near them with diffusion (about a quarter of S1), keeping the normal field elsewhere."""
    from morphomap.synthetic.masks import lung_stacks

    stack1, stack2, spacing = lung_stacks((2.0, 1.0, 1.0))
    s1 = mm.surface_from_mask(stack1, spacing, smooth=1.0)
    s2 = mm.surface_from_mask(stack2, spacing, smooth=1.0)
    normal = mm.map_surfaces(s1, s2, "normal")
    assert mm.quality(normal, s1, s2).folds > 0
    field = mm.map_surfaces(s1, s2, "auto")
    assert set(field.method) == {"normal", "diffusion"}
    np.testing.assert_array_equal(field.starts, s1.vertices)
    np.testing.assert_array_equal(field.faces, s1.faces)
    assert field.valid.all() and mm.quality(field, s1, s2).folds == 0
    kept = field.method == "normal"
    assert kept.mean() > 0.5
    np.testing.assert_array_equal(field.ends[kept], normal.ends[kept])
    assert mm.SurfaceIndex(s2.vertices, s2.faces).closest_points(field.ends).distances.max() < 1e-9
