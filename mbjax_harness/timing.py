"""The one timing helper every benchmark and reproduction uses.

Compile time and run time are reported separately: the first call compiles and runs, later calls
only run. Run time is the median of `repeats` calls after that warm-up, each ending with
`jax.block_until_ready` on the output so that JAX's asynchronous dispatch is not mistaken for speed.
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
