"""The Carpal Wrist as an `AbstractSystem` for `simulate` (seed 003 §6.4)."""

import equinox as eqx
from jax import Array

from mbjax.integrate.system import AbstractSystem
from mbjax.wrist import dynamics
from mbjax.wrist.model import CarpalWrist


class WristSystem(AbstractSystem):
    """q = theta, u = theta_dot; theta_ddot from eq 6.21 under the motor torques
    `torque(wrist, t, theta, theta_dot)` (a module from `mbjax.wrist.torques`, a torque spline or
    a controller from `mbjax.trajopt`). With `ExplicitEuler` this is the chapter's eq 6.45."""

    wrist: CarpalWrist
    torque: eqx.Module

    def kinematics(self, q: Array, u: Array) -> Array:
        return u

    def acceleration(self, t: Array, q: Array, u: Array) -> Array:
        return dynamics.forward_dynamics(self.wrist, q, u, self.torque(self.wrist, t, q, u))
