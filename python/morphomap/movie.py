"""A time-lapse file as a time series: one object's boundary per time point, the sample's drift
taken out.

:func:`movie_frames` reads a movie of masks or label images (``T`` among its axes, 2D ``TYX`` or
3D ``TZYX``: an ImageJ hyperstack or an OME-TIFF, read by :func:`morphomap.read_image`) and
returns one boundary per time point, with the spacing and the frame interval the file states.
:func:`register_frames` removes the drift from frame to frame. :func:`morphomap.map_series` calls
both when it is given a file.
"""

from __future__ import annotations

import math
import os
import warnings
from typing import NamedTuple, Optional

import numpy as np
import trimesh
from scipy import ndimage

from .curves import signed_area
from .images import boundary_from_mask, read_image, surface_from_mask
from .images.read import Image
from .surfaces import SurfaceIndex
from .transform import align_curves

#: How :func:`movie_frames` picks the object in each frame of a label movie.
OBJECTS = ("union", "largest", "follow")
#: What :func:`register_frames` removes: the translation, or the translation and the rotation.
REGISTRATIONS = ("translation", "rigid")


class Movie(NamedTuple):
    """What :func:`movie_frames` returns."""

    frames: list  # one boundary per time point: (N, 2) curves or trimesh.Trimesh surfaces
    dt: Optional[float]  # the frame interval the file states, in seconds; None where it states none
    spacing: tuple  # the pixel / voxel size used, per spatial axis (sy, sx) or (sz, sy, sx)
    unit: Optional[str]  # the unit of spacing and of the boundaries' coordinates; None: pixels


def _object(frame: np.ndarray, objects: str, label, previous, t: int) -> np.ndarray:
    """The mask of the object in one frame (a mask or a label image)."""
    name = f"frame {t}"
    if label is not None and (objects != "follow" or previous is None):
        chosen = frame == label  # linked labels, or where "follow" starts
    elif objects == "union":
        chosen = frame != 0
    elif objects == "largest" or previous is None:
        values, counts = np.unique(frame[frame != 0], return_counts=True)
        if len(values) == 0:
            raise ValueError(f"{name}: has no object (every pixel is 0)")
        chosen = frame == values[np.argmax(counts)]
    else:  # follow: the label overlapping the previous frame's object most
        values, counts = np.unique(frame[previous & (frame != 0)], return_counts=True)
        if len(values) == 0:
            raise ValueError(f"{name}: no object overlaps the one followed from frame {t - 1} "
                             f"(it moved more than its own size): use objects='largest' or label=")
        chosen = frame == values[np.argmax(counts)]
    if not chosen.any():
        raise ValueError(f"{name}: no pixel has the value {label}" if label is not None
                         else f"{name}: has no object (every pixel is 0)")
    # One object: its holes filled (the boundary is the outer one), the largest part where the
    # union falls apart (debris, or cells that do not touch), said once per frame.
    chosen = ndimage.binary_fill_holes(chosen)
    parts, count = ndimage.label(chosen)
    if count > 1:
        sizes = np.bincount(parts.ravel())[1:]
        warnings.warn(f"{name}: the object is {count} separate parts ({', '.join(map(str, sorted(sizes)[::-1][:4]))}"
                      f" pixels); the largest is kept", UserWarning, stacklevel=4)
        chosen = parts == 1 + int(np.argmax(sizes))
    return chosen  # boundary_from_mask / surface_from_mask warn where it touches the border


