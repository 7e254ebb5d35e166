"""Boundaries from segmented images: the first step of the paper's pipeline (its Figure 1 a -> b).

Contouring is scikit-image's marching squares (``skimage.measure.find_contours``), smoothing
scipy's Gaussian filter and object counting scipy's labelling: well-kept code that labs already
use, so that a boundary made here is the one their own scripts would make.
"""

from __future__ import annotations

import numbers
import warnings

import numpy as np
import trimesh
from scipy import ndimage
from skimage import measure

from .. import _core
from .._validate import as_length
from ..curves import signed_area


_AXES = {2: "(rows, columns)", 3: "(sz, sy, sx)"}


def _spacing(spacing, ndim: int) -> tuple[float, ...]:
    """The spacing along each axis, in the image's axis order, from one number or one per axis."""
    values = np.atleast_1d(np.asarray(spacing, dtype=object))
    if values.ndim != 1 or len(values) not in (1, ndim):
        raise ValueError(f"spacing: expected one number or one per axis {_AXES[ndim]}, got {spacing!r}")
    lengths = [as_length(v, "spacing", 1.0) for v in values]
    return tuple(lengths * ndim) if len(lengths) == 1 else tuple(lengths)


def _object(mask, label, name: str, ndim: int = 2) -> np.ndarray:
    """The boolean image of the one object to contour: ``label``'s pixels, or the foreground."""
    array = np.asarray(mask)
    if array.dtype == object or not (np.issubdtype(array.dtype, np.integer) or array.dtype == bool):
        raise TypeError(f"{name}: expected a boolean mask or an integer label image, got dtype {array.dtype}")
    if array.ndim != ndim:
        raise ValueError(f"{name}: expected a {ndim}D image, got shape {array.shape}")
    if label is None:
        if array.dtype == bool:
            return array
        labels = np.unique(array[array != 0])
        if len(labels) > 1 and array.dtype != bool:
            shown = ", ".join(str(v) for v in labels[:8]) + (", ..." if len(labels) > 8 else "")
            raise ValueError(f"{name}: a label image with {len(labels)} labels ({shown}): pass label= to pick one")
        return array != 0
    if isinstance(label, (bool, np.bool_)) or not isinstance(label, numbers.Integral):
        raise TypeError(f"label: expected an integer, got {type(label).__name__}")
    chosen = array == label
    if not chosen.any():
        raise ValueError(f"label: no pixel of {name} has the value {label}")
    return chosen


def _warn_at_border(pixels: np.ndarray, name: str) -> None:
    """A warning where the object touches the image border: the boundary there is the image's
    edge, not the tissue's."""
    if pixels.size and any(np.take(pixels, i, axis=a).any() for a in range(pixels.ndim) for i in (0, -1)):
        warnings.warn(f"{name}: the object touches the image border; the boundary there is the image's edge, "
                      f"not the tissue's (image a wider field, or crop the analysis away from the edge)",
                      UserWarning, stacklevel=3)


def _require_one_object(pixels: np.ndarray, name: str) -> None:
    # Face connectivity (4 in 2D, 6 in 3D): marching squares and cubes at level 0.5 separate
    # pixels that touch only at a corner or an edge.
    components, count = ndimage.label(pixels)
    unit = "pixels" if pixels.ndim == 2 else "voxels"
    if count == 0:
        raise ValueError(f"{name}: has no foreground {unit[:-1]}")
    if count > 1:
        sizes = np.sort(np.bincount(components.ravel())[1:])[::-1]
        shown = ", ".join(str(s) for s in sizes[:6]) + (", ..." if count > 6 else "")
        raise ValueError(f"{name}: {count} separate objects ({shown} {unit}), as when debris is segmented "
                         f"with the organ: keep one (scipy.ndimage.label) or pass a label image and label=")


#: Width of the default smoothing, in pixels along each axis: the narrowest Gaussian that brings
#: a digitised disc's perimeter within 0.5% of the circle's (one pixel leaves +0.6%).
DEFAULT_SMOOTH_PIXELS = 1.2
#: Objects thinner than this many default widths get a narrower Gaussian, in proportion: a
#: Gaussian moves a boundary inwards by about its variance times the curvature, which shrinks a
#: small disc more than its digitisation already errs.
DEFAULT_SMOOTH_THICKNESS = 5.0


