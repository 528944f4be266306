"""Progress on stderr: which items run, how many are done, the steps inside each, the time spent.

On a terminal one line, redrawn twice a second, with the clock and the step counter of each item
running; otherwise (a log, a pipe) a line per item started and finished, and a line at most every
few seconds on the steps of one running.

Inside an item, `step(what)` counts a step and names it: `mbjax_harness.timing.measure` does so for every
run it times and `mbjax_harness.plot.animate` for every animation, so each scene, reproduction and
benchmark shows its progress without code of its own.
"""

import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator

_sink: Callable[[str], None] | None = None     # where `step` reports: the running item's board


def step(what: str) -> None:
    """Count one step of the item running now and name it (`what`, a few words) on the progress
    display; nothing outside `progress` and `mbjax_harness.parallel.run`."""
    if _sink is not None:
        _sink(what)


def progress(items: Iterable, total: int, desc: str = "") -> Iterator:
    """Yield from `items` one after another, reporting each (a thread redraws the running
    item's clock twice a second on a terminal)."""
    global _sink
    outer = _sink       # a progress inside another's item: its steps are that item's too
    board = Board(desc, total)
    stop = threading.Event()
    ticker = threading.Thread(target=board.tick, args=(stop,), daemon=True)
    ticker.start()
    try:
        for item in items:
            start = time.perf_counter()
            board.started(item, start)

            def report(what: str, item=item) -> None:
                board.step(item, what)
                if outer is not None:
                    outer(what)

            _sink = report
            yield item
            _sink = outer
            board.finished(item, start)
    finally:
        _sink = outer
        stop.set()
        ticker.join()
    board.close()


class Board:
    """A progress display of several items that may run at once (`mbjax_harness.parallel.run`): on a
    terminal one line, redrawn, naming the items running with their clocks; otherwise a line per
    item started and finished."""

    width = 24
    log_every = 5.0     # seconds between two lines on one item's steps in a log

    def __init__(self, desc: str, total: int):
        self.desc, self.total, self.done = desc, total, 0
        self.start = time.perf_counter()
        self.running: dict = {}         # key: when it started
        self.steps: dict = {}           # key: (steps so far, the last one's name)
        self.logged: dict = {}          # key: when its steps were last written to a log
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
        self.running[key] = at
        if not self.tty:
            self._write(f"{self._bar()} {key} started  {at - self.start:6.1f} s")
        self.draw()

    def step(self, key, what: str) -> None:
        """One more step of `key`, named `what`."""
        count = self.steps.get(key, (0, ""))[0] + 1
        self.steps[key] = (count, what)
        now = time.perf_counter()
        if self.tty:
            self.draw()
        elif key in self.running and now - self.logged.get(key, self.running[key]) >= self.log_every:
            self.logged[key] = now
            self._write(f"{self._bar()} {key} step {count}: {what}  {now - self.start:6.1f} s")

    def _task(self, key, at: float, now: float) -> str:
        count, what = self.steps.get(key, (0, ""))
        return f"{key} {now - at:.0f} s" + (f" (step {count}: {what})" if count else "")

    def finished(self, key, began: float) -> None:
        self.running.pop(key, None)
        self.done += 1
        if not self.tty:
            now = time.perf_counter()
            self._write(f"{self._bar()} {key} done in {now - began:.1f} s  {now - self.start:6.1f} s")
        self.draw()

    def draw(self) -> None:
        if self.tty:
            now = time.perf_counter()
            tasks = ", ".join(self._task(key, at, now) for key, at in list(self.running.items()))
            self._write(f"{self._bar()} {tasks}  {now - self.start:6.1f} s")

    def tick(self, stop: threading.Event) -> None:
        """Redraw twice a second until `stop` is set (a thread's target)."""
        while not stop.wait(0.5):
            self.draw()

    def close(self) -> None:
        self._write(f"{self.desc} [{'#' * self.width}] {self.total}/{self.total} "
                    f"done in {time.perf_counter() - self.start:.1f} s", end="\n")
