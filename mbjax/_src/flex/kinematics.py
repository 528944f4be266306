"""Outward kinematics of a tree of rigid and flexible bodies (Anderson 1993 §2.3(i), eqs 5-8, 20-31).

As for rigid trees (`mbjax._src.rigid.kinematics`), spatial vectors are in ground components at the
ground origin, so the recursions carry no frame shifts. A body attached at grid point h of a
flexible parent sees the parent's frame moved by the deformation there: translation
o_h = rho_h + phi_h q (eqs 5-7) and rotation exp(r_h), r_h = psi_h q (eq 8, taken exact so the
attachment frame stays a rotation), each with the second-order part whose Hessian is the grid
point's unit-load geometric stiffness (`grid_point`), so that every load at a grid point stiffens
the body by its own virtual work (eq 33's distal terms; a cut joint's constraint load and an
applied wrench as well as a child's reaction). Its joint frame therefore moves relative to the
parent's frame with the spatial velocity G u (G: the attachment's partial velocities, 6 x mu,
eqs 20 and 22):

    G_body = (Gamma(r_h) dr_h/dq;  do_h/dq + o_h~ Gamma(r_h) dr_h/dq)    (at the parent origin)

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

from mbjax._src.flex.model import FlexibleModel
from mbjax._src.lie import exp, gamma, vee
from mbjax._src.rigid.kinematics import compose, to_ground
from mbjax._src.spatial import cross_motion, skew
from mbjax._src.tree import forward_pass


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


def _parents(model: FlexibleModel) -> tuple[np.ndarray, np.ndarray]:
    parents = np.asarray(model.model.topology.parents)
    return np.where(parents < 0, 0, parents), parents >= 0


def grid_point(rho: Array, phi: Array, psi: Array, K: Array, q: Array) -> tuple[Array, Array]:
    """(rotation vector r, origin o) of a grid point in its body's frame at modal coordinates q:
    Anderson 1993 eqs 5-8 (o = rho + phi q, r = psi q) plus the second-order part whose Hessian is the
    point's unit-load geometric stiffness K (6, mu, mu) (eq 33's K_distal: force x, y, z, then
    moment x, y, z):

        (o; r) += -1/2 (q^T K_j q)_j.

    A load F (6,) at the point then does work through phi^T F - sum_j F_j K_j q: eq 33's
    stiffening K_G(F) q comes from the load's own virtual work, for every load at the point (a
    child's reaction, a cut joint's constraint load, an applied wrench). On a straight beam only
    K_0 is nonzero (axial prestress, eq 32), and -1/2 q^T K_0 q is the foreshortening
    -1/2 integral w'^2 dx of the bent beam between the clamp and the point."""
    second = -0.5 * jnp.einsum("jst,s,t->j", K, q, q)
    return psi @ q + second[3:], rho + phi @ q + second[:3]


def _grid_shapes(model: FlexibleModel, body: np.ndarray, h: np.ndarray, on_node: np.ndarray):
    """(rho, phi, psi, K) of grid points h of bodies `body`; zero where on_node is False."""
    b = model.bodies
    return (jnp.where(on_node[:, None], b.node_position[body, h], 0.0),
            jnp.where(on_node[:, None, None], b.node_phi[body, h], 0.0),
            jnp.where(on_node[:, None, None], b.node_psi[body, h], 0.0),
            jnp.where(on_node[:, None, None, None], b.distal_stiffening[body, h], 0.0))


def attachment(model: FlexibleModel, q_parent: Array):
    """Per body: the attachment's rotation E and origin o on the parent, and the grid point's
    shapes (rho, phi, psi, K) (`grid_point`); the identity at zero shapes for bodies whose parent
    is rigid or the ground."""
    parent, _ = _parents(model)
    shapes = _grid_shapes(model, parent, np.maximum(np.asarray(model.attach), 0),
                          np.asarray(model.attach) >= 0)
    r, o = jax.vmap(grid_point)(*shapes, q_parent)
    return jax.vmap(exp)(r), o, shapes


def _partial_velocities(shapes, q: Array) -> Array:
    """G (6, mu) of one attachment at the parent's modal coordinates q, parent frame: the rates of
    the grid point's (r, o) (`grid_point`) as a spatial velocity at the parent's origin."""
    r, o = grid_point(*shapes, q)
    dr, do = jax.jacfwd(lambda q_: grid_point(*shapes, q_))(q)
    Gw = gamma(r) @ dr
    return jnp.concatenate([Gw, do + skew(o) @ Gw])


def body_and_marker_poses(model: FlexibleModel, q: Array) -> tuple[Array, Array, Array, Array]:
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
    E, o, shapes = attachment(model, q_parent)
    R, p = compose(model.model, E @ R_local, o + jnp.einsum("kij,kj->ki", E, p_local - shapes[0]))
    return R, p, (S_local, S_dot_local, q_parent, shapes, parent, has_parent)


