"""O(n) forward dynamics of rigid and modal flexible bodies: Anderson 1993 §2.3(ii)-(iii), eqs 48-86.

The three passes of `mbjax._src.rigid.aba`, with each body a (6 + mu)-block: its rigid frame's
spatial acceleration A and its modal accelerations u_dot.

(ii) inward, per body k (eqs 48-81): the body's own generalized mass and remainder force (the
     `ModalBody` in its frame, moved to ground components: I = X^-T M X^-1), its elastic force
     K q + D u and the geometric stiffening K_G q = G_s A + g_s (eqs 32-33, 46-47), plus what its
     children sent (their reactions stiffen the body through the attachment's second-order
     displacement, `mbjax._src.flex.kinematics.grid_point`, i.e. inside G). The modal accelerations
     are eliminated first (eq 53's inverse of the modal mass M^{B^k}, now including the
     children's articulated inertia):

         u_dot = -Y_A A - Y_p,   [Y_A, Y_p] = IA_ff^-1 [IA_fA, pA_f - Q_f]
         I6 = IA_AA - IA_Af Y_A, p6 = pA_A - IA_Af Y_p

     then the joint's, exactly as for a rigid body (U = I6 S, D = S^T I6 S, ...). The child hands
     its articulated inertia Ia and force pa to its parent through the attachment (eq 47):

         parent += L Ia [1, G],   L pa,   L = [1; G^T]

     where G are the attachment's partial velocities; G^T on the child's reaction F gives
     phi_h^T F - K_G(F) q, eq 33's distal-load (F^J) terms. The inertial stiffening makes the
     blocks unsymmetric, so the eliminations use general solves.
(iii) outward (eqs 82-86): A' = A_parent + G u_dot_parent + c, q_ddot = D^-1 (u - S^T I6 A'),
     A = A' + S q_ddot, u_dot = -Y_A A - Y_p.

Like `mbjax._src.rigid.aba.aba_responses`, one triangularization serves any number of extra load
columns (Anderson 1993's unit constraint loads, eqs 101-107), which the stabilized loop route uses.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.flex.body import inertial_stiffening, mass_matrix, velocity_terms
from mbjax._src.flex.kinematics import flex_kinematics, inverse_motion
from mbjax._src.flex.model import FlexibleModel
from mbjax._src.rigid.kinematics import gravity_acceleration
from mbjax._src.spatial import shift_force
from mbjax._src.tree import backward_pass, forward_pass


def _solve(D: Array, b: Array) -> Array:
    if D.shape[-1] == 1:
        return b / D[..., 0, :]
    return jnp.linalg.solve(D, b)


def body_blocks(model: FlexibleModel, kin) -> tuple[Array, Array]:
    """Per body, the (6 + mu)-block mass M_g (with the stiffening's acceleration coupling) and the
    remainder force b_g (velocity terms, elastic and damping forces, stiffening's velocity part),
    ground components at the ground origin for the rigid rows and columns."""
    def one(body, X, V, q, u):
        Xi = inverse_motion(X)
        Vb = Xi @ V
        M = mass_matrix(body, q)
        b = velocity_terms(body, q, jnp.concatenate([Vb, u]))
        G_s, g_s = inertial_stiffening(body, q, Vb)
        mu = q.shape[0]
        left = jax.scipy.linalg.block_diag(Xi.T, jnp.eye(mu, dtype=q.dtype))
        right = jax.scipy.linalg.block_diag(Xi, jnp.eye(mu, dtype=q.dtype))
        M_g = left @ M @ right
        M_g = M_g.at[6:, :6].add(G_s @ Xi)
        b_g = left @ b + jnp.concatenate([jnp.zeros(6, q.dtype),
                                          body.stiffness @ q + body.damping @ u + g_s])
        return M_g, b_g

    return jax.vmap(one)(model.bodies, kin.X, kin.V, kin.q, kin.u)


def flexible_aba_responses(model: FlexibleModel, q: Array, v: Array, tau: Array,
                           loads: Array, f_ext: Array | None = None) -> tuple[Array, Array]:
    """(v_dot (nv,), responses (m, nv)): the accelerations under tau, gravity, velocity,
    elasticity and the external wrenches f_ext (n, 6) (world frame, (torque about body k's frame
    origin; force), or None), and those each row of `loads` (m, nv) alone produces (no gravity,
    velocity, elasticity or wrench); O(n) in the bodies, O(n m) in the loads. A wrench acts on a
    body's reference frame (its joint grid J^k, where the modes are clamped), so it enters the
    rigid rows of the body's own force and loads no mode directly."""
    kin = flex_kinematics(model, q, v)
    n, mu, m = model.n, model.mu, loads.shape[0]
    dtype = q.dtype
    M_g, b_g = body_blocks(model, kin)
    pad = (~model.model.v_mask).astype(dtype)
    cols = 1 + m
    tau_cols = jnp.concatenate([tau[None], loads])                         # (cols, nv)
    tj, tf = jax.vmap(model.split)(tau_cols)                               # (cols, *), (cols, n, mu)
    t_joint = jnp.moveaxis(jax.vmap(model.model.body_v)(tj), 0, -1)        # (n, width, cols)
    t_modal = jnp.moveaxis(tf, 0, -1)                                      # (n, mu, cols)
    if f_ext is not None:
        b_g = b_g.at[:, :6].add(-shift_force(f_ext, kin.p))
    own_p = jnp.zeros((n, 6 + mu, cols), dtype).at[:, :, 0].set(b_g).at[:, 6:, :].add(-t_modal)
    c = jnp.zeros((n, 6, cols), dtype).at[:, :, 0].set(kin.c)

    def triangularize(received, inp):
        (IA, pA), (S, c, t, padding, G) = received, inp
        Y = jnp.linalg.solve(IA[6:, 6:], jnp.concatenate([IA[6:, :6], pA[6:]], -1))
        Y_A, Y_p = Y[:, :6], Y[:, 6:]
        I6 = IA[:6, :6] - IA[:6, 6:] @ Y_A
        p6 = pA[:6] - IA[:6, 6:] @ Y_p
        U, W = I6 @ S, S.T @ I6
        D = W @ S + jnp.diag(padding)
        u = t - S.T @ p6
        Ia = I6 - U @ _solve(D, W)
        pa = p6 + Ia @ c + U @ _solve(D, u)
        L = jnp.concatenate([jnp.eye(6, dtype=dtype), G.T])
        right = jnp.concatenate([jnp.eye(6, dtype=dtype), G], -1)
        return (Y_A, Y_p, W, D, u), (L @ Ia @ right, L @ pa)

    (Y_A, Y_p, W, D, u), _ = backward_pass(model.model.topology, triangularize, (M_g, own_p),
                                           (kin.S, c, t_joint, pad, kin.G))

    def substitute(parent, inp):
        (A_parent, u_dot_parent, _), (S, c, G, Y_A, Y_p, W, D, u) = parent, inp
        A_prime = A_parent + G @ u_dot_parent + c
        qdd = _solve(D, u - W @ A_prime)
        A = A_prime + S @ qdd
        return A, -(Y_A @ A + Y_p), qdd

    ground = (jnp.zeros((6, cols), dtype).at[:, 0].set(gravity_acceleration(model.model)),
              jnp.zeros((mu, cols), dtype), jnp.zeros((model.model.width, cols), dtype))
    _, u_dot, qdd = forward_pass(model.model.topology, substitute, ground,
                                 (kin.S, c, kin.G, Y_A, Y_p, W, D, u))
    flat = jax.vmap(lambda a, b: model.join(model.model.flat_v(a), b), in_axes=(-1, -1))(qdd, u_dot)
    return flat[0], flat[1:]


def flexible_aba(model: FlexibleModel, q: Array, v: Array, tau: Array,
                 f_ext: Array | None = None) -> Array:
    """Forward dynamics of a flexible tree by Anderson 1993's O(n) recursion (§2.3, eqs 48-86).

    Args:
        model: the flexible tree.
        q: configuration (joint, then modal coordinates), shape (nq,).
        v: generalized velocity (joint rates, then modal rates), shape (nv,).
        tau: generalized forces (joint forces [N m or N], then modal forces), shape (nv,).
        f_ext: external wrenches, one per body, world frame (torque about the body's frame
            origin [N m]; force [N]), shape (n, 6), acting on the body's reference frame (its
            joint grid); or None.

    Returns:
        v_dot under tau, gravity, velocity terms, elasticity (with geometric stiffening) and
        f_ext, shape (nv,).
    """
    return flexible_aba_responses(model, q, v, tau, jnp.zeros((0, model.nv), q.dtype), f_ext)[0]
