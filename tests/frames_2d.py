"""2D pairs of frames made the way labs make them: curves contoured from masks on one pixel grid (see frames.py)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage
from skimage import measure

from frame_seeds import STYLES, rng_of, style_of

#: Pixel spacings (sy, sx) in microns.
SPACINGS_2D = ((0.7, 1.0), (1.0, 1.0), (1.0, 0.7), (0.5, 0.8), (1.2, 0.6), (0.35, 0.5))
#: Raster shapes (rows, cols).
SHAPES_2D = ((96, 96), (112, 128), (128, 128), (128, 112), (120, 104))
RAW_2D = ("first", "concat", "debris")


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
    rng = rng_of(seed, 2)
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

