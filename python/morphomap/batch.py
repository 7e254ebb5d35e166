"""Batches of mappings on Dask distributed: a local cluster of worker processes, or yours.

Each job maps one pair of frame files and writes its field, with a sidecar saying what made it
(:mod:`morphomap.batch_record`); a rerun skips a job only when its inputs' contents and its options
are those of the sidecar. A job that fails is reported with its error while the others finish. A
worker process that dies (``kill -9``, a crash in a native library) fails the job it was running;
the jobs it held that had not begun are run again elsewhere.
"""

from __future__ import annotations

import math
import os
import time
import uuid
from dataclasses import dataclass
from numbers import Real

import dask
import numpy as np
from distributed import Client, LocalCluster, WorkerPlugin, as_completed
from distributed.scheduler import KilledWorker

from . import _core
from ._progress import _tqdm, as_progress
from .batch_record import fingerprint, remove_sidecar, up_to_date, write_sidecar, write_summary
from .io import write_field
from .io.frames import read_boundary
from .mapping import map_curves
from .quality import quality
from .surfaces import map_surfaces

# A job is run at most this many times when its workers die before it begins (a worker that
# dies takes with it the jobs the scheduler had already handed to it).
ATTEMPTS = 3


@dataclass
class Job:
    """One pair: frame files ``c1`` and ``c2`` (curves, surfaces, masks or stacks), the field
    written to ``output`` (any suffix :func:`morphomap.write_field` takes), and the options:
    ``method``, the masks' ``spacing`` (None: what the file states) and ``smooth`` (None: the
    reader's default), as :func:`morphomap.io.frames.read_boundary` takes them. ``label`` names the
    row in the summary table (default: empty)."""

    c1: str
    c2: str
    output: str
    method: str = "auto"
    spacing: tuple | None = None
    smooth: float | None = 0.0
    label: str = ""


@dataclass
class JobResult:
    """A job's outcome. ``status``: "done", "skipped" (its output was made from the same inputs
    and options) or "failed"; ``message``: the summary line, or the error. ``quality``: QM1, QM2,
    QM, defects (crossings or folds), missed and vectors, as the job reported them (a skipped job:
    as its sidecar kept them; None when unknown). ``seconds``: the job's own time in its worker.
    ``attempts``: how many times it was handed to a worker (0: skipped)."""

    job: Job
    status: str
    message: str = ""
    quality: dict | None = None
    seconds: float = math.nan
    attempts: int = 0


def run_job(job: Job) -> dict:
    """Map one job in this process and write its field; returns its quality (``vectors``,
    ``missed``, ``qm1``, ``qm2``, ``qm``, ``defects`` and ``defect_kind``: "crossings" in 2D,
    "folds" in 3D). Raises on failure."""
    (b1, _), (b2, _) = (read_boundary(p, spacing=job.spacing, smooth=job.smooth) for p in (job.c1, job.c2))
    if isinstance(b1, np.ndarray):
        field = map_curves(b1, b2, job.method)
    else:
        field = map_surfaces(b1, b2, job.method)
    q = quality(field, b1, b2)
    write_field(job.output, field)
    kind = "crossings" if field.dim == 2 else "folds"
    return {"vectors": len(field), "missed": int((~field.valid).sum()), "qm1": float(q.qm1), "qm2": float(q.qm2),
            "qm": float(q.qm), "defects": int(getattr(q, kind)), "defect_kind": kind}


def describe(report: dict) -> str:
    """The one-line summary of :func:`run_job`'s quality."""
    return (f"{report['vectors']} vectors, {report['missed']} missed, QM {report['qm']:.4g}, "
            f"{report['defect_kind']} {report['defects']}")


def _announce(topic: str, key: str) -> None:
    """Tell the scheduler, and wait until it has heard, that this attempt begins: when its worker
    dies, the client then knows whether the job was running (failed) or only waiting (run again)."""
    from distributed import get_worker
    from distributed.utils import sync

    try:
        worker = get_worker()
    except ValueError:  # not in a worker (a synchronous scheduler): nothing can die under it
        return
    sync(worker.loop, worker.scheduler.log_event, topic=topic, msg=key)


