"""Motor-torque laws for `WristSystem` built from `mbjax.control`."""

import equinox as eqx
import jax.numpy as jnp

from mbjax._src.control import PD
from mbjax._src.wrist import dynamics


def servo(wrist, theta_ref, stiffness, damping, gravity_feedforward: bool = True) -> PD:
    """A joint PD servo holding theta_ref: tau = stiffness (theta_ref - theta) - damping
    theta_dot, plus the gravity torque C(theta_ref) of eq 6.16 when `gravity_feedforward`."""
    theta_ref = jnp.asarray(theta_ref, dtype=float)
    # jitted: run op by op, the forward-mode Jacobians of eq 6.16 take seconds of dispatch
    feedforward = (eqx.filter_jit(dynamics.eom_terms)(wrist, theta_ref, jnp.zeros_like(theta_ref))[2]
                   if gravity_feedforward else 0.0)
    return PD(stiffness, damping, theta_ref, feedforward=feedforward)