def _markers(model: FlexibleModel, R: Array, p: Array, qf: Array):
    if not model.markers:
        return jnp.zeros((0, 3, 3), R.dtype), jnp.zeros((0, 3), R.dtype)
    body = np.array([b for b, _ in model.markers])
    h = np.array([max(n, 0) for _, n in model.markers])
    on_node = np.array([n >= 0 for _, n in model.markers])
    r, o = jax.vmap(grid_point)(*_grid_shapes(model, body, h, on_node), qf[body])
    return R[body] @ jax.vmap(exp)(r), p[body] + jnp.einsum("kij,kj->ki", R[body], o)


def marker_forces(model: FlexibleModel, q: Array, f: Array) -> Array:
    """The generalized forces (nv,) of world-frame wrenches f (markers, 6) (torque about each
    marker's origin; force applied there): the gradient in v of their power n . omega + f . p_dot,
    with the markers' motion from their poses, grid points' second-order part included (so a
    load at a grid point stiffens its body, `grid_point`)."""
    def power(v):
        (R, p), (R_dot, p_dot) = jax.jvp(lambda q_: body_and_marker_poses(model, q_)[2:], (q,),
                                         (model.q_dot(q, v),))
        omega = jax.vmap(vee)(R_dot @ jnp.swapaxes(R, -1, -2))        # world components
        return jnp.sum(f[:, :3] * omega) + jnp.sum(f[:, 3:] * p_dot)

    return jax.grad(power)(jnp.zeros(model.nv, q.dtype))


def inverse_motion(X: Array) -> Array:
    """X^-1 for X = [[R, 0], [p~ R, R]]: [[R^T, 0], [-R^T p~, R^T]] (no general inverse)."""
    R, pR = X[:3, :3], X[3:, :3]
    Rt = R.T
    zero = jnp.zeros_like(R)
    return jnp.block([[Rt, zero], [-Rt @ pR @ Rt, Rt]])


def body_velocities(model: FlexibleModel, q: Array, v: Array) -> Array:
    """(n, 6 + mu): per body its frame's (omega; v) in body components and its modal rates, the
    w of Anderson 1993 eq 34, from the recursion's velocities (any joint type)."""
    kin = flex_kinematics(model, q, v)
    Vb = jnp.einsum("kij,kj->ki", jax.vmap(inverse_motion)(kin.X), kin.V)
    return jnp.concatenate([Vb, kin.u], -1)


def motion_transform(R: Array, p: Array) -> Array:
    """(n, 6, 6) X: body-frame motion vectors at the body origin -> ground frame at the ground
    origin, [[R, 0], [p~ R, R]]."""
    return to_ground(R, p, jnp.broadcast_to(jnp.eye(6, dtype=R.dtype), (*R.shape[:-2], 6, 6)))


def flex_kinematics(model: FlexibleModel, q: Array, v: Array) -> FlexKinematics:
    """Poses, subspaces, attachments, velocities and remainder accelerations of every body."""
    R, p, (S_local, S_dot_local, q_parent, shapes, parent, has_parent) = _poses(model, q, v)
    _, qf = model.split(q)
    vj, uf = model.split(v)
    vb = model.model.body_v(vj)
    u_parent = jnp.where(has_parent[:, None], uf[parent], 0.0)
    X = motion_transform(R, p)
    eye = jnp.eye(6, dtype=q.dtype)
    X_parent = jnp.where(has_parent[:, None, None], X[parent], eye)
    _, c_body = jax.vmap(
        lambda sh, qp, up: jax.jvp(lambda q_: _partial_velocities(sh, q_) @ up, (qp,), (up,)))(
            shapes, q_parent, u_parent)
    G = X_parent @ jax.vmap(_partial_velocities)(shapes, q_parent)
    S = to_ground(R, p, S_local)
    joint_velocity = jnp.einsum("kij,kj->ki", S, vb)
    attach_velocity = jnp.einsum("kij,kj->ki", G, u_parent)
    V = forward_pass(model.model.topology, lambda V_parent, dV: V_parent + dV,
                     jnp.zeros(6, q.dtype), joint_velocity + attach_velocity)
    V_parent = jnp.where(has_parent[:, None], V[parent], 0.0)
    c = (cross_motion(V, joint_velocity) + jnp.einsum("kij,kj->ki", to_ground(R, p, S_dot_local), vb)
         + cross_motion(V_parent, attach_velocity) + jnp.einsum("kij,kj->ki", X_parent, c_body))
    return FlexKinematics(R, p, X, S, G, V, c, vb, qf, uf, q_parent)
