"""The set-up of map_batch's local worker processes (a module of its own: Dask is imported only
where a batch runs)."""

from __future__ import annotations

from distributed import WorkerPlugin


class ShareCores(WorkerPlugin):
    """Each worker of a local cluster runs the core's threads (TBB, and Embree on it) on its share
    of the cores: with as many single-threaded workers as cores, every worker's TBB would start a
    thread per core, and the workers' threads would fight over the cores. Importing the core here
    also loads it while the worker starts, before its first job."""

    name = "morphomap-share-cores"

    def __init__(self, threads: int):
        self.threads = threads

    def setup(self, worker):
        from . import _core

        _core.limit_threads(self.threads)
