"""Crocoddyl's ANYmal walk (`mbjax_harness.crocoddyl.gaits.anymal_walk`), mbjax's iLQR with
Crocoddyl's schedule against Crocoddyl's FDDP from the same quasi-static guess, mbjax's
iterations driven one jitted `ILQR.step` at a time from Python, so that each iteration's wall
time shows (`mbjax bench trajopt` times the whole solve as one program).

    python benchmarks/bench_gait_iterations.py [STEP_KNOTS] [SUPPORT_KNOTS]

Prints each iteration's wall time and cost, FDDP's time, iterations and cost, the cost of
mbjax's controls rolled out in Crocoddyl's own problem, and the linearization per knot at the
solution: mbjax's `Problem.linearize` (the knots' dynamics and costs, jitted) against
Crocoddyl's `calc` + `calcDiff` of the same problem, both divided by the number of knots.
"""

import sys
import time

import equinox as eqx
import jax
import jax.numpy as jnp

from mbjax.trajopt import CROCODDYL_SCHEDULE, ILQR
from mbjax_harness.crocoddyl.gaits import anymal_walk


def main(step_knots: int = 25, support_knots: int = 2) -> None:
    example = anymal_walk(step_knots=step_knots, support_knots=support_knots)
    problem = example.problem
    solver = ILQR(iterations=100, **CROCODDYL_SCHEDULE)
    init = eqx.filter_jit(lambda p, u: solver.init(p, u))
    step = eqx.filter_jit(lambda p, s: solver.step(p, s))
    start = time.perf_counter()
    state = jax.block_until_ready(init(problem, jnp.asarray(example.us0)))
    print(f"horizon {problem.horizon}, {len(problem.knots.templates)} phases; init (compile "
          f"included) {time.perf_counter() - start:.1f} s, cost {float(state['cost']):.10g}")
    while bool(solver.running(state)):
        start = time.perf_counter()
        state = jax.block_until_ready(step(problem, state))
        print(f"iteration {int(state['iteration'])}: {time.perf_counter() - start:.3f} s, cost "
              f"{float(state['cost']):.12g}")
    import crocoddyl

    croc = example.crocoddyl()
    croc.nthreads = 1                                  # single-threaded, as mbjax's CPU runs
    to_croc = example.controls(croc)
    fddp = crocoddyl.SolverFDDP(croc)
    us0 = to_croc(example.us0)
    start = time.perf_counter()
    fddp.solve(croc.rollout(us0), us0, 100, True)
    print(f"Crocoddyl FDDP: {time.perf_counter() - start:.3f} s, {fddp.iter} iterations, cost "
          f"{fddp.cost:.12g}")
    us = to_croc(state["us"])
    print(f"mbjax's controls rolled out in Crocoddyl's problem: cost "
          f"{croc.calc(croc.rollout(us), us):.12g}")

    linearize_program = eqx.filter_jit(lambda p, xs, us: p.linearize(xs, us))

    def linearize(xs, us):
        return linearize_program(problem, xs, us)

    xs = state["xs"]
    jax.block_until_ready(linearize(xs, state["us"]))
    xs_croc = croc.rollout(us)
    per_knot = {}
    for name, run in (("mbjax", lambda: jax.block_until_ready(linearize(xs, state["us"]))),
                      ("crocoddyl", lambda: (croc.calc(xs_croc, us), croc.calcDiff(xs_croc, us)))):
        times = []
        for _ in range(50):
            start = time.perf_counter()
            run()
            times.append(time.perf_counter() - start)
        per_knot[name] = sorted(times)[len(times) // 2] / problem.horizon
    print(f"linearization per knot: mbjax {per_knot['mbjax'] * 1e6:.0f} us, Crocoddyl calc + "
          f"calcDiff {per_knot['crocoddyl'] * 1e6:.0f} us "
          f"({per_knot['mbjax'] / per_knot['crocoddyl']:.1f}x)")


if __name__ == "__main__":
    jax.config.update("jax_enable_x64", True)
    main(*(int(a) for a in sys.argv[1:3]))
