"""Iterative LQR with box-constrained controls: DDP with the dynamics' first derivatives (`ILQR`,
whose docstring describes the iteration, its schedules and its stopping test)."""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.system.status import Status
from mbjax._src.linalg import small_dot, spd_solve
from mbjax._src.trajopt.problem import Problem
from mbjax._src.trajopt.result import (MU_CEILING, AbstractIterativeSolver, Result, cost_floor,
                                       history)

MU_MIN, MU_FACTOR = 1e-9, 10.0
# an infeasible start (Mastalli et al. 2020, FDDP): the gaps below which a trajectory is a
# rollout, and the fraction of a predicted cost increase a gap-closing step may cost
GAP_TOLERANCE, INCREASE_ACCEPTANCE = 1e-9, 2.0
CROCODDYL_SCHEDULE = {"steps": tuple(0.5**k for k in range(10)), "acceptance": 0.1,
                      "shrink_above": 0.5, "grow_below": 0.01, "regularization": 1e-9}
"""Crocoddyl's FDDP schedule, for `ILQR(**CROCODDYL_SCHEDULE)`: steps halving from 1 to 2^-9,
a tenth of the predicted decrease to accept, the regularization starting at 1e-9, shrunk after
steps above 1/2 and grown after steps of 1/100 or shorter (`ILQR`'s Schedules)."""
# the control blocks' Cholesky written out up to this size (`linalg.spd_solve`), so that the
# backward pass compiles as one kernel (a LAPACK call would keep it kernel by kernel)
UNROLL = 16


def box_qp(H: Array, g: Array, lower: Array, upper: Array, iterations: int, d: Array):
    """(d, free): argmin 1/2 d^T H d + g^T d over lower <= d <= upper for a positive-definite H,
    from the unconstrained minimizer d = -H^-1 g, by projected Newton steps on the controls not
    held at a bound (Bertsekas 1982) until a step changes nothing or `iterations` pass, and the
    mask of the controls left free."""
    eye = jnp.eye(g.shape[0], dtype=H.dtype)

    def clamped(d):
        grad = H @ d + g
        return ((d <= lower) & (grad > 0)) | ((d >= upper) & (grad < 0))

    def newton(carry):
        d, _, i = carry
        free = ~clamped(d)
        H_free = jnp.where(free[:, None] & free[None, :], H, eye)
        rhs = jnp.where(free, -(g + H @ jnp.where(free, 0.0, d)), d)
        return jnp.clip(spd_solve(H_free, rhs, UNROLL), lower, upper), d, i + 1

    def unsettled(carry):
        d, previous, i = carry
        return (i < iterations) & jnp.any(clamped(d)) & ((i == 0) | jnp.any(d != previous))

    d = jnp.clip(d, lower, upper)
    d, _, _ = jax.lax.while_loop(unsettled, newton, (d, d, jnp.array(0)))
    return d, ~clamped(d)


def riccati_step(problem: Problem, stage: tuple, u: Array, Vx: Array, Vxx: Array, mu: Array,
                 qp_iterations: int):
    """One stage of the backward pass (step 2 of `ILQR`'s iteration) from the next value (Vx, Vxx) and
    the stage's expansion (A, B, l_x, l_u, l_xx, l_ux, l_uu) about the control u: the control
    step k within the bounds, the feedback K on the free controls, this stage's value
    (Vx, Vxx), and Q_u, Q_uu. The unconstrained step and feedback come from one factorization
    of Q_uu; the box's projected Newton steps run only where that step leaves the bounds. Vx
    is the next value's gradient at the step's end, with a gap's term already added (FDDP)."""
    A, B, lx, lu, lxx, lux, luu = stage
    eye = jnp.eye(problem.nu, dtype=u.dtype)
    At, Bt = A.T, B.T
    Qx, Qu = lx + small_dot(At, Vx), lu + small_dot(Bt, Vx)
    VxxA, VxxB = small_dot(Vxx, A), small_dot(Vxx, B)
    Qxx, Qux = lxx + small_dot(At, VxxA), lux + small_dot(Bt, VxxA)
    Quu = luu + small_dot(Bt, VxxB)
    H = 0.5 * (Quu + Quu.T) + mu * eye
    kK = -spd_solve(H, jnp.concatenate([Qu[:, None], Qux], 1), UNROLL)
    lower, upper = problem.lower - u, problem.upper - u

    def within_bounds():
        k, free = box_qp(H, Qu, lower, upper, qp_iterations, kK[:, 0])
        H_free = jnp.where(free[:, None] & free[None, :], H, eye)
        K = -spd_solve(H_free, jnp.where(free[:, None], Qux, 0.0), UNROLL)
        return k, jnp.where(free[:, None], K, 0.0)

    if problem.bounded:
        k, K = jax.lax.cond(jnp.any((kK[:, 0] < lower) | (kK[:, 0] > upper)), within_bounds,
                            lambda: (kK[:, 0], kK[:, 1:]))
    else:
        k, K = kK[:, 0], kK[:, 1:]
    Kt, QuxT = K.T, Qux.T
    Vx = Qx + small_dot(Kt, small_dot(Quu, k)) + small_dot(Kt, Qu) + small_dot(QuxT, k)
    Vxx = Qxx + small_dot(Kt, small_dot(Quu, K)) + small_dot(Kt, Qux) + small_dot(QuxT, K)
    return k, K, Vx, 0.5 * (Vxx + Vxx.T), Qu, Quu


