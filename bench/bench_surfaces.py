"""3D surface queries: the paper's Figure 11 (normal mapping time vs number of vectors) and
morphomap's Embree kernels side by side with their peers.

    PYTHONPATH=build/dev-NAME/pkg python3 -m pytest bench -k surfaces      (pytest-benchmark)
    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_surfaces.py          (plain tables)
    PYTHONPATH=build/dev-NAME/pkg python3 bench/bench_surfaces.py --quick  (no 1.3M-face mesh)

Target: the ellipsoid with semi-axes 2, 1.5, 1.2 (the paper's Figure 12), meshed as an icosphere
(5120, 81920 and 1310720 faces: subdivisions 4, 6, 8) or as a latitude-longitude mesh (3456 and
3968 faces, the paper's "3'527 and 4'064 mesh-faces"). Lines: origins on the unit sphere, along
the radius (a normal mapping of the sphere), intersected in both directions; every tool returns
the distance to the nearest hit on either side, and is checked against morphomap's answer before
timing. Closest points: queries uniform in the box [-2.5, 2.5]^3. Scenes and trees are built
outside the timed part; times are the best of a few rounds.
"""

from __future__ import annotations

import argparse
import importlib
import time
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import pytest

import morphomap as mm

AXES = np.array([2.0, 1.5, 1.2])
SEED = 20141


def uv_ellipsoid(rings: int, segments: int):
    """Latitude-longitude mesh of the ellipsoid: 2 * segments * (rings - 1) faces, outward."""
    theta = np.pi * np.arange(1, rings) / rings
    phi = 2 * np.pi * np.arange(segments) / segments
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.column_stack(
        [np.sin(t).ravel() * np.cos(p).ravel(), np.sin(t).ravel() * np.sin(p).ravel(), np.cos(t).ravel()]
    )
    v = np.vstack([[0, 0, 1], ring, [0, 0, -1]]) * AXES
    s, south = segments, len(v) - 1
    faces = []
    for j in range(s):
        faces.append([0, 1 + j, 1 + (j + 1) % s])
        faces.append([south, 1 + (rings - 2) * s + (j + 1) % s, 1 + (rings - 2) * s + j])
    for r in range(rings - 2):
        for j in range(s):
            a, b = 1 + r * s + j, 1 + r * s + (j + 1) % s
            faces += [[a, a + s, b], [b, a + s, b + s]]
    return v, np.array(faces, dtype=np.int64)


def icosphere_ellipsoid(subdivisions: int):
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=subdivisions)
    return np.asarray(sphere.vertices) * AXES, np.asarray(sphere.faces, dtype=np.int64)


MESHES: dict[str, Callable[[], tuple[np.ndarray, np.ndarray]]] = {
    "uv3456": lambda: uv_ellipsoid(28, 64),
    "uv3968": lambda: uv_ellipsoid(32, 64),
    "ico5k": lambda: icosphere_ellipsoid(4),
    "ico80k": lambda: icosphere_ellipsoid(6),
    "ico1.3M": lambda: icosphere_ellipsoid(8),
}
_mesh_cache: dict[str, Any] = {}


def mesh(name):
    if name not in _mesh_cache:
        _mesh_cache[name] = MESHES[name]()
    return _mesh_cache[name]


