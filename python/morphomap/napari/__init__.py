"""morphomap in napari: a reader for label movies and mesh files, and a widget that maps a labels
movie through time, or one single-frame labels layer onto another, and shows its displacement
vectors, trajectories and growth.

An npe2 plugin (``napari.yaml`` beside this file; entry point group ``napari.manifest``, name
``morphomap``), installed with ``pip install "morphomap[napari]"``. ``import morphomap`` does not
import this package, nor napari: napari imports it when it loads the plugin.
"""
