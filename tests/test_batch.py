"""Batches on Dask distributed: a local cluster of worker processes; failures, dead and killed
workers, reruns that skip only unchanged rows, the manifest's columns and the summary table."""

import csv
import os
import signal
import threading
import time

import numpy as np
import pytest

import morphomap as mm
from conftest import circle, morphomap, require_client
from morphomap.batch import Job, describe
from morphomap.batch_manifest import read_manifest
from morphomap.batch_record import read_sidecar, sidecar_path

try:
    import dask
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
    # A skipped row keeps the quality its run reported.
    assert again[1].quality == results[1].quality and again[1].message.endswith(results[1].message)


def test_a_dead_worker_fails_its_job_only(frames):
    require_client(HAVE_DASK, "Dask distributed")
    folder, paths = frames

    def task(job):  # pickled by value into the worker
        from morphomap import _core
        from morphomap.batch import run_job

        if job.output.endswith("crash.csv"):
            os.kill(os.getpid(), signal.SIGSEGV)
        return f"{describe(run_job(job))}; threads {_core.active_threads()}"

    jobs = [Job(paths[0], paths[1], str(folder / "crash.csv")), Job(paths[1], paths[2], str(folder / "fine.csv"))]
    results = mm.map_batch(jobs, workers=2, progress=False, task=task)
    # The crash had begun: it fails at once, not tried on the next worker.
    assert results[0].status == "failed" and "KilledWorker" in results[0].message and results[0].attempts == 1
    assert results[1].status == "done" and np.isfinite(mm.read_field(folder / "fine.csv").ends).all()
    # The two workers share the cores: each runs the core's threads on its half.
    assert results[1].message.endswith(f"; threads {max(1, os.cpu_count() // 2)}"), results[1].message


def test_a_killed_worker_fails_the_running_job_and_its_waiting_jobs_run_elsewhere(frames):
    require_client(HAVE_DASK, "Dask distributed")
    folder, paths = frames
    flag = str(folder / "victim.pid")

    def task(job):  # pickled by value into the worker
        from morphomap.batch import run_job

        if job.label == "victim":  # waits, running, until the test kills its worker
            with open(flag + ".part", "w") as handle:
                handle.write(str(os.getpid()))
            os.replace(flag + ".part", flag)
            time.sleep(120)
        return run_job(job)

    killed = []

    def kill_the_victim():
        deadline = time.monotonic() + 60
        while not os.path.exists(flag) and time.monotonic() < deadline:
            time.sleep(0.02)
        if os.path.exists(flag):
            pid = int(open(flag).read())
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    jobs = [Job(paths[0], paths[1], str(folder / "victim.csv"), label="victim")]
    jobs += [Job(paths[k % 3], paths[k % 3 + 1], str(folder / f"f{k}.csv")) for k in range(5)]
    killer = threading.Thread(target=kill_the_victim)
    killer.start()
    # No work stealing: the scheduler keeps on the victim's worker the job it handed it to run
    # next, so that the kill takes a job that had not begun.
    with dask.config.set({"distributed.scheduler.work-stealing": False}):
        results = mm.map_batch(jobs, workers=2, progress=False, task=task)
    killer.join()
    assert killed, "the victim job never started"
    assert [r.status for r in results] == ["failed"] + ["done"] * 5, [r.message for r in results]
    assert "KilledWorker" in results[0].message and results[0].attempts == 1
    # The job waiting on the killed worker was run again, once, elsewhere.
    assert sorted(r.attempts for r in results[1:]) == [1, 1, 1, 1, 2]
    for r in results[1:]:
        assert mm.read_field(r.job.output).valid.all()


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


def test_a_rerun_recomputes_exactly_the_rows_whose_inputs_or_options_changed(frames):
    require_client(HAVE_DASK, "Dask distributed")
    folder, paths = frames
    jobs = [Job(paths[k], paths[k + 1], str(folder / f"r{k}.csv")) for k in range(3)]
    jobs.append(Job(paths[0], paths[2], str(folder / "r3.csv")))
    assert [r.status for r in mm.map_batch(jobs, workers=1, progress=False)] == ["done"] * 4
    assert read_sidecar(jobs[0].output)["fingerprint"]["method"] == "auto"
    before = [os.stat(job.output).st_mtime_ns for job in jobs]
    later = time.time() + 5
    os.utime(paths[0], (later, later))  # touched, content unchanged: rows 0 and 3 still match
    jobs[1].method = "normal"  # row 1's options change
    mm.write_curve(paths[3], circle(150, 2.5))  # row 2's second frame is rewritten with another curve
    os.unlink(sidecar_path(jobs[3].output))  # row 3's output no longer says what made it
    again = mm.map_batch(jobs, workers=2, progress=False)
    assert [r.status for r in again] == ["skipped", "done", "done", "done"]
    assert os.stat(jobs[0].output).st_mtime_ns == before[0]
    assert mm.read_field(jobs[1].output).method[0] == "normal"
    assert np.allclose(np.linalg.norm(mm.read_field(jobs[2].output).ends, axis=1), 2.5, atol=1e-3)
    assert [r.status for r in mm.map_batch(jobs, workers=1, progress=False)] == ["skipped"] * 4


