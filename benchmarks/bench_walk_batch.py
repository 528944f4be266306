"""A batch of ANYmal walks with different step lengths (issue 57's batch target): mbjax's ILQR on
the whole batch in one call (`mbjax.trajopt.solve` on a batched problem: a working set per
device) against Crocoddyl's FDDP solving the same walks one after another, single-threaded,
both with Crocoddyl's regularization schedule, each from its own quasi-static guess.

    python benchmarks/bench_walk_batch.py [WALKS] [STEP_KNOTS] [SUPPORT_KNOTS]

Prints each engine's wall time for the batch, mbjax's compile time, and the largest relative
gap between the two libraries' optimal costs over the batch (each walk's mbjax controls priced
in Crocoddyl's own problem).
"""

import os
import sys
import time

# a device per core, as `mbjax bench` runs batches (before JAX starts)
if "host_platform_device_count" not in os.environ.get("XLA_FLAGS", ""):
    os.environ["XLA_FLAGS"] = (os.environ.get("XLA_FLAGS", "") + " --xla_force_host_platform_"
                               f"device_count={os.cpu_count() or 1}").strip()

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from mbjax.trajopt import CROCODDYL_SCHEDULE, ILQR, solve
from mbjax_harness.crocoddyl.gaits import anymal_walk


def stacked(problems):
    """The problems as one batched problem: their arrays stacked along a first axis (their
    static parts, the phases' structure, must be equal)."""
    parts = [eqx.partition(p, eqx.is_array) for p in problems]
    static = parts[0][1]
    for _, other in parts[1:]:
        if jax.tree.structure(other) != jax.tree.structure(static):
            raise ValueError("the walks differ in structure, not only in their arrays")
    treedef = jax.tree.structure(parts[0][0])
    leaves = [jnp.stack(a) for a in zip(*[jax.tree.leaves(p) for p, _ in parts])]
    return eqx.combine(jax.tree.unflatten(treedef, leaves), static)


def main(walks: int = 16, step_knots: int = 25, support_knots: int = 2) -> None:
    import crocoddyl

    lengths = np.linspace(0.15, 0.35, walks)
    examples = [anymal_walk(step_length=float(s), step_knots=step_knots,
                            support_knots=support_knots) for s in lengths]
    batch = stacked([e.problem for e in examples])
    us0 = jnp.stack([jnp.asarray(e.us0) for e in examples])
    solver = ILQR(iterations=100, **CROCODDYL_SCHEDULE)
    run = eqx.filter_jit(lambda p, us: solve(p, solver, us))
    start = time.perf_counter()
    jax.block_until_ready(run(batch, us0))
    first = time.perf_counter() - start
    start = time.perf_counter()
    result = jax.block_until_ready(run(batch, us0))
    warm = time.perf_counter() - start
    print(f"{walks} walks of {examples[0].problem.horizon} knots, step lengths "
          f"{lengths[0]:.2f}-{lengths[-1]:.2f} m; {len(jax.devices())} device(s)")
    print(f"mbjax ILQR, one batched solve: {warm:.3f} s (first call {first:.1f} s, so compile "
          f"{first - warm:.1f} s); iterations {np.asarray(result.iterations).tolist()}, "
          f"statuses {np.asarray(result.status).tolist()}")
    crocs, guesses = [], []
    for e in examples:
        croc = e.crocoddyl()
        croc.nthreads = 1
        crocs.append((croc, e.controls(croc)))
        guesses.append(crocs[-1][1](e.us0))
    costs, iterations = [], []
    start = time.perf_counter()
    for (croc, _), u0 in zip(crocs, guesses, strict=True):
        fddp = crocoddyl.SolverFDDP(croc)
        fddp.solve(croc.rollout(u0), u0, 100, True)
        costs.append(fddp.cost)
        iterations.append(fddp.iter)
    sequential = time.perf_counter() - start
    print(f"Crocoddyl FDDP, {walks} solves in turn: {sequential:.3f} s; iterations {iterations}")
    gaps = []
    for (croc, to_croc), us, best in zip(crocs, np.asarray(result.us), costs, strict=True):
        u = to_croc(us)
        gaps.append(abs(croc.calc(croc.rollout(u), u) - best) / abs(best))
    print(f"largest relative cost gap to FDDP's optimum: {max(gaps):.2e}; mbjax / Crocoddyl "
          f"wall time {warm / sequential:.1f}x")


if __name__ == "__main__":
    jax.config.update("jax_enable_x64", True)
    main(*(int(a) for a in sys.argv[1:4]))