def _attempt(work, job: Job, print_: dict, topic: str, key: str) -> dict:
    """One job in a worker: ``work(job)`` between the announcement of its start and the sidecar
    recording what made its output."""
    _announce(topic, key)
    remove_sidecar(job.output)
    start = time.perf_counter()
    out = work(job)
    seconds = time.perf_counter() - start
    report = {"message": describe(out), "quality": out} if isinstance(out, dict) else \
        {"message": str(out), "quality": None}
    report["seconds"] = seconds
    if os.path.exists(job.output):
        write_sidecar(job.output, print_, report)
    return report


class ShareCores(WorkerPlugin):
    """Each worker of a local cluster runs the core's threads (TBB, and Embree on it) on its share
    of the cores: with as many single-threaded workers as cores, every worker's TBB would start a
    thread per core, and the workers' threads would fight over the cores. The worker unpickles the
    plugin while it starts, which imports this module and the core; ``setup`` imports the readers
    too (trimesh, SciPy), so that the first job does not wait for them."""

    name = "morphomap-share-cores"

    def __init__(self, threads: int):
        self.threads = threads

    def setup(self, worker):
        _core.limit_threads(self.threads)
        import scipy.spatial  # noqa: F401
        import trimesh  # noqa: F401


def _task_name(work) -> str:
    return f"{getattr(work, '__module__', '?')}.{getattr(work, '__qualname__', type(work).__name__)}"


def _check(k: int, job) -> None:
    if not isinstance(job, Job):
        raise TypeError(f"jobs[{k}]: expected a morphomap.batch.Job, got {type(job).__name__}")
    for name in ("c1", "c2", "output", "method", "label"):
        if not isinstance(getattr(job, name), (str, os.PathLike)):
            raise TypeError(f"jobs[{k}].{name}: expected a string, got {type(getattr(job, name)).__name__}")
    spacing = job.spacing
    if spacing is not None and (isinstance(spacing, (str, bytes)) or not hasattr(spacing, "__len__")
                                or len(spacing) not in (1, 2, 3)
                                or not all(isinstance(s, Real) and 0 < s < math.inf for s in spacing)):
        raise ValueError(f"jobs[{k}].spacing: expected None or 1-3 finite lengths > 0, got {spacing!r}")
    if job.smooth is not None and not (isinstance(job.smooth, Real) and 0 <= job.smooth < math.inf):
        raise ValueError(f"jobs[{k}].smooth: expected None or a finite width >= 0, got {job.smooth!r}")


