"""Progress bars of the long calls (3D diffusion and mapping, series, batches): one rule for all.

``progress=None`` shows a tqdm bar on stderr once a call has run for 3 seconds, and only when
stderr is a terminal; ``True`` shows it at once, anywhere; ``False`` never. Progress is a
courtesy: it never changes a result.
"""

from __future__ import annotations

import sys

import numpy as np
from tqdm import tqdm

DELAY = 3.0  # seconds before a bar appears with progress=None


def as_progress(value) -> bool | None:
    if value is not None and not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"progress: expected True, False or None, got {type(value).__name__}")
    return None if value is None else bool(value)


def _tqdm(progress, **options):
    """A tqdm bar, or None where the rule says no bar."""
    if progress is False or (progress is None and not sys.stderr.isatty()):
        return None
    return tqdm(delay=0 if progress else DELAY, **options)


def progress_over(iterable, total, progress, description, unit):
    """``iterable`` with a bar counting its items, or itself where the rule says no bar."""
    bar = _tqdm(as_progress(progress), iterable=iterable, total=total, desc=description, unit=unit)
    return iterable if bar is None else bar


class StageBar:
    """A bar over the named stages of one call into the core: ``on_stage`` (the core's callback,
    or None when no bar is shown) moves it to the stage that begins; ``close`` fills it."""

    def __init__(self, progress, description, stages):
        self.stages = tuple(stages)
        self.bar = _tqdm(as_progress(progress), total=len(self.stages), desc=description, unit="stage") \
            if self.stages else None

    @property
    def callback(self):
        return self._on_stage if self.bar is not None else None

    def _on_stage(self, stage):
        if stage in self.stages:  # a stage may come again (auto's second diffusion): the bar goes back
            done = self.stages.index(stage)
            self.bar.update(done - self.bar.n)
        self.bar.set_postfix_str(stage)

    def close(self):
        if self.bar is not None:
            self.bar.update(len(self.stages) - self.bar.n)
            self.bar.close()
