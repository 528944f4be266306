"""Motor-torque laws tau(t, theta, theta_dot) for `WristSystem`: equinox modules, so their
parameters can be optimised (`mbjax.trajopt`) and swept."""

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax.wrist import dynamics


class ZeroTorque(eqx.Module):
    """Unpowered motors."""

    def __call__(self, wrist, t: Array, theta: Array, theta_dot: Array) -> Array:
        return jnp.zeros_like(theta)


class Servo(eqx.Module):
    """A joint PD servo holding theta_ref: tau = -stiffness (theta - theta_ref) - damping
    theta_dot, plus the gravity torque C(theta_ref) of eq 6.16 when `gravity_feedforward`."""

    theta_ref: Array
    stiffness: Array
    damping: Array
    gravity_feedforward: bool = eqx.field(static=True, default=True)

    def __call__(self, wrist, t: Array, theta: Array, theta_dot: Array) -> Array:
        tau = -self.stiffness * (theta - self.theta_ref) - self.damping * theta_dot
        if self.gravity_feedforward:
            tau = tau + dynamics.eom_terms(wrist, self.theta_ref, jnp.zeros_like(theta))[2]
        return tau
