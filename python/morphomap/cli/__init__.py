"""The ``morphomap`` command: ``demo``, ``map``, ``extend``, ``series`` and ``batch``."""

from .main import main

__all__ = ["main"]