def movie_frames(movie, *, label=None, objects=None, smooth=None, edge_length=None, spacing=None,
                 unit="um") -> Movie:
    """One boundary per time point of a movie of masks or label images.

    Parameters
    ----------
    movie : path or Image
        A file :func:`morphomap.read_image` reads, or its result, with a ``T`` axis and spatial
        axes ``YX`` (a 2D movie: curves) or ``ZYX`` (3D: surfaces, by
        :func:`morphomap.surface_from_mask`); no channel axis.
    label : int, optional
        The object's value: in every frame (labels linked across frames), or with
        ``objects="follow"`` only in the first.
    objects : {"union", "largest", "follow"}, optional
        Which object each frame gives, for label movies whose labels are not linked across frames:
        ``"union"`` (the default without ``label``): every labelled pixel, the tissue;
        ``"largest"``: the label with the most pixels in each frame; ``"follow"``: the first
        frame's ``label`` (else its largest), then in each frame the label that overlaps most with
        the previous frame's object. Holes are filled; an object in several parts keeps its
        largest, with a warning; one that touches the image border is warned about.
    smooth, edge_length : as :func:`morphomap.boundary_from_mask` (2D) and
        :func:`morphomap.surface_from_mask` (3D) take them.
    spacing : float or tuple, optional
        The pixel size, overriding the file's; without either, 1 (pixel units).
    unit : str
        The unit the file's spacing is converted to (``read_image``'s ``unit``).

    Returns
    -------
    Movie
        ``frames``, ``dt`` (the file's frame interval in seconds, or None), ``spacing`` and
        ``unit``.
    """
    if objects is None:
        objects = "union" if label is None else "largest"
    if objects not in OBJECTS:
        raise ValueError(f"objects: expected one of {', '.join(OBJECTS)}, got {objects!r}")
    image = movie if isinstance(movie, Image) else read_image(movie, unit=unit)
    axes = image.axes
    if "C" in axes:
        raise ValueError(f"movie: has a channel axis (axes {axes}): an RGB or multichannel image, not a mask; "
                         f"segment it first, or save one channel of labels")
    if "T" not in axes:
        raise ValueError(f"movie: has no time axis (axes {axes}): a single frame or a z-stack; save the movie "
                         f"with its T axis (an ImageJ hyperstack or OME-TIFF), or pass the frames as a list")
    spatial = axes.replace("T", "")
    if spatial not in ("YX", "ZYX"):
        raise ValueError(f"movie: axes {axes}: expected TYX or TZYX")
    data = np.moveaxis(image.data, axes.index("T"), 0)
    if len(data) < 2:
        raise ValueError(f"movie: has {len(data)} time point; expected at least 2")
    if spacing is not None:
        used = tuple(float(v) for v in np.broadcast_to(np.asarray(spacing, dtype=float), (len(spatial),)))
        used_unit = unit
    elif image.spacing is not None:
        used, used_unit = tuple(float(v) for v in image.spacing), image.unit
    else:
        used, used_unit = (1.0,) * len(spatial), None
    frames, previous = [], None
    for t, frame in enumerate(data):
        mask = _object(np.asarray(frame), objects, label, previous, t)
        previous = mask
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            if len(spatial) == 2:
                frames.append(boundary_from_mask(mask, used, smooth=smooth))
            else:
                frames.append(surface_from_mask(mask, used, smooth=0.0 if smooth is None else smooth,
                                                edge_length=edge_length))
        for caught_warning in caught:  # said of the frame (the border warning of the mask readers)
            warnings.warn(f"frame {t}: {caught_warning.message}", caught_warning.category, stacklevel=3)
    return Movie(frames, image.frame_interval, used, used_unit)