class ILQR(AbstractIterativeSolver):
    """Iterative LQR (DDP with the dynamics' first derivatives) with box-constrained controls.

    A solver strategy for `mbjax.trajopt.solve`; the algorithm and its schedule are described
    in docs/details.md. It steps in the state's tangent space, so floating bases and continuous
    joints need nothing special. The result's `feedback` holds the gains of the last
    accepted iteration, acting on deviations `Problem.difference(x_k, x)`.

    Args:
        iterations: the most iterations (static).
        tolerance: the relative cost decrease below which it stops.
        regularization: mu's first value, the regularization of Q_uu.
        steps: the step lengths alpha tried in turn in each forward pass, longest first
            (static).
        acceptance: the fraction of the predicted decrease a step must achieve.
        shrink_above: mu shrinks tenfold after an accepted step longer than this.
        grow_below: mu grows tenfold after an accepted step this short or shorter (and after
            a failure).
        qp_iterations: projected Newton steps of the bounded control step (static).

    More on the iteration, schedules, infeasible start, stopping: the documentation site's Details
    page (docs/details.md).
    """

    iterations: int = eqx.field(static=True, default=200)
    tolerance: float = 1e-8
    regularization: float = 1e-6
    steps: tuple = eqx.field(static=True, default=(1.0, 0.5, 0.25, 0.1, 0.03, 0.01, 1e-3))
    acceptance: float = 1e-4
    shrink_above: float = 0.0
    grow_below: float = 0.0
    qp_iterations: int = eqx.field(static=True, default=8)

    def init(self, problem: Problem, us: Array, states: Array | None = None) -> dict:
        """The iteration's state before the first iteration, from the first guess us and a
        state trajectory (an infeasible start; None for us's rollout): its cost, mu, and room
        for the expansion and the costs' history."""
        N, nx, nu = problem.horizon, problem.ndx, problem.nu
        # a problem whose knots solve contacts rolls us out in the first step's forward pass
        # (`fresh`): priced as it steps (one stance solve a knot), and no second instance of
        # the forward pass to compile
        fresh = states is None and not problem.vectorized
        if fresh:
            xs = jnp.broadcast_to(problem.x0, (N + 1, problem.nx))
            cost = jnp.asarray(jnp.inf, us.dtype)
        else:
            xs = problem.initial_states(states, us)
            cost = problem.cost(xs, us)
        return dict(xs=xs, us=us, cost=cost, mu=jnp.asarray(self.regularization, cost.dtype),
                    iteration=jnp.array(0), done=jnp.array(False), stalled=jnp.array(False),
                    fresh=jnp.array(fresh),
                    met_nonfinite=jnp.array(False),
                    costs=history(self.iterations + 1, cost),
                    step_lengths=jnp.full(self.iterations, jnp.nan, cost.dtype),
                    K=jnp.zeros((N, nu, nx), cost.dtype), stale=jnp.array(True),
                    expansion=_zero_expansion(N, nx, nu, cost.dtype))

    def running(self, s: dict) -> Array:
        """Whether the iteration goes on from state s (its first guess not yet rolled out, or
        not converged, not stalled, iterations left)."""
        return s["fresh"] | (~s["done"] & ~s["stalled"] & (s["iteration"] < self.iterations))

    def step(self, problem: Problem, s: dict) -> dict:
        """One iteration (steps 1-4 of `ILQR`'s iteration) from state s; from a fresh state
        (`init`), the first guess's rollout instead: a forward pass of no step and no
        feedback, taken whatever its cost, which counts no iteration."""
        alphas = jnp.asarray(self.steps, s["cost"].dtype)
        fresh = s["fresh"]
        # linearized at the top of an iteration, after an accepted step (and first): the
        # expansion is traced once, inside the loop, not also before it
        expansion = jax.lax.cond(s["stale"], lambda: self._linearize(problem, s["xs"], s["us"]),
                                 lambda: s["expansion"])
        k, K, (dg, dq), Vxx, ok = self._backward(problem, expansion, s["us"], s["mu"])
        k, K = jnp.where(fresh, 0.0, k), jnp.where(fresh, 0.0, K)
        ok = ok | fresh
        gaps = expansion[0][2]
        gap = jnp.max(jnp.abs(gaps))

        def predicted(xs, alpha):
            """The model's cost decrease for a step alpha that lands on xs (FDDP's, with the
            gaps' term dv, zero on a rollout)."""
            dx = jax.vmap(problem.difference)(xs[1:], s["xs"][1:])
            dv = -jnp.sum(gaps * jnp.einsum("kij,kj->ki", Vxx, dx))
            return alpha * (dg + dv + 0.5 * alpha * (dq - 2.0 * dv))

        def acceptable(trial):
            xs, _, cost, i, _ = trial
            alpha = alphas[jnp.maximum(i - 1, 0)]
            expected = predicted(xs, alpha)
            change = s["cost"] - cost
            decreased = jnp.where(expected >= 0, change > self.acceptance * expected,
                                  change > INCREASE_ACCEPTANCE * expected)
            return (i > 0) & (fresh | (jnp.isfinite(cost) & decreased))

        def next_step(trial):                          # the longest acceptable step first
            i, blocked = trial[3], trial[4]
            xs, us, cost = self._forward(problem, s["xs"], s["us"], k, K, gaps, alphas[i])
            return xs, us, cost, i + 1, blocked | ~jnp.isfinite(cost)

        first = (s["xs"], s["us"], s["cost"], jnp.array(0), jnp.array(False))
        xs, us, cost, tried, blocked = jax.lax.while_loop(
            lambda t: ok & ~acceptable(t) & (t[3] < len(self.steps)), next_step, first)
        accept = ok & acceptable((xs, us, cost, tried, blocked))
        xs, us, cost = (jnp.where(accept, new, old) for new, old in
                        zip((xs, us, cost), (s["xs"], s["us"], s["cost"]), strict=True))
        change = s["cost"] - cost
        # stationary: the model, not shrunk by a raised regularization, predicts a
        # negligible decrease, or an accepted step made one, unless a longer step's cost was
        # not finite (the step was cut short by the non-finite region, not by the optimum)
        # (relative to the cost, above round-off: `cost_floor`, an exact optimum's 0)
        floor = cost_floor(cost.dtype)
        taken = alphas[jnp.maximum(tried - 1, 0)]
        # converged only from a trajectory without gaps (a step from one with gaps compares
        # costs of different kinds, and may raise the cost)
        converged = ~fresh & (gap <= GAP_TOLERANCE) & (
            (ok & (s["mu"] <= self.regularization)
             & (dg <= self.tolerance * jnp.abs(s["cost"]) + floor))
            | (accept & ~blocked & (change <= self.tolerance * jnp.abs(cost) + floor)))
        mu = jnp.where(fresh, s["mu"], jnp.where(
            accept & (taken > self.shrink_above), jnp.maximum(s["mu"] / MU_FACTOR, MU_MIN),
            jnp.where(accept & (taken > self.grow_below), s["mu"], s["mu"] * MU_FACTOR)))
        i = s["iteration"] + jnp.where(fresh, 0, 1)
        # a rejected step leaves the trajectory, and so its expansion, as they were
        return dict(xs=xs, us=us, cost=cost, mu=mu, iteration=i, done=converged,
                    stalled=mu > MU_CEILING, costs=s["costs"].at[i].set(cost),
                    step_lengths=jnp.where(fresh, s["step_lengths"], s["step_lengths"].at[i - 1].set(
                        jnp.where(accept, taken, 0.0))),
                    K=jnp.where(accept, K, s["K"]), expansion=expansion, stale=accept,
                    fresh=jnp.array(False),
                    met_nonfinite=~fresh & blocked & ~(accept & (change > self.tolerance
                                                                 * jnp.abs(cost))))

    def result(self, problem: Problem, s: dict) -> Result:
        """The `Result` of the iteration's state s."""
        # NONFINITE also where it stopped unconverged after an iteration that a non-finite
        # cost kept from progressing (the region it could not step into is what stopped it)
        finite = (jnp.isfinite(s["cost"]) & jnp.all(jnp.isfinite(s["xs"]))
                  & (s["done"] | ~s["met_nonfinite"]))
        status = (jnp.where(s["done"], 0, int(Status.NOT_CONVERGED))
                  | jnp.where(finite, 0, int(Status.NONFINITE)))
        q, v = problem.split(s["xs"])
        return Result(qs=q, vs=v, us=s["us"], cost=s["cost"], costs=s["costs"],
                      iterations=s["iteration"], feedback=s["K"], status=status,
                      regularization=s["mu"], step_lengths=s["step_lengths"], solver="ILQR",
                      hint=self._hint())

    def _hint(self) -> str:
        """What to try where the accepted steps stay short (`Result.messages`): a schedule
        that raises the regularization after short steps, unless this one does already."""
        other = "MultipleShooting() for a long horizon or an unstable rollout"
        if not isinstance(self.grow_below, jax.core.Tracer) and self.grow_below > 0:
            return f"more iterations, ILQR(iterations=...), or {other}"
        return ("ILQR(**mbjax.trajopt.CROCODDYL_SCHEDULE), a regularization schedule that "
                f"raises it after short steps, or {other}")

    @staticmethod
    def _linearize(problem: Problem, xs: Array, us: Array) -> tuple:
        """The dynamics' and costs' expansion about (xs, us): (A, B, e, l_x, l_u, l_xx, l_ux,
        l_uu) per step (e the gaps) and the terminal (V_x, V_xx)."""
        dynamics, costs = problem.linearize(xs, us)
        return (*dynamics, *costs), problem.final_expansion(xs[-1])

    def _backward(self, problem: Problem, expansion: tuple, us: Array, mu: Array):
        """(k, K, (dg, dq), V_xx, ok): the Riccati pass over an `expansion` about the trajectory
        of us, with the predicted decrease's terms dg = -sum k^T Q_u and dq = -sum k^T Q_uu k
        and, for gaps e, -sum V_x^T e and sum e^T V_xx e (FDDP), and the value's Hessian at each
        step's end (for the gaps' term of a trial step)."""
        stages, (Vx, Vxx) = expansion

        def back(carry, inputs):
            Vx, Vxx = carry
            A, B, e, lx, lu, lxx, lux, luu, u = inputs
            Vx = Vx + small_dot(Vxx, e)          # the value at the step's end, across its gap
            gap_terms = (-Vx @ e, e @ small_dot(Vxx, e))
            k, K, Vx_k, Vxx_k, Qu, Quu = riccati_step(problem, (A, B, lx, lu, lxx, lux, luu), u,
                                                      Vx, Vxx, mu, self.qp_iterations)
            return (Vx_k, Vxx_k), (k, K, -k @ Qu + gap_terms[0], -k @ Quu @ k + gap_terms[1],
                                   Vxx)

        _, (k, K, dg, dq, Vxx_next) = jax.lax.scan(back, (Vx, Vxx), (*stages, us), reverse=True)
        ok = jnp.all(jnp.isfinite(k)) & jnp.all(jnp.isfinite(K))
        return k, K, (jnp.sum(dg), jnp.sum(dq)), Vxx_next, ok

    @staticmethod
    def _forward(problem: Problem, xs: Array, us: Array, k: Array, K: Array, gaps: Array,
                 alpha: Array):
        """(xs, us, cost) of the closed-loop rollout with step length alpha, which closes that
        fraction of each gap (FDDP's forward pass; a rollout where alpha = 1 or no gaps)."""
        # knots that solve contacts price their step's forces as they step (one stance solve a
        # knot, not two); a vectorized problem's costs stay vectorized over the knots
        fused = not problem.vectorized

        def f(x, inputs):
            x_ref, u_ref, k_, K_, e, i = inputs
            u = jnp.clip(u_ref + alpha * k_ + K_ @ problem.difference(x_ref, x), problem.lower,
                         problem.upper)
            x1, cost = problem.step_cost(x, u, i) if fused else (problem.step(x, u, i), None)
            return problem.integrate(x1, (alpha - 1.0) * e), (x, u, cost)

        x_end, (x_seq, u_seq, costs) = jax.lax.scan(f, xs[0], (xs[:-1], us, k, K, gaps,
                                                               jnp.arange(problem.horizon)))
        x_new = jnp.concatenate([x_seq, x_end[None]])
        if not fused:
            return x_new, u_seq, problem.cost(x_new, u_seq)
        return x_new, u_seq, jnp.sum(costs) + problem.final_cost(x_end)


def _zero_expansion(N: int, n: int, m: int, dtype) -> tuple:
    """Room for `ILQR._linearize`'s expansion, zeros of its shapes (N steps, deviations of n,
    controls of m): written out, not `jax.eval_shape` of it, which would trace the whole
    linearization (a stance's contact solve and its derivatives) a second time."""
    def z(*shape):
        return jnp.zeros(shape, dtype)
    return ((z(N, n, n), z(N, n, m), z(N, n), z(N, n), z(N, m), z(N, n, n), z(N, m, n),
             z(N, m, m)), (z(n), z(n, n)))
