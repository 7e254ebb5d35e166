"""Segmented images in: reading masks, stacks and movies with their axes, spacing, unit and frame
interval, and the boundary of a mask as a curve (2D) or a remeshed surface (3D)."""

from .masks import boundary_from_mask, surface_from_mask
from .read import Image, read_image

__all__ = ["Image", "boundary_from_mask", "read_image", "surface_from_mask"]
