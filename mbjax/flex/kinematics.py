"""Outward kinematics of a tree of rigid and flexible bodies (seed 002 §2.3(i), eqs 5-8, 20-31).

As for rigid trees (`mbjax.rigid.kinematics`), spatial vectors are in ground components at the
ground origin, so the recursions carry no frame shifts. A body attached at grid point h of a
flexible parent sees the parent's frame moved by the deformation there: translation
o_h = rho_h + phi_h q (eqs 5-7) and rotation exp(psi_h q) (eq 8, taken exact so the attachment
frame stays a rotation). Its joint frame therefore moves relative to the parent's frame with the
spatial velocity G u (G: the attachment's partial velocities, 6 x mu, eqs 20 and 22):

    G_body = (Gamma(psi_h q) psi_h;  phi_h + o_h~ Gamma(psi_h q) psi_h)    (at the parent origin)

and the recursions of the rigid tree gain the parent's modal rates (eqs 21-31):

    V[k] = V[parent] + G[k] u[parent] + S[k] v[k]
    c[k] = V[k] x S[k] v[k] + S_dot v[k] + V[parent] x G[k] u[parent] + X (dG/dq u) u   (eqs 28-31)

The last term, the rate of the attachment's partial velocities, comes from a `jax.jvp`.
"""

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax.flex.model import FlexibleModel
from mbjax.lie import exp, gamma
from mbjax.rigid.kinematics import compose, to_ground
from mbjax.spatial import cross_motion, skew
from mbjax.tree import forward_pass


class FlexKinematics(NamedTuple):
    R: Array          # (n, 3, 3) body frames (joint grids) in the ground frame
    p: Array          # (n, 3) their origins
    X: Array          # (n, 6, 6) motion transforms body -> ground (at the ground origin)
    S: Array          # (n, 6, width) joint motion subspaces, ground frame
    G: Array          # (n, 6, mu) attachment partial velocities on the parent's modal rates
    V: Array          # (n, 6) spatial velocities, ground frame
    c: Array          # (n, 6) remainder accelerations (joint and attachment)
    v: Array          # (n, width) joint velocities, zero-padded
    q: Array          # (n, mu) own modal coordinates
    u: Array          # (n, mu) own modal rates
    q_parent: Array   # (n, mu) the parent's modal coordinates (zero for base bodies)
    x_node: Array     # (n, 3) where body k's joint is attached on its parent, ground frame


def _parents(model: FlexibleModel) -> tuple[np.ndarray, np.ndarray]:
    parents = np.asarray(model.model.topology.parents)
    return np.where(parents < 0, 0, parents), parents >= 0


def attachment(model: FlexibleModel, q_parent: Array):
    """Per body: the attachment's (rotation E, origin o, rho_h, psi_h, phi_h) on the parent; the
    identity at zero shapes for bodies whose parent is rigid or the ground."""
    parent, _ = _parents(model)
    h = np.maximum(np.asarray(model.attach), 0)
    has = (np.asarray(model.attach) >= 0)
    b = model.bodies
    rho = jnp.where(has[:, None], b.node_position[parent, h], 0.0)
    phi = jnp.where(has[:, None, None], b.node_phi[parent, h], 0.0)
    psi = jnp.where(has[:, None, None], b.node_psi[parent, h], 0.0)
    r = jnp.einsum("kis,ks->ki", psi, q_parent)
    o = rho + jnp.einsum("kis,ks->ki", phi, q_parent)
    return jax.vmap(exp)(r), o, rho, psi, phi


def _partial_velocities(psi: Array, phi: Array, rho: Array, q: Array) -> Array:
    """G (6, mu) of one attachment at the parent's modal coordinates q, parent frame."""
    Gw = gamma(psi @ q) @ psi
    return jnp.concatenate([Gw, phi + skew(rho + phi @ q) @ Gw])


def frame_poses(model: FlexibleModel, q: Array) -> tuple[Array, Array, Array, Array]:
    """(R, p) of every body frame, and (R, p) of every marker (`FlexibleModel.markers`)."""
    R, p, _ = _poses(model, q, jnp.zeros(model.nv, q.dtype))
    return (R, p, *_markers(model, R, p, model.split(q)[1]))


def _poses(model: FlexibleModel, q: Array, v: Array):
    rigid = model.model
    qj, qf = model.split(q)
    vj, _ = model.split(v)
    R_local, p_local, S_local, S_dot_local = rigid.joints(qj, vj)
    parent, has_parent = _parents(model)
    q_parent = jnp.where(has_parent[:, None], qf[parent], 0.0)
    E, o, rho, psi, phi = attachment(model, q_parent)
    R, p = compose(model.model, E @ R_local, o + jnp.einsum("kij,kj->ki", E, p_local - rho))
    return R, p, (S_local, S_dot_local, q_parent, psi, phi, rho, parent, has_parent)


