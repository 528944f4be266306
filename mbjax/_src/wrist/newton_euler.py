"""An independent route to the Carpal Wrist's motor torques: Newton-Euler on the tool and the
principle of virtual power through the wrist Jacobian (the legs are massless).

The tool's velocities come from the closed-form Jacobian (`chart_jacobian`, K^-1 D), not from the
Lagrangian: (p, g)_dot = J theta_dot, N_dot from N = (-g, 1) / s, omega = 2 N x N_dot (the
mirror plate's angular velocity, `docs/carpal-wrist-model.md`), c_D = 2 p N_z N and v_G = c_D_dot +
omega x R G. Then the wrench the distal plate exerts on the tool, about G,

    F = m (a_G + g e3),      n = I_B omega_dot + omega x I_B omega,   I_B = R I_G R^T,

maps to motor torques through the velocity Jacobians, tau = J_v^T F + J_omega^T n, because the
motors' power tau . theta_dot equals F . v_G + n . omega for every theta_dot.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.wrist.kinematics import chart_jacobian, midplane, normal_from_slope, rotation_from_slope


def tool_velocity(wrist, theta: Array, theta_dot: Array) -> tuple[Array, Array]:
    """(v_G, omega) from the closed-form Jacobian (physical rotation model only)."""
    p, g = midplane(wrist, theta)
    rates = chart_jacobian(wrist, theta) @ theta_dot
    p_dot, g_dot = rates[0], rates[1:]
    s = jnp.sqrt(1.0 + g @ g)
    N = normal_from_slope(g)
    N_dot = jnp.concatenate([-g_dot, jnp.zeros(1, g.dtype)]) / s - N * (g @ g_dot) / s**2
    omega = 2 * jnp.cross(N, N_dot)
    c_dot = 2 * (p_dot * N[2] * N + p * N_dot[2] * N + p * N[2] * N_dot)
    R = rotation_from_slope(g, "physical")
    return c_dot + jnp.cross(omega, R @ wrist.tool_com), omega


def newton_euler_torques(wrist, theta: Array, theta_dot: Array, theta_ddot: Array) -> Array:
    """Motor torques for the motion (theta, theta_dot, theta_ddot) by Newton-Euler on the tool."""
    if wrist.rotation_model != "physical":
        raise ValueError("the Newton-Euler route models the physical mirror plate; "
                         "rotation_model='chapter' has no physical angular velocity to match")
    theta, theta_dot, theta_ddot = (jnp.asarray(x) for x in (theta, theta_dot, theta_ddot))
    velocities = lambda th, thd: tool_velocity(wrist, th, thd)      # noqa: E731
    (v, omega), (a, omega_dot) = jax.jvp(velocities, (theta, theta_dot), (theta_dot, theta_ddot))
    J_v, J_omega = jax.jacfwd(velocities, argnums=1)(theta, theta_dot)   # linear in theta_dot
    R = rotation_from_slope(midplane(wrist, theta)[1], "physical")
    I_B = R @ wrist.tool_inertia @ R.T
    F = wrist.tool_mass * (a + jnp.array([0.0, 0.0, wrist.gravity]))
    n = I_B @ omega_dot + jnp.cross(omega, I_B @ omega)
    return J_v.T @ F + J_omega.T @ n