def _outer_contour(image: np.ndarray):
    """``(outer, pieces)``: the level 0.5 of ``image`` with the largest area, as (row, column)
    points with the end repeated, and the number of contours outside it (pieces the object fell
    into besides the outer one; holes do not count). None when no contour is left."""
    contours = [c for c in measure.find_contours(image, 0.5) if len(c) >= 4]
    if not contours:
        return None
    outer = max(contours, key=lambda c: abs(signed_area(c)))
    apart = [c for c in contours if c is not outer and not measure.points_in_poly(c[:1], outer)[0]]
    return outer, len(apart)


def _smoothed(image: np.ndarray, sigma_pixels) -> np.ndarray:
    if max(sigma_pixels) <= 0:
        return image
    # The Gaussian reads zeros beyond the array (mode "constant"), as if padded by its reach, and
    # its level 0.5 stays inside the object's bounding box (beyond it a half-plane holds less than
    # half the kernel), so a wide one needs no wide padding.
    return ndimage.gaussian_filter(image, sigma_pixels, mode="constant")


def _default_contour(image: np.ndarray):
    """The outer contour at the default smoothing (see :func:`boundary_from_mask`), halving the
    width while the object vanishes, splits or loses a part, down to none."""
    pixels = image > 0.5
    thickness = ndimage.distance_transform_edt(pixels).max()
    width = min(DEFAULT_SMOOTH_PIXELS, DEFAULT_SMOOTH_PIXELS * thickness / DEFAULT_SMOOTH_THICKNESS)
    while True:
        if width < 0.25 * DEFAULT_SMOOTH_PIXELS:
            width = 0.0  # narrower Gaussians barely touch the staircase: the pixels as they are
        smoothed = _smoothed(image, (width, width))
        found = _outer_contour(smoothed)
        if width == 0.0:
            return found
        if found is not None and found[1] == 0:
            # A part is lost where an object pixel lies more than one pixel outside what the
            # smoothed image keeps (a thin spur or a one-pixel line).
            kept = ndimage.binary_dilation(smoothed >= 0.5, structure=np.ones((3, 3), bool))
            if not (pixels & ~kept).any():
                return found
        width *= 0.5


def boundary_from_mask(mask, spacing=1.0, *, label=None, smooth=None) -> np.ndarray:
    """The boundary of the object in a 2D mask, as a closed curve in physical units.

    Parameters
    ----------
    mask : (rows, columns) bool or integer array
        A binary mask (non-zero is the object) or a label image (``label`` picks the object).
        The mask must hold one object (4-connected); its holes are ignored: the curve is the
        outer boundary.
    spacing : float or (row spacing, column spacing)
        Pixel size, in the image's axis order (as a stack's ``(sz, sy, sx)`` in 3D).
    label : int, optional
        The value of the object in a label image; required when the image holds several labels.
    smooth : float or None
        Width (standard deviation, in physical units) of a Gaussian applied to the mask before
        contouring; 0 contours the pixels as they are (their staircase). A width that makes the
        object vanish or fall apart raises ValueError.

        None (the default): about one pixel, chosen per mask so that the outline is sub-pixel
        and never loses the object. A Gaussian of 1.2 pixels along each axis (whatever the
        spacing), narrower in proportion for objects less than 5 pixels thick: width =
        1.2 * min(1, thickness / 5) pixels, the thickness being the largest distance, in
        pixels, from an object pixel to the background. Where that Gaussian would make the
        object vanish, split it or lose a part of it (an object pixel more than one pixel
        outside what it keeps, as of a one-pixel-wide line or spur), the width is halved until
        none happens, and below 0.3 pixels the pixels are contoured as they are. No error and
        no warning: the outline covers the object to within one pixel.

    Returns
    -------
    (N, 2) float array
        The curve without a repeated end point, counter-clockwise in (x, y), with
        **x = column * column spacing and y = row * row spacing** (the image's own axes, as Fiji
        reports coordinates: y grows downwards on the screen, so the curve turns clockwise as
        the image is shown). The level 0.5 of the (smoothed) mask by marching squares, which
        unsmoothed puts it half a pixel outside the centres of the object's edge pixels.
        Unsmoothed (``smooth=0``), the curve follows the pixels' staircase: a disc of radius 50
        pixels gives its area within 0.5% but a perimeter 5.5% too long, and its normals point
        in the staircase's 45 and 90 degree directions. At the default the same disc's
        perimeter and area are within 0.5% and every point within half a pixel of the circle,
        at any sub-pixel centre and with unequal row and column spacings; discs of radius 3 to
        5 pixels keep every point within half a pixel of their circle too (their area then errs
        by up to 15%, as their pixels already do).
    """
    pixels = _object(mask, label, "mask")
    row_spacing, column_spacing = _spacing(spacing, 2)
    default = smooth is None
    sigma = 0.0 if default else as_length(smooth, "smooth", 0.0, allow_zero=True)
    _require_one_object(pixels, "mask")
    _warn_at_border(pixels, "mask")
    # One pixel of padding closes the contour of an object touching the border.
    pad = 1
    image = np.pad(pixels.astype(float), pad)
    if default:
        outer, _ = _default_contour(image)
    else:
        found = _outer_contour(_smoothed(image, (sigma / row_spacing, sigma / column_spacing)))
        if found is None:
            raise ValueError(f"mask: the object vanishes when smoothed by {sigma}: use a smaller smooth=")
        outer, apart = found
        # The other contours are holes (inside the outer one) unless smoothing cut a neck.
        if apart:
            raise ValueError(f"smooth: a Gaussian of width {sigma} splits the object into {apart + 1} pieces: "
                             f"use a smaller smooth=")
    rows_columns = outer[:-1]  # the outer boundary, without its repeated end point
    curve = np.column_stack([(rows_columns[:, 1] - pad) * column_spacing, (rows_columns[:, 0] - pad) * row_spacing])
    if signed_area(curve) < 0:
        curve = curve[::-1]
    return np.ascontiguousarray(curve)


