"""Runge-Kutta-Munthe-Kaas of order 4 (`RKMK4`, whose docstring describes the step)."""

import jax.numpy as jnp

from mbjax._src.integrate.base import AbstractIntegrator


class RKMK4(AbstractIntegrator):
    """Runge-Kutta-Munthe-Kaas of order 4: RK4 in a chart that moves with the solution (Munthe-Kaas 1999).

    Each step integrates the local coordinate xi about the step's start configuration and
    retracts (see The method, below): rotations stay exactly on the rotation group. Order 4; on
    Euclidean systems it is RK4. Takes no arguments.

    The method:
        Each step integrates the local coordinate xi about the configuration q0 at the start of the
        step, xi_dot = local_rate(q0, xi, u) = dexp^-1_xi(velocity), from xi = 0, and maps back with
        q1 = retract(q0, xi1). For rotations dexp^-1 is Gamma^-T (Borri 1990 eqs 2.8, A.21), so this
        is RK4 on the incremental rotation vector of Borri 1990 §2: the configuration stays exactly
        on the rotation group and the chart never approaches the singularity of Gamma at |xi| = 2
        pi.
    """

    order = 4
    name = "rkmk4"

    def step(self, system, t, q, u, dt, a0=None):
        def f(s, xi, u_):
            return (system.local_rate(q, xi, u_),
                    system.acceleration(s, system.retract(q, xi), u_))

        xi0 = jnp.zeros_like(u)
        k1x, k1u = ((system.local_rate(q, xi0, u), a0) if a0 is not None else f(t, xi0, u))
        k2x, k2u = f(t + dt / 2, dt / 2 * k1x, u + dt / 2 * k1u)
        k3x, k3u = f(t + dt / 2, dt / 2 * k2x, u + dt / 2 * k2u)
        k4x, k4u = f(t + dt, dt * k3x, u + dt * k3u)
        xi1 = dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        u1 = u + dt / 6 * (k1u + 2 * k2u + 2 * k3u + k4u)
        return system.project(system.retract(q, xi1)), u1, jnp.array(True)
