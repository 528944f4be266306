"""Motor-torque laws for `WristSystem` built from `mbjax.control`."""

import equinox as eqx
import jax.numpy as jnp

from mbjax._src.control import PD
from mbjax._src.wrist import dynamics


def servo(wrist, theta_ref, stiffness, damping, gravity_feedforward: bool = True) -> PD:
    """A joint PD servo holding theta_ref, a control for `WristSystem`.

    tau = stiffness (theta_ref - theta) - damping theta_dot, plus the gravity torque
    C(theta_ref) of eq 6.16 when `gravity_feedforward`.

    Args:
        wrist (CarpalWrist): the `CarpalWrist`.
        theta_ref (Array): the input angles to hold [rad], shape (3,).
        stiffness (float | Array): proportional gain [N m/rad], a scalar or shape (3,).
        damping (float | Array): derivative gain [N m s/rad], a scalar or shape (3,).
        gravity_feedforward: add C(theta_ref), the torques that hold theta_ref against gravity.

    Returns:
        An `mbjax.control.PD` control.
    """
    theta_ref = jnp.asarray(theta_ref, dtype=float)
    # jitted: run op by op, dispatching the forward-mode Jacobians of eq 6.16 costs far more
    # than computing them
    feedforward = (eqx.filter_jit(dynamics.eom_terms)(wrist, theta_ref, jnp.zeros_like(theta_ref))[2]
                   if gravity_feedforward else 0.0)
    return PD(stiffness, damping, theta_ref, feedforward=feedforward)
