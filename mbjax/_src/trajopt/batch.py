"""Many problems through a working set: converged members leave, the next problems take their
slots.

`jax.vmap` of a solve iterates every member until the slowest is done (the 64 arm targets: 200
iterations for a mean of 85) and carries all of them through every iteration, out of cache. A
working set of `width` slots instead runs one iteration of every slot at a time (the solver's
`step`, vmapped over the slots); a member that stops (converged, stalled or out of iterations)
writes its result and its slot takes the next problem of the batch, its first guess rolled out
(`init`). The whole is one `lax.while_loop`, compiled once for a batch size: the iterations
spent are about the batch's total divided by the width, and the slots' arrays stay small.

The slots share nothing but the loop: each member runs its own solve's algorithm. The slots'
arithmetic is batched, so it rounds differently from a lone solve's, and a member that is slow to
settle (the arm's far targets, 100-200 iterations of tiny steps) can take a different number of
iterations to its tolerance. On a CPU a vmapped iteration of w members costs more than w
iterations one by one (benchmarks/README.md), so `solve` gives each CPU device a working set of
one: what pays there is the loop compiled once and the batch split over the cores.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.trajopt.problem import Problem
from mbjax._src.trajopt.result import AbstractIterativeSolver, Result


def working_set(solver: AbstractIterativeSolver, problems: Problem, us0: Array,
                width: int) -> Result:
    """The results (a leading batch axis on every field) of `solver` on each problem of the
    batch `problems` (every array leaf with a leading axis of B, as `equinox.filter_vmap` of a problem's
    builder makes them) from the first guesses us0 (B, horizon, nu), `width` at a time."""
    params, static = eqx.partition(problems, eqx.is_array)
    size = us0.shape[0]
    width = min(width, size)

    def members(index):
        return jax.tree.map(lambda x: x[index], params)

    def problem(p):
        return eqx.combine(p, static)

    init = jax.vmap(lambda p, us: solver.init(problem(p), us))
    step = jax.vmap(lambda p, s: solver.step(problem(p), s))
    running = jax.vmap(solver.running)
    result = jax.vmap(lambda p, s: solver.result(problem(p), s))

    def choose(mask, new, old):
        return jax.tree.map(lambda a, b: jnp.where(mask.reshape(-1, *[1] * (a.ndim - 1)), a, b),
                            new, old)

    slots = jnp.arange(width)
    P = members(slots)
    S = init(P, us0[slots])
    out = jax.tree.map(lambda r: jnp.zeros((size, *r.shape[1:]), r.dtype),
                       jax.eval_shape(result, P, S))

    def iterate(carry):
        P, S, index, active, following, out = carry
        S = choose(active, step(P, S), S)
        finished = active & ~running(S)

        def retire(carry):
            P, S, index, active, following, out = carry
            done = result(P, S)
            out = jax.tree.map(lambda o, r: o.at[jnp.where(finished, index, size)].set(
                r, mode="drop"), out, done)
            new = following + jnp.cumsum(finished) - 1              # the next problems, in turn
            refill = finished & (new < size)
            source = jnp.where(refill, new, index)
            P_new = members(source)
            S_new = init(P_new, us0[source])
            return (choose(refill, P_new, P), choose(refill, S_new, S),
                    jnp.where(refill, new, index), jnp.where(finished, refill, active),
                    following + jnp.sum(refill), out)

        carry = (P, S, index, active, following, out)
        return jax.lax.cond(jnp.any(finished), retire, lambda c: c, carry)

    carry = (P, S, slots, jnp.ones(width, bool), jnp.asarray(width), out)
    return jax.lax.while_loop(lambda c: jnp.any(c[3]), iterate, carry)[-1]
