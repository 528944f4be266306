"""The implicit midpoint rule, solved by Newton's method with an autodiff Jacobian."""

import equinox as eqx
import jax
import jax.numpy as jnp

from mbjax.integrate.base import AbstractIntegrator


class ImplicitMidpoint(AbstractIntegrator):
    """y1 = y0 + dt f(t0 + dt/2, (y0 + y1)/2) for y = (q, u). Order 2, A-stable and symplectic;
    it conserves every quadratic invariant exactly (the norm of a quaternion, the kinetic energy
    and angular momentum of a free rigid body).

    The nonlinear equations are solved by a fixed number of full Newton iterations (a `lax.scan`,
    so reverse-mode differentiation passes through them) started from an explicit Euler predictor.
    The step reports convergence when the last Newton correction is below `rtol` (1 + |y1|);
    with quadratic convergence the error left after it is then of order rtol^2.
    """

    newton_iterations: int = eqx.field(default=6, static=True)
    rtol: float | None = eqx.field(default=None, static=True)  # None: sqrt(eps) of the dtype

    order = 2
    name = "implicit_midpoint"

    def step(self, system, t, q, u, dt):
        n = q.shape[0]
        y0 = jnp.concatenate([q, u])
        tm = t + dt / 2

        def residual(y1):
            ym = (y0 + y1) / 2
            qm, um = ym[:n], ym[n:]
            f = jnp.concatenate([system.kinematics(qm, um), system.acceleration(tm, qm, um)])
            return y1 - y0 - dt * f

        def newton(y, _):
            delta = jnp.linalg.solve(jax.jacfwd(residual)(y), residual(y))
            return y - delta, jnp.linalg.norm(delta)

        predictor = y0 - residual(y0)  # explicit Euler
        y1, corrections = jax.lax.scan(newton, predictor, None, length=self.newton_iterations)
        rtol = jnp.sqrt(jnp.finfo(y1.dtype).eps) if self.rtol is None else self.rtol
        converged = corrections[-1] <= rtol * (1.0 + jnp.linalg.norm(y1))
        return system.project(y1[:n]), y1[n:], converged
