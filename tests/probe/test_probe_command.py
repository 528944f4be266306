"""Probes of the `mbjax` command (`mbjax_harness.cli`) (issue 43, item 5): names, options, output
and cache folders drawn by hypothesis; every bad one exits with status 2 and a reason on one line
(argparse's usage lines above it for a bad command line), never a traceback.

Most probes call `main(argv)` in this process (a bad --out or cache folder is refused before any
scene, reproduction or benchmark runs); one runs the installed module as users do, to see the
exit status and the whole of stderr."""

import atexit
import contextlib
import io
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import jax
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mbjax_harness.bench import SUITES
from mbjax_harness.cli import main
from mbjax_harness.reproduce import REPRODUCTIONS
from mbjax_harness.tour import TOUR

# one xdist worker runs the module, so its programs compile once (the group tests/conftest.py
# adds comes after xdist has read the groups)
pytestmark = pytest.mark.xdist_group("tests/probe/test_probe_command.py")

# `mbjax bench throughput|trajopt` makes one XLA device per core when JAX has not started its
# backend yet: started here, so this process keeps its devices whatever the command does
jax.devices()

FEW = settings(max_examples=15, deadline=None)
FOLDER = Path(tempfile.mkdtemp(prefix="mbjax-probe-command-"))
atexit.register(shutil.rmtree, FOLDER, ignore_errors=True)
A_FILE = FOLDER / "a-file"
A_FILE.write_text("not a folder")
LOOP, BROKEN = FOLDER / "loop", FOLDER / "broken"
LOOP.symlink_to(LOOP)                                   # a link to itself
BROKEN.symlink_to(FOLDER / "nowhere" / "folder")        # a link to nothing
CHOICES = {"reproduce": sorted(REPRODUCTIONS), "bench": sorted(SUITES), "tour": list(TOUR)}


def _run(argv, env=None):
    """(exit status, stderr) of main(argv) in this process; a SystemExit is an exit status, any
    other exception escapes (a traceback: the failure these probes look for)."""
    err, out = io.StringIO(), io.StringIO()
    with contextlib.ExitStack() as stack:
        stack.enter_context(contextlib.redirect_stderr(err))
        stack.enter_context(contextlib.redirect_stdout(out))
        patch = stack.enter_context(pytest.MonkeyPatch.context())
        for key, value in (env or {}).items():
            if value is None:
                patch.delenv(key, raising=False)
            else:
                patch.setenv(key, value)
        try:
            status = main(argv)
        except SystemExit as exit_:
            status = exit_.code
    return status, err.getvalue()


def _reason(stderr: str) -> str:
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert lines, "no reason on stderr"
    assert "Traceback" not in stderr
    return lines[-1]


names = st.text("abcdefghijklmnopqrstuvwxyz0123456789-_.", min_size=1, max_size=16).filter(
    lambda s: not s.startswith("-"))


