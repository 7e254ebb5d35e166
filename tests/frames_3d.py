"""3D pairs of frames made the way labs make them: surfaces contoured from voxel masks on one grid (see frames.py)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage
from skimage import measure

from capped_frames import capped_pair
from frame_seeds import STYLES, rng_of, style_of
from surface_shapes import signed_volume

#: Voxel spacings (sz, sy, sx).
SPACINGS_3D = ((2.0, 1.0, 1.0), (1.5, 1.0, 1.0), (1.0, 1.0, 1.0), (2.5, 0.8, 0.8), (1.0, 0.7, 1.0))
RAW_3D = ("all_components", "unoriented")


def _directions(count):
    """Roughly uniform unit vectors (a Fibonacci sphere)."""
    i = np.arange(count) + 0.5
    z = 1 - 2 * i / count
    t = np.pi * (1 + 5**0.5) * i
    s = np.sqrt(1 - z * z)
    return np.column_stack([s * np.cos(t), s * np.sin(t), z])


def _unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


@dataclass
class Blob3D:
    """A star-shaped lumpy ball in units of its base radius, plus optional knobs (balls)."""

    waves: list  # (axis (3,), degree k, amplitude): amplitude * T_k(u . axis), T_k Chebyshev
    bumps: list = field(default_factory=list)  # (axis, height, width in radians); height < 0: neck
    knobs: list = field(default_factory=list)  # (axis, offset, radius)
    scale_xyz: tuple = (1.0, 1.0, 1.0)
    window: tuple | None = None  # (axis, threshold t, amount): where u . axis > t the surface moves
    shift: tuple = (0.0, 0.0, 0.0)

    def radius(self, u):
        u = np.asarray(u, dtype=float)
        r = np.ones(len(u))
        for axis, k, amplitude in self.waves:
            r = r + amplitude * np.cos(k * np.arccos(np.clip(u @ axis, -1, 1)))
        for axis, height, width in self.bumps:
            angle = np.arccos(np.clip(u @ axis, -1, 1))
            r = r + height * np.exp(-0.5 * (angle / width) ** 2)
        if self.window is not None:
            axis, t, amount = self.window
            s = np.clip((u @ axis - t) / max(1 - t, 1e-9), 0, 1)
            r = r + amount * np.sin(0.5 * np.pi * s) ** 2
        return np.maximum(r, 0.2)

    def inside(self, points, scale):
        """Mask of points (P, 3) (x, y, z relative to the centre, physical) inside the blob."""
        p = (points - np.asarray(self.shift) * scale) / (scale * np.asarray(self.scale_xyz))
        rho = np.linalg.norm(p, axis=1)
        u = p / np.maximum(rho, 1e-12)[:, None]
        mask = rho < self.radius(u)
        for axis, offset, radius in self.knobs:
            centre = axis * self.radius(axis[None])[0] * offset
            mask |= np.linalg.norm(p - centre, axis=1) < radius
        return mask

    def extent(self):
        """Half-extent along x, y and z, in units of the base radius."""
        u = _directions(3000)
        points = u * self.radius(u)[:, None]
        for axis, offset, radius in self.knobs:
            centre = axis * self.radius(axis[None])[0] * offset
            points = np.vstack([points, centre + radius * u])
        return np.abs(points).max(0) * np.asarray(self.scale_xyz) + np.abs(self.shift)

    def copy(self, **changes):
        values = dict(waves=list(self.waves), bumps=list(self.bumps), knobs=list(self.knobs),
                      scale_xyz=self.scale_xyz, window=self.window, shift=self.shift)
        values.update(changes)
        return Blob3D(**values)


def _random_blob_3d(rng) -> Blob3D:
    waves = []
    for _ in range(int(rng.integers(1, 5))):
        k = int(rng.integers(1, 4))
        waves.append((_unit(rng), k, rng.uniform(-0.18, 0.18) / k**0.5))
    blob = Blob3D(waves)
    low = blob.radius(_directions(2000)).min()
    if low < 0.5:
        blob.waves = [(axis, k, amplitude * 0.5 / (1.0 - low + 0.5)) for axis, k, amplitude in waves]
    for _ in range(int(rng.choice([0, 1, 1, 2]))):
        blob.bumps.append((_unit(rng), rng.uniform(0.2, 0.6), rng.uniform(0.25, 0.5)))
    if rng.random() < 0.2:
        blob.bumps.append((_unit(rng), -rng.uniform(0.15, 0.3), rng.uniform(0.15, 0.3)))
    if rng.random() < 0.15:
        blob.knobs.append((_unit(rng), rng.uniform(1.0, 1.2), rng.uniform(0.3, 0.45)))
    return blob


def _grow_3d(blob: Blob3D, rng) -> tuple[Blob3D, str]:
    kinds = ["scale", "bud", "partial", "partial", "mixed", "drift"] + (["knob"] if blob.knobs else [])
    kind = str(rng.choice(kinds))
    if kind == "scale":
        s = rng.uniform(0.08, 0.35)
        grown = blob.copy(scale_xyz=tuple(1 + s + rng.uniform(-0.08, 0.08, 3)))
        if rng.random() < 0.4:
            grown.shift = tuple(rng.uniform(-0.05, 0.05, 3))
    elif kind == "bud":
        bumps = list(blob.bumps)
        if bumps and bumps[0][1] > 0 and rng.random() < 0.7:
            axis, height, width = bumps[0]
            bumps[0] = (axis, height + rng.uniform(0.2, 0.6), width * rng.uniform(0.8, 1.1))
        else:
            bumps.append((_unit(rng), rng.uniform(0.3, 0.7), rng.uniform(0.25, 0.45)))
        grown = blob.copy(bumps=bumps)
    elif kind == "knob":
        knobs = list(blob.knobs)
        axis, offset, radius = knobs[0]
        knobs[0] = (axis, offset + rng.uniform(0.05, 0.25), radius * rng.uniform(1.15, 1.5))
        grown = blob.copy(knobs=knobs)
    elif kind == "partial":
        # Where u . axis > t (a cap of (1 - t) / 2 of the directions) the surface moves out.
        amount = rng.uniform(0.12, 0.45) * (-0.5 if rng.random() < 0.15 else 1.0)
        grown = blob.copy(window=(_unit(rng), rng.uniform(-0.6, 0.4), amount))
    elif kind == "drift":
        # Grown a little and moved by a fifth of its size or more: the surfaces cross, as frames
        # of a drifting sample do before registration.
        s = rng.uniform(0.0, 0.15)
        grown = blob.copy(scale_xyz=(1 + s, 1 + s, 1 + s), shift=tuple(_unit(rng) * rng.uniform(0.2, 0.35)))
    else:
        s = rng.uniform(0.04, 0.15)
        grown = blob.copy(scale_xyz=(1 + s, 1 + s, 1 + s * rng.uniform(0.5, 1.5)),
                          bumps=list(blob.bumps) + [(_unit(rng), rng.uniform(0.3, 0.6), rng.uniform(0.25, 0.45))])
    return grown, kind


@dataclass
class SurfacePair:
    seed: int
    style: str
    s1: object  # trimesh.Trimesh or a (vertices, faces) pair
    s2: object
    info: dict

    @staticmethod
    def arrays(surface):
        if isinstance(surface, tuple):
            return surface
        return np.asarray(surface.vertices, dtype=float), np.asarray(surface.faces, dtype=np.int64)

    @property
    def identical(self) -> bool:
        v1, f1 = self.arrays(self.s1)
        v2, f2 = self.arrays(self.s2)
        return v1.shape == v2.shape and f1.shape == f2.shape and np.array_equal(v1, v2) and np.array_equal(f1, f2)


def _surface(volume, spacing, style_kind):
    import trimesh

    pad = 1
    padded = np.pad(np.asarray(volume, dtype=float), pad)
    verts, faces, _, _ = measure.marching_cubes(padded, 0.5, spacing=spacing)
    verts = (verts - pad * np.asarray(spacing))[:, ::-1]  # (z, y, x) -> (x, y, z)
    faces = np.asarray(faces, dtype=np.int64)
    if style_kind != "unoriented" and signed_volume(verts, faces) < 0:
        faces = faces[:, ::-1]
    mesh = trimesh.Trimesh(np.ascontiguousarray(verts, dtype=float), np.ascontiguousarray(faces), process=True)
    components = int(mesh.body_count)
    if style_kind == "careful" and components > 1:
        parts = mesh.split(only_watertight=False)
        if len(parts) > 1:
            mesh = max(parts, key=lambda part: abs(signed_volume(part.vertices, part.faces)))
    return mesh, components


def surface_pair(seed: int, style: str | None = None, fine: int = 1, capped: bool = False) -> SurfacePair:
    """The 3D pair of frames of ``seed`` (style: ``style_of(seed)`` unless given). ``fine``: voxels
    that many times smaller along each axis, the same shapes (``fine=5``: some 10,000-55,000
    vertices, the large surfaces the default maps through coarse copies). ``capped``: a careful
    pair cut by one plane and closed by caps of long thin triangles (``capped_frames.py``; info
    ``capped`` says whether the cut left one disc on each, else the pair is as it was)."""
    style = style_of(seed) if style is None else style
    if style not in STYLES:
        raise ValueError(f"style: expected one of {STYLES}, got {style!r}")
    rng = rng_of(seed, 3)
    coarsest = SPACINGS_3D[int(rng.integers(len(SPACINGS_3D)))]
    # The finest axis has 24-34 voxels (times `fine`) and the physical extents are about equal, as
    # in a stack with few, thick z slices.
    length = rng.uniform(24, 34) * min(coarsest)
    spacing = tuple(s / fine for s in coarsest)
    shape = tuple(int(np.clip(round(length * rng.uniform(0.9, 1.15) / s), 12 * fine, 38 * fine))
                  for s in spacing)  # (nz, ny, nx)
    extent = np.array([shape[2] * spacing[2], shape[1] * spacing[1], shape[0] * spacing[0]])  # x, y, z
    centre = extent * rng.uniform(0.46, 0.54, 3)
    room = np.minimum(centre, extent - centre) - 1.5 * np.array(spacing[::-1])
    size = rng.uniform(0.7, 0.95)
    zz, yy, xx = np.indices(shape)
    points = np.column_stack([xx.ravel() * spacing[2], yy.ravel() * spacing[1], zz.ravel() * spacing[0]]) - centre

    for attempt in range(20):
        blob = _random_blob_3d(rng)
        grown, kind = _grow_3d(blob, rng)
        scale = size * float(np.min(room / np.maximum(blob.extent(), grown.extent())))
        m1 = blob.inside(points, scale).reshape(shape)
        m2 = grown.inside(points, scale).reshape(shape)
        if m1.sum() > 150 and not np.array_equal(m1, m2):
            break
    else:  # pragma: no cover
        raise RuntimeError(f"seed {seed}: could not draw two different frames")
    # One pair in ten instead swells: frame 2 is frame 1's mask dilated by 1-1.8 of the coarsest
    # voxel, as a thresholded stack grows between time points (the shapes that crashed Mesh_3).
    # Its own generator, so that the other pairs stay what they were.
    swell = np.random.default_rng([int(seed), 3, 1])
    if swell.random() < 0.1:
        kind = "swell"
        reach = swell.uniform(1.0, 1.8) * max(spacing)
        m2 = ndimage.distance_transform_edt(~m1, sampling=spacing) <= reach
    info = dict(dim=3, seed=int(seed), style=style, kind=kind, spacing=spacing, shape=shape, fine=fine,
                buds=sum(h > 0 for _, h, _ in blob.bumps), necks=sum(h < 0 for _, h, _ in blob.bumps),
                knobs=len(blob.knobs), attempts=attempt + 1)

    p_debris, p_hole = (0.8, 0.4) if style == "raw" else (0.3, 0.15)
    debris = []
    if rng.random() < p_debris:
        which = str(rng.choice(["1", "2", "both"]))
        clear = ndimage.distance_transform_edt(~(m1 | m2), sampling=spacing)
        for frame, mask in (("1", m1), ("2", m2)):
            if which in (frame, "both"):
                radius = rng.uniform(1.2, 2.2) * max(spacing)
                free = np.argwhere(clear > radius + 2 * max(spacing))
                free = free[(free >= 2).all(1) & (free < np.array(shape) - 2).all(1)]
                if len(free):
                    spot = free[int(rng.integers(len(free)))]
                    distance = np.sqrt((((np.indices(shape).T - spot) * spacing) ** 2).sum(-1)).T
                    mask |= distance < radius
                    debris.append(frame)
    holes = []
    if rng.random() < p_hole:
        depth = ndimage.distance_transform_edt(m1 & m2, sampling=spacing)
        radius = rng.uniform(1.2, 2.5) * max(spacing)
        candidates = np.argwhere(depth > radius + 2 * max(spacing))
        if len(candidates):
            spot = candidates[int(rng.integers(len(candidates)))]
            cavity = np.sqrt((((np.indices(shape).T - spot) * spacing) ** 2).sum(-1)).T < radius
            which = str(rng.choice(["1", "2", "both"]))
            if which in ("1", "both"):
                m1 &= ~cavity
                holes.append("1")
            if which in ("2", "both"):
                m2 &= ~cavity
                holes.append("2")
    info.update(debris=debris, holes=holes)

    smoothing = str(rng.choice(["none", "none", "float"]))
    sigma = float(rng.uniform(0.6, 1.1))
    volumes = [m if smoothing == "none" else ndimage.gaussian_filter(m.astype(float), sigma) for m in (m1, m2)]
    info.update(smoothing=smoothing, sigma=round(sigma, 3) if smoothing != "none" else None)

    kind_of_style = "careful" if style == "careful" else str(rng.choice(RAW_3D))
    info["raw"] = None if style == "careful" else kind_of_style
    mesh1, parts1 = _surface(volumes[0], spacing, kind_of_style)
    mesh2, parts2 = _surface(volumes[1], spacing, kind_of_style)
    if capped:
        # Its own generator, so that the uncapped pair stays what it was.
        cut = capped_pair(mesh1, mesh2, np.random.default_rng([int(seed), 3, 2])) if style == "careful" else None
        info["capped"] = cut is not None
        if cut is not None:
            mesh1, mesh2 = cut[0], cut[1]
            info.update(cut[2])
    as_tuple = rng.random() < 0.5  # half the pairs go in as (vertices, faces), half as Trimesh
    if as_tuple:
        s1 = (np.asarray(mesh1.vertices, dtype=float), np.asarray(mesh1.faces, dtype=np.int64))
        s2 = (np.asarray(mesh2.vertices, dtype=float), np.asarray(mesh2.faces, dtype=np.int64))
    else:
        s1, s2 = mesh1, mesh2
    info.update(as_tuple=bool(as_tuple), components=(parts1, parts2),
                vertices=(len(mesh1.vertices), len(mesh2.vertices)), faces=(len(mesh1.faces), len(mesh2.faces)),
                watertight=(bool(mesh1.is_watertight), bool(mesh2.is_watertight)))
    return SurfacePair(int(seed), style, s1, s2, info)