def _markers(model: FlexibleModel, R: Array, p: Array, qf: Array):
    if not model.markers:
        return jnp.zeros((0, 3, 3), R.dtype), jnp.zeros((0, 3), R.dtype)
    body = np.array([b for b, _ in model.markers])
    h = np.array([max(n, 0) for _, n in model.markers])
    on_node = np.array([n >= 0 for _, n in model.markers])
    b = model.bodies
    rho = jnp.where(on_node[:, None], b.node_position[body, h], 0.0)
    phi = jnp.where(on_node[:, None, None], b.node_phi[body, h], 0.0)
    psi = jnp.where(on_node[:, None, None], b.node_psi[body, h], 0.0)
    E = jax.vmap(exp)(jnp.einsum("kis,ks->ki", psi, qf[body]))
    o = rho + jnp.einsum("kis,ks->ki", phi, qf[body])
    return R[body] @ E, p[body] + jnp.einsum("kij,kj->ki", R[body], o)


def inverse_motion(X: Array) -> Array:
    """X^-1 for X = [[R, 0], [p~ R, R]]: [[R^T, 0], [-R^T p~, R^T]] (no general inverse)."""
    R, pR = X[:3, :3], X[3:, :3]
    Rt = R.T
    zero = jnp.zeros_like(R)
    return jnp.block([[Rt, zero], [-Rt @ pR @ Rt, Rt]])


def body_velocities(model: FlexibleModel, q: Array, v: Array) -> Array:
    """(n, 6 + mu): per body its frame's (omega; v) in body components and its modal rates, the
    w of seed 002 eq 34, from the recursion's velocities (any joint type)."""
    kin = flex_kinematics(model, q, v)
    Vb = jnp.einsum("kij,kj->ki", jax.vmap(inverse_motion)(kin.X), kin.V)
    return jnp.concatenate([Vb, kin.u], -1)


def motion_transform(R: Array, p: Array) -> Array:
    """(n, 6, 6) X: body-frame motion vectors at the body origin -> ground frame at the ground
    origin, [[R, 0], [p~ R, R]]."""
    return to_ground(R, p, jnp.broadcast_to(jnp.eye(6, dtype=R.dtype), (*R.shape[:-2], 6, 6)))


def flex_kinematics(model: FlexibleModel, q: Array, v: Array) -> FlexKinematics:
    """Poses, subspaces, attachments, velocities and remainder accelerations of every body."""
    R, p, (S_local, S_dot_local, q_parent, psi, phi, rho, parent, has_parent) = _poses(model, q, v)
    _, qf = model.split(q)
    vj, uf = model.split(v)
    vb = model.model.body_v(vj)
    u_parent = jnp.where(has_parent[:, None], uf[parent], 0.0)
    X = motion_transform(R, p)
    eye = jnp.eye(6, dtype=q.dtype)
    X_parent = jnp.where(has_parent[:, None, None], X[parent], eye)
    _, c_body = jax.vmap(
        lambda ps, ph, rh, qp, up: jax.jvp(lambda q_: _partial_velocities(ps, ph, rh, q_) @ up,
                                           (qp,), (up,)))(psi, phi, rho, q_parent, u_parent)
    G = X_parent @ jax.vmap(_partial_velocities)(psi, phi, rho, q_parent)
    S = to_ground(R, p, S_local)
    joint_velocity = jnp.einsum("kij,kj->ki", S, vb)
    attach_velocity = jnp.einsum("kij,kj->ki", G, u_parent)
    V = forward_pass(model.model.topology, lambda V_parent, dV: V_parent + dV,
                     jnp.zeros(6, q.dtype), joint_velocity + attach_velocity)
    V_parent = jnp.where(has_parent[:, None], V[parent], 0.0)
    c = (cross_motion(V, joint_velocity) + jnp.einsum("kij,kj->ki", to_ground(R, p, S_dot_local), vb)
         + cross_motion(V_parent, attach_velocity) + jnp.einsum("kij,kj->ki", X_parent, c_body))
    R_parent = jnp.where(has_parent[:, None, None], R[parent], jnp.eye(3, dtype=q.dtype))
    p_parent = jnp.where(has_parent[:, None], p[parent], 0.0)
    _, o, _, _, _ = attachment(model, q_parent)
    x_node = p_parent + jnp.einsum("kij,kj->ki", R_parent, o)
    return FlexKinematics(R, p, X, S, G, V, c, vb, qf, uf, q_parent, x_node)
