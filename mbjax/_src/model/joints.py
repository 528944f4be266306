"""Joint models: what each joint type contributes to the tree recursions.

For joint k between its proximal body and body k, `joint_calc` gives (Featherstone's jcalc; Anderson
1993 eqs 21, 23, 25, 27, 29, 31 for one subjoint each):

    R_J, p_J   orientation and origin of body k's frame in the joint frame (x_joint = R_J x_k + p_J),
    S          the motion subspace, 6 x width in body-k coordinates: V_rel = S v_k,
    S_dot      its rate dS/dt (non-zero for the universal joint only), so that the
               velocity-product term is S_dot v_k,

and `joint_rate` maps (q_k, v_k) to q_dot_k. The joint frame sits in the proximal body at the
placement (R_T, p_T); a revolute or prismatic axis is a unit vector in the joint frame.

Types, with (nq, nv):
    revolute   (1, 1)  rotation q about `axis` (Anderson 1993's revolute subjoint, lambda = axis);
    prismatic  (1, 1)  translation q along `axis` (the prismatic subjoint);
    universal  (2, 2)  a Hooke joint: two revolute subjoints, about `axis` then about `axis2`
                       (Anderson 1993 §2.3(i): a multi-DOF joint as a sequence of 1-DOF subjoints);
    spherical  (4, 3)  manifold coordinates: a unit quaternion (w, x, y, z); v = body angular
                       velocity;
    free       (7, 6)  floating base: origin position (3) then a unit quaternion (4);
                       v = (omega, v_origin) in body coordinates.
Quaternions are normalized where they are read, so a drifted state still gives a rotation.
"""

from typing import NamedTuple

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.lie import (
    gamma,
    gamma_inv,
    quat_conjugate,
    quat_from_rotvec,
    quat_multiply,
    quat_to_matrix,
    rotvec_from_quat,
)
from mbjax._src.spatial import skew


class JointType(NamedTuple):
    """A joint type's number of configuration (nq) and velocity (nv) coordinates."""

    nq: int
    nv: int


JOINT_TYPES = {
    "revolute": JointType(1, 1),
    "prismatic": JointType(1, 1),
    "universal": JointType(2, 2),
    "spherical": JointType(4, 3),
    "free": JointType(7, 6),
}

NEUTRAL = {  # the zero configuration of each type
    "revolute": (0.0,),
    "prismatic": (0.0,),
    "universal": (0.0, 0.0),
    "spherical": (1.0, 0.0, 0.0, 0.0),
    "free": (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0),
}


def axis_rotation(axis: Array, angle: Array) -> Array:
    """The rotation by `angle` about the unit vector `axis` (Rodrigues' formula).

    Args:
        axis: unit axis, shape (3,).
        angle: angle [rad], a scalar.

    Returns:
        The rotation matrix, shape (3, 3).
    """
    K = skew(axis)
    # one product of (sin, 1 - cos) with the constant (K, K^2): as a sum of two scaled matrices,
    # XLA fuses the library's sin and cos into each of the nine entries, nine calls where one
    # does (most of the time of a batch of forward kinematics; benchmarks/README.md, trajopt)
    terms = jnp.stack([jnp.sin(angle), 1 - jnp.cos(angle)]) @ jnp.stack([K, K @ K]).reshape(2, 9)
    return jnp.eye(3, dtype=K.dtype) + terms.reshape(3, 3)


def _unit(q: Array) -> Array:
    return q / jnp.linalg.norm(q)


