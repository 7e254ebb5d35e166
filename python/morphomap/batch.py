"""Batches of mappings on Dask distributed: a local cluster of worker processes, or yours.

Each job maps one pair of frame files and writes its field; a job that fails, or whose worker
process dies (a crash in a native library, say), is reported with its error while the others
finish. Outputs are written atomically, so a rerun skips the jobs whose output exists.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import dask
import numpy as np
from distributed import Client, LocalCluster, WorkerPlugin, as_completed

from . import _core
from ._progress import as_progress, progress_over
from .io import write_field
from .io.frames import read_boundary
from .mapping import map_curves
from .quality import quality
from .surfaces import map_surfaces


@dataclass
class Job:
    """One pair: frame files ``c1`` and ``c2`` (curves, surfaces, masks or stacks), the field
    written to ``output`` (any suffix :func:`morphomap.write_field` takes), and the options."""

    c1: str
    c2: str
    output: str
    method: str = "auto"
    spacing: tuple | None = None
    smooth: float = 0.0


@dataclass
class JobResult:
    job: Job
    status: str  # "done", "skipped" (its output existed) or "failed"
    message: str = ""  # the summary, or the error


def run_job(job: Job) -> str:
    """Map one job in this process; returns a one-line summary. Raises on failure."""
    (b1, _), (b2, _) = (read_boundary(p, spacing=job.spacing, smooth=job.smooth) for p in (job.c1, job.c2))
    if isinstance(b1, np.ndarray):
        field = map_curves(b1, b2, job.method)
    else:
        field = map_surfaces(b1, b2, job.method)
    q = quality(field, b1, b2)
    write_field(job.output, field)
    defects = f"crossings {q.crossings}" if field.dim == 2 else f"folds {q.folds}"
    return f"{len(field)} vectors, {int((~field.valid).sum())} missed, QM {q.qm:.4g}, {defects}"


class ShareCores(WorkerPlugin):
    """Each worker of a local cluster runs the core's threads (TBB, and Embree on it) on its share
    of the cores: with as many single-threaded workers as cores, every worker's TBB would start a
    thread per core, and the workers' threads would fight over the cores. The worker unpickles the
    plugin while it starts, which imports this module and the core before its first job."""

    name = "morphomap-share-cores"

    def __init__(self, threads: int):
        self.threads = threads

    def setup(self, worker):
        _core.limit_threads(self.threads)


def map_batch(jobs, client=None, *, workers=None, progress=None, task=None) -> list:
    """Run ``jobs`` (a list of :class:`Job`) as Dask tasks; returns one :class:`JobResult` each.

    ``task``: the function each job runs in its worker (default :func:`run_job`; it gets the job
    and returns a summary line, writing ``job.output`` atomically).
    ``client``: a ``distributed.Client`` (e.g. ``Client("tcp://scheduler:8786")`` for a cluster);
    by default a local cluster of ``workers`` processes (one thread each; default: one per core,
    at most one per job) is started and closed, each worker's core using its share of the cores
    (one thread each when the workers fill them; a job's result does not depend on it).
    A task is not retried on another worker when its worker dies: the job is reported failed.
    ``progress``: a bar counting the jobs, by default on a terminal once the batch has run for 3
    seconds (``True``: at once, ``False``: never).
    """
    jobs = list(jobs)
    progress = as_progress(progress)
    results = {}
    pending = []
    for k, job in enumerate(jobs):
        if not isinstance(job, Job):
            raise TypeError(f"jobs[{k}]: expected a morphomap.batch.Job, got {type(job).__name__}")
        if os.path.exists(job.output):
            results[k] = JobResult(job, "skipped", "output exists")
        else:
            pending.append(k)
    if not pending:
        return [results[k] for k in range(len(jobs))]
    own = client is None
    # A worker's statistical profiler samples its threads every 10 ms for a dashboard that our
    # own cluster does not serve: off there.
    settings = {"distributed.scheduler.allowed-failures": 0}
    if own:
        settings["distributed.worker.profile.enabled"] = False
    with dask.config.set(settings):
        if own:
            count = workers or min(len(pending), os.cpu_count() or 1)
            cluster = LocalCluster(n_workers=count, threads_per_worker=1, processes=True, dashboard_address=None,
                                   plugins={ShareCores(max(1, (os.cpu_count() or 1) // count))})
            client = Client(cluster)
        try:
            work = run_job if task is None else task
            futures = {client.submit(work, jobs[k], pure=False, key=f"morphomap-job-{k}"): k for k in pending}
            for future in progress_over(as_completed(futures), len(futures), progress, "map_batch", "job"):
                k = futures[future]
                try:
                    results[k] = JobResult(jobs[k], "done", future.result())
                except Exception as error:  # the job's own error, or KilledWorker when its process died
                    results[k] = JobResult(jobs[k], "failed", f"{type(error).__name__}: {error}")
        finally:
            if own:
                client.close()
                cluster.close()
    return [results[k] for k in range(len(jobs))]