def _centroid(frame) -> np.ndarray:
    if isinstance(frame, trimesh.Trimesh):
        return np.asarray(frame.center_mass, dtype=float)
    x, y = frame[:, 0], frame[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 3.0 * cross.sum()
    return np.array([((x + xn) * cross).sum() / area, ((y + yn) * cross).sum() / area])


def _moved(frame, matrix):
    if isinstance(frame, trimesh.Trimesh):
        return trimesh.Trimesh(trimesh.transform_points(frame.vertices, matrix), frame.faces, process=False)
    return frame @ matrix[:2, :2].T + matrix[:2, 2]


def _rotation(angle: float, centre: np.ndarray) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    matrix = np.eye(3)
    matrix[:2, :2] = [[c, -s], [s, c]]
    matrix[:2, 2] = centre - matrix[:2, :2] @ centre
    return matrix


def _icp(points: np.ndarray, surface: trimesh.Trimesh, iterations: int = 50) -> np.ndarray:
    """The rigid motion (4 x 4) that brings ``points`` closest to ``surface``: iterative closest
    points, each step the least-squares rotation and shift (Kabsch) onto the current closest
    points. Our own because trimesh's ``registration.icp`` needs rtree, which morphomap does not
    depend on; the closest points come from the core's index (Embree)."""
    index = SurfaceIndex(surface.vertices, surface.faces)
    matrix = np.eye(4)
    moved = points
    for _ in range(iterations):
        target = index.closest_points(moved).points
        a, b = moved.mean(axis=0), target.mean(axis=0)
        u, _, vt = np.linalg.svd((moved - a).T @ (target - b))
        flip = np.diag([1.0, 1.0, np.sign(np.linalg.det(vt.T @ u.T))])
        turn = vt.T @ flip @ u.T
        step = np.eye(4)
        step[:3, :3], step[:3, 3] = turn, b - turn @ a
        matrix = step @ matrix
        moved = points @ matrix[:3, :3].T + matrix[:3, 3]
        if np.abs(step - np.eye(4)).max() < 1e-9:
            break
    return matrix


def register_frames(frames, register: str):
    """``(frames, motion)``: each frame moved onto the previous one as moved, so that what is left
    between frames is growth, not the sample's drift.

    ``register="translation"``: each frame's centroid (of its area in 2D, its volume in 3D) put
    on the first frame's. ``"rigid"``: also turned, in 2D by the angle of the paper's Appendix A
    alignment of the frame onto the previous one (:func:`morphomap.align_curves`, whose scaling to
    the other's area is left out: that is growth), in 3D by trimesh's ICP of its vertices onto
    the previous surface (iterative closest points, rigid). A growth that moves the
    centroid (a bud on one side) is taken for drift as far as it moves it.

    ``motion``: ``(T, d + 1, d + 1)`` homogeneous matrices, ``motion[k]`` mapping frame k as given
    onto frame k as mapped (the identity for frame 0).
    """
    if register not in REGISTRATIONS:
        raise ValueError(f"register: expected one of {', '.join(REGISTRATIONS)} or None, got {register!r}")
    dim = 3 if isinstance(frames[0], trimesh.Trimesh) else 2
    origin = _centroid(frames[0])
    moved, motion = [frames[0]], [np.eye(dim + 1)]
    for frame in frames[1:]:
        shift = np.eye(dim + 1)
        shift[:dim, dim] = origin - _centroid(frame)
        matrix = shift
        if register == "rigid":
            placed = _moved(frame, shift)
            if dim == 2:
                closed_turn = math.copysign(1.0, signed_area(placed)) == math.copysign(1.0, signed_area(moved[-1]))
                if not closed_turn:
                    raise ValueError("frames: consecutive outlines turn opposite ways; give them one orientation")
                angle = align_curves(placed, moved[-1]).angle
                matrix = _rotation(angle, origin) @ shift
            else:
                matrix = _icp(placed.vertices, moved[-1]) @ shift
        moved.append(_moved(frame, matrix))
        motion.append(matrix)
    return moved, np.array(motion)


def describe_motion(motion: np.ndarray) -> list:
    """One line per frame: the translation and (2D) the rotation in degrees that ``motion`` applied."""
    lines = []
    dim = motion.shape[1] - 1
    for k, matrix in enumerate(motion):
        shift = " ".join(f"{v:+.4g}" for v in matrix[:dim, dim])
        if dim == 2:
            angle = math.degrees(math.atan2(matrix[1, 0], matrix[0, 0]))
            lines.append(f"frame {k}: moved by ({shift}), turned by {angle:+.3f} degrees")
        else:
            lines.append(f"frame {k}: moved by ({shift}), rotation {np.round(matrix[:3, :3], 4).tolist()}")
    return lines


def is_movie_path(frames) -> bool:
    """Whether map_series was given one file (a movie) rather than a sequence of frames."""
    return isinstance(frames, (str, os.PathLike))
