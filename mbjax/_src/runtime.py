"""XLA's and JAX's CPU runtime settings for mbjax's programs, applied when mbjax is imported.

mbjax's kernels are loops of small operations: a tree pass is a `lax.scan` over bodies whose step
is a few dozen 6-vector and 6x6 operations, and a rollout is a scan of those. XLA's CPU runtime
launches each fused operation of a loop body as a kernel of its own (a thunk); at a few dozen per
body, the launches are the cost, not the arithmetic. Four settings address this; the
measurements behind them are in benchmarks/README.md.

1. Loops compiled as one kernel
   (``--xla_backend_extra_options=xla_cpu_small_while_loop_byte_threshold=1000000000``). XLA's
   CPU compiler has a pass that turns a loop into one function of straight-line code
   (`SmallWhileLoopHoistingPass`, emitted by the classic IR emitter), for loops whose operations
   it can emit that way (no scatter, sort or library call) and whose cost analysis reads fewer
   bytes than a threshold, 1 kB by default, which no tree pass meets; mbjax raises it. This
   makes forward dynamics inside a rollout several times faster and shortens compilation;
   results agree to a few ulps. For loops to qualify, mbjax's tree passes and their derivatives
   hold no scatter (`mbjax._src.tree.take`).
2. No concurrency scheduling (``--xla_cpu_enable_concurrency_optimized_scheduler=false``). XLA's
   CPU runtime schedules a program's kernels for concurrency by default, which pays off for
   large independent operations and costs a thread hand-off per small one. It changes the order
   kernels run in, not what they compute.
3. The classic fusion emitter (``--xla_cpu_use_fusion_emitters=false``: the classic elemental
   emitter instead of the MLIR fusion emitters) for the fusions outside such loops. It shortens
   compile times, not run times, which matters because a program of a few operations is mostly
   compile time and programs outside `jit` (arrays handled op by op) are compiled one per
   operation and shape. The two emitters round a few operations differently (a few ulps after a
   200-step rollout).
4. Synchronous dispatch (JAX's `jax_cpu_enable_async_dispatch` off). JAX's CPU client runs a
   program on a worker thread and hands the result back, so that Python can go on while a large
   program runs; for mbjax's calls, whose programs run for microseconds, the hand-off is the
   cost. With dispatch synchronous the call returns when its result is ready; nothing else
   changes.

A fifth is per program, not per process:

5. No loop-invariant code motion in a program that loops over knots solving contacts
   (`CONTACT_OPTIONS`, XLA's ``while-loop-invariant-code-motion`` pass off; `contact_jit`). Such
   a knot's step runs the tree's passes several times on the same state (the mass matrix, the
   contacts' positions, Jacobians and drift, the costs' frames), each a loop that XLA merges
   into one by common-subexpression elimination where the step stands alone. Inside the loop
   over a phase's knots, loop-invariant code motion first hoists a different part of each copy
   out of the loop, so the copies no longer match and all of them are compiled and run:
   ANYmal's stance step compiled 85 matrix products instead of 40. Off, the legged guide's step
   compiles about a tenth faster and runs faster; a problem without contacts (the quadrotor)
   ran slower without it, so only programs that solve contacts turn it off
   (benchmarks/README.md, "Issue 61").

The first four are read once, when JAX first starts a backend. So `import mbjax` sets them only
if no backend has started yet, each only if the user has not set it (XLA_FLAGS naming the flag or
option; JAX_CPU_ENABLE_ASYNC_DISPATCH), and the XLA flags only on a jaxlib known to have them (an
unknown flag aborts the process). MBJAX_XLA_DEFAULTS=0 leaves all alone. `applied()` and
`synchronous()` say whether the running process has them.
"""

import os

HOIST_BYTES = 1_000_000_000
FLAGS = (f"--xla_backend_extra_options=xla_cpu_small_while_loop_byte_threshold={HOIST_BYTES}",
         "--xla_cpu_enable_concurrency_optimized_scheduler=false",
         "--xla_cpu_use_fusion_emitters=false")
# what names each flag in XLA_FLAGS (the user's own setting of it wins); the extra options are
# one flag, so a user's own --xla_backend_extra_options keeps the threshold at XLA's default
NAMES = ("--xla_backend_extra_options", "--xla_cpu_enable_concurrency_optimized_scheduler",
         "--xla_cpu_use_fusion_emitters")
FLAG = " ".join(FLAGS)
# jaxlib releases whose XLA has the flags (checked on each; an unknown XLA flag is fatal)
TESTED = ((0, 10),)


def _jaxlib_version() -> tuple[int, int]:
    import jaxlib

    major, minor = jaxlib.__version__.split(".")[:2]
    return int(major), int(minor)


def configure_xla() -> bool:
    """Add FLAGS to XLA_FLAGS and make CPU dispatch synchronous (see the module).

    Only where the user has not chosen, MBJAX_XLA_DEFAULTS is not 0, no backend has started and
    the jaxlib is one of `TESTED`.

    Returns:
        True if any flag was added to XLA_FLAGS.
    """
    if os.environ.get("MBJAX_XLA_DEFAULTS", "") in ("0", "false", "no"):
        return False
    import jax
    from jax._src import xla_bridge

    if xla_bridge.backends_are_initialized():
        return False
    if "JAX_CPU_ENABLE_ASYNC_DISPATCH" not in os.environ:
        jax.config.update("jax_cpu_enable_async_dispatch", False)
    flags = os.environ.get("XLA_FLAGS", "")
    if _jaxlib_version() not in TESTED:
        return False
    added = [flag for flag, name in zip(FLAGS, NAMES, strict=True) if name not in flags]
    if added:
        os.environ["XLA_FLAGS"] = " ".join([flags, *added]).strip()
    return bool(added)


def applied() -> bool:
    """Whether this process's XLA runs with all of FLAGS (XLA_FLAGS names them)."""
    flags = os.environ.get("XLA_FLAGS", "")
    return all(flag in flags for flag in FLAGS)


def hoisting() -> bool:
    """Whether this process's XLA compiles small loops as one kernel with mbjax's threshold."""
    return FLAGS[0] in os.environ.get("XLA_FLAGS", "")


def synchronous() -> bool:
    """Whether JAX's CPU client runs programs on the calling thread (async dispatch off)."""
    import jax

    return not jax.config.read("jax_cpu_enable_async_dispatch")


# 5: per program (a `jax.jit` compiler option), for programs that loop over contact knots
CONTACT_OPTIONS = {"xla_disable_hlo_passes": "while-loop-invariant-code-motion"}


def contact_jit(fn):
    """fn under `eqx.filter_jit` twice: plain, and with `CONTACT_OPTIONS` (item 5 of the
    module). Returns `pick(solves_contacts, *args) -> jitted fn`: the second for a program that
    solves contacts, on a CPU, unless MBJAX_XLA_DEFAULTS is 0 or args hold tracers (called
    inside another `jax.jit`, whose compilation decides: only a top-level jit takes options)."""
    import equinox as eqx
    import jax

    plain, contacts = eqx.filter_jit(fn), eqx.filter_jit(fn, compiler_options=CONTACT_OPTIONS)
    defaults = os.environ.get("MBJAX_XLA_DEFAULTS", "") not in ("0", "false", "no")

    def pick(solves_contacts: bool, *args):
        traced = any(isinstance(x, jax.core.Tracer) for x in jax.tree.leaves(args))
        top = solves_contacts and defaults and not traced and jax.default_backend() == "cpu"
        return contacts if top else plain
    return pick


configure_xla()

# Read once, here, so that algorithm choices made while tracing do not read the environment.
HOISTING = hoisting()
