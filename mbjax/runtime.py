"""XLA's and JAX's CPU runtime settings for mbjax's programs, applied when mbjax is imported.

mbjax's kernels are many small loop kernels (a tree pass runs a few dozen per body). XLA's CPU
runtime schedules the kernels of a program for concurrency by default, which pays off for large
independent operations and costs a thread hand-off per small one. With that scheduler off
(``--xla_cpu_enable_concurrency_optimized_scheduler=false``), measured with `mbjax bench speed`
(benchmarks/README.md, float64, 2-core x86_64 CPU): the 7-link chain's forward dynamics inside a
jitted rollout 11.5 -> 7.1 us per evaluation, one jitted call 60 -> 28 us; the 30-link chain 45 ->
35 us; batched throughput (`batch_aba`, `vmap` at B = 1024-4096) unchanged. Results are
bit-for-bit the same: it changes the order kernels run in, not what they compute.

The second setting is JAX's: its CPU client runs a program on a worker thread and hands the
result back (`jax_cpu_enable_async_dispatch`), so that Python can go on while a large program
runs. For mbjax's calls, whose programs run for microseconds, the hand-off is the cost: one jitted
forward-dynamics call of the 7-link chain, median of 2000, 62 -> 15.5 us with the model closed
over and 94 -> 24 us with the model an argument (min 18 -> 15 and 27 -> 23: the hand-off is what
varies). With dispatch synchronous the call returns when its result is ready; nothing else changes.

Both settings are read once, when JAX first starts a backend. So `import mbjax` sets them only if
no backend has started yet, only if the user has not set them (XLA_FLAGS naming the flag;
JAX_CPU_ENABLE_ASYNC_DISPATCH), and the XLA flag only on a jaxlib known to have it (an unknown
flag aborts the process). MBJAX_XLA_DEFAULTS=0 leaves both alone. `applied()` and
`synchronous()` say whether the running process has them.
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
    """Add FLAG to XLA_FLAGS and make CPU dispatch synchronous, where the user has not chosen and
    it can still take effect (see the module); True if FLAG was added."""
    if os.environ.get("MBJAX_XLA_DEFAULTS", "") in ("0", "false", "no"):
        return False
    import jax
    from jax._src import xla_bridge

    if xla_bridge.backends_are_initialized():
        return False
    if "JAX_CPU_ENABLE_ASYNC_DISPATCH" not in os.environ:
        jax.config.update("jax_cpu_enable_async_dispatch", False)
    flags = os.environ.get("XLA_FLAGS", "")
    if NAME in flags or _jaxlib_version() not in TESTED:
        return False
    os.environ["XLA_FLAGS"] = f"{flags} {FLAG}".strip()
    return True


def applied() -> bool:
    """Whether this process's XLA runs with FLAG (XLA_FLAGS names it)."""
    return FLAG in os.environ.get("XLA_FLAGS", "")


def synchronous() -> bool:
    """Whether JAX's CPU client runs programs on the calling thread (async dispatch off)."""
    import jax

    return not jax.config.read("jax_cpu_enable_async_dispatch")


configure_xla()
