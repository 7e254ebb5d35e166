"""The method "best", which Python adds to the core's method table.

It runs the core's methods and keeps the best field (:mod:`morphomap.best`), so it sits above the
mappings that it calls and registers its functions here when it is imported; morphomap's
``__init__`` imports it. :func:`map_curves` and :func:`map_surfaces` find it here.
"""

#: The name that ``map_curves`` and ``map_surfaces`` take for it.
BEST = "best"
#: The function each mapping calls for :data:`BEST`: ``"curves"`` (``map_curves``) and
#: ``"surfaces"`` (``map_surfaces``), filled by :mod:`morphomap.best`.
CHOOSERS = {}
