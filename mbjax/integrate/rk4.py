"""The classical fourth-order Runge-Kutta method on the coordinates (q, u)."""

import jax.numpy as jnp

from mbjax.integrate.base import AbstractIntegrator


class RK4(AbstractIntegrator):
    """Classical RK4 on (q, u), coordinates projected after the step. Order 4; conditionally
    stable (|lambda dt| < 2.83 on the imaginary axis)."""

    order = 4
    name = "rk4"

    def step(self, system, t, q, u, dt):
        def f(s, q_, u_):
            return system.kinematics(q_, u_), system.acceleration(s, q_, u_)

        k1q, k1u = f(t, q, u)
        k2q, k2u = f(t + dt / 2, q + dt / 2 * k1q, u + dt / 2 * k1u)
        k3q, k3u = f(t + dt / 2, q + dt / 2 * k2q, u + dt / 2 * k2u)
        k4q, k4u = f(t + dt, q + dt * k3q, u + dt * k3u)
        q1 = q + dt / 6 * (k1q + 2 * k2q + 2 * k3q + k4q)
        u1 = u + dt / 6 * (k1u + 2 * k2u + 2 * k3u + k4u)
        return system.project(q1), u1, jnp.array(True)
