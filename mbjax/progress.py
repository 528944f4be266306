"""Progress on stderr: which items run, how many are done, the time spent.

On a terminal one line, redrawn, with the clock of each item running; otherwise (a log, a
pipe) a line per item started and finished.
"""

import sys
import threading
import time
from collections.abc import Iterable, Iterator


def progress(items: Iterable, total: int, desc: str = "") -> Iterator:
    """Yield from `items` one after another, reporting each (a thread redraws the running
    item's clock twice a second on a terminal)."""
    board = Board(desc, total)
    stop = threading.Event()
    ticker = threading.Thread(target=board.tick, args=(stop,), daemon=True)
    ticker.start()
    try:
        for item in items:
            start = time.perf_counter()
            board.started(item, start)
            yield item
            board.finished(item, start)
    finally:
        stop.set()
        ticker.join()
    board.close()


class Board:
    """A progress display of several items that may run at once (`mbjax.parallel.run`): on a
    terminal one line, redrawn, naming the items running with their clocks; otherwise a line per
    item started and finished."""

    width = 24

    def __init__(self, desc: str, total: int):
        self.desc, self.total, self.done = desc, total, 0
        self.start = time.perf_counter()
        self.running: dict = {}         # key: when it started
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
            tasks = ", ".join(f"{key} {now - at:.0f} s" for key, at in list(self.running.items()))
            self._write(f"{self._bar()} {tasks}  {now - self.start:6.1f} s")

    def tick(self, stop: threading.Event) -> None:
        """Redraw twice a second until `stop` is set (a thread's target)."""
        while not stop.wait(0.5):
            self.draw()

    def close(self) -> None:
        self._write(f"{self.desc} [{'#' * self.width}] {self.total}/{self.total} "
                    f"done in {time.perf_counter() - self.start:.1f} s", end="\n")
