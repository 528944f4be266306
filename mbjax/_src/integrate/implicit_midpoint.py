"""The implicit midpoint rule, solved by Newton's method with an autodiff Jacobian."""

import equinox as eqx
import jax
import jax.numpy as jnp

from mbjax._src.integrate.base import AbstractIntegrator


class ImplicitMidpoint(AbstractIntegrator):
    """The implicit midpoint rule y1 = y0 + dt f(t0 + dt/2, (y0 + y1)/2) for y = (q, u).

    Order 2, A-stable and symplectic; it conserves every quadratic invariant exactly (the norm
    of a quaternion, the kinetic energy and angular momentum of a free rigid body). The
    nonlinear equations are solved by a fixed number of Newton iterations, full or simplified.

    Args:
        newton_iterations: the number of Newton iterations per step (static).
        rtol: the convergence test's relative tolerance on the last Newton correction; None
            (default) for sqrt(eps) of the state's dtype.
        simplified: simplified Newton with a forward-difference Jacobian per step (see
            Newton iterations, below) instead of full Newton.

    Newton iterations:
        The nonlinear equations are solved by a fixed number of Newton iterations (a
        `lax.scan`, so reverse-mode differentiation passes through them). The step reports
        convergence when the last Newton correction is below `rtol` (1 + |y1|).

        - `simplified=False` (default): full Newton, the Jacobian at every iterate, started from
          an explicit Euler predictor; with quadratic convergence the error left is of order
          rtol^2.
        - `simplified=True`: simplified Newton, for stiff systems with few coordinates and dear
          dynamics (modal flexible bodies: the axial and high modes that bound an explicit
          step): the Jacobian of the dynamics once per step, at its start, by forward
          differences (the dynamics at y0 and its m perturbations, m = len(q) + len(u)), and
          each iteration one evaluation of the dynamics and a dense solve of size m. All
          m + 1 + newton_iterations evaluations run as one scan, so the dynamics compile once:
          differences rather than `jax.linearize`, whose tangent program compiles much more
          slowly than the dynamics (see benchmarks/README.md), and simplified Newton needs no
          exact Jacobian. The first iteration is the linearly implicit midpoint step, exact for
          the linear (elastic) part at any step, so the stiff modes stay bounded however far dt
          is past their period; the later ones converge linearly at a rate of order dt times the
          change of the Jacobian over the step.
    """

    newton_iterations: int = eqx.field(default=6, static=True)
    rtol: float | None = eqx.field(default=None, static=True)  # None: sqrt(eps) of the dtype
    simplified: bool = eqx.field(default=False, static=True)

    order = 2
    name = "implicit_midpoint"

    def step(self, system, t, q, u, dt, a0=None):
        n = q.shape[0]
        y0 = jnp.concatenate([q, u])
        tm = t + dt / 2

        def rate(ym):
            qm, um = ym[:n], ym[n:]
            return jnp.concatenate([system.kinematics(qm, um), system.acceleration(tm, qm, um)])

        def residual(y1):
            return y1 - y0 - dt * rate((y0 + y1) / 2)

        if self.simplified:
            return self._simplified_step(system, rate, q, y0, dt)

        def newton(y, _):
            delta = jnp.linalg.solve(jax.jacfwd(residual)(y), residual(y))
            return y - delta, jnp.linalg.norm(delta)

        start = y0 - residual(y0)  # explicit Euler
        y1, corrections = jax.lax.scan(newton, start, None, length=self.newton_iterations)
        return self._finish(system, n, y1, corrections[-1])

    def _finish(self, system, n, y1, correction):
        rtol = jnp.sqrt(jnp.finfo(y1.dtype).eps) if self.rtol is None else self.rtol
        converged = correction <= rtol * (1.0 + jnp.linalg.norm(y1))
        return system.project(y1[:n]), y1[n:], converged

    def _simplified_step(self, system, rate, q, y0, dt):
        """Simplified Newton as one scan over the evaluations of the dynamics, so that they are
        traced and compiled once (as RK4's stages are): slot 0 evaluates f(y0), slots 1 ... m the
        difference quotients of the Jacobian's columns (the last one also takes the linearly
        implicit step), the remaining `newton_iterations` slots the Newton iterations."""
        m = y0.shape[0]
        eye = jnp.eye(m, dtype=y0.dtype)
        h = jnp.sqrt(jnp.finfo(y0.dtype).eps) * jnp.maximum(1.0, jnp.abs(y0))

        def slot(carry, i):
            jacobian, f0, y, _ = carry
            differences = (i >= 1) & (i <= m)
            column = jnp.where(differences, eye[jnp.clip(i - 1, 0, m - 1)], 0.0)
            newton = i > m
            f = rate(jnp.where(newton, (y0 + y) / 2, y0 + h * column))
            f0 = jnp.where(i == 0, f, f0)
            jacobian = jacobian + jnp.outer((f - f0) / jnp.where(differences, h @ column, 1.0), column)
            lu = jax.scipy.linalg.lu_factor(eye - dt / 2 * jacobian)
            start = y0 + dt * jax.scipy.linalg.lu_solve(lu, f0)    # the linearly implicit step
            delta = jax.scipy.linalg.lu_solve(lu, y - y0 - dt * f)
            y = jnp.where(i == m, start, jnp.where(newton, y - delta, y))
            return (jacobian, f0, y, jnp.where(newton, jnp.linalg.norm(delta), jnp.inf)), None

        init = (jnp.zeros((m, m), y0.dtype), y0, y0, jnp.asarray(jnp.inf, y0.dtype))
        (_, _, y1, correction), _ = jax.lax.scan(slot, init, jnp.arange(m + 1 + self.newton_iterations))
        return self._finish(system, q.shape[0], y1, correction)
