"""Pairs of frames made the way labs make them: rasterised masks, contoured (issue "Real segmentations").

Every generator is a pure function of an integer seed.

2D (:func:`curve_pair`): a smooth random blob (random Fourier radius r(theta) with k <= 6, buds as
Gaussian bumps in r(theta), necks as narrow dips, sometimes a knob: a disc stuck onto the boundary)
and a grown version of it (scaled non-uniformly, a bud grown out, a knob grown, or only part of
the boundary moved so that at least ~10% of it stays where it was). Both are rasterised on the
SAME pixel grid with anisotropic spacing (sy, sx) as boolean masks, optionally smoothed (Gaussian
then threshold, or the smoothed float image contoured directly), optionally with debris (a small
separate blob) and holes, and contoured with ``skimage.measure.find_contours`` at 0.5; physical
coordinates are x = col * sx, y = row * sy. Pixel stretches the growth did not touch are
therefore shared exactly by both curves.

- style ``"careful"``: the largest contour of each frame, its repeated last point dropped.
- style ``"raw"``: what a careless user passes on: ``"first"`` (``find_contours(...)[0]``, with
  its repeated last point: may be debris or a hole), ``"concat"`` (all contours of a frame
  concatenated into one array) or ``"debris"`` (a debris contour kept as a curve of its own).

3D (:func:`surface_pair`): the same with voxel volumes (24-34 voxels along the finest axis, anisotropic spacing
(sz, sy, sx)): a lumpy ball (zonal-harmonic-like radius perturbations about random axes, buds,
knobs) and a grown version on the same grid (or one moved by a fifth of its size or more, so that
the two cross), optionally debris and a cavity and smoothing;
``skimage.measure.marching_cubes`` on the zero-padded volume with the spacing, vertices reordered
to (x, y, z), faces oriented outward (by the signed volume), duplicate vertices merged
(``trimesh.Trimesh(process=True)``).

- style ``"careful"``: the largest connected component.
- style ``"raw"``: ``"all_components"`` (debris and cavity kept in the one mesh) or
  ``"unoriented"`` (the marching-cubes faces after the axis swap, not re-oriented: inward).

Run as a script to print a summary of some seeds: ``python tests/frames.py [2d|3d] [N]``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage
from skimage import measure

#: Pixel spacings (sy, sx) in microns.
SPACINGS_2D = ((0.7, 1.0), (1.0, 1.0), (1.0, 0.7), (0.5, 0.8), (1.2, 0.6), (0.35, 0.5))
#: Raster shapes (rows, cols).
SHAPES_2D = ((96, 96), (112, 128), (128, 128), (128, 112), (120, 104))
#: Voxel spacings (sz, sy, sx).
SPACINGS_3D = ((2.0, 1.0, 1.0), (1.5, 1.0, 1.0), (1.0, 1.0, 1.0), (2.5, 0.8, 0.8), (1.0, 0.7, 1.0))

STYLES = ("careful", "raw")
RAW_2D = ("first", "concat", "debris")
RAW_3D = ("all_components", "unoriented")


def _rng(seed: int, dim: int) -> np.random.Generator:
    return np.random.default_rng([int(seed), 1000 + dim])


def style_of(seed: int) -> str:
    """Which style a seed gets: one in four is raw."""
    return "raw" if int(seed) % 4 == 3 else "careful"


# --------------------------------------------------------------------------------------------- 2D

def _wrap(angle):
    return (angle + np.pi) % (2 * np.pi) - np.pi


@dataclass
class Blob2D:
    """A star-shaped blob in units of its base radius, plus optional knobs (discs)."""

    a: np.ndarray  # Fourier amplitudes, k = 1..6
    phi: np.ndarray  # and phases
    bumps: list = field(default_factory=list)  # (angle, height, width); height < 0 is a neck
    knobs: list = field(default_factory=list)  # (angle, offset, radius): disc at r(angle) * offset
    scale_xy: tuple = (1.0, 1.0)  # non-uniform growth of the whole blob
    tilt: float = 0.0  # orientation of that growth
    window: tuple | None = None  # (angle, half_width, amount): only part of the boundary moves
    shift: tuple = (0.0, 0.0)

    def radius(self, theta):
        theta = np.asarray(theta, dtype=float)
        k = np.arange(1, len(self.a) + 1)
        r = 1.0 + (self.a[:, None] * np.cos(k[:, None] * theta.ravel()[None] + self.phi[:, None])).sum(0)
        r = r.reshape(theta.shape)
        for angle, height, width in self.bumps:
            r = r + height * np.exp(-0.5 * (_wrap(theta - angle) / width) ** 2)
        if self.window is not None:
            angle, half, amount = self.window
            d = np.abs(_wrap(theta - angle)) / half
            w = np.where(d < 1, 0.5 * (1 + np.cos(np.pi * np.minimum(d, 1))), 0.0)
            r = r + amount * w
        return np.maximum(r, 0.15)

    def inside(self, x, y, scale):
        """Mask of the points (x, y) (relative to the centre, physical units) inside the blob."""
        x = x - self.shift[0] * scale
        y = y - self.shift[1] * scale
        # Undo the non-uniform growth: rotate by -tilt, divide by the scales, rotate back.
        c, s = np.cos(self.tilt), np.sin(self.tilt)
        u, v = (c * x + s * y) / self.scale_xy[0], (-s * x + c * y) / self.scale_xy[1]
        x, y = c * u - s * v, s * u + c * v
        theta = np.arctan2(y, x)
        rho = np.hypot(x, y) / scale
        mask = rho < self.radius(theta)
        for angle, offset, radius in self.knobs:
            rb = self.radius(np.array([angle]))[0] * offset
            kx, ky = rb * np.cos(angle), rb * np.sin(angle)
            mask |= np.hypot(x / scale - kx, y / scale - ky) < radius
        return mask

    def extent(self):
        """Largest distance of the blob from its centre, in units of the base radius."""
        theta = np.linspace(-np.pi, np.pi, 2048, endpoint=False)
        r = self.radius(theta).max()
        for angle, offset, radius in self.knobs:
            r = max(r, self.radius(np.array([angle]))[0] * offset + radius)
        return r * max(self.scale_xy) + np.hypot(*self.shift)

    def copy(self, **changes):
        values = dict(a=self.a.copy(), phi=self.phi.copy(), bumps=list(self.bumps), knobs=list(self.knobs),
                      scale_xy=self.scale_xy, tilt=self.tilt, window=self.window, shift=self.shift)
        values.update(changes)
        return Blob2D(**values)


def _random_blob_2d(rng) -> Blob2D:
    kmax = int(rng.integers(1, 7))
    a = np.zeros(6)
    a[:kmax] = rng.uniform(-1, 1, kmax) * 0.22 / np.arange(1, kmax + 1) ** rng.uniform(0.3, 1.2)
    phi = rng.uniform(0, 2 * np.pi, 6)
    blob = Blob2D(a, phi)
    theta = np.linspace(-np.pi, np.pi, 1024, endpoint=False)
    low = blob.radius(theta).min()
    if low < 0.45:  # keep it a blob, not a pinwheel
        blob.a *= 0.55 / (1.0 - low + 0.55)
    for _ in range(int(rng.choice([0, 0, 1, 1, 2]))):
        blob.bumps.append((rng.uniform(-np.pi, np.pi), rng.uniform(0.15, 0.6), rng.uniform(0.12, 0.4)))
    if rng.random() < 0.25:
        blob.bumps.append((rng.uniform(-np.pi, np.pi), -rng.uniform(0.15, 0.4), rng.uniform(0.06, 0.2)))
    if rng.random() < 0.2:
        blob.knobs.append((rng.uniform(-np.pi, np.pi), rng.uniform(1.0, 1.25), rng.uniform(0.2, 0.4)))
    return blob


def _grow_2d(blob: Blob2D, rng) -> tuple[Blob2D, str]:
    kinds = ["scale", "bud", "partial", "partial", "mixed"] + (["knob"] if blob.knobs else [])
    kind = str(rng.choice(kinds))
    if kind == "scale":
        s = rng.uniform(0.04, 0.35)
        e = rng.uniform(0.0, 0.15)
        grown = blob.copy(scale_xy=(1 + s + e, 1 + s - e), tilt=rng.uniform(0, np.pi))
        if rng.random() < 0.5:
            grown.shift = tuple(rng.uniform(-0.06, 0.06, 2))
    elif kind == "bud":
        bumps = list(blob.bumps)
        if bumps and bumps[0][1] > 0 and rng.random() < 0.7:
            angle, height, width = bumps[0]
            bumps[0] = (angle, height + rng.uniform(0.15, 0.6), width * rng.uniform(0.8, 1.1))
        else:
            bumps.append((rng.uniform(-np.pi, np.pi), rng.uniform(0.2, 0.7), rng.uniform(0.12, 0.35)))
        grown = blob.copy(bumps=bumps)
    elif kind == "knob":
        knobs = list(blob.knobs)
        angle, offset, radius = knobs[0]
        knobs[0] = (angle, offset + rng.uniform(0.05, 0.3), radius * rng.uniform(1.1, 1.6))
        grown = blob.copy(knobs=knobs)
    elif kind == "partial":
        # A raised-cosine window of half-width up to 0.9 pi moves; at least 10% stays put.
        amount = rng.uniform(0.08, 0.4) * (-0.6 if rng.random() < 0.2 else 1.0)
        grown = blob.copy(window=(rng.uniform(-np.pi, np.pi), rng.uniform(0.35, 0.9) * np.pi, amount))
    else:  # mixed: a little overall growth and a bud
        s = rng.uniform(0.02, 0.12)
        bumps = list(blob.bumps) + [(rng.uniform(-np.pi, np.pi), rng.uniform(0.2, 0.5), rng.uniform(0.15, 0.35))]
        grown = blob.copy(scale_xy=(1 + s, 1 + s * rng.uniform(0.5, 1.5)), tilt=rng.uniform(0, np.pi), bumps=bumps)
    return grown, kind


def _place_disc(rng, occupied, radius_px, tries=60):
    """Centre (row, col) of a disc of radius_px pixels clear of `occupied` by 3 pixels, or None."""
    clear = ndimage.distance_transform_edt(~occupied)
    rows, cols = occupied.shape
    margin = radius_px + 3
    for _ in range(tries):
        r, c = rng.uniform(margin, rows - margin), rng.uniform(margin, cols - margin)
        if clear[int(r), int(c)] > radius_px + 4:
            return r, c
    return None


def _disc(shape, centre, radius_px, spacing=None):
    rows, cols = np.indices(shape)
    return np.hypot(rows - centre[0], cols - centre[1]) < radius_px


def _contours_2d(image, spacing):
    """find_contours at 0.5 of the zero-padded image, in physical (x, y); closed ones only repeat."""
    pad = 2
    padded = np.pad(np.asarray(image, dtype=float), pad)
    contours = []
    for c in measure.find_contours(padded, 0.5):
        rows, cols = c[:, 0] - pad, c[:, 1] - pad
        contours.append(np.column_stack([cols * spacing[1], rows * spacing[0]]))
    return contours


def _area(points):
    x, y = points[:, 0], points[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _drop_repeat(points):
    if len(points) > 1 and np.array_equal(points[0], points[-1]):
        return points[:-1]
    return points


@dataclass
class CurvePair:
    seed: int
    style: str
    c1: np.ndarray
    c2: np.ndarray
    info: dict
    contours1: list  # every contour of each frame, as find_contours gave them (physical units)
    contours2: list

    @property
    def identical(self) -> bool:
        return self.c1.shape == self.c2.shape and np.array_equal(self.c1, self.c2)


def curve_pair(seed: int, style: str | None = None) -> CurvePair:
    """The 2D pair of frames of ``seed`` (style: ``style_of(seed)`` unless given)."""
    style = style_of(seed) if style is None else style
    if style not in STYLES:
        raise ValueError(f"style: expected one of {STYLES}, got {style!r}")
    rng = _rng(seed, 2)
    spacing = SPACINGS_2D[int(rng.integers(len(SPACINGS_2D)))]
    shape = SHAPES_2D[int(rng.integers(len(SHAPES_2D)))]
    rows, cols = np.indices(shape)
    height, width = shape[0] * spacing[0], shape[1] * spacing[1]
    centre = (width * rng.uniform(0.45, 0.55), height * rng.uniform(0.45, 0.55))
    x, y = cols * spacing[1] - centre[0], rows * spacing[0] - centre[1]
    room = min(centre[0], width - centre[0], centre[1], height - centre[1]) - 3 * max(spacing)
    size = rng.uniform(0.45, 1.0)

    for attempt in range(20):
        blob = _random_blob_2d(rng)
        grown, kind = _grow_2d(blob, rng)
        scale = size * room / max(blob.extent(), grown.extent())
        m1, m2 = blob.inside(x, y, scale), grown.inside(x, y, scale)
        if m1.sum() > 30 and not np.array_equal(m1, m2):
            break
    else:  # pragma: no cover - 20 draws that all rasterise to the same mask
        raise RuntimeError(f"seed {seed}: could not draw two different frames")

    info = dict(dim=2, seed=int(seed), style=style, kind=kind, spacing=spacing, shape=shape,
                buds=sum(h > 0 for _, h, _ in blob.bumps), necks=sum(h < 0 for _, h, _ in blob.bumps),
                knobs=len(blob.knobs), attempts=attempt + 1)

    # Debris and holes (raw pairs nearly always get some, so that picking matters).
    p_debris, p_hole = (0.85, 0.4) if style == "raw" else (0.3, 0.15)
    debris = []
    if rng.random() < p_debris:
        which = str(rng.choice(["1", "2", "both"]))
        for frame, mask in (("1", m1), ("2", m2)):
            if which in (frame, "both"):
                radius = rng.uniform(1.5, 4.0)
                spot = _place_disc(rng, m1 | m2, radius)
                if spot is not None:
                    mask |= _disc(shape, spot, radius)
                    debris.append(frame)
    holes = []
    if rng.random() < p_hole:
        depth = ndimage.distance_transform_edt(m1 & m2)
        radius = rng.uniform(1.5, 3.5)
        candidates = np.argwhere(depth > radius + 3)
        if len(candidates):
            spot = candidates[int(rng.integers(len(candidates)))]
            hole = _disc(shape, spot, radius)
            which = str(rng.choice(["1", "2", "both"]))
            if which in ("1", "both"):
                m1 &= ~hole
                holes.append("1")
            if which in ("2", "both"):
                m2 &= ~hole
                holes.append("2")
    info.update(debris=debris, holes=holes)

    smoothing = str(rng.choice(["none", "none", "threshold", "float"]))
    sigma = float(rng.uniform(0.6, 1.5))
    images = []
    for mask in (m1, m2):
        if smoothing == "none":
            images.append(mask)
        else:
            blurred = ndimage.gaussian_filter(mask.astype(float), sigma)
            images.append(blurred > 0.5 if smoothing == "threshold" else blurred)
    info.update(smoothing=smoothing, sigma=round(sigma, 3) if smoothing != "none" else None)

    contours1, contours2 = _contours_2d(images[0], spacing), _contours_2d(images[1], spacing)
    if not contours1 or not contours2:  # pragma: no cover - the blob is at least 30 pixels
        raise RuntimeError(f"seed {seed}: a frame has no contour")
    largest1 = _drop_repeat(max(contours1, key=_area))
    largest2 = _drop_repeat(max(contours2, key=_area))

    if style == "careful":
        c1, c2 = largest1, largest2
        info["raw"] = None
    else:
        raw = str(rng.choice(RAW_2D))
        info["raw"] = raw
        if raw == "first":
            c1, c2 = contours1[0], contours2[0]
        elif raw == "concat":
            c1, c2 = np.concatenate(contours1), np.concatenate(contours2)
        else:  # debris: the smallest contour of one frame kept as the curve
            side = "2" if rng.random() < 0.5 else "1"
            c1 = min(contours1, key=_area) if side == "1" else largest1
            c2 = min(contours2, key=_area) if side == "2" else largest2
            info["raw"] = f"debris{side}"
    info.update(n1=len(c1), n2=len(c2), contours=(len(contours1), len(contours2)))
    return CurvePair(int(seed), style, np.ascontiguousarray(c1, dtype=float), np.ascontiguousarray(c2, dtype=float),
                     info, contours1, contours2)


# --------------------------------------------------------------------------------------------- 3D

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


def _signed_volume(vertices, faces):
    a, b, c = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


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
    if style_kind != "unoriented" and _signed_volume(verts, faces) < 0:
        faces = faces[:, ::-1]
    mesh = trimesh.Trimesh(np.ascontiguousarray(verts, dtype=float), np.ascontiguousarray(faces), process=True)
    components = int(mesh.body_count)
    if style_kind == "careful" and components > 1:
        parts = mesh.split(only_watertight=False)
        if len(parts) > 1:
            mesh = max(parts, key=lambda part: abs(_signed_volume(part.vertices, part.faces)))
    return mesh, components


def surface_pair(seed: int, style: str | None = None) -> SurfacePair:
    """The 3D pair of frames of ``seed`` (style: ``style_of(seed)`` unless given)."""
    style = style_of(seed) if style is None else style
    if style not in STYLES:
        raise ValueError(f"style: expected one of {STYLES}, got {style!r}")
    rng = _rng(seed, 3)
    spacing = SPACINGS_3D[int(rng.integers(len(SPACINGS_3D)))]
    # The finest axis has 24-34 voxels and the physical extents are about equal, as in a stack
    # with few, thick z slices.
    length = rng.uniform(24, 34) * min(spacing)
    shape = tuple(int(np.clip(round(length * rng.uniform(0.9, 1.15) / s), 12, 38)) for s in spacing)  # (nz, ny, nx)
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
    info = dict(dim=3, seed=int(seed), style=style, kind=kind, spacing=spacing, shape=shape,
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


def pair(dim: int, seed: int, style: str | None = None):
    """``curve_pair`` (dim 2) or ``surface_pair`` (dim 3)."""
    if dim == 2:
        return curve_pair(seed, style)
    if dim == 3:
        return surface_pair(seed, style)
    raise ValueError(f"dim: expected 2 or 3, got {dim!r}")


if __name__ == "__main__":  # a summary of some seeds, for looking at what the generators make
    import sys
    import time

    dim = 3 if len(sys.argv) > 1 and sys.argv[1] == "3d" else 2
    count = int(sys.argv[2]) if len(sys.argv) > 2 else 20
    for seed in range(count):
        clock = time.perf_counter()
        made = pair(dim, seed)
        print(f"{time.perf_counter() - clock:6.3f}s", made.info)
