"""Outputs written whole or not at all (`mbjax_harness.outputs`), and the command's exits on an
output or cache folder it cannot write."""

import json
import os
import subprocess
import sys

import pytest

from mbjax_harness import outputs
from mbjax_harness.cli import main
from mbjax_harness.reproduce import REPRODUCTIONS


def _previous_run(folder):
    (folder / "fake.json").write_text('{"run": "previous"}')
    (folder / "fake.png").write_bytes(b"previous figure")


def _fake(fail_after_json: bool):
    def reproduce(out, quick=False):
        (out / "fake.json").write_text(json.dumps({"run": "new"}))
        if fail_after_json:
            raise KeyboardInterrupt                     # Ctrl-C between the two files
        (out / "fake.png").write_bytes(b"new figure")
        return {"run": "new"}
    return reproduce


def test_an_interrupted_reproduction_leaves_the_previous_files(tmp_path, monkeypatch):
    _previous_run(tmp_path)
    monkeypatch.setitem(REPRODUCTIONS, "fake", _fake(fail_after_json=True))
    with pytest.raises(KeyboardInterrupt):
        main(["--no-cache", "reproduce", "fake", "--out", str(tmp_path)])
    assert json.loads((tmp_path / "fake.json").read_text()) == {"run": "previous"}
    assert (tmp_path / "fake.png").read_bytes() == b"previous figure"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fake.json", "fake.png"]   # no staging


def test_a_finished_reproduction_replaces_both_files(tmp_path, monkeypatch, capsys):
    _previous_run(tmp_path)
    monkeypatch.setitem(REPRODUCTIONS, "fake", _fake(fail_after_json=False))
    assert main(["--no-cache", "reproduce", "fake", "--out", str(tmp_path)]) == 0
    assert json.loads((tmp_path / "fake.json").read_text()) == {"run": "new"}
    assert (tmp_path / "fake.png").read_bytes() == b"new figure"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fake.json", "fake.png"]
    assert f"wrote {tmp_path / 'fake.json'}, {tmp_path / 'fake.png'}" in capsys.readouterr().out


def test_a_staging_folder_left_by_a_killed_run_is_removed(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    left = tmp_path / f"{outputs.PREFIX}{dead.stdout.strip()}-abc"
    left.mkdir()
    (left / "half.json").write_text("{")
    mine = tmp_path / f"{outputs.PREFIX}{os.getpid()}-xyz"          # a live process's: kept
    mine.mkdir()
    with outputs.staged(tmp_path) as staging:
        (staging / "sub").mkdir()
        (staging / "sub" / "a.txt").write_text("a")
    assert not left.exists() and mine.exists()
    assert (tmp_path / "sub" / "a.txt").read_text() == "a"


@pytest.mark.parametrize("command", [["reproduce", "fake"], ["bench", "rigid"], ["tour"]])
def test_an_output_folder_that_cannot_be_written_exits_2_with_one_line(tmp_path, command,
                                                                       monkeypatch, capsys):
    monkeypatch.setitem(REPRODUCTIONS, "fake", _fake(fail_after_json=False))
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    assert main(["--no-cache", *command, "--out", str(blocker / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("mbjax: error: --out: cannot write to")
    assert str(blocker / "out") in err[0]


def test_a_cache_folder_that_cannot_be_written_exits_2_with_one_line(tmp_path, monkeypatch,
                                                                     capsys):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("JAX_COMPILATION_CACHE_DIR", str(blocker / "cache"))
    monkeypatch.delenv("MBJAX_NO_CACHE", raising=False)
    assert main(["reproduce", "integrators", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "compilation cache" in err[0] and "--no-cache" in err[0]
    assert not (tmp_path / "out").exists()


_PROGRAM = """
import sys, warnings
import jax, jax.numpy as jnp
jax.config.update("jax_enable_x64", True)
from mbjax._src.cache import use_compilation_cache
use_compilation_cache(sys.argv[1])
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    value = float(jax.jit(lambda x: jnp.sin(x) * 3.0 + 1.25)(jnp.float64(0.5)))
print(value, sum("could not be read" in str(w.message) for w in caught))
"""


def test_a_corrupt_cache_entry_is_recompiled_and_written_anew(tmp_path):
    cache = tmp_path / "cache"
    env = {k: v for k, v in os.environ.items()
           if k not in ("MBJAX_NO_CACHE", "JAX_COMPILATION_CACHE_DIR",
                        "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS")}     # the tests' settings

    def run():
        out = subprocess.run([sys.executable, "-c", _PROGRAM, str(cache)], env=env,
                             capture_output=True, text=True, check=True)
        value, warned = out.stdout.split()
        return float(value), int(warned)

    first, warned = run()
    assert warned == 0
    entries = sorted(cache.glob("*-cache"))
    assert entries
    for entry in entries:
        entry.write_bytes(b"not a compiled program")          # corrupted, as on a full disk
    again, warned = run()
    assert again == first and warned >= 1
    assert all(entry.exists() and entry.read_bytes() != b"not a compiled program"
               for entry in entries)                          # written anew
    assert run() == (first, 0)                                # and read back next time
