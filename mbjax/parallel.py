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
import sys
import threading
import time
from collections.abc import Callable, Hashable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

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
    _events.put((key, start))
    return start, task(key)


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
    board = _Board(desc, len(keys))
    results = {}
    if jobs == 1:
        stop = threading.Event()
        ticker = threading.Thread(target=board.tick, args=(stop,), daemon=True)
        ticker.start()
        try:
            for key in keys:
                start = time.perf_counter()
                board.started(key, start)
                results[key] = task(key)
                board.finished(key, start)
        finally:
            stop.set()
            ticker.join()
        board.close()
        return results
    context = multiprocessing.get_context("spawn")      # JAX's threads do not survive a fork
    events = context.Queue()
    with ProcessPoolExecutor(jobs, context, initializer=_start_worker,
                             initargs=(_settings(), events)) as pool:
        pending = {pool.submit(_run, task, key): key for key in keys}
        try:
            while pending:
                done, _ = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
                while not events.empty():
                    board.started(*events.get())
                for future in done:
                    key = pending.pop(future)
                    start, results[key] = future.result()
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


class _Board:
    """The progress display of `run`."""

    width = 24

    def __init__(self, desc: str, total: int):
        self.desc, self.total, self.done = desc, total, 0
        self.start = time.perf_counter()
        self.running: dict = {}         # key: when it started
        self.ended: set = set()
        self.tty = sys.stderr.isatty()
        self.lock = threading.Lock()

    def _write(self, line: str, end: str = "") -> None:
        with self.lock:
            sys.stderr.write(("\r" + line + "\033[K" + end) if self.tty else line + "\n")
            sys.stderr.flush()

    def _bar(self) -> str:
        filled = self.width * self.done // self.total
        return f"{self.desc} [{'#' * filled}{'.' * (self.width - filled)}] {self.done}/{self.total}"

    def started(self, key, at: float) -> None:
        if key in self.ended:           # its notice came after its result
            return
        self.running[key] = at
        if not self.tty:
            self._write(f"{self._bar()} {key} started  {at - self.start:6.1f} s")
        self.draw()

    def finished(self, key, began: float) -> None:
        if key not in self.running:     # its result came before its notice
            self.started(key, began)
        self.running.pop(key)
        self.ended.add(key)
        self.done += 1
        if not self.tty:
            now = time.perf_counter()
            self._write(f"{self._bar()} {key} done in {now - began:.1f} s  {now - self.start:6.1f} s")
        self.draw()

    def draw(self) -> None:
        if self.tty:
            now = time.perf_counter()
            tasks = ", ".join(f"{key} {now - at:.0f} s" for key, at in list(self.running.items()))
            self._write(f"{self._bar()} {tasks}  {now - self.start:6.1f} s")

    def tick(self, stop: threading.Event) -> None:
        """Redraw twice a second until `stop` is set (a thread's target)."""
        while not stop.wait(0.5):
            self.draw()

    def close(self) -> None:
        self._write(f"{self.desc} [{'#' * self.width}] {self.total}/{self.total} "
                    f"done in {time.perf_counter() - self.start:.1f} s", end="\n")
