"""Carpal Wrist dynamics from its Lagrangian by autodiff (Canfield 1997 §6.3).

L(theta, theta_dot) = T - V (eq 6.7) is written once, in the input angles theta (the chapter's
generalized coordinates), from the closed-form kinematics:

    T = 1/2 m v_G . v_G + 1/2 omega . (R I_G R^T) omega,     V = m g x_G . e3,

with v_G and R_dot from one forward-mode derivative of the pose along theta_dot and
[omega]x = R_dot R^T. (Eq 6.7 prints omega_i R_ij I_jk omega_k; the inertia in B is R I R^T.)
Lagrange's equations (eq 6.5) then give eq 6.16, tau = A(theta) theta_ddot + B(theta, theta_dot)
+ C(theta), with

    A = d^2 T / d theta_dot^2,   B = (d^2 T / d theta_dot d theta) theta_dot - dT/d theta,
    C = dV / d theta,

all by autodiff: none of the chapter's hand expansions (eqs 6.8-6.15, 6.22-6.42) is needed.
`eom_terms` evaluates them from the pose's first and second derivatives (T is quadratic in
theta_dot: A = J^T diag(m, I) J from the velocity Jacobians, B from dA/dtheta), and
`inverse_dynamics` differentiates L itself, so the two are independent routes to the same
equations (tests/wrist/test_dynamics.py). The legs are massless, so A is singular where a leg is
(the inverse singularity, the workspace boundary); inside the workspace it is positive definite
and eq 6.21 is solved by Cholesky.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.linalg import spd_solve
from mbjax._src.wrist.kinematics import _dot, _matmul, com_and_rotation


def _vee(W: Array) -> Array:
    """The axial vector of the skew part of W."""
    return 0.5 * jnp.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]])


def tool_velocity(wrist, theta: Array, theta_dot: Array) -> tuple[Array, Array]:
    """(v_G, omega) in B: the tool's centre-of-mass velocity and angular velocity, from the
    derivative of the pose along theta_dot ([omega]x = R_dot R^T; eq 6.2 for the chapter's R)."""
    (_, R), (v, R_dot) = jax.jvp(lambda th: com_and_rotation(wrist, th), (theta,), (theta_dot,))
    return v, _vee(_matmul(R_dot, R.T))


def kinetic_energy(wrist, theta: Array, theta_dot: Array) -> Array:
    """T of eq 6.7."""
    R = com_and_rotation(wrist, theta)[1]
    v, omega = tool_velocity(wrist, theta, theta_dot)
    omega_D = _dot(R.T, omega)                       # in D, where the inertia is constant
    return 0.5 * wrist.tool_mass * _dot(v, v) + 0.5 * _dot(omega_D, _dot(wrist.tool_inertia, omega_D))


def potential_energy(wrist, theta: Array) -> Array:
    """V of eq 6.7: m g (p + R33 p + R3j G_j) = m g x_G . e3."""
    return wrist.tool_mass * wrist.gravity * com_and_rotation(wrist, theta)[0][2]


def lagrangian(wrist, theta: Array, theta_dot: Array) -> Array:
    """L = T - V (eq 6.6)."""
    return kinetic_energy(wrist, theta, theta_dot) - potential_energy(wrist, theta)


def energy(wrist, theta: Array, theta_dot: Array) -> Array:
    """T + V, conserved with zero motor torque."""
    return kinetic_energy(wrist, theta, theta_dot) + potential_energy(wrist, theta)


def velocity_jacobians(wrist, theta: Array) -> tuple[Array, Array]:
    """(J_G, J_D) with v_G = J_G theta_dot (in B) and omega_D = R^T omega = J_D theta_dot (in D):
    one forward-mode Jacobian of the pose, column k of J_D being R^T omega_k with
    [omega_k]x = dR/dtheta_k R^T, as in `tool_velocity`."""
    def pose(th):
        x_G, R = com_and_rotation(wrist, th)
        return (x_G, R), R

    (dx, dR), R = jax.jacfwd(pose, has_aux=True)(theta)               # (3, 3), (3, 3, 3)
    J_D = jax.vmap(lambda dR_k: _dot(R.T, _vee(_matmul(dR_k, R.T))), out_axes=1)(
        jnp.moveaxis(dR, -1, 0))
    return dx, J_D


def _mass_matrix_and_jacobian(wrist, theta: Array) -> tuple[Array, Array]:
    J_G, J_D = velocity_jacobians(wrist, theta)
    A = wrist.tool_mass * _matmul(J_G.T, J_G) + _matmul(J_D.T, _matmul(wrist.tool_inertia, J_D))
    return A, J_G


def mass_matrix(wrist, theta: Array) -> Array:
    """A(theta) of eq 6.16, the Hessian of T (eq 6.7) in theta_dot. T is quadratic in theta_dot,
    1/2 theta_dot^T A theta_dot, so A = m J_G^T J_G + J_D^T I_D J_D (`velocity_jacobians`)."""
    return _mass_matrix_and_jacobian(wrist, jnp.asarray(theta))[0]


def eom_terms(wrist, theta: Array, theta_dot: Array) -> tuple[Array, Array, Array]:
    """(A, B, C) of eq 6.16: tau = A theta_ddot + B + C.

    Lagrange's equations (eq 6.5) with T = 1/2 theta_dot^T A(theta) theta_dot give
    B = A_dot theta_dot - dT/dtheta, whose parts are both read from one forward-mode Jacobian
    dA/dtheta: A_dot = dA/dtheta . theta_dot and dT/dtheta_k = 1/2 theta_dot^T dA/dtheta_k
    theta_dot; C = dV/dtheta = m g (J_G)_3. Second derivatives of the kinematics, where
    differentiating T itself (A = d^2T/dtheta_dot^2, B's mixed term) nests three: the same
    numbers (tests/wrist/test_dynamics.py) from a smaller graph, which compiles faster
    (benchmarks/README.md)."""
    theta, theta_dot = jnp.asarray(theta), jnp.asarray(theta_dot)

    def inertia(th):
        A, J_G = _mass_matrix_and_jacobian(wrist, th)
        return A, (A, J_G)

    dA, (A, J_G) = jax.jacfwd(inertia, has_aux=True)(theta)          # dA[i, j, k] = dA_ij/dtheta_k
    A_dot = _dot(dA, theta_dot)
    dT = 0.5 * _dot(_dot(jnp.moveaxis(dA, -1, 0), theta_dot), theta_dot)
    B = _dot(A_dot, theta_dot) - dT
    C = wrist.tool_mass * wrist.gravity * J_G[2]
    return A, B, C


def external_torques(wrist, theta: Array, wrench: Array, point: Array | None = None) -> Array:
    """The motor torques (3,) equivalent to a world-frame wrench (torque; force) (6,) on the tool,
    its force acting at the distal-plate centre (the origin of the tool's frame D) or at `point`
    (D coordinates): J^T w, by one reverse pass through the velocity map theta_dot -> (omega,
    v_point), which is linear."""
    offset = -wrist.tool_com if point is None else jnp.asarray(point) - wrist.tool_com

    def pose(th):
        x_G, R = com_and_rotation(wrist, th)
        return x_G + _dot(R, offset), R

    def velocities(theta_dot):
        (_, R), (v, R_dot) = jax.jvp(pose, (theta,), (theta_dot,))
        return _vee(_matmul(R_dot, R.T)), v

    return jax.vjp(velocities, jnp.zeros_like(theta))[1]((wrench[:3], wrench[3:]))[0]


def forward_dynamics(wrist, theta: Array, theta_dot: Array, torque: Array) -> Array:
    """theta_ddot = A^-1 (tau - B - C) (eqs 6.17-6.21), by Cholesky (written out: `mbjax._src.linalg`)."""
    A, B, C = eom_terms(wrist, theta, theta_dot)
    return spd_solve(A, jnp.asarray(torque) - B - C)


def inverse_dynamics(wrist, theta: Array, theta_dot: Array, theta_ddot: Array) -> Array:
    """tau = d/dt(dL/d theta_dot) - dL/d theta (eq 6.5): one forward-mode derivative of
    dL/d theta_dot along (theta_dot, theta_ddot), no mass matrix formed."""
    theta, theta_dot, theta_ddot = (jnp.asarray(x) for x in (theta, theta_dot, theta_ddot))
    dL_dqd = jax.jacfwd(lagrangian, argnums=2)
    ddt = jax.jvp(lambda th, thd: dL_dqd(wrist, th, thd), (theta, theta_dot), (theta_dot, theta_ddot))[1]
    return ddt - jax.jacfwd(lagrangian, argnums=1)(wrist, theta, theta_dot)
