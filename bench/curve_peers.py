"""Inputs, peers and agreement checks shared by bench_curve_queries.py and report.py.

Each tool is described by a ``Tool``: ``build(curve)`` makes its index or scene (not part of the
query timing), ``prepare(state, case)`` converts the queries to the tool's own layout (not timed
either), and ``run(state, prepared)`` is the timed query. ``run`` returns one distance per query
(for lines: the distance from the origin to the nearest hit on either side, ``inf`` for a miss),
so that the results of all tools can be compared.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

CURVE_SIZES = (10**3, 10**4, 10**5)
QUERY_SIZES = (10**4, 10**5, 10**6)
KERNELS = ("closest_points", "line_intersections")
SEED = 20141

# Shapely runs one query at a time on one core; above these sizes one call takes too long.
# Closest points: STRtree.query_nearest is ~O(log n) per query, so only the 10^6 query sets are left
# out. Lines: a long line's envelope covers most of the tree, so each query tests ~all segments.
SHAPELY_MAX_WORK = {"closest_points": 10**5, "line_intersections": 10**4}  # max queries
SHAPELY_MAX_CURVE = {"closest_points": 10**5, "line_intersections": 10**3}


def wobbly_curve(n: int) -> np.ndarray:
    """n points of the non-convex closed curve r = 1 + 0.3 sin 5t + 0.1 cos 11t."""
    t = 2 * np.pi * np.arange(n) / n
    r = 1.0 + 0.3 * np.sin(5 * t) + 0.1 * np.cos(11 * t)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


@dataclass
class Case:
    """One benchmark size: the curve, query points (also the line origins) and unit directions."""

    n: int
    q: int
    curve: np.ndarray
    points: np.ndarray
    directions: np.ndarray
    reach: float  # half-length of a segment that stands in for a whole line (shapely)

    @property
    def label(self) -> str:
        return f"curve=1e{round(np.log10(self.n))} queries=1e{round(np.log10(self.q))}"


def make_case(n: int, q: int) -> Case:
    curve = wobbly_curve(n)
    rng = np.random.default_rng([SEED, n, q])
    lo, hi = curve.min(axis=0), curve.max(axis=0)
    margin = 0.1 * (hi - lo)  # the box enlarged by 20% in each direction
    lo, hi = lo - margin, hi + margin
    points = rng.uniform(lo, hi, size=(q, 2))
    angles = rng.uniform(0.0, 2 * np.pi, size=q)
    directions = np.column_stack([np.cos(angles), np.sin(angles)])
    return Case(n, q, curve, points, directions, reach=2.0 * float(np.linalg.norm(hi - lo)))


def segment_ends(curve: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return curve, np.roll(curve, -1, axis=0)


def edges(n: int) -> np.ndarray:
    i = np.arange(n, dtype=np.int64)
    return np.column_stack([i, (i + 1) % n])


def wall(curve: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The closed polyline extruded over z in [-1, 1]: float32 vertices and two triangles a segment.

    The vertices are shared, so the diagonal that a ray at z = 0 crosses is watertight.
    """
    n = len(curve)
    vertices = np.empty((2 * n, 3), dtype=np.float32)
    vertices[0::2, :2] = curve
    vertices[0::2, 2] = -1.0
    vertices[1::2, :2] = curve
    vertices[1::2, 2] = 1.0
    i = np.arange(n)
    j = (i + 1) % n
    triangles = np.concatenate([
        np.column_stack([2 * i, 2 * j, 2 * i + 1]),
        np.column_stack([2 * j, 2 * j + 1, 2 * i + 1]),
    ]).astype(np.int32)
    return vertices, triangles


def both_ways(case: Case) -> tuple[np.ndarray, np.ndarray]:
    """2M rays at z = 0: each line as a ray along +direction then, in the second half, -direction."""
    origins = np.zeros((2 * case.q, 3), dtype=np.float32)
    origins[:, :2] = np.concatenate([case.points, case.points])
    directions = np.zeros((2 * case.q, 3), dtype=np.float32)
    directions[:, :2] = np.concatenate([case.directions, -case.directions])
    return origins, directions


