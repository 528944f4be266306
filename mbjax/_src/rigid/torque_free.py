"""Closed-form motion of a torque-free rigid body with an axis of symmetry (Borri 1990 §8.1)."""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src import lie


@jax.jit
def torque_free_motion(J_a, J_t, R0: Array, Omega0: Array, t: Array,
                       axis=(0.0, 0.0, 1.0)) -> tuple[Array, Array]:
    """Rotation R(t) and body angular velocity Omega(t) of a symmetric body with no torque.

    With h = J omega (constant), the precession omega_p = h / J_t (Borri 1990 eq 8.3) and the
    relative spin omega_r = omega - omega_p (eq 8.5), the motion is (eqs 8.7-8.8)

        R(t) = exp(t omega_p x I) exp(t omega_r(0) x I) R0,
        omega(t) = omega_p + exp(t omega_p x I) omega_r(0).

    Args:
        J_a: axial moment of inertia about the centre of mass [kg m^2], a scalar.
        J_t: transverse moment of inertia about the centre of mass [kg m^2], a scalar.
        R0: rotation (body to world) at t = 0, shape (3, 3).
        Omega0: body-frame angular velocity at t = 0 [rad/s], shape (3,).
        t: time [s], a scalar.
        axis: the symmetry axis in the body frame, shape (3,) (normalized here).

    Returns:
        (R(t), Omega(t)): the rotation, shape (3, 3), and the body-frame angular velocity
            [rad/s], shape (3,).
    """
    a = jnp.asarray(axis, dtype=float)
    a = a / jnp.linalg.norm(a)
    J_body = J_a * jnp.outer(a, a) + J_t * (jnp.eye(3) - jnp.outer(a, a))  # eq 8.1
    R0 = jnp.asarray(R0, dtype=float)
    omega0 = R0 @ Omega0
    h = R0 @ (J_body @ Omega0)
    omega_p = h / J_t
    omega_r0 = omega0 - omega_p
    Rp = lie.exp(t * omega_p)
    R = Rp @ lie.exp(t * omega_r0) @ R0
    omega = omega_p + Rp @ omega_r0
    return R, R.T @ omega