def joint_calc(kind: str, q: Array, v: Array, axis: Array, axis2: Array, width: int):
    """One joint's transform and motion subspace (Featherstone's jcalc; see the module).

    Args:
        kind: the joint type, a key of `JOINT_TYPES`.
        q: the joint's own configuration, shape (nq of the type,) (or padded longer).
        v: the joint's own velocity, shape (nv of the type,) (or padded longer).
        axis: the joint axis in the joint frame, shape (3,).
        axis2: a universal joint's second axis, shape (3,).
        width: the model's widest joint; S and S_dot are padded with zero columns to it so
            every body has one shape.

    Returns:
        R_J: body k's orientation in the joint frame, shape (3, 3).
        p_J: body k's origin in the joint frame, shape (3,).
        S: the motion subspace in body-k coordinates, shape (6, width).
        S_dot: its rate, shape (6, width).

    Raises:
        ValueError: an unknown joint type.
    """
    dtype = axis.dtype
    zero3 = jnp.zeros(3, dtype)
    eye = jnp.eye(3, dtype=dtype)
    if kind == "revolute":
        R, p = axis_rotation(axis, q[0]), zero3
        S = jnp.concatenate([axis, zero3])[:, None]
    elif kind == "prismatic":
        R, p = eye, axis * q[0]
        S = jnp.concatenate([zero3, axis])[:, None]
    elif kind == "universal":
        R2 = axis_rotation(axis2, q[1])
        R, p = axis_rotation(axis, q[0]) @ R2, zero3
        a1 = R2.T @ axis                    # the first axis seen from body k
        S = jnp.stack([jnp.concatenate([a1, zero3]), jnp.concatenate([axis2, zero3])], -1)
        # d/dt (R2^T axis) = (R2^T axis) x axis2 q2_dot; axis2 is fixed in body k
        S_dot = jnp.stack([jnp.concatenate([jnp.cross(a1, axis2) * v[1], zero3]),
                           jnp.zeros(6, dtype)], -1)
    elif kind == "spherical":
        R, p = quat_to_matrix(_unit(q[:4])), zero3
        S = jnp.concatenate([eye, jnp.zeros((3, 3), dtype)])
    elif kind == "free":
        R, p = quat_to_matrix(_unit(q[3:7])), q[:3]
        S = jnp.eye(6, dtype=dtype)
    else:
        raise ValueError(f"unknown joint type {kind!r}; choose from {sorted(JOINT_TYPES)}")
    if kind != "universal":
        S_dot = jnp.zeros_like(S)
    pad = ((0, 0), (0, width - S.shape[1]))
    return R, p, jnp.pad(S, pad), jnp.pad(S_dot, pad)


def joint_rate(kind: str, q: Array, v: Array) -> Array:
    """One joint's configuration rate: v itself, or the quaternion kinematics q * (0, w) / 2.

    Args:
        kind: the joint type.
        q: the joint's configuration, shape (nq,).
        v: the joint's velocity, shape (nv,).

    Returns:
        q_dot, shape (nq,).
    """
    if kind == "spherical":
        return 0.5 * quat_multiply(_unit(q[:4]), jnp.concatenate([jnp.zeros(1, v.dtype), v[:3]]))
    if kind == "free":
        R = quat_to_matrix(_unit(q[3:7]))
        quat_dot = 0.5 * quat_multiply(_unit(q[3:7]),
                                       jnp.concatenate([jnp.zeros(1, v.dtype), v[:3]]))
        return jnp.concatenate([R @ v[3:6], quat_dot])
    return v[: JOINT_TYPES[kind].nq]


