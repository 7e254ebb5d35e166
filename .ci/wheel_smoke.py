"""Smoke test of an installed morphomap wheel: 2D and 3D mapping, diffusion included.

Run by .ci/wheel inside the bare Debian root, where only the wheel and its PyPI dependencies are
installed; the test suite needs the source tree and its test extras, this needs neither.
"""

import numpy as np
import trimesh

import morphomap as mm


def check(name, field, c1, c2):
    assert np.isfinite(field.ends).all(), f"{name}: {np.count_nonzero(~np.isfinite(field.ends).all(axis=1))} misses"
    quality = mm.quality(field, c1, c2)
    print(f"{name}: {len(field.ends)} vectors, methods {sorted(map(str, set(field.method)))}, {quality}")
    return quality


c1, c2 = mm.load_example("kidney")
check("2D auto", mm.map_curves(c1, c2), c1, c2)
check("2D diffusion", mm.map_curves(c1, c2, "diffusion"), c1, c2)
check("2D minimal_distance", mm.map_curves(c1, c2, "minimal_distance"), c1, c2)

sphere = trimesh.creation.icosphere(subdivisions=3)
s1 = (sphere.vertices, sphere.faces)
s2 = (sphere.vertices * [1.6, 1.3, 1.1], sphere.faces)
assert check("3D normal", mm.map_surfaces(s1, s2, "normal"), s1, s2).folds == 0
check("3D diffusion", mm.map_surfaces(s1, s2, "diffusion", progress=False), s1, s2)
check("3D auto", mm.map_surfaces(s1, s2), s1, s2)

hits = mm.SurfaceIndex(*s2).closest_points(np.random.default_rng(0).normal(size=(1000, 3)))
assert np.isfinite(hits.points).all()
print("wheel smoke test passed:", mm.build_info())
