"""The dense route for flexible trees: Lagrange's equations from the energies, by autodiff, O(n^3).

An independent check of the O(n) recursion (`mbjax._src.flex.aba`) that shares none of its partial
velocities or remainder terms: only the frame poses (`body_and_marker_poses`) and each body's generalized
mass (`mbjax._src.flex.body.mass_matrix`). The body-frame velocities come from differentiating the
poses, omega~ = R^T R_dot, v = R^T p_dot, so

    T(q, v) = sum_k w_k^T M_k(q_k) w_k / 2,  w_k = (omega_k, v_k, u_k)          (Anderson 1993 eq 34)
    V(q)    = -g . sum_k (m_k p_k + R_k S_k q_bar_k) + sum_k q_k^T K_k q_k / 2

and the residual of Lagrange's equations, d/dt dT/dv - dT/dq + dV/dq + D u + K_G q - tau, is
linear in v_dot; its Jacobian in v_dot (the mass matrix, unsymmetric with acceleration-dependent
stiffening) is solved densely. Coordinates must be their own rates (q_dot = v: revolute,
prismatic and universal joints).
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.flex.body import kinetic_energy as body_kinetic_energy
from mbjax._src.flex.kinematics import body_and_marker_poses
from mbjax._src.flex.model import FlexibleModel
from mbjax._src.flex.stiffening import inertial_scalars
from mbjax._src.lie import vee


def _check(model: FlexibleModel) -> None:
    if model.model.nq != model.model.nv:
        raise ValueError("the dense flexible route needs q_dot = v (revolute, prismatic and "
                         "universal joints); use the recursion for quaternion joints")


def _body_motion(model: FlexibleModel, q: Array, v: Array, v_dot: Array):
    """Per body: R, p, body-frame (omega, v), and body-frame (alpha, a) with a the classical
    acceleration of the frame origin less gravity, all from derivatives of the poses."""
    def poses(q_):
        R, p, _, _ = body_and_marker_poses(model, q_)
        return R, p

    def rates(q_, v_):
        return jax.jvp(poses, (q_,), (v_,))

    ((R, p), (R_dot, p_dot)), ((_, _), (R_ddot, p_ddot)) = jax.jvp(rates, (q, v), (v, v_dot))
    Rt = jnp.swapaxes(R, -1, -2)
    W = Rt @ R_dot                                           # omega~ in body components
    omega = jax.vmap(vee)(W)
    velocity = jnp.einsum("kij,kj->ki", Rt, p_dot)
    alpha = jax.vmap(vee)(Rt @ R_ddot - W @ W)               # d/dt (R^T R_dot) = R^T R_ddot - W^2
    a = jnp.einsum("kij,kj->ki", Rt, p_ddot - model.model.gravity)
    return R, p, omega, velocity, alpha, a


def kinetic_energy(model: FlexibleModel, q: Array, v: Array) -> Array:
    _, _, omega, velocity, _, _ = _body_motion(model, q, v, jnp.zeros_like(v))
    _, qf = model.split(q)
    _, uf = model.split(v)
    w = jnp.concatenate([omega, velocity, uf], -1)
    return jnp.sum(jax.vmap(body_kinetic_energy)(model.bodies, qf, w))


def potential_energy(model: FlexibleModel, q: Array) -> Array:
    """Gravity's potential (zero at the ground origin) plus the modal strain energy."""
    R, p, _, _ = body_and_marker_poses(model, q)
    _, qf = model.split(q)
    b = model.bodies
    q_bar = jnp.concatenate([jnp.ones((model.n, 1), q.dtype), qf], -1)
    first_moment = b.mass[:, None] * p + jnp.einsum("kij,kja,ka->ki", R, b.first, q_bar)
    strain = 0.5 * jnp.einsum("ks,kst,kt->", qf, b.stiffness, qf)
    return -jnp.sum(first_moment @ model.model.gravity) + strain


def energy(model: FlexibleModel, q: Array, v: Array) -> Array:
    return kinetic_energy(model, q, v) + potential_energy(model, q)


def residual(model: FlexibleModel, q: Array, v: Array, v_dot: Array, tau: Array) -> Array:
    """d/dt dT/dv - dT/dq + dV/dq + D u + K_G q - tau."""
    dT_dv = lambda q_, v_: jax.grad(kinetic_energy, argnums=2)(model, q_, v_)   # noqa: E731
    inertia = jax.jvp(dT_dv, (q, v), (v, v_dot))[1]
    generalized = (inertia - jax.grad(kinetic_energy, argnums=1)(model, q, v)
                   + jax.grad(potential_energy, argnums=1)(model, q) - tau)
    _, _, omega, _, alpha, a = _body_motion(model, q, v, v_dot)
    _, qf = model.split(q)
    _, uf = model.split(v)
    b = model.bodies
    s = jax.vmap(inertial_scalars)(a, alpha, omega)                        # Table 1's scalars
    modal = (jnp.einsum("kq,kqst,kt->ks", s, b.inertial_stiffening, qf)
             + jnp.einsum("kst,kt->ks", b.damping, uf))
    return generalized + model.join(jnp.zeros(model.model.nv, q.dtype), modal)


def external_forces(model: FlexibleModel, q: Array, f_ext: Array) -> Array:
    """The generalized forces (nv,) of world-frame wrenches f_ext (n, 6) (torque about each body
    frame's origin; force): the gradient in v of their power n . omega + f . p_dot."""
    def power(v):
        R, _, omega, velocity, _, _ = _body_motion(model, q, v, jnp.zeros_like(v))
        return (jnp.sum(f_ext[:, :3] * jnp.einsum("kij,kj->ki", R, omega))
                + jnp.sum(f_ext[:, 3:] * jnp.einsum("kij,kj->ki", R, velocity)))

    return jax.grad(power)(jnp.zeros(model.nv, q.dtype))


def lagrangian_forward_dynamics(model: FlexibleModel, q: Array, v: Array, tau: Array,
                           f_ext: Array | None = None, loads: Array | None = None):
    """v_dot from Lagrange's equations (the residual's Jacobian in v_dot solved densely), under
    generalized forces tau and external wrenches f_ext (as `external_forces`); with `loads`
    (m, nv), also the accelerations each row alone produces, (v_dot, responses (m, nv)), as
    `mbjax._src.flex.aba.flexible_aba_responses` (closed loops on this route).

    Distal-load stiffening (the reactions of child bodies, eq 33's second sum) needs no joint
    reactions here: the child's energies see its joint move with the grid point's second-order
    displacement (`mbjax._src.flex.kinematics.grid_point`), and Lagrange's equations turn that into
    K_G(F) q."""
    _check(model)
    if f_ext is not None:
        tau = tau + external_forces(model, q, f_ext)
    zero = jnp.zeros_like(v)
    r0 = residual(model, q, v, zero, tau)
    M = jax.jacfwd(lambda a: residual(model, q, v, a, tau))(zero)
    if loads is None:
        return jnp.linalg.solve(M, -r0)
    x = jnp.linalg.solve(M, jnp.concatenate([-r0[:, None], loads.T], 1))
    return x[:, 0], x[:, 1:].T
