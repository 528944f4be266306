"""Outward kinematics of a tree (Anderson 1993 §2.3 step (i), eqs 20-31 for rigid bodies).

Anderson 1993 writes its recursions with vectors and dyadics, free of any frame; mbjax evaluates them in
ground-frame components, with 6-D spatial vectors (angular; linear) taken at the ground origin.
Then the recursions need no frame changes at all:

    V[k] = V[parent] + S[k] v[k]                                     (eqs 21, 23)
    c[k] = V[k] x (S[k] v[k]) + S_dot_local v[k]                      (eqs 29, 31: the remainder)

where S[k] is joint k's motion subspace at the ground origin. Only the poses need a sequential
product (`forward_kinematics`); everything else is vectorized over the bodies.
"""

import functools
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.linalg import unrolled_dot
from mbjax._src.linear_map import linear_map
from mbjax._src.lie import vee
from mbjax._src.model import Model
from mbjax._src.model.joints import joint_calc
from mbjax._src.model.model import _layout
from mbjax._src.rigid.tangents import instantiate, is_zero
from mbjax._src.spatial import cross_motion, inertia_matrix, skew
from mbjax._src.tree import forward_pass, path_sum

# the joints whose motion subspace is fixed in the joint's own body: moving joint j along one of
# its columns moves j's outward set rigidly about that screw (a universal joint's first axis is
# fixed in its parent instead)
JOINTS_FIXED_IN_BODY = ("revolute", "prismatic", "spherical", "free")


class Kinematics(NamedTuple):
    R: Array      # (n, 3, 3) body orientations in the ground frame
    p: Array      # (n, 3) body-frame origins (the hinge points h_k), ground frame
    S: Array      # (n, 6, width) motion subspaces, ground frame at the ground origin
    V: Array      # (n, 6) spatial velocities, ground frame at the ground origin
    c: Array      # (n, 6) remainder (velocity-product) accelerations, same frame
    I: Array      # (n, 6, 6) spatial inertias about the ground origin, ground frame  # noqa: E741 (the papers' name)
    v: Array      # (n, width) joint velocities, zero-padded


@jax.jit
def forward_kinematics(model: Model, q: Array) -> tuple[Array, Array]:
    """World orientation and origin of every body frame.

    Its derivative in q is written out (for the joints `fixed_in_body` accepts): moving the
    coordinates along dq moves body k rigidly by the twist xi_k, the sum of the joints' twists
    S_j e_j over k's path from the ground (ground frame at the ground origin; e_j the joint's
    increments along its columns, dq_j itself for a hinge), xi = pi (S e) with Jerkovsky 1978's path
    matrix pi (eq 1); then dR_k = xi_k,w x R_k and dp_k = xi_k,w x p_k + xi_k,v. One product of
    6-vectors per direction instead of the derivative of the products of rotations, so
    `jax.jacfwd` of a pose is cheaper (benchmarks/README.md). The derivative in the model's
    parameters is JAX's own.

    Args:
        model: the tree.
        q: configuration, shape (nq,).

    Returns:
        (R, p): each body's rotation (body to world), shape (n, 3, 3), and the origin of its
            frame (its joint) in the world [m], shape (n, 3).
    """
    if fixed_in_body(model):
        return _poses(model, q)
    return _poses.fun(model, q)


@jax.custom_jvp
def _poses(model: Model, q: Array) -> tuple[Array, Array]:
    R, p, _, _ = model.joints(q, jnp.zeros(model.nv, q.dtype))
    return compose(model, R, p)


@functools.partial(_poses.defjvp, symbolic_zeros=True)
def _poses_jvp(primals, tangents):
    model, q = primals
    d_model, dq = tangents
    still = jnp.zeros(model.nv, q.dtype)
    R_local, p_local, S_local, _ = model.joints(q, still)
    R, p = compose(model, R_local, p_local)
    dR, dp = jnp.zeros_like(R), jnp.zeros_like(p)
    if not is_zero(dq):
        S = to_ground(R, p, S_local)
        twist = path_sum(model.topology, columns(S, joint_increments(model, q, still, dq)))
        w = twist[:, :3]
        # w x each column of R
        dR = jnp.swapaxes(jnp.cross(w[:, None], jnp.swapaxes(R, -1, -2)), -1, -2)
        dp = jnp.cross(w, p) + twist[:, 3:]
    if not is_zero(d_model):
        _, (dR_m, dp_m) = jax.jvp(lambda m: _poses.fun(m, q), (model,),
                                  (instantiate(d_model, model),))
        dR, dp = dR + dR_m, dp + dp_m
    return (R, p), (dR, dp)


def fixed_in_body(model: Model) -> bool:
    """Whether every joint's motion subspace is fixed in its own body (`JOINTS_FIXED_IN_BODY`):
    the condition of the written-out derivatives here and in `rnea_derivatives`."""
    return all(kind in JOINTS_FIXED_IN_BODY for kind in model.joint_types)


def joint_increments(model: Model, q: Array, v: Array, dq: Array) -> Array:
    """Each joint's increments (n, width) along its columns for the coordinate tangent dq: dq
    itself for revolute and prismatic joints; otherwise S_local^T (vee(R^T dR); R^T dp) of the
    joint's local pose (R, p), a quaternion's normalization included. Linear in dq: a batch of
    directions at one state (`jax.jacfwd`) is one product with `increments_matrix`."""
    if model.euclidean:
        return model.body_v(dq)
    return _increments((model, q, v), dq)


