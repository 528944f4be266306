"""A minimal progress bar on stderr (one line per item when stderr is not a terminal)."""

import sys
import time
from collections.abc import Iterable, Iterator


def progress(items: Iterable, total: int, desc: str = "") -> Iterator:
    """Yield from `items`, reporting which item runs, how many are done and the time spent."""
    start = time.perf_counter()
    tty = sys.stderr.isatty()
    width = 24
    for i, item in enumerate(items):
        filled = width * i // total
        line = (f"{desc} [{'#' * filled}{'.' * (width - filled)}] {i}/{total} "
                f"{item}  {time.perf_counter() - start:6.1f} s")
        sys.stderr.write(("\r" + line + "\033[K") if tty else line + "\n")
        sys.stderr.flush()
        yield item
    line = f"{desc} [{'#' * width}] {total}/{total} done in {time.perf_counter() - start:.1f} s"
    sys.stderr.write(("\r" + line + "\033[K\n") if tty else line + "\n")