def _local_cluster(count: int):
    cluster = LocalCluster(n_workers=count, threads_per_worker=1, processes=True, dashboard_address=None,
                           plugins={ShareCores(max(1, (os.cpu_count() or 1) // count))})
    return cluster, Client(cluster)


def map_batch(jobs, client=None, *, workers=None, progress=None, task=None, summary=None) -> list:
    """Run ``jobs`` (a list of :class:`Job`) as Dask tasks; returns one :class:`JobResult` each.

    Parameters
    ----------
    jobs : list of Job
        The pairs; no two may write the same output.
    client : distributed.Client, optional
        E.g. ``Client("tcp://scheduler:8786")`` for a cluster. By default a local cluster of
        ``workers`` processes (one thread each) is started and closed, each worker's core using
        its share of the cores (a job's result does not depend on it).
    workers : int, optional
        Worker processes of the local cluster (default: one per core, at most one per job).
    progress : bool, optional
        A bar counting the jobs: by default on a terminal once the batch has run for 3 seconds
        (``True``: at once, ``False``: never).
    task : callable, optional
        What each job runs in its worker (default :func:`run_job`): it gets the job, writes
        ``job.output`` atomically and returns its quality (a dict as :func:`run_job`'s) or a
        summary line.
    summary : path, optional
        A CSV file to write the table of all jobs into (see :func:`batch_record.write_summary`).

    Notes
    -----
    A job is skipped when its output exists with a sidecar whose fingerprint (the inputs' content
    hashes and the job's options) is the job's; otherwise it runs, and its output and sidecar are
    replaced. A worker that dies fails the job it was running (it may be what killed it: a crash in
    a native library would kill the next worker too); the jobs the scheduler had handed it that
    had not begun are submitted again, up to :data:`ATTEMPTS` times. On the local cluster the
    scheduler itself retries nothing (``distributed.scheduler.allowed-failures`` 0); a ``client``'s
    scheduler retries a dead worker's tasks as its own setting says (Dask's default: 3 times),
    so set it to 0 there for the same behaviour.
    """
    jobs = list(jobs)
    progress = as_progress(progress)
    if workers is not None and (not isinstance(workers, (int, np.integer)) or isinstance(workers, bool)
                                or workers < 1):
        raise ValueError(f"workers: expected None or a whole number of at least 1, got {workers!r}")
    for k, job in enumerate(jobs):
        _check(k, job)
    outputs = {}
    for k, job in enumerate(jobs):
        other = outputs.setdefault(os.path.abspath(os.fspath(job.output)), k)
        if other != k:
            raise ValueError(f"jobs[{k}].output: {job.output} is also jobs[{other}]'s output; give each job its own")
    work = run_job if task is None else task
    digests, prints, results, pending = {}, {}, {}, []
    for k, job in enumerate(jobs):
        prints[k] = fingerprint(job, _task_name(work), digests)
        kept = up_to_date(job, prints[k])
        if kept is None:
            pending.append(k)
        else:
            results[k] = JobResult(job, "skipped", f"inputs and options unchanged: {kept.get('message', '')}",
                                   kept.get("quality"), kept.get("seconds", math.nan))
    if pending:
        _run(jobs, pending, prints, results, work, client, workers, progress)
    ordered = [results[k] for k in range(len(jobs))]
    if summary is not None:
        write_summary(summary, ordered)
    return ordered


def _run(jobs, pending, prints, results, work, client, workers, progress) -> None:
    own = client is None
    # A worker's statistical profiler samples its threads every 10 ms for a dashboard that our
    # own cluster does not serve: off there.
    settings = {"distributed.scheduler.allowed-failures": 0}
    if own:
        settings["distributed.worker.profile.enabled"] = False
    token = uuid.uuid4().hex[:12]
    topic = f"morphomap-started-{token}"
    attempts = dict.fromkeys(pending, 0)
    with dask.config.set(settings):
        if own:
            cluster, client = _local_cluster(workers or min(len(pending), os.cpu_count() or 1))
        bar = _tqdm(progress, total=len(pending), desc="map_batch", unit="job")
        try:
            def submit(k):
                attempts[k] += 1
                key = f"morphomap-job-{token}-{k}-{attempts[k]}"
                future = client.submit(_attempt, work, jobs[k], prints[k], topic, key, pure=False, key=key)
                futures[future] = (k, key)
                return future

            futures = {}
            running = as_completed([submit(k) for k in pending])
            for future in running:
                k, key = futures.pop(future)
                try:
                    report = future.result()
                except Exception as error:  # the job's own error, or KilledWorker when its process died
                    if isinstance(error, KilledWorker) and attempts[k] < ATTEMPTS and \
                            key not in {msg for _, msg in client.get_events(topic)}:
                        running.add(submit(k))  # it had not begun: its worker died under another job
                        continue
                    results[k] = JobResult(jobs[k], "failed", f"{type(error).__name__}: {error}", attempts=attempts[k])
                else:
                    results[k] = JobResult(jobs[k], "done", report["message"], report["quality"],
                                           report["seconds"], attempts[k])
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
            if own:
                client.close()
                cluster.close()
