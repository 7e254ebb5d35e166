"""Closed test surfaces with known geometry: subdivided spheres and the paper's ellipsoid."""

import numpy as np

AXES = np.array([2.0, 1.5, 1.2])  # the ellipsoid of the paper's Figure 12


def subdivide_onto_sphere(vertices, faces, levels):
    """Split each face in four ``levels`` times, the new vertices pushed onto the unit sphere."""
    vertices = list(vertices)
    for _ in range(levels):
        middle = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in middle:
                p = vertices[a] + vertices[b]
                vertices.append(p / np.linalg.norm(p))
                middle[key] = len(vertices) - 1
            return middle[key]

        out = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            out += [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
        faces = out
    return np.array(vertices), np.array(faces, np.int64)


def icosphere(subdivisions, radius=1.0):
    """An icosahedron subdivided ``subdivisions`` times onto the sphere; outward faces."""
    g = (1 + 5**0.5) / 2
    v = [[-1, g, 0], [1, g, 0], [-1, -g, 0], [1, -g, 0], [0, -1, g], [0, 1, g],
         [0, -1, -g], [0, 1, -g], [g, 0, -1], [g, 0, 1], [-g, 0, -1], [-g, 0, 1]]
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    vertices, faces = subdivide_onto_sphere([np.array(p, float) / np.linalg.norm(p) for p in v], f, subdivisions)
    return radius * vertices, faces


def ellipsoid(subdivisions):
    v, f = icosphere(subdivisions)
    return v * AXES, f


def face_areas(v, f):
    return 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)


def signed_volume(vertices, faces):
    """The volume a closed triangle surface encloses: positive where its faces turn outwards."""
    a, b, c = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)