def _bounding_box(mask: np.ndarray) -> tuple[slice, ...] | None:
    """The smallest box holding every set voxel of ``mask``, as one slice per axis; None if none is set.
    Two passes: over the slices, then over the rows and columns of the slices that hold the object."""
    slices = np.flatnonzero(mask.reshape(len(mask), -1).any(axis=1)) if mask.size else []
    if len(slices) == 0:
        return None
    z = slice(slices[0], slices[-1] + 1)
    plane = mask[z].any(axis=0)
    rows, columns = np.flatnonzero(plane.any(axis=1)), np.flatnonzero(plane.any(axis=0))
    return z, slice(rows[0], rows[-1] + 1), slice(columns[0], columns[-1] + 1)


def _block_mean(mask: np.ndarray, factors) -> np.ndarray:
    """The fraction of ``mask``'s voxels set over blocks of ``factors`` voxels, as float32; each
    axis's length must be a multiple of its factor. Counted in small integers by adding the
    strided views of each axis (three times faster than summing a reshaped axis)."""
    counts = mask.view(np.uint8)
    wide = np.uint8 if np.prod(factors) < 2**8 else np.uint16 if np.prod(factors) < 2**16 else np.uint32
    for axis, f in enumerate(factors):
        if f > 1:
            views = [counts[(slice(None),) * axis + (slice(k, None, f),)] for k in range(f)]
            total = views[0].astype(wide)
            for view in views[1:]:
                total += view
            counts = total
    return counts.astype(np.float32) / np.float32(np.prod(factors))


#: Rounds of isotropic remeshing: three bring the smallest angles above 20 degrees (bench/README.md).
REMESH_ROUNDS = 3


