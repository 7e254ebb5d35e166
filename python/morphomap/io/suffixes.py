"""The file suffixes of each kind of boundary: a module without imports, so that telling a file's
kind (:func:`morphomap.io.frames.read_boundary`) loads no reader it does not need."""

#: Closed surfaces: mesh files (:func:`morphomap.read_surface`, :func:`morphomap.write_surface`).
SURFACE_SUFFIXES = (".stl", ".ply", ".obj", ".off")
#: Segmented images: masks and stacks (:func:`morphomap.read_image`).
IMAGE_SUFFIXES = (".png", ".tif", ".tiff", ".npy")
