"""Embree queries on triangle surfaces against brute force and closed forms: lines, closest points,
ties at shared vertices and edges, far origins and many threads."""

import threading

import numpy as np
import pytest

import morphomap as mm
from surface_shapes import AXES, ellipsoid


def brute_lines(v, f, origins, directions):
    """Nearest |t| intersection of each whole line with all triangles (Moller-Trumbore, float64),
    and whether a hit on the other side is as near to within 1e-12 (a tie that rounding decides)."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    e1, e2 = b - a, c - a
    out = np.full(len(origins), np.nan)
    tie = np.zeros(len(origins), bool)
    for i, (o, d) in enumerate(zip(origins, directions)):
        u = d / np.linalg.norm(d)
        p = np.cross(u, e2)
        det = np.einsum("ij,ij->i", e1, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = o - a
            bu = np.einsum("ij,ij->i", s, p) / det
            q = np.cross(s, e1)
            bv = q @ u / det
            t = np.einsum("ij,ij->i", e2, q) / det
        # Inclusive by 1e-12: without slack, rounding lets a line through a vertex or an edge slip
        # between the triangles around it (Moller-Trumbore is not watertight).
        ok = (det != 0) & (bu >= -1e-12) & (bv >= -1e-12) & (bu + bv <= 1 + 1e-12)
        if ok.any():
            t = t[ok]
            out[i] = t[np.argmin(np.abs(t))]
            tie[i] = (np.abs(np.abs(t[np.sign(t) != np.sign(out[i])]) - abs(out[i])) < 1e-12).any()
    return out, tie


def brute_closest(v, f, queries):
    """Distance from each query to the nearest triangle: in the face's plane when the projection
    is inside it, else to the nearest edge (float64, all triangles)."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1)[:, None]

    def segment(p, x, y):
        d = y - x
        t = np.clip(np.einsum("ij,ij->i", p - x, d) / np.einsum("ij,ij->i", d, d), 0, 1)
        return np.linalg.norm(p - (x + t[:, None] * d), axis=1)

    out = np.empty(len(queries))
    for i, p in enumerate(queries):
        h = np.einsum("ij,ij->i", p - a, n)
        x = p - h[:, None] * n
        inside = np.ones(len(f), bool)
        for s, t in ((a, b), (b, c), (c, a)):
            inside &= np.einsum("ij,ij->i", np.cross(t - s, x - s), n) >= 0
        d = np.minimum.reduce([segment(p, a, b), segment(p, b, c), segment(p, c, a)])
        out[i] = np.where(inside, np.abs(h), d).min()
    return out


def random_lines(rng, q):
    return rng.uniform(-2.5, 2.5, (q, 3)), rng.normal(size=(q, 3))


def test_line_intersections_equal_brute_force(rng):
    v, f = ellipsoid(5)
    origins, directions = random_lines(rng, 300)
    # Lines through the centre and vertices make ties and edge hits likely.
    origins[:50] = 0.0
    directions[50:100] = v[rng.choice(len(v), 50)] - origins[50:100]
    hits = mm.SurfaceIndex(v, f).line_intersections(origins, directions)
    expected, tie = brute_lines(v, f, origins, directions)
    assert np.array_equal(np.isnan(hits.distances), np.isnan(expected))
    found = ~np.isnan(expected)
    assert found.sum() > 150
    assert tie[:50].all()  # the ellipsoid mesh is symmetric about its centre
    size = np.ptp(v, axis=0).max()
    assert np.abs(np.abs(hits.distances[found]) - np.abs(expected[found])).max() <= 1e-9 * size
    signed = found & ~tie
    assert np.abs(hits.distances[signed] - expected[signed]).max() <= 1e-9 * size
    u = directions / np.linalg.norm(directions, axis=1)[:, None]
    np.testing.assert_allclose(hits.points[found], origins[found] + hits.distances[found, None] * u[found],
                               atol=1e-12 * size)
    assert (hits.faces[found] >= 0).all() and (hits.faces[~found] == -1).all()
    assert np.isnan(hits.points[~found]).all()


def test_closest_points_equal_brute_force(rng):
    v, f = ellipsoid(4)
    queries = rng.uniform(-2.5, 2.5, (300, 3))
    queries[:20] = v[:20]  # on the surface
    hits = mm.SurfaceIndex(v, f).closest_points(queries)
    expected = brute_closest(v, f, queries)
    assert np.abs(hits.distances - expected).max() <= 1e-12
    np.testing.assert_allclose(np.linalg.norm(hits.points - queries, axis=1), hits.distances, atol=1e-14)
    # The point lies on the face reported.
    a, b, c = (v[f[hits.faces, k]] for k in range(3))
    n = np.cross(b - a, c - a)
    assert np.abs(np.einsum("ij,ij->i", hits.points - a, n / np.linalg.norm(n, axis=1)[:, None])).max() < 1e-12


