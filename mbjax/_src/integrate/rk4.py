"""The classical fourth-order Runge-Kutta method on the coordinates (q, u)."""

import jax
import jax.numpy as jnp

from mbjax._src.integrate.base import AbstractIntegrator

# Butcher tableau: k_i = f(t + C_i dt, y + dt sum_j A_ij k_j), y1 = y + dt sum_i B_i k_i.
A = ((0.0, 0.0, 0.0, 0.0), (0.5, 0.0, 0.0, 0.0), (0.0, 0.5, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0))
B = (1 / 6, 1 / 3, 1 / 3, 1 / 6)
C = (0.0, 0.5, 0.5, 1.0)


class RK4(AbstractIntegrator):
    """The classical fourth-order Runge-Kutta method on (q, u), coordinates projected after the step.

    Order 4; conditionally stable (|lambda dt| < 2.83 on the imaginary axis). Takes no
    arguments. It steps the coordinates themselves, a quaternion's four included, and normalizes
    after the step: the classical method, kept as the reference for its form on the rotation
    group and SE(3), `RKMK4` (the Euler methods step on the group).

    The four stages run as one `lax.scan` over the tableau rows, so the system's equations of
    motion are traced and compiled once per step, not four times, which shortens compilation
    for a heavy right-hand side (an autodiff Lagrangian, a flexible body) at no cost in run
    time; see benchmarks/README.md.
    """

    order = 4
    name = "rk4"

    def step(self, system, t, q, u, dt, a0=None):
        a, c = jnp.asarray(A, q.dtype), jnp.asarray(C, q.dtype)

        def stage(ks, i):
            kq, ku = ks
            yq = q + dt * jnp.tensordot(a[i], kq, axes=1)
            yu = u + dt * jnp.tensordot(a[i], ku, axes=1)
            s = t + c[i] * dt
            return (kq.at[i].set(system.kinematics(yq, yu)),
                    ku.at[i].set(system.acceleration(s, yq, yu))), None

        zeros = (jnp.zeros((4,) + q.shape, q.dtype), jnp.zeros((4,) + u.shape, u.dtype))
        if a0 is None:
            (kq, ku), _ = jax.lax.scan(stage, zeros, jnp.arange(4))
        else:                                   # the first stage's acceleration is known
            first = (zeros[0].at[0].set(system.kinematics(q, u)), zeros[1].at[0].set(a0))
            (kq, ku), _ = jax.lax.scan(stage, first, jnp.arange(1, 4))
        b = jnp.asarray(B, q.dtype)
        q1 = q + dt * jnp.tensordot(b, kq, axes=1)
        u1 = u + dt * jnp.tensordot(b, ku, axes=1)
        return system.project(q1), u1, jnp.array(True)
