"""The README's Python blocks and the getting-started guide run as pasted, as a script and at
the interactive prompt, from an empty folder outside the repository, and print what they say.

Each README block is a whole program (its own imports, float64 switch and data), run in a fresh
interpreter. The guide is one session: its blocks run in order in one interpreter, each using
what the blocks before it defined, as a reader following the page would paste them. The
interactive runs feed the code line by line to `code.InteractiveConsole`, the standard prompt's
own parser, which needs what pasting needs: a blank line after an indented block, none inside
one."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent
README = ROOT / "README.md"
GUIDE = ROOT / "docs" / "getting-started.md"
LEGGED = ROOT / "docs" / "legged-robots.md"
SOLVING = ROOT / "docs" / "solving.md"
FIRST_LINES, MAX_WORDS = 60, 3000


def _blocks(path: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", path.read_text(), re.S)


BLOCKS = _blocks(README)

# line by line at the prompt: a traceback or a syntax error fails the run
PROMPT = """
import code, sys

class Prompt(code.InteractiveConsole):
    failed = False

    def showtraceback(self):
        self.failed = True
        super().showtraceback()

    def showsyntaxerror(self, filename=None, **kwargs):
        self.failed = True
        super().showsyntaxerror(filename)

prompt = Prompt(filename="<stdin>")
more = False
for line in open(sys.argv[1]).read().splitlines():
    more = prompt.push(line)
if more:
    prompt.push("")
sys.exit(1 if prompt.failed else 0)
"""


def _run(code: str, folder: Path, interactive: bool) -> subprocess.CompletedProcess:
    script = folder / "block.py"
    script.write_text(code)
    args = ["-c", PROMPT, str(script)] if interactive else [str(script)]
    return subprocess.run([sys.executable, *args], cwd=folder, capture_output=True, text=True,
                          timeout=600)


def _check(result: subprocess.CompletedProcess) -> None:
    assert result.returncode == 0, (result.stdout[-2000:], result.stderr[-4000:])
    assert result.stdout.strip(), "each example prints what it computed"
    assert "Traceback" not in result.stderr and "Error" not in result.stderr, result.stderr[-4000:]


def test_the_readme_is_short_and_leads_with_code():
    """At most 3,000 words, its first Python block within the first 60 lines, and the two
    commands of a fresh machine: the tour and the tests."""
    text = README.read_text()
    assert len(text.split()) <= MAX_WORDS
    first = text.splitlines().index("```python") + 1
    assert first <= FIRST_LINES, first
    assert "pip install . ./harness && mbjax tour --quick" in text
    assert 'pip install ".[test]" ./harness && python -m pytest' in text
    assert len(BLOCKS) >= 5


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_block_runs_as_pasted(index, tmp_path):
    """As a script, then at the prompt (which finds the script's programs in the suite's
    compilation cache)."""
    for interactive in (False, True):
        _check(_run(BLOCKS[index], tmp_path, interactive))


def test_the_getting_started_guide_runs_as_one_session(tmp_path):
    blocks = _blocks(GUIDE)
    assert len(blocks) >= 8
    for interactive in (False, True):
        result = _run("\n".join(blocks), tmp_path, interactive)
        _check(result)
        assert "Result: success" in result.stdout and (tmp_path / "arm.gif").exists()


@pytest.mark.slow
def test_the_legged_robots_guide_runs_as_one_session(tmp_path):
    """The legged-robots guide (it needs the `robots` extra): ANYmal stands under its servo,
    its hand-written step compiles two phases and lands its foot, the trot and Talos's walk
    solve; as a script, then at the prompt (from the compilation cache)."""
    pytest.importorskip("example_robot_data")
    blocks = _blocks(LEGGED)
    for interactive in (False, True):
        result = _run("\n".join(blocks), tmp_path, interactive)
        _check(result)
        out = result.stdout
        assert "Solution: success" in out and out.count("Result: success") == 3, out[-3000:]
        assert "17 knots, 2 compiled phases" in out and (tmp_path / "step.gif").exists()


@pytest.mark.slow
def test_the_solving_guide_runs_as_one_session(tmp_path):
    """The guide to an unconverged solve (it needs the `robots` extra): the UR5's first reach
    stops on short steps and names Crocoddyl's schedule, which converges within 1 mm; a second
    target reuses the compiled solve; as a script, then at the prompt."""
    pytest.importorskip("example_robot_data")
    blocks = _blocks(SOLVING)
    for interactive in (False, True):
        result = _run("\n".join(blocks), tmp_path, interactive)
        _check(result)
        out = result.stdout.splitlines()
        first = next(line for line in out if line.startswith("Result: not converged"))
        assert first.startswith("Result: not converged (iterations=200 ran out on short steps")
        assert "ILQR(**mbjax.trajopt.CROCODDYL_SCHEDULE)" in first
        solved = [line.split() for line in out if line.startswith("Result: success")]
        assert len(solved) == 2 and all(float(words[-1]) < 1e-3 for words in solved), out


def test_the_prompt_runner_fails_what_pasting_fails(tmp_path):
    """A block that runs as a script but not when pasted (no blank line after a `def`) fails
    the interactive run: the check is not vacuous."""
    code = "def f(x):\n    return x + 1\nprint(f(1))\n"
    assert _run(code, tmp_path, interactive=False).returncode == 0
    assert _run(code, tmp_path, interactive=True).returncode != 0
