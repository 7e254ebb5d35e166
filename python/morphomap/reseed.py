"""Keeping followed boundary points dense: new material points where the old ones spread apart.

Followed points drift apart where the boundary grows (the tip of a bud); without new points such
stretches would end up unsampled. Each function here takes the material points carried onto a
frame and the pieces between them, and splits every piece that grew longer than ``limit`` with new
points placed on that frame's boundary. A piece's children inherit its accumulated growth.
"""

from __future__ import annotations

import numpy as np

from .curves import perimeter
from .queries import CurveIndex
from .surfaces import SurfaceIndex

#: At most this many rounds of edge splits per frame in 3D (each round at least halves the longest
#: edges, so this is only a guard against a surface that cannot be sampled).
MAX_SPLIT_ROUNDS = 64


def reseed_curve(points, chain, growth, frame, spacing, limit, closed):
    """Split the pieces of a followed curve longer than ``limit`` (arc length along ``frame``).

    points : (M, 2) float, every material point's position on this frame (NaN for points not alive).
    chain : (K,) int, the alive points in their order along the boundary.
    growth : (P,) float, the accumulated stretch of each piece (piece i runs from chain[i] to the
        next point; P = K closed, K - 1 open).
    frame : (N, 2) float, the boundary of this frame. A piece's length is the arc length along it
        between its two points' closest points (the shorter way round a closed frame), and its new
        points are equally spaced along that arc.
    spacing : the spacing new points are placed at (pieces longer than ``limit`` are cut into
        equal parts no longer than ``spacing``).

    Returns ``(new_points (B, 2), chain, growth)``: the new points get the ids ``M``, ``M + 1``, ...
    in that order and sit in ``chain`` between the two points whose piece they split.
    """
    pieces = len(chain) if closed else len(chain) - 1
    if pieces < 1:
        return np.empty((0, 2)), chain, growth
    index = CurveIndex(frame, closed=closed)
    along = index.closest_points(points[chain]).arc_lengths
    total = perimeter(frame, closed=closed)
    start = along[:pieces]
    end = np.roll(along, -1)[:pieces] if closed else along[1:]
    # On an open curve a piece runs the only way between its points. Round a closed frame the
    # chain runs one way (the way whose arcs add up to less: once round), whichever way the frame
    # runs; a piece whose arc that way is more than half round, in a chain that then goes round
    # more than once, is two neighbours that swapped places: it runs the shorter way back.
    if closed:
        forward = np.mod(end - start, total)
        backward = np.mod(total - forward, total)
        direction = 1.0 if forward.sum() <= backward.sum() else -1.0
        arc = forward if direction > 0 else backward
        way = np.full(pieces, direction)
        if arc.sum() > 1.5 * total:
            back = arc > total / 2
            arc[back], way[back] = total - arc[back], -direction
    else:
        arc, way = np.abs(end - start), np.sign(end - start)
    counts = np.where(arc > limit, np.ceil(arc / spacing).astype(np.int64) - 1, 0)
    if not counts.any():
        return np.empty((0, 2)), chain, growth
    # Arc-length positions of the new points: equal parts of each piece that is split.
    owner = np.repeat(np.arange(pieces), counts)
    rank = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts) + 1
    step = arc[owner] / (counts[owner] + 1) * way[owner]
    positions = start[owner] + rank * step
    vertices = np.vstack([frame, frame[:1]]) if closed else frame
    knots = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(vertices, axis=0), axis=1))])
    if closed:
        positions = np.mod(positions, total)
    new = np.column_stack([np.interp(positions, knots, vertices[:, 0]), np.interp(positions, knots, vertices[:, 1])])
    ids = len(points) + np.arange(len(new))
    # New chain: each old point followed by the new points of its piece.
    slots = np.concatenate([np.zeros(1, dtype=np.int64), np.cumsum(1 + np.pad(counts, (0, len(chain) - pieces)))])[:-1]
    longer = np.empty(len(chain) + len(new), dtype=np.int64)
    longer[slots] = chain
    inserted = np.setdiff1d(np.arange(len(longer)), slots)
    longer[inserted] = ids
    return new, longer, np.repeat(growth, counts + 1)


def reseed_surface(points, faces, growth, frame, limit):
    """Split the edges of followed triangles longer than ``limit`` until none is.

    points : (M, 3) float, every material point's position on this frame (NaN for points not alive).
    faces : (F, 3) int, the followed triangles (oriented as the frame's outward triangles).
    growth : (F,) float, the accumulated area ratio of each triangle.
    frame : ``(vertices, faces)`` of this frame's surface; a new point is the middle of the edge
        it splits, moved to the closest point of the frame's surface.

    In each round every triangle picks its longest edge (ties by a fixed edge order), and an edge
    is split where all triangles sharing it picked it: the two triangles become four, keeping
    their orientation, and the children inherit the growth of the parent.

    Returns ``(new_points (B, 3), faces, growth)``, the new points numbered from ``M`` on.
    """
    index = None
    points = np.asarray(points, dtype=float)
    grown = []
    for _ in range(MAX_SPLIT_ROUNDS):
        every = np.vstack([points] + grown) if grown else points
        corners = every[faces]
        lengths = np.linalg.norm(corners[:, [1, 2, 0]] - corners, axis=2)  # edge j runs from corner j to j + 1
        if not (lengths > limit).any():
            break
        pairs = np.sort(np.stack([faces, faces[:, [1, 2, 0]]], axis=2).reshape(-1, 2), axis=1)
        # One integer per edge (a 1D unique is many times faster than a unique over rows).
        codes, edge_of = np.unique(pairs[:, 0] * len(every) + pairs[:, 1], return_inverse=True)
        keys = np.column_stack([codes // len(every), codes % len(every)])
        edge_of = edge_of.reshape(-1, 3)
        edge_length = np.zeros(len(keys))
        edge_length[edge_of.ravel()] = lengths.ravel()
        rank = np.empty(len(keys), dtype=np.int64)
        rank[np.lexsort((np.arange(len(keys)), -edge_length))] = np.arange(len(keys))
        local = np.argmin(rank[edge_of], axis=1)
        picked = edge_of[np.arange(len(faces)), local]
        picked = np.where(lengths[np.arange(len(faces)), local] > limit, picked, -1)
        sharing = np.bincount(edge_of.ravel(), minlength=len(keys))
        votes = np.bincount(picked[picked >= 0], minlength=len(keys))
        chosen = (votes == sharing) & (votes > 0)
        split = np.flatnonzero(chosen[np.maximum(picked, 0)] & (picked >= 0))
        edges = np.flatnonzero(chosen)
        if index is None:
            index = SurfaceIndex(*frame)
        middle = every[keys[edges]].mean(axis=1)
        new_id = np.full(len(keys), -1, dtype=np.int64)
        new_id[edges] = len(every) + np.arange(len(edges))
        grown.append(index.closest_points(middle).points)
        # Triangle (a, b, c) with its edge a-b split at m becomes (a, m, c) and (m, b, c).
        rolled = faces[split][np.arange(len(split))[:, None], (local[split][:, None] + np.arange(3)) % 3]
        m = new_id[picked[split]]
        children = np.concatenate([np.column_stack([rolled[:, 0], m, rolled[:, 2]]),
                                   np.column_stack([m, rolled[:, 1], rolled[:, 2]])])
        kept = np.ones(len(faces), dtype=bool)
        kept[split] = False
        faces = np.concatenate([faces[kept], children])
        growth = np.concatenate([growth[kept], growth[split], growth[split]])
    new = np.vstack(grown) if grown else np.empty((0, 3))
    return new, faces, growth