# ---------------------------------------------------------------- morphomap


def _mm_build(curve):
    import morphomap as mm

    return mm.CurveIndex(curve)


def _mm_closest(index, case):
    return index.closest_points(case.points).distances


def _mm_lines(index, case):
    d = np.abs(index.line_intersections(case.points, case.directions).distances)
    return np.where(np.isnan(d), np.inf, d)


# ---------------------------------------------------------------- libigl


def _igl_build(curve):
    import igl

    vertices = np.column_stack([curve, np.zeros(len(curve))])
    elements = edges(len(curve))  # simplices of size 2: libigl's AABB takes edges directly
    tree = igl.AABB()
    tree.init(vertices, elements)
    return tree, vertices, elements


def _igl_prepare(state, case):
    return np.column_stack([case.points, np.zeros(case.q)])


def _igl_closest(state, points3):
    tree, vertices, elements = state
    squared, _, _ = tree.squared_distance(vertices, elements, points3)
    return np.sqrt(squared)


# ---------------------------------------------------------------- scipy


def _kdtree_build(curve):
    from scipy.spatial import cKDTree

    return cKDTree(curve)


def _kdtree_closest(tree, case):
    return tree.query(case.points, workers=-1)[0]


# ---------------------------------------------------------------- shapely


def _shapely_build(curve):
    import shapely

    a, b = segment_ends(curve)
    segments = shapely.linestrings(np.stack([a, b], axis=1))
    return shapely.STRtree(segments), a, b - a, segments


def _shapely_points(state, case):
    import shapely

    return shapely.points(case.points), case.points


def _shapely_closest(state, prepared):
    """Nearest segment from the tree, then the closest point on it (vectorised, as the output)."""
    tree, a, e, _ = state
    geometries, points = prepared
    (_, segment), distance = tree.query_nearest(geometries, all_matches=False, return_distance=True)
    s = np.einsum("ij,ij->i", points - a[segment], e[segment]) / np.einsum("ij,ij->i", e[segment], e[segment])
    closest = a[segment] + np.clip(s, 0.0, 1.0)[:, None] * e[segment]  # noqa: F841 (equal output)
    return distance


def _shapely_lines_prepare(state, case):
    import shapely

    ends = np.stack([case.points - case.reach * case.directions, case.points + case.reach * case.directions], axis=1)
    return shapely.linestrings(ends), case.points, case.directions


def _shapely_lines(state, prepared):
    """Candidate pairs from STRtree.query(intersects), their intersections, the nearest per line."""
    import shapely

    tree, _, _, segments = state
    lines, origins, directions = prepared
    line, segment = tree.query(lines, predicate="intersects")
    crossings = shapely.intersection(lines[line], segments[segment])
    coords, which = shapely.get_coordinates(crossings, return_index=True)
    owner = line[which]
    t = np.abs(np.einsum("ij,ij->i", coords - origins[owner], directions[owner]))
    nearest = np.full(len(origins), np.inf)
    np.minimum.at(nearest, owner, t)
    return nearest


# ---------------------------------------------------------------- Open3D


def _o3d_build(curve):
    import open3d as o3d

    vertices, triangles = wall(curve)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(vertices), o3d.core.Tensor(triangles.astype(np.uint32)))
    # The BVH is built lazily by the first cast; do it here so it counts as build time.
    scene.cast_rays(o3d.core.Tensor(np.array([[0, 0, 0, 1, 0, 0]], dtype=np.float32)))
    return scene


def _o3d_prepare(scene, case):
    import open3d as o3d

    origins, directions = both_ways(case)
    return o3d.core.Tensor(np.concatenate([origins, directions], axis=1)), case.q


def _o3d_lines(scene, prepared):
    rays, q = prepared
    t = scene.cast_rays(rays)["t_hit"].numpy()
    return np.minimum(t[:q], t[q:])


# ---------------------------------------------------------------- embreex


def _embree_build(curve):
    from embreex import mesh_construction, rtcore_scene

    vertices, triangles = wall(curve)
    scene = rtcore_scene.EmbreeScene()
    mesh = mesh_construction.TriangleMesh(scene, vertices, triangles)
    one = np.zeros((1, 3), dtype=np.float32)
    scene.run(one, one + np.float32([1, 0, 0]))  # commits the scene (builds the BVH)
    return scene, mesh


