"""`mbjax_harness.parallel.run`: tasks in worker processes with the parent's JAX settings, results by
key, a worker's exception raised in the parent, and the progress it reports."""

import os

import jax
import pytest

from mbjax_harness import parallel, progress


def _worker_facts(key):
    """What a task sees: its process, the precision arrays get, the compilation cache. It reports
    a step, as `mbjax_harness.timing.measure` does."""
    progress.step(f"looking at {key}")
    return {"key": key, "pid": os.getpid(), "dtype": jax.numpy.ones(1).dtype.name,
            "cache": jax.config.jax_compilation_cache_dir}


def _fails_on_two(key):
    if key == 2:
        raise ValueError(f"task {key} failed")
    return key


def test_workers_get_the_parents_settings(capsys, monkeypatch):
    monkeypatch.setattr(progress.Board, "log_every", 0.0)      # every step on its own line
    facts = parallel.run(_worker_facts, ["a", "b", "c"], jobs=2, desc="facts")
    assert sorted(facts) == ["a", "b", "c"]
    assert all(f["key"] == key for key, f in facts.items())
    assert all(f["pid"] != os.getpid() for f in facts.values())
    assert all(f["dtype"] == "float64" for f in facts.values())           # x64, as here
    assert all(f["cache"] == jax.config.jax_compilation_cache_dir for f in facts.values())
    err = capsys.readouterr().err                   # not a terminal: a line per event
    assert all(f"{key} started" in err and f"{key} done in" in err for key in "abc")
    assert all(f"{key} step 1: looking at {key}" in err for key in "abc")   # a worker's steps
    assert "facts [########################] 3/3 done in" in err


def test_one_job_runs_here_in_order(capsys, monkeypatch):
    monkeypatch.setattr(progress.Board, "log_every", 0.0)
    facts = parallel.run(_worker_facts, [3, 1, 2], jobs=1)
    assert list(facts) == [3, 1, 2] and {f["pid"] for f in facts.values()} == {os.getpid()}
    err = capsys.readouterr().err
    assert "3/3 done in" in err and "2 step 1: looking at 2" in err


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_tasks_exception_reaches_the_caller(jobs):
    with pytest.raises(ValueError, match="task 2 failed"):
        parallel.run(_fails_on_two, [1, 2, 3], jobs=jobs)


def test_jobs_below_one_are_refused():
    with pytest.raises(ValueError, match="jobs must be at least 1"):
        parallel.run(_worker_facts, ["a"], jobs=0)