def test_bad_jobs_are_refused_naming_the_job(frames):
    folder, paths = frames
    with pytest.raises(ValueError, match=r"jobs\[1\].output: .* is also jobs\[0\]'s output"):
        mm.map_batch([Job(paths[0], paths[1], str(folder / "o.csv"))] * 2, progress=False)
    with pytest.raises(ValueError, match=r"jobs\[0\].spacing: expected None or 1-3 finite lengths > 0"):
        mm.map_batch([Job(paths[0], paths[1], str(folder / "o.csv"), spacing=(0.0,))], progress=False)
    with pytest.raises(ValueError, match=r"jobs\[0\].smooth"):
        mm.map_batch([Job(paths[0], paths[1], str(folder / "o.csv"), smooth=-1)], progress=False)
    with pytest.raises(ValueError, match=r"workers: expected None or a whole number of at least 1, got 0"):
        mm.map_batch([Job(paths[0], paths[1], str(folder / "o.csv"))], workers=0, progress=False)


def test_manifest_rows_name_the_bad_row_and_column(tmp_path):
    manifest = tmp_path / "m.csv"
    cases = {
        "c1,c2,spacing\na.npy,b.npy,0.5 x\n": r"row 1, column spacing: expected lengths > 0, got 'x'",
        "c1,c2,smooth\na.npy,b.npy,-1\n": r"row 1, column smooth: expected a width >= 0",
        "c1,c2,method\na,b,\na,b,nope\n": r"row 2, column method: expected one of",
        "c1,c2,label\na,b,x\na,b,x\n": r"row 2, column label: 'x' is row 1's label too",
        "c1,c2,label\na,b,../x\n": r"row 1, column label: expected a file-name-safe name",
        "c1,c2,size\na,b,1\n": r"unknown column 'size'",
        "c1,c2,label\na,b,c,d\n": r"row 1: 4 values for the 3 columns",
        "c1,c2\na,b,c,d\n": r"row 1: expected c1,c2\[,method\]",
        "a,b,c,d\n": r"row 1: expected c1,c2\[,method\]",
        "label,c1,c2\nx,,b\n": r"row 1, column c1: the frame file is missing",
    }
    for text, message in cases.items():
        manifest.write_text(text)
        with pytest.raises(ValueError, match=message):
            read_manifest(manifest, tmp_path / "out", methods=("auto", "normal"))


def test_batch_command_one_worker_manifest_columns_and_summary(tmp_path):
    require_client(HAVE_DASK, "Dask distributed")
    rows, columns = np.mgrid[0:80, 0:80]
    for name, radius in (("small", 15), ("large", 25)):
        np.save(tmp_path / f"{name}.npy", ((rows - 40) ** 2 + (columns - 40) ** 2 <= radius**2).astype(np.uint8))
    mm.write_curve(tmp_path / "c.csv", circle(100))
    (tmp_path / "bad.csv").write_text("x,y\n0,0\n")
    (tmp_path / "jobs.csv").write_text(
        "label,c1,c2,method,spacing,smooth\n"
        "unit,small.npy,large.npy,normal,,\n"
        "half,small.npy,large.npy,,0.5,0\n"
        "broken,c.csv,bad.csv,,,\n"
    )
    command = ["batch", tmp_path / "jobs.csv", "--out", tmp_path / "b", "--workers", "1", "--method", "diffusion",
               "--no-progress"]
    done = morphomap(*command)
    assert done.returncode == 1 and "3 jobs: 2 done or skipped, 1 failed (0 skipped" in done.stderr, done.stderr
    unit, half = mm.read_field(tmp_path / "b" / "unit.csv"), mm.read_field(tmp_path / "b" / "half.csv")
    assert unit.method[0] == "normal" and half.method[0] == "diffusion"  # the row's method, else --method
    # Spacing 0.5, smoothing 0: the pixel outline at half the size.
    assert np.ptp(half.starts[:, 0]) == pytest.approx(np.ptp(unit.starts[:, 0]) / 2, rel=0.1)
    assert np.ptp(half.starts[:, 0]) == pytest.approx(15, abs=1)
    with open(tmp_path / "b" / "summary.csv", newline="") as handle:
        table = list(csv.DictReader(handle))
    assert [(r["label"], r["status"]) for r in table] == [("unit", "done"), ("half", "done"), ("broken", "failed")]
    assert table[0]["c1"] == str(tmp_path / "small.npy") and table[0]["output"] == str(tmp_path / "b" / "unit.csv")
    for r in table[:2]:
        assert 0 <= float(r["qm"]) < 1 and r["defect_kind"] == "crossings" and float(r["seconds"]) > 0
        assert int(r["missed"]) == 0 and int(r["defects"]) == 0 and r["attempts"] == "1"
    assert table[2]["qm"] == "" and "at least 3 points" in table[2]["message"]
    again = morphomap(*command)
    assert "3 jobs: 2 done or skipped, 1 failed (2 skipped" in again.stderr, again.stderr
    with open(tmp_path / "b" / "summary.csv", newline="") as handle:
        assert [r["qm"] for r in csv.DictReader(handle)] == [r["qm"] for r in table]
