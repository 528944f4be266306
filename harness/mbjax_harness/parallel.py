"""Independent tasks side by side, one worker process per core, with live progress.

Most of what a JAX program costs before it runs is single-threaded Python and compiler work:
tracing, lowering, XLA's compile of each program (or, with the persistent cache, finding and
loading it). One process uses one core for all of it, so `mbjax tour` runs its scenes in worker
processes, as many at a time as there are cores (measured in benchmarks/README.md, compile
section). A worker starts with the parent's JAX settings (float64, the persistent compilation
cache) and keeps them for all its tasks; the programs a worker compiles reach the others through
that cache.

Run times measured inside a task are each measured on one core while the other cores run other
tasks; `jobs=1` runs everything in this process, one task after another.
"""

import multiprocessing
import os
import time
from collections.abc import Callable, Hashable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

from mbjax_harness import progress as _progress
from mbjax_harness.progress import Board, progress

# JAX settings a worker takes from the parent
_SETTINGS = ("jax_enable_x64", "jax_compilation_cache_dir",
             "jax_persistent_cache_min_compile_time_secs",
             "jax_persistent_cache_min_entry_size_bytes")
_events = None      # in a worker: the queue its start notices go to


def cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:      # not on Linux
        return os.cpu_count() or 1


def _settings() -> dict:
    import jax

    return {name: getattr(jax.config, name) for name in _SETTINGS}


def _start_worker(settings: dict, events) -> None:
    import jax

    global _events
    _events = events
    for name, value in settings.items():
        if value is not None:
            jax.config.update(name, value)


def _run(task: Callable, key: Hashable) -> tuple[float, object]:
    start = time.perf_counter()
    _events.put((key, start, None))
    _progress._sink = lambda what: _events.put((key, None, what))   # the task's steps
    try:
        return start, task(key)
    finally:
        _progress._sink = None


def run(task: Callable, keys: Sequence[Hashable], jobs: int | None = None,
        desc: str = "") -> dict:
    """{key: task(key)} for every key, `jobs` tasks at a time (default: one per core, at most
    one per key) in worker processes, started in the order of `keys` (longest first balances
    the load best); with one job, here, one after another. `task` must be picklable (a
    module-level function or a `functools.partial` of one). Progress goes to stderr: on a
    terminal one line, redrawn twice a second, naming the tasks running and their clocks;
    otherwise a line per task started and finished. A task's exception is raised here, the tasks
    not yet started cancelled."""
    if jobs is not None and jobs < 1:
        raise ValueError(f"jobs must be at least 1, got {jobs}")
    jobs = max(min(jobs or cores(), len(keys)), 1)
    if jobs == 1:
        return {key: task(key) for key in progress(keys, len(keys), desc)}
    board = Board(desc, len(keys))
    results = {}
    context = multiprocessing.get_context("spawn")      # JAX's threads do not survive a fork
    # a manager's queue: a worker's put returns once the notice is here, so a task's notices
    # arrive before its result (a plain Queue's feeder thread could deliver a step after it)
    manager = context.Manager()
    events = manager.Queue()
    with manager, ProcessPoolExecutor(jobs, context, initializer=_start_worker,
                                      initargs=(_settings(), events)) as pool:
        pending = {pool.submit(_run, task, key): key for key in keys}
        try:
            while pending:
                done, _ = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
                while not events.empty():
                    key, start, what = events.get()
                    if key in results:              # a notice may come after its result
                        continue
                    if start is not None:
                        board.started(key, start)
                    elif key in board.running:
                        board.step(key, what)
                for future in done:
                    key = pending.pop(future)
                    start, results[key] = future.result()
                    if key not in board.running:    # its result came before its notice
                        board.started(key, start)
                    board.finished(key, start)
                board.draw()
        except BrokenProcessPool as error:
            raise RuntimeError(
                "a worker process died: out of memory, or this was called from a script whose "
                "top-level code is not under `if __name__ == \"__main__\":` (a worker is a new "
                "Python that imports the main script); jobs=1 runs the tasks here") from error
        except BaseException:
            pool.shutdown(wait=False, cancel_futures=True)
            raise
    board.close()
    return results