def _unwritable(kind: str, name: str) -> Path:
    """A folder that cannot be created or written, whoever runs the tests (root included)."""
    if kind == "a file":
        return A_FILE
    if kind == "under a file":
        return A_FILE / name
    if kind == "too long a name":
        return FOLDER / (name * (256 // len(name) + 1))
    if kind == "a link to itself":
        return LOOP if len(name) % 2 else LOOP / name
    if kind == "a link to nothing":
        return BROKEN
    if Path("/proc/self").exists():                     # procfs: no folders can be made there
        return Path("/proc") / f"mbjax-probe-{name}"
    return A_FILE / name


def _command(which: str, index: int) -> list[str]:
    choices = CHOICES[which]
    name = choices[index % len(choices)]
    return [which, name] if which != "tour" else ["tour", "--scene", name]


# -- the command line --------------------------------------------------------------------------------

@FEW
@given(which=st.sampled_from(["reproduce", "bench", "tour"]), name=names)
def test_unknown_names_exit_2_naming_the_choice(which, name):
    if name in CHOICES[which]:
        name += "-x"
    argv = [which, name] if which != "tour" else ["tour", "--scene", name]
    status, stderr = _run(argv)
    assert status == 2
    assert f"invalid choice: '{name}'" in _reason(stderr)


@FEW
@given(which=st.sampled_from(["reproduce", "bench", "tour", None]),
       option=st.text("abcdefghijklmnopqrstuvwxyz-", min_size=1, max_size=12))
def test_unknown_options_exit_2_naming_them(which, option):
    option = "--probe-" + option
    argv = ([which] if which else []) + ([option] if which else ["tour", option])
    status, stderr = _run(argv)
    assert status == 2
    assert f"unrecognized arguments: {option}" in _reason(stderr)


@FEW
@given(st.one_of(st.integers(-100, 0).map(str), st.sampled_from(["", "abc", "1.5", "1e9", "two", "∞"])))
def test_a_bad_job_count_exits_2_naming_jobs(jobs):
    status, stderr = _run(["tour", "--jobs", jobs])
    assert status == 2
    assert "argument --jobs" in _reason(stderr)


@FEW
@given(which=st.sampled_from(["reproduce", "bench"]))
def test_a_missing_name_exits_2_listing_the_choices(which):
    status, stderr = _run([which])
    assert status == 2
    reason = _reason(stderr)
    assert "needs a" in reason and all(name in reason for name in CHOICES[which])


# -- output and cache folders ------------------------------------------------------------------------

@FEW
@given(kind=st.sampled_from(["a file", "under a file", "too long a name", "a link to itself",
                             "a link to nothing", "system"]), name=names,
       which=st.sampled_from(["reproduce", "bench", "tour"]), index=st.integers(0, 20),
       cache=st.booleans())
def test_an_output_folder_that_cannot_be_written_exits_2_on_one_line(kind, name, which, index, cache):
    out = _unwritable(kind, name)
    assert not os.path.isdir(out)                            # never a folder a run could fill
    argv = (["--no-cache"] if not cache else []) + _command(which, index) + ["--out", str(out)]
    status, stderr = _run(argv)
    assert status == 2
    assert stderr.count("\n") == 1 and "Traceback" not in stderr
    assert stderr.startswith(f"mbjax: error: --out: cannot write to {out}: ")


@FEW
@given(kind=st.sampled_from(["a file", "under a file", "too long a name"]), name=names,
       argv=st.sampled_from([["reproduce", "--list"], ["tour", "--list"], ["bench", "--list"]]),
       how=st.sampled_from(["JAX_COMPILATION_CACHE_DIR", "XDG_CACHE_HOME"]))
def test_a_cache_folder_that_cannot_be_written_exits_2_and_no_cache_lists(kind, name, argv, how):
    """The command keeps compiled programs on disk: an unwritable cache folder is refused on one
    line naming it (its list then needs --no-cache or MBJAX_NO_CACHE=1, which lists as usual);
    `mbjax bench` keeps none (it times the compiles), so its list needs no cache."""
    folder = _unwritable(kind, name)
    env = ({"JAX_COMPILATION_CACHE_DIR": str(folder), "MBJAX_NO_CACHE": None} if how != "XDG_CACHE_HOME"
           else {"JAX_COMPILATION_CACHE_DIR": None, "XDG_CACHE_HOME": str(folder),
                 "MBJAX_NO_CACHE": None})
    status, stderr = _run(argv, env)
    if argv[0] == "bench":
        assert status == 0 and stderr == ""
        return
    assert status == 2
    assert stderr.count("\n") == 1 and "Traceback" not in stderr
    assert stderr.startswith("mbjax: error: the compilation cache's folder (") and "--no-cache" in stderr
    status, stderr = _run(["--no-cache", *argv], env)
    assert status == 0 and stderr == ""
    status, _ = _run(argv, {**env, "MBJAX_NO_CACHE": "1"})
    assert status == 0


# -- as users run it ---------------------------------------------------------------------------------

@settings(max_examples=1, deadline=None)      # a process of its own: about 2 s
@given(which=st.sampled_from(["reproduce", "bench"]), index=st.integers(0, 20))
def test_the_installed_command_exits_2_with_one_line_and_no_traceback(which, index):
    argv = [sys.executable, "-m", "mbjax_harness.cli", "--no-cache", *_command(which, index),
            "--out", str(A_FILE)]
    run = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    assert run.returncode == 2, run.stderr
    assert run.stderr == f"mbjax: error: --out: cannot write to {A_FILE}: File exists\n"
    assert run.stdout == ""
