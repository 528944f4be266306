"""XLA's CPU runtime settings for mbjax's programs, applied when mbjax is imported.

mbjax's kernels are many small loop kernels (a tree pass runs a few dozen per body). XLA's CPU
runtime schedules the kernels of a program for concurrency by default, which pays off for large
independent operations and costs a thread hand-off per small one. With that scheduler off
(``--xla_cpu_enable_concurrency_optimized_scheduler=false``), measured with `mbjax bench speed`
(benchmarks/README.md, float64, 2-core x86_64 CPU): the 7-link chain's forward dynamics inside a
jitted rollout 11.5 -> 7.1 us per evaluation, one jitted call 60 -> 28 us; the 30-link chain 45 ->
35 us; batched throughput (`batch_aba`, `vmap` at B = 1024-4096) unchanged. Results are
bit-for-bit the same: it changes the order kernels run in, not what they compute.

The setting lives in the XLA_FLAGS environment variable, which XLA reads once, when JAX first
starts a backend. So `import mbjax` adds it only if no backend has started yet, only if the user's
XLA_FLAGS does not already name the flag, and only on a jaxlib known to have it (an unknown flag
aborts the process). MBJAX_XLA_DEFAULTS=0 leaves XLA_FLAGS alone. `applied()` says whether the
running process has it.
"""

import os

FLAG = "--xla_cpu_enable_concurrency_optimized_scheduler=false"
NAME = FLAG.split("=")[0]
# jaxlib releases whose XLA has the flag (checked on each; an unknown XLA flag is fatal)
TESTED = ((0, 10),)


def _jaxlib_version() -> tuple[int, int]:
    import jaxlib

    major, minor = jaxlib.__version__.split(".")[:2]
    return int(major), int(minor)


def configure_xla() -> bool:
    """Add FLAG to XLA_FLAGS if it can still take effect (see the module); True if it did."""
    if os.environ.get("MBJAX_XLA_DEFAULTS", "") in ("0", "false", "no"):
        return False
    flags = os.environ.get("XLA_FLAGS", "")
    if NAME in flags or _jaxlib_version() not in TESTED:
        return False
    from jax._src import xla_bridge

    if xla_bridge.backends_are_initialized():
        return False
    os.environ["XLA_FLAGS"] = f"{flags} {FLAG}".strip()
    return True


def applied() -> bool:
    """Whether this process's XLA runs with FLAG (XLA_FLAGS names it)."""
    return FLAG in os.environ.get("XLA_FLAGS", "")


configure_xla()
