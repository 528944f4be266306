"""Semi-implicit (symplectic) Euler."""

import jax.numpy as jnp

from mbjax._src.integrate.base import AbstractIntegrator


class SemiImplicitEuler(AbstractIntegrator):
    """Semi-implicit (symplectic) Euler: u1 = u0 + dt u_dot(t0, q0, u0), then q1 = q0 (+) dt u1.

    The configuration steps on its group (`retract` along `tangent`: q0 + dt q_dot(q0, u1) for
    Euclidean coordinates, Pinocchio's `integrate` for a tree's quaternion joints), so on a
    tree it is Crocoddyl's `IntegratedActionModelEuler`. Order 1; symplectic for separable
    Hamiltonians, so energy errors stay bounded instead of growing. Takes no arguments.
    """

    order = 1
    name = "semi_implicit_euler"

    def step(self, system, t, q, u, dt, a0=None):
        u1 = u + dt * (system.acceleration(t, q, u) if a0 is None else a0)
        q1 = system.project(system.retract(q, dt * system.tangent(q, u1)))
        return q1, u1, jnp.array(True)
