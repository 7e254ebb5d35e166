"""Frames cut by one plane and closed by flat caps of long thin triangles, as the real limb stages
are (../shared/cases/limb-bud/3d: every stage cut from the body in one plane, each cap's polygon
triangulated without inner points, corners down to 0.06 degrees).

:func:`capped_pair` cuts both surfaces of a 3D fuzz pair by the same plane and closes each by
ear clipping its rim: every cap triangle spans the rim, so the caps have the slivers of the real
input (a few hundredths of a degree), and both caps lie in one plane where the surfaces meet it.
Written here because trimesh caps a cut only through optional triangulation packages
(``triangle``, ``mapbox_earcut``) that morphomap does not depend on.
"""

from __future__ import annotations

import numpy as np
import trimesh


def _rim(faces):
    """The one boundary loop of an open triangle surface, in its faces' order, or None where the
    boundary is not a single simple loop."""
    directed = np.c_[faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]].reshape(-1, 2)
    undirected = np.sort(directed, axis=1)
    _, inverse, counts = np.unique(undirected, axis=0, return_inverse=True, return_counts=True)
    following = {}
    for a, b in directed[counts[inverse.ravel()] == 1]:
        if a in following:
            return None
        following[int(a)] = int(b)
    if not following:
        return None
    start = next(iter(following))
    loop = [start]
    while (step := following[loop[-1]]) != start:
        if step not in following or len(loop) > len(following):
            return None
        loop.append(step)
    return loop if len(loop) == len(following) else None


def _ear_clipped(polygon):
    """Triangles (rows of indices) of a simple counter-clockwise polygon (k, 2) by ear clipping,
    or None where no ear is found (a polygon that is not simple)."""
    def turn(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    left = list(range(len(polygon)))
    triangles = []
    while len(left) > 3:
        for k in range(len(left)):
            i, j, m = left[k - 1], left[k], left[(k + 1) % len(left)]
            a, b, c = polygon[i], polygon[j], polygon[m]
            if turn(a, b, c) <= 0:
                continue
            if any(turn(a, b, polygon[q]) >= 0 and turn(b, c, polygon[q]) >= 0 and turn(c, a, polygon[q]) >= 0
                   for q in left if q not in (i, j, m)):
                continue
            triangles.append((i, j, m))
            left.pop(k)
            break
        else:
            return None
    triangles.append(tuple(left))
    return np.array(triangles)


def _capped(mesh, normal, origin):
    """`mesh` cut by the plane through `origin`, the side `normal` points to dropped, and closed
    by an ear-clipped cap facing `normal`; None where the cut leaves other than one disc."""
    cut = trimesh.intersections.slice_mesh_plane(mesh, -normal, origin, cap=False)
    cut.merge_vertices()
    loop = _rim(np.asarray(cut.faces))
    if loop is None:
        return None
    t1 = np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(normal, t1)
    flat = (cut.vertices[loop] - origin) @ np.c_[t1, t2]
    area = 0.5 * np.sum(flat[:, 0] * np.roll(flat[:, 1], -1) - np.roll(flat[:, 0], -1) * flat[:, 1])
    order = np.arange(len(loop)) if area > 0 else np.arange(len(loop))[::-1]
    triangles = _ear_clipped(flat[order])
    if triangles is None:
        return None
    cap = np.asarray(loop)[order][triangles]
    closed = trimesh.Trimesh(cut.vertices, np.vstack([cut.faces, cap]), process=False)
    if not (closed.is_watertight and closed.is_winding_consistent and closed.volume > 0):
        return None
    return closed


def capped_pair(s1, s2, rng):
    """Both surfaces (trimesh.Trimesh) cut by one plane normal to an axis, between 30% and 70% of
    their joint extent along it, and capped; with what was done, or None where either cut leaves
    other than one disc."""
    both = np.vstack([s1.vertices, s2.vertices])
    low, high = both.min(axis=0), both.max(axis=0)
    axis = int(rng.integers(3))
    normal = np.eye(3)[axis] * float(rng.choice([-1.0, 1.0]))
    origin = (low + high) / 2
    origin[axis] = low[axis] + (high[axis] - low[axis]) * rng.uniform(0.3, 0.7)
    c1, c2 = _capped(s1, normal, origin), _capped(s2, normal, origin)
    if c1 is None or c2 is None:
        return None
    smallest = min(c1.face_angles.min(), c2.face_angles.min())
    return c1, c2, dict(cut_axis=axis, cut_at=round(float(origin[axis]), 3),
                        smallest_angle_degrees=round(float(np.degrees(smallest)), 4))
