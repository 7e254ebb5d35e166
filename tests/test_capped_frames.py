"""Fuzz frames cut by one plane and capped by long thin triangles (tests/capped_frames.py), as the
real limb stages are, and the default on them."""

import numpy as np
import pytest
import trimesh

import frames
import morphomap as mm


def as_mesh(surface):
    return surface if hasattr(surface, "vertices") else trimesh.Trimesh(*surface, process=False)


@pytest.mark.parametrize("seed", [0, 4, 8])
def test_capped_frames_are_closed_with_caps_of_slivers_in_one_plane(seed):
    made = frames.pair(3, seed, capped=True)
    assert made.info["capped"]
    axis, at = made.info["cut_axis"], made.info["cut_at"]
    for surface in (as_mesh(made.s1), as_mesh(made.s2)):
        assert surface.is_watertight and surface.is_winding_consistent and surface.volume > 0
        on_plane = np.abs(surface.vertices[:, axis] - at) < 1e-3
        cap = on_plane[surface.faces].all(axis=1)
        assert cap.sum() >= 10
        # Ear clipping spans the rim: slivers, as on the real stages (their caps reach 0.06 degrees).
        assert np.degrees(surface.face_angles[cap].min()) < 1.0
    # The uncapped pair is what it was: capping draws from a generator of its own.
    plain, again = frames.pair(3, seed), frames.pair(3, seed)
    np.testing.assert_array_equal(as_mesh(plain.s1).vertices, as_mesh(again.s1).vertices)
    assert plain.info["vertices"] != made.info["vertices"]


# On this capped pair a sliver of S1's cap, its image turned, measured D of -1e14 in the
# untangling's barrier, whose regulariser then rounded to 0: the energy went infinite and a NaN end
# reached an internal query, which raised "queries: row 280 has a non-finite coordinate". Now the
# default answers by its contract: a complete, fold-free field, or GeometryError.
def test_the_default_on_a_capped_pair_whose_sliver_turns():
    made = frames.pair(3, 40, capped=True)
    assert made.info["capped"]
    try:
        field = mm.map_surfaces(made.s1, made.s2, progress=False)
    except mm.GeometryError as error:
        assert "no complete, fold-free field from the" in str(error)
        return
    assert field.valid.all()
    assert mm.quality(field, made.s1, made.s2).folds == 0