def _embree_prepare(state, case):
    origins, directions = both_ways(case)
    return origins, directions, case.q


def _embree_lines(state, prepared):
    scene, _ = state
    origins, directions, q = prepared
    hit = scene.run(origins, directions, output=1)
    t = np.where(hit["primID"] >= 0, hit["tfar"], np.inf)
    return np.minimum(t[:q], t[q:])


# ---------------------------------------------------------------- registry


def _as_is(state, case):
    return case


@dataclass(frozen=True)
class Tool:
    name: str
    kernel: str
    module: str  # import name; the tool is skipped when it cannot be imported
    build: Callable[[np.ndarray], Any]
    run: Callable[[Any, Any], np.ndarray]
    prepare: Callable[[Any, Case], Any] = _as_is
    threads: str = "all cores"
    equal_work: bool = True  # False for the nearest-vertex lower bound

    def runs_at(self, n: int, q: int) -> bool:
        if self.name == "shapely":
            return q <= SHAPELY_MAX_WORK[self.kernel] and n <= SHAPELY_MAX_CURVE[self.kernel]
        return True

    def available(self) -> bool:
        try:
            importlib.import_module(self.module)
        except ImportError:
            return False
        return True


TOOLS = (
    Tool("morphomap", "closest_points", "morphomap", _mm_build, _mm_closest),
    Tool("libigl", "closest_points", "igl", _igl_build, _igl_closest, _igl_prepare),
    Tool("shapely", "closest_points", "shapely", _shapely_build, _shapely_closest, _shapely_points, "1 core"),
    Tool("cKDTree-vertex", "closest_points", "scipy.spatial", _kdtree_build, _kdtree_closest,
         equal_work=False),
    Tool("morphomap", "line_intersections", "morphomap", _mm_build, _mm_lines),
    Tool("Open3D", "line_intersections", "open3d", _o3d_build, _o3d_lines, _o3d_prepare),
    Tool("embreex", "line_intersections", "embreex", _embree_build, _embree_lines, _embree_prepare, "1 core"),
    Tool("shapely", "line_intersections", "shapely", _shapely_build, _shapely_lines, _shapely_lines_prepare,
         "1 core"),
)


def tools(kernel: str) -> list[Tool]:
    return [tool for tool in TOOLS if tool.kernel == kernel]


def tool(kernel: str, name: str) -> Tool:
    return next(t for t in TOOLS if t.kernel == kernel and t.name == name)


# ---------------------------------------------------------------- agreement


def check(kernel: str, name: str, reference: np.ndarray, result: np.ndarray) -> str:
    """Assert that ``result`` of tool ``name`` matches morphomap's ``reference``; return a summary.

    closest_points: equal distances to 1e-9 (double precision peers), cKDTree only a bound.
    line_intersections: equal hit distances to 1e-4 relative (float32 peers); a line that grazes
    the curve may hit or miss in float32 alone, so up to 1e-4 of the lines (at least 5) may disagree.
    """
    if kernel == "closest_points":
        if name == "cKDTree-vertex":
            assert np.all(result >= reference - 1e-12), "a vertex is nearer than the nearest curve point"
            return "bound holds"
        error = float(np.max(np.abs(result - reference)))
        assert error <= 1e-9, f"{name}: closest distances differ by up to {error:.3g}"
        return f"max |diff| {error:.1e}"
    both_miss = np.isinf(reference) & np.isinf(result)
    close = np.isclose(result, reference, rtol=1e-4, atol=1e-6) | both_miss
    bad = int(np.count_nonzero(~close))
    assert bad <= max(5, 1e-4 * len(reference)), (
        f"{name}: {bad} of {len(reference)} line hits differ by more than 1e-4 relative"
    )
    finite = np.isfinite(reference) & np.isfinite(result) & close
    error = np.abs(result[finite] - reference[finite])
    return f"max |diff| {np.max(error, initial=0):.1e} where they agree, {bad} of {len(reference)} disagree"