def joint_integrate(kind: str, q0: Array, v: Array) -> Array:
    """One joint's configuration q0 (+) v: moved along v for one unit of time on its group.

    q0 + v for revolute, prismatic and universal joints; the body-frame rotation increment
    quat0 * exp(omega) (Borri 1990 §2) for a spherical joint; for a free joint the exponential of
    the body twist v = (omega; u) on SE(3): R0 exp(omega), p0 + R0 Gamma(omega) u, with Gamma the
    tangent map of Borri 1990 eq A.17 (Pinocchio's `integrate`, its exp6). The quaternion is
    kept in q0's hemisphere (q and -q are one rotation), as Pinocchio keeps it, so that a
    trajectory's quaternions do not jump sign.

    Args:
        kind: the joint type.
        q0: the joint's configuration, shape (nq,).
        v: a tangent vector (a velocity times a time), shape (nv,).

    Returns:
        The configuration, shape (nq,).
    """
    if kind in ("spherical", "free"):
        quat0 = _unit(q0[-4:])
        quat = quat_multiply(quat0, quat_from_rotvec(v[:3]))
        quat = jnp.where(quat @ quat0 < 0, -quat, quat)       # q0's hemisphere, as Pinocchio's
        if kind == "spherical":
            return quat
        return jnp.concatenate([q0[:3] + quat_to_matrix(quat0) @ (gamma(v[:3]) @ v[3:6]), quat])
    n = JOINT_TYPES[kind].nq
    return q0[:n] + v[:n]


def joint_difference(kind: str, q0: Array, q1: Array, continuous: Array) -> Array:
    """One joint's tangent vector v with q0 (+) v = q1 (`joint_integrate`'s inverse).

    q1 - q0 for prismatic and universal joints and for a revolute joint with limits; the angle
    wrapped to [-pi, pi) for a revolute joint without (continuous, as Pinocchio's); the body-frame
    rotation vector log(quat0^-1 quat1) for a spherical joint, with |omega| <= pi; and the
    SE(3) logarithm (omega; Gamma(omega)^-1 R0^T (p1 - p0)) for a free joint.

    Args:
        kind: the joint type.
        q0: the first configuration, shape (nq,).
        q1: the second configuration, shape (nq,).
        continuous: a boolean scalar, whether a revolute joint has no limits.

    Returns:
        v, shape (nv,).
    """
    if kind in ("spherical", "free"):
        quat0, quat1 = _unit(q0[-4:]), _unit(q1[-4:])
        omega = rotvec_from_quat(quat_multiply(quat_conjugate(quat0), quat1))
        if kind == "spherical":
            return omega
        u = gamma_inv(omega) @ (quat_to_matrix(quat0).T @ (q1[:3] - q0[:3]))
        return jnp.concatenate([omega, u])
    n = JOINT_TYPES[kind].nq
    d = q1[:n] - q0[:n]
    return jnp.where(continuous, wrap_angle(d), d) if kind == "revolute" else d


def wrap_angle(d: Array) -> Array:
    """An angle, or angles, wrapped to [-pi, pi)."""
    return d - 2 * jnp.pi * jnp.floor((d + jnp.pi) / (2 * jnp.pi))


def joint_local_rate(kind: str, q0: Array, xi: Array, v: Array) -> Array:
    """One joint's chart rate xi_dot at chart point xi about q0 for velocity v.

    The chart is `joint_integrate`: q = q0 (+) xi. Its rate is v itself for Euclidean joints;
    Gamma(xi)^-T omega for the rotation increment (Borri 1990 eq 2.8); and for a free joint's
    translation, from d/dt (Gamma(xi_omega) xi_u) = exp(xi_omega) u,
    xi_u_dot = Gamma^-1 (exp(xi_omega) u - (d Gamma / dt) xi_u).

    Args:
        kind: the joint type.
        q0: the chart's base configuration, shape (nq,).
        xi: the chart point, shape (nv,).
        v: the joint's velocity, shape (nv,).

    Returns:
        xi_dot, shape (nv,).
    """
    if kind in ("spherical", "free"):
        omega_rate = gamma_inv(xi[:3]).T @ v[:3]
        if kind == "spherical":
            return omega_rate
        _, gamma_rate = jax.jvp(lambda w: gamma(w) @ xi[3:6], (xi[:3],), (omega_rate,))
        u_rate = gamma_inv(xi[:3]) @ (quat_to_matrix(quat_from_rotvec(xi[:3])) @ v[3:6]
                                      - gamma_rate)
        return jnp.concatenate([omega_rate, u_rate])
    return v[: JOINT_TYPES[kind].nv]
