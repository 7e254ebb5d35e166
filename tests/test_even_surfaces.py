"""3D method="optimal": ends moved along S2 to even out the area ratios, never folding."""

import numpy as np
import pytest
import trimesh

import morphomap as mm
from morphomap.synthetic.lung import lung_pair
from conftest import SHARED_CASES, require_cases


def _off_s2(field, s2):
    index = mm.SurfaceIndex(np.asarray(s2.vertices), np.asarray(s2.faces))
    return index.closest_points(field.ends).distances.max() / np.linalg.norm(s2.extents)


def test_concentric_spheres_keep_the_radial_map():
    s1 = trimesh.creation.icosphere(3)
    s2 = s1.copy().apply_scale(2.0)
    field = mm.map_surfaces(s1, s2, "optimal")
    rms = np.sqrt(np.mean(np.sum((field.ends - 2.0 * s1.vertices) ** 2, axis=1)))
    assert rms < 1e-5  # the energy's minimum, returned as the normal map gives it
    assert set(field.method) == {"optimal"}


def test_sphere_onto_ellipsoid_is_evener_than_auto():
    # The paper's Figure 12 pair: a sphere onto an ellipsoid around it.
    s1 = trimesh.creation.icosphere(3)
    s2 = s1.copy()
    s2.vertices = s2.vertices * [1.6, 1.2, 1.1]
    auto, even = (mm.map_surfaces(s1, s2, m) for m in ("auto", "optimal"))
    qa, qe = mm.quality(auto, s1, s2), mm.quality(even, s1, s2)
    assert qe.folds == 0 and even.valid.all() and _off_s2(even, s2) < 1e-9
    assert qe.qm <= 0.5 * qa.qm and qe.qm1 < 0.01 * qa.qm1


def test_lung_pair_lower_qm_without_folds():
    s1, s2 = lung_pair(resolution=15.0)
    auto, even = (mm.map_surfaces(s1, s2, m) for m in ("auto", "optimal"))
    qa, qe = mm.quality(auto, s1, s2), mm.quality(even, s1, s2)
    assert qe.folds == 0 and even.valid.all() and len(even) == len(s1.vertices)
    assert _off_s2(even, s2) < 1e-9
    # LDDMM with a varifold loss reaches 0.087 on this pair in minutes (issue "even 3D"); measured
    # here 5.87 -> 0.001.
    assert qe.qm <= 0.087 and qe.qm < 0.5 * qa.qm


def test_best_in_3d_tries_optimal():
    s1 = trimesh.creation.icosphere(2)
    s2 = s1.copy()
    s2.vertices = s2.vertices * [1.5, 1.0, 0.8]
    field = mm.map_surfaces(s1, s2, "best")
    names = [c.name for c in field.candidates]
    assert names.count("optimal") == 1 and "reverse_optimal" not in names
    assert mm.quality(field, s1, s2).qm <= [c.qm for c in field.candidates if c.name == "optimal"][0]


# The stages remeshed (edges of 30 units) and as given (coarse, flat caps of long thin triangles;
# 270 and 290 h cross near the flank). 290 -> 250 h is left out: the default raises there (no
# method maps it fold-free, bench/README "Real 3D stages") and "optimal" starts from its field.
@pytest.mark.parametrize("pair,edge", [(("250", "270"), 30.0), (("270", "290"), 30.0), (("290", "270"), 30.0),
                                       (("250", "270"), None), (("270", "250"), None), (("270", "290"), None),
                                       (("290", "270"), None), (("250", "290"), None)])
def test_limb_stages_halve_auto_qm_fold_free_on_s2(pair, edge):
    folder = SHARED_CASES / "limb-bud" / "3d"
    require_cases(folder)
    s1, s2 = (mm.read_surface(folder / f"limb_{h}h_closed.ply") for h in pair)
    if edge is not None:
        s1, s2 = (mm.remesh_surface(s, edge) for s in (s1, s2))
    auto = mm.map_surfaces(s1, s2)
    even = mm.map_surfaces(s1, s2, "optimal")
    qa, qe = mm.quality(auto, s1, s2), mm.quality(even, s1, s2)
    assert qe.folds == 0 and even.valid.all() and len(even) == len(s1.vertices) and _off_s2(even, s2) < 1e-9
    assert qe.qm <= 0.5 * qa.qm  # the target; measured 28x-6,000x lower (bench/README)
