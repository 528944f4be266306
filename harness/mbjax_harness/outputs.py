"""A command's outputs, written whole or not at all.

`mbjax tour`, `mbjax reproduce` and `mbjax bench` write into a staging folder inside the output
folder (`.mbjax-partial-PID-...`) and move each finished file into place (`os.replace`, atomic
on one file system) only when the command has finished. An interrupted run (an error, Ctrl-C)
removes its staging folder, so the output folder keeps the previous run's complete set of files
and never a new JSON beside an old figure. A staging folder left by a killed process is removed
by the next run that writes there.
"""

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

PREFIX = ".mbjax-partial-"


class OutputError(Exception):
    """The output folder cannot be created or written: its path and the system's reason."""


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:           # another user's process
        return True
    return True


def _sweep(out: Path) -> None:
    """Remove the staging folders of processes that are gone (killed before they could)."""
    for folder in out.glob(PREFIX + "*"):
        pid = folder.name[len(PREFIX):].split("-")[0]
        if folder.is_dir() and pid.isdigit() and not _alive(int(pid)):
            shutil.rmtree(folder, ignore_errors=True)


@contextlib.contextmanager
def staged(out: Path) -> Iterator[Path]:
    """A staging folder for a command's outputs, moved into `out` when the block completes and
    removed if it raises.

    Args:
        out: the output folder, created if missing.

    Yields:
        The staging folder to write into (the same relative names as in `out`).

    Raises:
        OutputError: `out` cannot be created or written (a file of that name, no permission).
    """
    try:
        out.mkdir(parents=True, exist_ok=True)
        _sweep(out)
        staging = Path(tempfile.mkdtemp(prefix=f"{PREFIX}{os.getpid()}-", dir=out))
    except OSError as error:
        raise OutputError(f"cannot write to {out}: {error.strerror or error}") from error
    try:
        yield staging
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    for path in sorted(p for p in staging.rglob("*") if p.is_file()):
        target = out / path.relative_to(staging)
        target.parent.mkdir(parents=True, exist_ok=True)
        os.replace(path, target)
    shutil.rmtree(staging, ignore_errors=True)
