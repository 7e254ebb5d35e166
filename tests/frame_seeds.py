"""What every frame generator shares: the styles and how a seed picks its style and its random stream."""

from __future__ import annotations

import numpy as np

STYLES = ("careful", "raw")


def rng_of(seed: int, dim: int) -> np.random.Generator:
    return np.random.default_rng([int(seed), 1000 + dim])


def style_of(seed: int) -> str:
    """Which style a seed gets: one in four is raw."""
    return "raw" if int(seed) % 4 == 3 else "careful"