def test_closest_points_on_shared_vertices_take_the_lowest_face(rng):
    # A query on a vertex is at distance 0 from every face around it: the tie goes to the lowest
    # face index, whatever order the faces come in (3D diffusion's start points rely on it).
    v, f = ellipsoid(4)
    for faces in (f, f[rng.permutation(len(f))], f[::-1]):
        hits = mm.SurfaceIndex(v, faces).closest_points(v)
        lowest = np.full(len(v), len(faces))
        for k in range(3):
            np.minimum.at(lowest, faces[:, k], np.arange(len(faces)))
        assert (hits.distances == 0).all()
        np.testing.assert_array_equal(hits.faces, lowest)


def test_queries_release_the_gil(rng):
    v, f = ellipsoid(5)
    index = mm.SurfaceIndex(v, f)
    origins, directions = random_lines(rng, 200_000)
    threads = [threading.Thread(target=index.line_intersections, args=(origins, directions)) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()


def cube():
    """The cube [-1, 1]^3, each square split along a diagonal; outward faces."""
    v = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
    quads = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
    f = [[a, b, c] for a, b, c, d in quads] + [[a, c, d] for a, b, c, d in quads]
    return v, np.array(f, np.int64)


def test_lines_and_queries_from_beyond_float_range_of_a_tiny_surface():
    # Origins 1e102 unit-box lengths away once made Embree's ray invalid (an assertion abort);
    # such lines are tested in double against every face.
    v, f = cube()
    v = v * 1e-100
    index = mm.SurfaceIndex(v, f)
    origins = np.array([[800.0, 0.0, 0.0], [800.0, 0.0, 0.0], [0.0, 0.0, -5.0]])
    directions = np.array([[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    hits = index.line_intersections(origins, directions)
    # The first line meets the squares x = +-1e-100, the third z = +-1e-100 (in double, 800 - 1e-100
    # and 800 + 1e-100 are the same distance, so either square may win the tie); the second passes
    # 800 units beside the cube. The points o + t u round to within |o| eps of 0.
    assert abs(v[f[hits.faces[0]], 0].sum()) == 3e-100 and abs(v[f[hits.faces[2]], 2].sum()) == 3e-100
    assert hits.faces[1] == -1 and np.isnan(hits.points[1]).all()
    assert hits.distances[0] == pytest.approx(800.0, rel=1e-15)
    assert hits.distances[2] == pytest.approx(5.0, rel=1e-15)
    # A closest-point query that far gets a clear error, not Embree's float answer (it was wrong).
    with pytest.raises(ValueError, match="^queries: row 0 lies more than 1e30 times"):
        index.closest_points(origins[:1])
    np.testing.assert_array_equal(index.closest_points([[0.0, 0.0, -3e-100]]).points, [[0.0, 0.0, -1e-100]])


def test_line_origins_beyond_embree_ray_range_do_not_abort(child):
    # A ray whose origin lies beyond Embree's limit (1.844e18 unit-box lengths) fails its
    # ray.valid() assertion, which aborts the process (Debian's Embree keeps assertions): such lines
    # must go to the double test. In a child process, so that an abort fails this test with its input.
    line = "mm.SurfaceIndex(vertices, faces).line_intersections(origins, directions)"
    # Input of test_random_arrays_never_crash's kind: one point (no extent, so no scaling) 1e30 away.
    vertices = np.array([[1e-300, 1e30, 5e-324]])
    faces = np.zeros((6, 3), np.int64)
    origins = np.array([[-490.250303868375, -1.0, 98.34505936273649],
                        [827.8600131485025, 513.4969534877225, 1e-300],
                        [0.0, -52.81608018327927, -183.35326721158856]])
    hits = child.run(line, vertices=vertices, faces=faces, origins=origins, directions=origins + 1)
    np.testing.assert_array_equal(hits.faces, [-1, -1, -1])
    # The cube shrunk to half-widths 1e-20 and 1e-25, lines 1 away: 5e19 and 5e24 unit-box lengths
    # (in double both squares a line crosses are 1 away, so either may win the tie).
    v, f = cube()
    origins = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [1.0, 1.0, 0.0]])
    directions = np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    for size in (1e-20, 1e-25):
        hits = child.run(line, vertices=v * size, faces=f, origins=origins, directions=directions)
        assert (abs(v[f[hits.faces[0]], 0]) == 1.0).all() and (abs(v[f[hits.faces[1]], 2]) == 1.0).all()
        assert hits.faces[2] == -1
        np.testing.assert_allclose(hits.distances[:2], [1.0, 1.0], rtol=1e-15)


def octahedron():
    v = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    f = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    return v, np.array(f, np.int64)


@pytest.mark.parametrize("shape", [cube, octahedron])
@pytest.mark.parametrize("placed", [False, True])
def test_lines_through_vertices_and_edges_all_hit(rng, shape, placed):
    v, f = shape()
    # Vertices, edge midpoints and points a third of the way along every edge (diagonals too).
    edges = {tuple(sorted((a, b))) for a, b, c in f for a, b in ((a, b), (b, c), (c, a))}
    targets = np.vstack([v] + [v[a] + s * (v[b] - v[a]) for a, b in sorted(edges) for s in (0.5, 1 / 3)])
    inside = np.vstack([np.zeros((1, 3)), rng.uniform(-0.3, 0.3, (5, 3))])
    # From points inside through each target, and from outside straight at it.
    origins = np.repeat(inside, len(targets), axis=0)
    directions = np.tile(targets, (len(inside), 1)) - origins
    origins = np.vstack([origins, origins + 3.0 * directions])
    directions = np.vstack([directions, -directions])
    if placed:  # rounded in the unit box and in float
        v, origins = 3.7 * v + [10.0, -4.0, 2.0], 3.7 * origins + [10.0, -4.0, 2.0]
    hits = mm.SurfaceIndex(v, f).line_intersections(origins, directions)
    assert not np.isnan(hits.distances).any()
    with np.errstate(invalid="ignore"):  # lines parallel to some faces
        expected, tie = brute_lines(v, f, origins, directions)
    size = np.ptp(v, axis=0).max()
    assert np.abs(np.abs(hits.distances) - np.abs(expected)).max() <= 1e-9 * size
    assert np.abs(hits.distances[~tie] - expected[~tie]).max() <= 1e-9 * size


def test_many_lines_on_a_large_surface_in_any_order(rng):
    # Enough faces and lines for the index to trace the lines in spatial order: the answers are
    # those of the same lines asked in small batches, which keep their order.
    rings, segments = 300, 256
    theta = np.pi * np.arange(1, rings) / rings
    phi = 2 * np.pi * np.arange(segments) / segments
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.column_stack([np.sin(t).ravel() * np.cos(p).ravel(), np.sin(t).ravel() * np.sin(p).ravel(),
                            np.cos(t).ravel()])
    v = np.vstack([[0, 0, 1], ring, [0, 0, -1]]) * AXES
    j = np.arange(segments)
    r = np.arange(rings - 2)[:, None]
    a, b = 1 + r * segments + j, 1 + r * segments + (j + 1) % segments
    south, last = len(v) - 1, 1 + (rings - 2) * segments
    f = np.vstack([np.column_stack([np.zeros(segments, int), 1 + j, 1 + (j + 1) % segments]),
                   np.column_stack([np.full(segments, south), last + (j + 1) % segments, last + j]),
                   np.column_stack([a.ravel(), (a + segments).ravel(), b.ravel()]),
                   np.column_stack([b.ravel(), (a + segments).ravel(), (b + segments).ravel()])]).astype(np.int64)
    assert len(f) >= 2**17
    origins, directions = random_lines(rng, 50_000)
    origins[:1000] = 0.0
    directions[1000:2000] = v[rng.choice(len(v), 1000)]
    index = mm.SurfaceIndex(v, f)
    hits = index.line_intersections(origins, directions)
    for k in range(0, len(origins), 10_000):
        part = index.line_intersections(origins[k:k + 10_000], directions[k:k + 10_000])
        np.testing.assert_array_equal(part.faces, hits.faces[k:k + 10_000])
        np.testing.assert_array_equal(part.distances, hits.distances[k:k + 10_000])
        np.testing.assert_array_equal(part.points, hits.points[k:k + 10_000])
    pick = rng.choice(len(origins), 20, replace=False)
    expected, tie = brute_lines(v, f, origins[pick], directions[pick])
    assert np.array_equal(np.isnan(hits.distances[pick]), np.isnan(expected))
    found = ~np.isnan(expected)
    assert np.abs(np.abs(hits.distances[pick][found]) - np.abs(expected[found])).max() <= 1e-9 * 4.0
