"""Batches on Dask distributed: a local cluster of worker processes; failures and dead workers."""

import os
import signal

import numpy as np
import pytest

import morphomap as mm
from conftest import circle, require_client
from morphomap.batch import Job

try:
    import distributed  # noqa: F401

    HAVE_DASK = True
except ImportError:
    HAVE_DASK = False


@pytest.fixture
def frames(tmp_path):
    paths = []
    for k in range(4):
        path = tmp_path / f"t{k}.csv"
        mm.write_curve(path, circle(150, 1.0 + 0.25 * k) * [1.0, 1.0 + 0.1 * k])
        paths.append(str(path))
    (tmp_path / "bad.csv").write_text("x,y\n0,0\n")
    return tmp_path, paths


def test_jobs_run_fail_alone_and_are_skipped_on_rerun(frames):
    require_client(HAVE_DASK, "Dask distributed")
    folder, paths = frames
    jobs = [Job(paths[k], paths[k + 1], str(folder / f"field{k}.csv")) for k in range(3)]
    jobs.append(Job(paths[0], str(folder / "bad.csv"), str(folder / "bad_field.csv")))
    results = mm.map_batch(jobs, workers=2, progress=False)
    assert [r.status for r in results] == ["done", "done", "done", "failed"]
    assert "c2: a closed curve needs at least 3 points" in results[3].message
    assert not (folder / "bad_field.csv").exists()
    field = mm.read_field(folder / "field1.csv")
    assert field.valid.all() and len(field) == 150
    again = mm.map_batch(jobs, workers=2, progress=False)
    assert [r.status for r in again] == ["skipped", "skipped", "skipped", "failed"]


def test_a_dead_worker_fails_its_job_only(frames):
    require_client(HAVE_DASK, "Dask distributed")
    folder, paths = frames

    def task(job):  # pickled by value into the worker
        from morphomap import _core
        from morphomap.batch import run_job

        if job.output.endswith("crash.csv"):
            os.kill(os.getpid(), signal.SIGSEGV)
        return f"{run_job(job)}; threads {_core.active_threads()}"

    jobs = [Job(paths[0], paths[1], str(folder / "crash.csv")), Job(paths[1], paths[2], str(folder / "fine.csv"))]
    results = mm.map_batch(jobs, workers=2, progress=False, task=task)
    assert results[0].status == "failed" and "KilledWorker" in results[0].message
    assert results[1].status == "done" and np.isfinite(mm.read_field(folder / "fine.csv").ends).all()
    # The two workers share the cores: each runs the core's threads on its half.
    assert results[1].message.endswith(f"; threads {max(1, os.cpu_count() // 2)}"), results[1].message


def test_progress_bar_only_when_asked(frames, capfd):
    require_client(HAVE_DASK, "Dask distributed")
    folder, paths = frames
    jobs = [Job(paths[k], paths[k + 1], str(folder / f"p{k}.csv")) for k in range(2)]
    mm.map_batch(jobs, workers=2, progress=True)
    assert "map_batch: 100%" in capfd.readouterr().err
    jobs = [Job(paths[k], paths[k + 1], str(folder / f"q{k}.csv")) for k in range(2)]
    mm.map_batch(jobs[:1], workers=1, progress=False)
    mm.map_batch(jobs[1:], workers=1)  # stderr is not a terminal here
    assert "map_batch" not in capfd.readouterr().err
