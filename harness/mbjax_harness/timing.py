"""The timing helpers every benchmark and reproduction uses.

`measure`: compile time and run time reported separately: the first call compiles and runs, later
calls only run. Run time is the median of `repeats` calls after that warm-up, each ending with
`jax.block_until_ready` on the output so that JAX's asynchronous dispatch is not mistaken for speed.
`in_turns`: engines compared side by side, each the fastest of its calls, the calls alternating.
`timed`: `measure` with its repeats cut to a time budget.
"""

import functools
import json
import statistics
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import jax

from mbjax_harness.progress import step


@dataclass(frozen=True)
class Timing:
    compile_s: float   # first call minus a typical call: tracing + XLA compilation
    run_s: float       # median run time after warm-up
    runs: int


def measure(fn: Callable, *args, repeats: int = 10) -> tuple[object, Timing]:
    """Call fn(*args) once to compile, then `repeats` times; return (output, Timing). Each call
    of `measure` is a step on the progress display (`mbjax_harness.progress.step`), named after `fn`."""
    step(_name(fn))
    start = time.perf_counter()
    out = jax.block_until_ready(fn(*args))
    first = time.perf_counter() - start
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        jax.block_until_ready(fn(*args))
        samples.append(time.perf_counter() - start)
    run = statistics.median(samples)
    return out, Timing(compile_s=max(first - run, 0.0), run_s=run, runs=repeats)


def in_turns(runs: dict[str, Callable], repeats: int) -> dict[str, float]:
    """The fastest of `repeats` calls of each of `runs` (name: a function of no arguments, which
    blocks until its result is ready), after one warm-up call each, the functions taking turns:
    a slow spell of a shared machine then falls on every one of them, not on one."""
    step("runs in turns")
    for run in runs.values():
        run()
    samples = {name: [] for name in runs}
    for _ in range(repeats):
        for name, run in runs.items():
            start = time.perf_counter()
            run()
            samples[name].append(time.perf_counter() - start)
    return {name: min(times) for name, times in samples.items()}


def _name(fn: Callable) -> str:
    while isinstance(fn, functools.partial):
        fn = fn.func
    name = getattr(fn, "__name__", type(fn).__name__)
    return "a timed run" if name == "<lambda>" else name


def write_jsonl(path: Path, records: Iterable[dict]) -> None:
    """One JSON object per line."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as f:
        for record in records:
            f.write(json.dumps(record) + "\n")


def timed(fn, *args, repeats: int, budget_s: float) -> tuple[object, Timing]:
    """`measure` with the repeats cut to what fits in budget_s (at least one): one compiling call
    and one run first, then up to `repeats` runs whose median is the run time."""
    out, first = measure(fn, *args, repeats=1)
    runs = int(min(repeats, budget_s / max(first.run_s, 1e-9)))
    if runs < 2:
        return out, first
    _, more = measure(fn, *args, repeats=runs)   # already compiled: its first call only runs
    return out, Timing(compile_s=max(first.compile_s + first.run_s - more.run_s, 0.0),
                       run_s=more.run_s, runs=more.runs)