def _increments_along(fixed: tuple, dq: Array) -> Array:
    model, q, v = fixed
    (R, _, S_local, _), (dR, dp, _, _) = jax.jvp(lambda q: model.joints(q, v), (q,), (dq,))
    Rt = jnp.swapaxes(R, -1, -2)
    twist = jnp.concatenate([jax.vmap(vee)(Rt @ dR), jnp.einsum("kij,kj->ki", Rt, dp)], -1)
    return jnp.einsum("kic,ki->kc", S_local, twist)


def _increments_batch(fixed: tuple, dqs: Array) -> Array:
    model, q, v = fixed
    return jax.vmap(model.body_v)(dqs @ increments_matrix(model, q, v).T)


_increments = linear_map("joint_increments", _increments_along, _increments_batch)


def increments_matrix(model: Model, q: Array, v: Array) -> Array:
    """The matrix G (nv, nq) of `joint_increments` (flattened): e = G dq. Each joint's
    increments depend on its own coordinates only, so G is block-diagonal: the identity for
    revolute and prismatic joints, S_local^T (vee(R^T dR / dq_k); R^T dp / dq_k) of the joint's
    own pose for the others (the placement cancels), from `jax.jacfwd` over its few
    coordinates."""
    if model.euclidean:
        return jnp.eye(model.nv, dtype=q.dtype)
    layout = _layout(model.joint_types)
    n, width, q_width = model.n, model.width, layout["q_width"]

    def block(kind, qk, vk, axis, axis2):
        if kind in ("revolute", "prismatic"):
            return jnp.eye(width, q_width, dtype=qk.dtype)
        def pose(qk):
            return joint_calc(kind, qk, vk, axis, axis2, width)[:2]
        (R, _), (dR, dp) = pose(qk), jax.jacfwd(pose)(qk)               # (3, 3, m), (3, m)
        twist = jnp.concatenate([jax.vmap(vee)(R.T @ jnp.moveaxis(dR, -1, 0)).T, R.T @ dp])
        S_local = joint_calc(kind, qk, vk, axis, axis2, width)[2]
        return jnp.pad(S_local.T @ twist, [(0, 0), (0, q_width - qk.shape[0])])

    blocks = model._per_type(block, q, v)                                  # (n, width, q_width)
    with jax.ensure_compile_time_eval():          # static: each coordinate's joint and column
        body_of = np.asarray(model._flat_q(np.broadcast_to(np.arange(n)[:, None], (n, q_width))))
        q_col = np.asarray(model._flat_q(np.broadcast_to(np.arange(q_width), (n, q_width))))
        v_col = np.asarray(model.flat_v(np.broadcast_to(np.arange(width), (n, width))))
    rows = blocks[model.dof_body(), v_col]                                 # (nv, q_width)
    return jnp.where(model.dof_body()[:, None] == body_of[None, :], rows[:, q_col], 0.0)


def columns(S: Array, x: Array) -> Array:
    """sum_c S[k, :, c] x[k, c]: (n, 6, width), (n, width) -> (n, 6)."""
    return unrolled_dot(S, x)


def compose(model: Model, R: Array, p: Array) -> tuple[Array, Array]:
    """World poses (R, p) of every body from each body's pose (R, p) in its parent's frame: the
    outward product along the tree (one tree pass)."""
    def step(parent, local):
        (R_parent, p_parent), (R_local, p_local) = parent, local
        return R_parent @ R_local, p_parent + R_parent @ p_local

    return forward_pass(model.topology, step, (jnp.eye(3, dtype=R.dtype), jnp.zeros(3, R.dtype)),
                        (R, p))


def to_ground(R: Array, p: Array, m: Array) -> Array:
    """Motion vectors (or the columns of a matrix, (..., 6, k)) from body coordinates at the body
    origin to ground coordinates at the ground origin: (R w; p x R w + R v)."""
    w, v = R @ m[..., :3, :], R @ m[..., 3:, :]
    return jnp.concatenate([w, skew(p) @ w + v], -2)


@jax.jit
def body_kinematics(model: Model, q: Array, v: Array) -> Kinematics:
    """Poses, motion subspaces, velocities, remainder accelerations and inertias of every body."""
    R_local, p_local, S_local, S_dot_local = model.joints(q, v)
    R, p = compose(model, R_local, p_local)
    S = to_ground(R, p, S_local)
    vb = model.body_v(v)
    joint_velocity = jnp.einsum("kij,kj->ki", S, vb)
    V = forward_pass(model.topology, lambda V_parent, Sv: V_parent + Sv, jnp.zeros(6, q.dtype),
                     joint_velocity)
    c = (cross_motion(V, joint_velocity)
         + jnp.einsum("kij,kj->ki", to_ground(R, p, S_dot_local), vb))
    com = p + jnp.einsum("kij,kj->ki", R, model.com)
    inertia = inertia_matrix(model.mass, com, R @ model.inertia @ jnp.swapaxes(R, -1, -2))
    return Kinematics(R, p, S, V, c, inertia, vb)


def gravity_acceleration(model: Model) -> Array:
    """The ground's fictitious spatial acceleration (0; -g) that puts gravity into a recursion."""
    return jnp.concatenate([jnp.zeros(3, model.gravity.dtype), -model.gravity])