def rays(q: int):
    rng = np.random.default_rng([SEED, q])
    d = rng.normal(size=(q, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    return d.copy(), d  # origins on the unit sphere, radial directions


def queries(q: int):
    return np.random.default_rng([SEED, q, 1]).uniform(-2.5, 2.5, (q, 3))


def nearest(t_forward, t_backward):
    """Distance to the nearest hit on either side from the two ray distances (inf: miss)."""
    return np.minimum(t_forward, t_backward)


# ---- the tools: build(v, f) -> state (not timed); run(state, a, b) -> distances (timed) --------


@dataclass
class Tool:
    name: str
    module: str
    build: Callable
    run: Callable


def _mm_build(v, f):
    return mm.SurfaceIndex(v, f)


def _mm_lines(index, o, d):
    return np.abs(index.line_intersections(o, d).distances)


def _mm_closest(index, p):
    return index.closest_points(p).distances


def _o3d_build(v, f):
    import open3d as o3d

    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(v.astype(np.float32)), o3d.core.Tensor(f.astype(np.uint32)))
    return scene


def _o3d_lines(scene, o, d):
    import open3d as o3d

    forward = np.hstack([o, d]).astype(np.float32)
    backward = np.hstack([o, -d]).astype(np.float32)
    tf = scene.cast_rays(o3d.core.Tensor(forward))["t_hit"].numpy()
    tb = scene.cast_rays(o3d.core.Tensor(backward))["t_hit"].numpy()
    return nearest(tf, tb)


def _o3d_closest(scene, p):
    import open3d as o3d

    found = scene.compute_closest_points(o3d.core.Tensor(p.astype(np.float32)))["points"].numpy()
    return np.linalg.norm(found - p, axis=1)


def _trimesh_build(v, f):
    import trimesh

    return trimesh.Trimesh(v, f, process=False)


def _trimesh_lines(m, o, d):
    out = []
    for sign in (1, -1):
        t = np.full(len(o), np.inf)
        _, rays_hit, locations = m.ray.intersects_id(o, sign * d, multiple_hits=False, return_locations=True)
        t[rays_hit] = np.linalg.norm(locations - o[rays_hit], axis=1)
        out.append(t)
    return nearest(*out)


def _embreex_build(v, f):
    from embreex import rtcore_scene as rtcs
    from embreex.mesh_construction import TriangleMesh

    scene = rtcs.EmbreeScene()
    TriangleMesh(scene, v[f].astype(np.float32))
    return scene


def _embreex_lines(scene, o, d):
    out = []
    o32 = o.astype(np.float32)
    for sign in (1, -1):
        r = scene.run(o32, (sign * d).astype(np.float32), output=1)
        out.append(np.where(r["primID"] >= 0, r["tfar"], np.inf))
    return nearest(*out)


def _igl_closest(state, p):
    import igl

    v, f = state
    d2, _, _ = igl.point_mesh_squared_distance(p, v, f)
    return np.sqrt(d2)


def _pcu_closest(state, p):
    import point_cloud_utils as pcu

    v, f = state
    d, _, _ = pcu.closest_points_on_mesh(p, v, f.astype(np.int32))
    return np.asarray(d)


LINE_TOOLS = (
    Tool("morphomap", "morphomap", _mm_build, _mm_lines),
    Tool("open3d", "open3d", _o3d_build, _o3d_lines),
    Tool("trimesh", "trimesh", _trimesh_build, _trimesh_lines),
    Tool("embreex", "embreex", _embreex_build, _embreex_lines),
)
CLOSEST_TOOLS = (
    Tool("morphomap", "morphomap", _mm_build, _mm_closest),
    Tool("open3d", "open3d", _o3d_build, _o3d_closest),
    Tool("libigl", "igl", lambda v, f: (v, f), _igl_closest),
    Tool(
        "point-cloud-utils",
        "point_cloud_utils",
        lambda v, f: (v, np.ascontiguousarray(f, dtype=np.int32)),
        _pcu_closest,
    ),
)


def available(tool: Tool) -> bool:
    try:
        importlib.import_module(tool.module)
        return True
    except ImportError:
        return False


def check(reference, result, tolerance):
    """Largest difference from morphomap's distances; misses must agree (float peers may graze)."""
    both = np.isfinite(reference) & np.isfinite(result)
    disagree = int((np.isfinite(reference) != np.isfinite(result)).sum())
    worst = float(np.abs(reference[both] - result[both]).max()) if both.any() else 0.0
    if disagree > 1e-4 * len(reference) or worst > tolerance:
        raise AssertionError(f"disagrees with morphomap: {disagree} misses differ, max difference {worst:.2e}")
    return worst


def best_time(fn, *args, rounds=3):
    best = np.inf
    for _ in range(rounds):
        start = time.perf_counter()
        fn(*args)
        best = min(best, time.perf_counter() - start)
    return best


# ---- pytest-benchmark -----------------------------------------------------------------------

PYTEST_MESHES = ("ico5k", "ico80k")
PYTEST_Q = 10**5


@pytest.mark.parametrize("mesh_name", PYTEST_MESHES)
@pytest.mark.parametrize("tool", LINE_TOOLS, ids=lambda t: t.name)
def test_surface_lines(benchmark, tool, mesh_name):
    pytest.importorskip(tool.module)
    v, f = mesh(mesh_name)
    o, d = rays(PYTEST_Q)
    state = tool.build(v, f)
    result = tool.run(state, o, d)
    if tool.name != "morphomap":
        benchmark.extra_info["check"] = check(_mm_lines(mm.SurfaceIndex(v, f), o, d), result, 1e-4)
    benchmark.group = f"surface lines {mesh_name} rays=1e5"
    benchmark.pedantic(tool.run, args=(state, o, d), rounds=3, iterations=1)
    benchmark.extra_info["rays_per_s"] = PYTEST_Q / benchmark.stats.stats.min


@pytest.mark.parametrize("mesh_name", PYTEST_MESHES)
@pytest.mark.parametrize("tool", CLOSEST_TOOLS, ids=lambda t: t.name)
def test_surface_closest(benchmark, tool, mesh_name):
    pytest.importorskip(tool.module)
    v, f = mesh(mesh_name)
    p = queries(PYTEST_Q)
    state = tool.build(v, f)
    result = tool.run(state, p)
    if tool.name != "morphomap":
        benchmark.extra_info["check"] = check(_mm_closest(mm.SurfaceIndex(v, f), p), result, 1e-4)
    benchmark.group = f"surface closest {mesh_name} queries=1e5"
    benchmark.pedantic(tool.run, args=(state, p), rounds=3, iterations=1)


@pytest.mark.parametrize("q", (10**3, 10**4, 10**5, 10**6))
@pytest.mark.parametrize("mesh_name", ("uv3456", "uv3968"))
def test_figure11_normal_mapping(benchmark, mesh_name, q):
    v, f = mesh(mesh_name)
    o, d = rays(q)
    index = mm.SurfaceIndex(v, f)
    benchmark.group = f"figure 11 {mesh_name}"
    benchmark.pedantic(index.line_intersections, args=(o, d), rounds=3, iterations=1)


# ---- script mode ----------------------------------------------------------------------------


def figure11():
    print("Figure 11: normal mapping (line intersections, both directions) vs number of vectors")
    print(f"{'mesh':>8} {'faces':>6} {'rays':>8} {'time s':>9} {'us/ray':>7}")
    for name in ("uv3456", "uv3968"):
        v, f = mesh(name)
        index = mm.SurfaceIndex(v, f)
        for q in (10**3, 10**4, 10**5, 10**6):
            o, d = rays(q)
            t = best_time(index.line_intersections, o, d, rounds=5 if q < 10**6 else 3)
            print(f"{name:>8} {len(f):>6} {q:>8} {t:>9.4f} {1e6 * t / q:>7.3f}")
    v, f = mesh("ico5k")
    sphere = icosphere_ellipsoid(5)[0] / AXES, icosphere_ellipsoid(5)[1]
    t = best_time(mm.map_surfaces, sphere, (v, f), "normal")
    print(f"map_surfaces(normal), sphere of {len(sphere[0])} vertices onto ico5k, end to end: {t:.4f} s")


def peers(kind, tools, mesh_names, q):
    print(f"\n{kind}: {q} queries, throughput in millions per second (ratio = morphomap / peer)")
    header = f"{'mesh':>8} {'faces':>8} " + " ".join(f"{t.name:>18}" for t in tools)
    print(header)
    for name in mesh_names:
        v, f = mesh(name)
        if kind == "lines":
            args = rays(q)
        else:
            args = (queries(q),)
        reference = None
        cells, rates = [], {}
        for tool in tools:
            if not available(tool):
                cells.append(f"{'n/a':>18}")
                continue
            state = tool.build(v, f)
            result = tool.run(state, *args)
            if reference is None:
                reference = result
            else:
                check(reference, result, 1e-4)
            t = best_time(tool.run, state, *args)
            rates[tool.name] = q / t / 1e6
            ratio = "" if tool.name == "morphomap" else f" ({rates['morphomap'] / rates[tool.name]:.2f}x)"
            cells.append(f"{rates[tool.name]:>8.3f}{ratio:>10}")
        print(f"{name:>8} {len(f):>8} " + " ".join(cells))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="leave out the 1.3M-face mesh")
    parser.add_argument("--queries", type=int, default=10**6)
    args = parser.parse_args()
    print(f"morphomap {mm.__version__}, {mm.build_info()['threads']} threads")
    figure11()
    names = ("ico5k", "ico80k") if args.quick else ("ico5k", "ico80k", "ico1.3M")
    peers("lines", LINE_TOOLS, names, args.queries)
    peers("closest points", CLOSEST_TOOLS, names, args.queries // 10)


if __name__ == "__main__":
    main()
