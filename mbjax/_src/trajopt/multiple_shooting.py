"""Multiple shooting: the states at the knots are unknowns beside the controls, and the dynamics
are constraints (`MultipleShooting`, whose docstring describes the method)."""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.trajopt.ilqr import riccati_step
from mbjax._src.trajopt.problem import Problem
from mbjax._src.trajopt.result import (MU_CEILING, AbstractSolver, Result, cost_floor,
                                       history, rollout_result)

STEPS = tuple(0.5**k for k in range(10))


class MultipleShooting(AbstractSolver):
    """Multiple shooting: knot states and controls as unknowns, the dynamics as constraints.

    The defects are enforced by an augmented Lagrangian, the steps taken by Gauss-Newton (see
    The method, below). A solver strategy for `mbjax.trajopt.solve`; it steps in the state's tangent
    space, so floating bases need nothing special, and takes a state trajectory as first
    guess. Success when the largest defect is below `defect_tolerance` and the last inner
    solve settled.

    Args:
        iterations: the most Gauss-Newton steps in all (static).
        inner: the most Gauss-Newton steps between two multiplier updates (static).
        penalty: rho's first value.
        tolerance: an inner solve ends when a step lowers the merit by less than this
            (relative).
        defect_tolerance: the largest defect accepted, in the state's units.
        regularization: added to the control blocks, raised tenfold after a failed step.
        qp_iterations: projected Newton steps of the bounded control step (static).

    More on the method, first guess and result: the documentation site's Details page
    (docs/details.md).
    """

    iterations: int = eqx.field(static=True, default=300)
    inner: int = eqx.field(static=True, default=20)
    penalty: float = 1e2
    tolerance: float = 1e-8
    defect_tolerance: float = 1e-9
    regularization: float = 1e-6
    qp_iterations: int = eqx.field(static=True, default=8)

    def solve(self, problem: Problem, us: Array, states: Array | None = None) -> Result:
        """Optimise the controls of `problem` from `us` (normally through `mbjax.trajopt.solve`).

        Args:
            problem: the trajectory-optimisation problem.
            us: the first guess, inside the bounds, shape (horizon, nu).
            states: the knots' first states, shape (horizon + 1, nx) (the first replaced by
                the problem's x0); None for the rollout of us.

        Returns:
            The `Result`: the rollout of the final controls, `costs` the merit after each
                inner iteration.
        """
        alphas = jnp.asarray(STEPS, us.dtype)
        nx = problem.ndx

        def defects(xs, us):
            return problem.defects(xs, us)

        def merit(xs, us, lam, rho):
            e = defects(xs, us)
            return problem.cost(xs, us) + jnp.sum(lam * e) + 0.5 * rho * jnp.sum(e * e)

        def direction(xs, us, lam, rho, mu):
            """The Gauss-Newton step (dxs, dus) of the merit, and whether it is finite."""
            (A, B, e), (lx, lu, lxx, lux, luu) = problem.linearize(xs, us)
            vx, Vxx = problem.final_expansion(xs[-1])
            eye_x = jnp.eye(nx, dtype=us.dtype)

            def back(carry, inputs):
                v, V = carry
                A, B, lx, lu, lxx, lux, luu, u, e, lam = inputs
                S = jnp.linalg.inv(rho * eye_x + V)
                P = rho * S @ V
                P = 0.5 * (P + P.T)
                g = S @ (V @ lam + rho * v) + P @ e          # the value's gradient at w = e
                k, K, v, V, _, _ = riccati_step(problem, (A, B, lx, lu, lxx, lux, luu), u, g, P,
                                                mu, self.qp_iterations)
                return (v, V), (k, K, S, v, V)

            _, (k, K, S, v, V) = jax.lax.scan(back, (vx, Vxx), (A, B, lx, lu, lxx, lux, luu, us,
                                                                e, lam), reverse=True)
            # the values at k + 1 that each stage's y needs: V_{k+1}, v_{k+1} (terminal last)
            v_next = jnp.concatenate([v[1:], vx[None]])

            def forward(dx, inputs):
                A, B, k, K, S, v, e, lam = inputs
                du = k + K @ dx
                w = e + A @ dx + B @ du
                y = S @ (rho * w + lam - v)
                return y, (du, y)

            _, (dus, dys) = jax.lax.scan(forward, jnp.zeros(nx, us.dtype),
                                         (A, B, k, K, S, v_next, e, lam))
            dxs = jnp.concatenate([jnp.zeros((1, nx), us.dtype), dys])
            ok = jnp.all(jnp.isfinite(dxs)) & jnp.all(jnp.isfinite(dus))
            return dxs, dus, ok

        def inner(s):
            xs, us, lam, rho, mu, value, _, i, costs = s
            dxs, dus, ok = direction(xs, us, lam, rho, mu)

            def trial(j):
                u = jnp.clip(us + alphas[j] * dus, problem.lower, problem.upper)
                x = jax.vmap(problem.integrate)(xs, alphas[j] * dxs)
                return x, u, merit(x, u, lam, rho)

            def worse(t):
                _, _, m, j = t
                return ok & ~(m < value) & (j < len(STEPS))

            def next_trial(t):
                j = t[3]
                return (*trial(j), j + 1)

            x, u, m, _ = jax.lax.while_loop(worse, next_trial, (xs, us, value, jnp.array(0)))
            accept = ok & (m < value)
            xs, us = jnp.where(accept, x, xs), jnp.where(accept, u, us)
            change = value - m
            value = jnp.where(accept, m, value)
            # a merit at round-off (`cost_floor`: an exact optimum's 0) cannot decrease further
            settled = ((accept & (change <= self.tolerance * jnp.abs(value)))
                       | (jnp.abs(value) <= cost_floor(value.dtype)))
            mu = jnp.where(accept, jnp.maximum(mu / 10.0, 1e-9), mu * 10.0)
            return xs, us, lam, rho, mu, value, settled, i + 1, costs.at[i + 1].set(value)

        def outer(s):
            xs, us, lam, rho, mu, value, _, i, costs, defect = s
            stop = jnp.minimum(i + self.inner, self.iterations)

            def more(t):
                return ~t[6] & (t[7] < stop) & (t[4] < MU_CEILING)

            xs, us, lam, rho, mu, value, settled, i, costs = jax.lax.while_loop(
                more, inner, (xs, us, lam, rho, mu, value, jnp.array(False), i, costs))
            e = defects(xs, us)
            new = jnp.max(jnp.abs(e))
            lam = lam + rho * e
            rho = jnp.where(new > 0.25 * defect, 10.0 * rho, rho)
            return (xs, us, lam, rho, mu, merit(xs, us, lam, rho), settled, i, costs, new)

        def running(s):
            settled, i, mu, defect = s[6], s[7], s[4], s[9]
            done = settled & (defect <= self.defect_tolerance)
            return ~done & (i < self.iterations) & (mu < MU_CEILING)

        xs = problem.initial_states(states, us)
        lam = jnp.zeros((problem.horizon, nx), us.dtype)
        rho = jnp.asarray(self.penalty, us.dtype)
        value = merit(xs, us, lam, rho)
        s = (xs, us, lam, rho, jnp.asarray(self.regularization, us.dtype), value,
             jnp.array(False), jnp.array(0), history(self.iterations + 1, value),
             jnp.asarray(jnp.inf, us.dtype))
        s = jax.lax.while_loop(running, outer, s)
        us, mu, settled, iterations, costs, defect = s[1], s[4], s[6], s[7], s[8], s[9]
        return rollout_result(problem, us, costs, iterations,
                              settled & (defect <= self.defect_tolerance), "MultipleShooting", mu)