def surface_from_mask(volume, spacing=(1.0, 1.0, 1.0), *, label=None, smooth=0.0, edge_length=None):
    """The boundary of the object in a 3D mask, as a closed, remeshed triangle surface.

    Parameters
    ----------
    volume : (z, y, x) bool or integer array
        A binary mask (non-zero is the object) or a label image (``label`` picks the object),
        indexed ``[z, y, x]`` as microscopy stacks are. The object must be one piece
        (6-connected); cavities inside it are filled: the surface is the outer boundary.
    spacing : float or (sz, sy, sx)
        Voxel size in the volume's axis order (a confocal stack is often 0.5 x 0.5 x 2 um).
    label : int, optional
        The value of the object in a label image; required when the image holds several labels.
    smooth : float
        Width (standard deviation, in physical units) of a Gaussian applied to the mask before
        contouring; 0 contours the voxels as they are.
    edge_length : float, optional
        Target edge length of the triangles, in physical units; by default the largest voxel
        size.

    Returns
    -------
    trimesh.Trimesh
        Watertight, one component, normals outwards, vertices (x, y, z) in physical units with
        **x = column * sx, y = row * sy, z = slice * sz**. The level 0.5 of the (smoothed) mask
        by marching cubes (scikit-image), then remeshed to near-uniform triangles of
        ``edge_length`` by CGAL's isotropic remeshing in the C++ core, which projects every
        vertex back onto the marching-cubes surface: the raw surface's slivers (which make
        3D quality measures explode) are gone, its shape is kept. Detail much finer than the
        edge length cannot be kept by such triangles, so the mask is first averaged over blocks
        of about 3/4 of it (anti-aliasing its staircase). A ball of radius 20 um in a
        0.5 x 0.5 x 2 um stack, unsmoothed, at the default edge length: volume -0.7%, area
        +0.9%, every vertex within 0.7 um of the sphere. With triangles as fine as the voxels
        (``edge_length=1``) an unsmoothed surface follows the staircase (area 11% too large);
        ``smooth=1`` brings it back within 0.2%.
    """
    voxels = _object(volume, label, "volume", ndim=3)
    _warn_at_border(voxels, "volume")
    step = _spacing(spacing, 3)
    sigma = as_length(smooth, "smooth", 0.0, allow_zero=True)
    edge = as_length(edge_length, "edge_length", max(step))
    # Only the object's bounding box is labelled, averaged and contoured: an organ rarely fills
    # its stack, and every step below costs in proportion to the voxels.
    box = _bounding_box(voxels)
    corner = np.zeros(3) if box is None else np.array([b.start for b in box])
    voxels = voxels if box is None else voxels[box]
    _require_one_object(voxels, "volume")
    # Triangles of edge `edge` cannot hold detail much finer than the edge: contouring the image
    # averaged over blocks of about 3/4 of it (anti-aliased) hands the remesher about as many
    # triangles as it will make, most of them a little short, so that it mostly collapses edges;
    # finer blocks leave it many more to collapse, blocks of the whole edge many to split, both
    # slower (bench/README.md).
    factors = tuple(max(1, int(0.75 * edge / h)) for h in step)
    # One whole block of padding on each side closes the surface of an object touching the border:
    # the outermost samples are then empty blocks (one voxel would share a block with the object
    # and could average above 0.5). The Gaussian needs none (see boundary_from_mask). The far side
    # gets what makes each axis a whole number of blocks.
    pads = factors
    padded = np.pad(voxels, [(f, f + -n % f) for n, f in zip(voxels.shape, factors)])
    # Cavities are the background not connected to the outside (the padded corner); labelling
    # finds them 4x faster than scipy's binary_fill_holes.
    background, pieces = ndimage.label(~padded)
    filled = padded if pieces == 1 else background != background[0, 0, 0]
    del background
    # The Gaussian, a convolution like the block mean, runs after it on the blocks' grid: a few
    # times fewer voxels.
    image = _block_mean(filled, factors)
    grid = tuple(h * f for h, f in zip(step, factors))
    if sigma > 0:
        image = ndimage.gaussian_filter(image, tuple(sigma / g for g in grid), mode="constant")
    if image.max() <= 0.5:
        raise ValueError(f"volume: the object vanishes when smoothed by {sigma}: use a smaller smooth=")
    vertices, faces, _, _ = measure.marching_cubes(image, 0.5, spacing=grid)
    # (z, y, x) -> (x, y, z); a block's sample sits at the centre of its voxels, and the padding is
    # taken off and the box's corner put back, so that coordinates are the volume's.
    origin = np.array([((f - 1) / 2 - pad + c) * h for h, f, pad, c in zip(step, factors, pads, corner)])
    vertices = np.ascontiguousarray((vertices + origin)[:, ::-1])
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    try:
        remeshed = _core.remesh_surface(vertices, faces, edge, REMESH_ROUNDS)
        vertices, faces = remeshed["vertices"], remeshed["faces"]
    except ValueError as error:
        if "several connected components" not in str(error):
            raise
        raise ValueError(f"smooth: a Gaussian of width {sigma} splits the object into pieces: "
                         f"use a smaller smooth=") from None
    surface = trimesh.Trimesh(vertices, faces, process=False)
    if surface.volume < 0:
        surface.invert()
    return surface
