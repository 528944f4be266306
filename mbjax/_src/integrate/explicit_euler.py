"""Explicit (forward) Euler, the Carpal Wrist chapter's time stepping (Canfield 1997 eq 6.45)."""

import jax.numpy as jnp

from mbjax._src.integrate.base import AbstractIntegrator


class ExplicitEuler(AbstractIntegrator):
    """Explicit (forward) Euler: q1 = q0 (+) dt u0, u1 = u0 + dt u_dot(t0, q0, u0).

    The configuration steps on its group, as in `SemiImplicitEuler`.

    Order 1. It adds energy to every undamped oscillation and so is unconditionally unstable
    for conservative mechanics; it is here as the Carpal Wrist chapter's time stepping
    (Canfield 1997 eq 6.45). Takes no arguments.
    """

    order = 1
    name = "explicit_euler"

    def step(self, system, t, q, u, dt, a0=None):
        q1 = system.project(system.retract(q, dt * system.tangent(q, u)))
        u1 = u + dt * (system.acceleration(t, q, u) if a0 is None else a0)
        return q1, u1, jnp.array(True)
