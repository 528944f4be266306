"""O(n) forward dynamics: Anderson 1993 §2.3, rigid bodies (the articulated-body recursion).

Three tree passes, each a `lax.scan` (compile time flat in n), in ground coordinates at the ground
origin (see `kinematics`), so no quantity changes frame on its way along the tree:

(i)   outward kinematics: motion subspaces S (Anderson 1993's partial velocities P, eq 41), velocities
      V and remainder accelerations c (eqs 20-31);
(ii)  inward triangularization (eqs 48-50, 80-81): each body starts from its own inertia I_1 and
      remainder force F_1 = -(V x* I V) (eq 43 with no applied load); it adds its children's
      articulated inertia I_3 and force F_3 (I_2, F_2) and eliminates its own joint accelerations:
          U = I_2 P,   D = P^T U,   u = tau - P^T F_2
          I_3 = I_2 - U D^-1 U^T,   F_3 = F_2 + I_3 c + U D^-1 u
      which its parent receives as they are (Anderson 1993's shift S of eq 45 is the identity here);
(iii) outward back-substitution (eqs 82-84): a' = a_parent + c, u_dot = D^-1 (u - U^T a'),
      a = a' + P u_dot. The ground's acceleration is -g, which puts gravity in every body.

P may have several columns for multi-DOF joints; D is then a small symmetric positive-definite
block solved by Cholesky. The passes run at one width for every body, so a floating base (a free
joint under revolute ones) is eliminated on its own, outside the passes, with 6 x 6 blocks, and
the revolute bodies keep their division instead of a 6 x 6 Cholesky factorization each
(`_wide_root`; the effect on a humanoid is in benchmarks/README.md).

Step (ii) eliminates M(q) itself: (S, U, D) per body (`Factor`, from `aba_factored`) is a sparse
L D L^T factorization of the mass matrix, with which `solve` applies M^-1 in two vector passes
(the derivatives of `mbjax._src.rigid.adjoint` use it).
"""

from functools import partial
from typing import NamedTuple

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.linalg import spd_solve as _solve
from mbjax._src.linear_map import linear_map
from mbjax._src.model import Model
from mbjax._src.model.joints import JOINT_TYPES
from mbjax._src.rigid.kinematics import body_kinematics, gravity_acceleration
from mbjax._src.spatial import cross_force, shift_force
from mbjax._src.tree import backward_pass, forward_pass


class Factor(NamedTuple):
    """The articulated-body factorization of the mass matrix at q, step (ii)'s elimination: per
    body the motion subspace S (n, 6, w), U = I_2 S (n, 6, w) and D = S^T U (n, w, w), and for a
    floating base eliminated on its own (see `_wide_root`) its S, U, D (6 x 6, else None). It is
    a sparse L D L^T factorization of M(q) (the triangularization of Anderson 1993 eqs 48-50), so
    `solve` applies M(q)^-1 in two vector passes."""

    S: Array
    U: Array
    D: Array
    root: tuple[Array, Array, Array] | None


def _wide_root(model: Model) -> tuple[int | None, int]:
    """(root, w): a floating base, the tree's only base body when its joint is wider than every
    other body's, is eliminated on its own with 6 x 6 blocks, and the tree passes run at the
    width w of the other joints (1 for a humanoid of revolute joints: a division per body, not a
    6 x 6 Cholesky factorization). (None, model.width) for any other tree."""
    widths = [JOINT_TYPES[kind].nv for kind in model.joint_types]
    roots = [k for k, parent in enumerate(model.topology.parents) if parent < 0]
    rest = max((w for k, w in enumerate(widths) if k != roots[0]), default=0)
    if len(roots) == 1 and widths[roots[0]] > rest > 0:
        return roots[0], rest
    return None, model.width


def aba(model: Model, q: Array, v: Array, tau: Array, f_ext: Array | None = None) -> Array:
    """Joint accelerations (nv,) of the tree at (q, v) under joint forces tau, gravity and the
    external wrenches f_ext (see `aba_responses`)."""
    return aba_responses(model, q, v, tau, jnp.zeros((0, model.nv), q.dtype), f_ext)[0]


def aba_factored(model: Model, q: Array, v: Array, tau: Array,
                 f_ext: Array | None = None) -> tuple[Array, Factor]:
    """(`aba(model, q, v, tau, f_ext)`, the `Factor` of M(q) it eliminated with)."""
    (u_dot, _), factor = _recursion(model, q, v, tau, jnp.zeros((0, model.nv), q.dtype), f_ext)
    return u_dot, factor


def solve(model: Model, factor: Factor, b: Array) -> Array:
    """M(q)^-1 b from the `Factor` at q: the accelerations joint forces b produce with no
    velocity and no gravity, steps (ii) and (iii) with the inertias already eliminated
    (c = 0, a_ground = 0): u = b - S^T F_2, F_3 = F_2 + U D^-1 u; u_dot = D^-1 (u - U^T a_p),
    a = a_p + S u_dot."""
    root, w = _wide_root(model)
    t = model.body_v(b)
    t_scan = t[:, :w] if root is None else _set_row(t[:, :w], root, 0.0)

    def forces(F2, inp):
        S, U, D, t = inp
        u = t - S.T @ F2
        return u, F2 + U @ _solve(D, u)

    u, F_root = backward_pass(model.topology, forces, jnp.zeros((model.n, 6), b.dtype),
                              (factor.S, factor.U, factor.D, t_scan))
    ground = jnp.zeros(6, b.dtype)
    if root is not None:              # the floating base: F_root is what it received
        S_r, U_r, D_r = factor.root
        u_dot_root = _solve(D_r, t[root] - S_r.T @ F_root)
        ground = S_r @ u_dot_root

    def substitute(parent, inp):
        (a_parent, _), (S, U, D, u) = parent, inp
        u_dot = _solve(D, u - U.T @ a_parent)
        return a_parent + S @ u_dot, u_dot

    _, u_dot = forward_pass(model.topology, substitute, (ground, jnp.zeros(w, b.dtype)),
                            (factor.S, factor.U, factor.D, u))
    if root is not None:
        u_dot = _set_row(_widen(u_dot, model.width), root, u_dot_root)
    return model.flat_v(u_dot)


def _solves(fixed: tuple, bs: Array) -> Array:
    """`solve` for a batch bs (B, nv): from nv right-hand sides on, M^-1 once (its columns, M^-1
    being symmetric) and a product, instead of the passes per right-hand side."""
    model, factor = fixed
    if bs.shape[0] < model.nv:
        return jax.vmap(partial(solve, model, factor))(bs)
    return bs @ jax.vmap(partial(solve, model, factor))(jnp.eye(model.nv, dtype=bs.dtype))


_mass_solve = linear_map("mass_solve", lambda fixed, b: solve(*fixed, b), _solves)


def mass_solve(model: Model, factor: Factor, b: Array) -> Array:
    """`solve(model, factor, b)` as a `linear_map`: the passes for one right-hand side and in
    reverse mode, M^-1 formed once for a batch of them (`jax.jacfwd`)."""
    return _mass_solve((model, factor), b)


def _set_row(x: Array, k: int, value) -> Array:
    """x with row k (static) set to value: an update of a slice, whose derivatives are slices
    too (an `.at[k].set` is a scatter, and its transpose a scatter-add)."""
    row = jnp.broadcast_to(jnp.asarray(value, x.dtype), x.shape[1:])
    return jax.lax.dynamic_update_index_in_dim(x, row, k, 0)


def _widen(x: Array, width: int) -> Array:
    """(n, w, ...) -> (n, width, ...), zero columns appended."""
    pad = [(0, 0)] * x.ndim
    pad[1] = (0, width - x.shape[1])
    return jnp.pad(x, pad)


def aba_responses(model: Model, q: Array, v: Array, tau: Array, loads: Array,
                  f_ext: Array | None = None) -> tuple[Array, Array]:
    """(u_dot, Gamma^T): the accelerations (nv,) under tau, gravity and the external wrenches
    f_ext (n, 6) (world frame, (torque about body k's origin; force), or None), and the
    accelerations (m, nv) that each row of `loads` (m, nv) alone produces (no gravity, no
    velocity), the unit constraint-load responses of Anderson 1993 eqs 101-107. An external wrench
    enters body k's own force F_1 of step (ii) (Anderson 1993 eq 43's applied load).

    The articulated inertias (I_3, U, D) depend on q only, so one triangularization serves every
    load: the force recursion and the back-substitution run on 1 + m columns at once (Anderson 1993's
    O(n + m n) for the loads)."""
    return _recursion(model, q, v, tau, loads, f_ext)[0]


def _recursion(model: Model, q: Array, v: Array, tau: Array, loads: Array,
               f_ext: Array | None) -> tuple[tuple[Array, Array], Factor]:
    kin = body_kinematics(model, q, v)
    m = loads.shape[0]
    bias = cross_force(kin.V, jnp.einsum("kij,kj->ki", kin.I, kin.V))
    if f_ext is not None:
        bias = bias - shift_force(f_ext, kin.p)
    # padded columns get 1 (identity, u = 0); real ones the joint's armature, added to D
    pad = (~model.v_mask).astype(q.dtype) + model.body_v(model.armature)
    # Columns: 0 the motion under tau, gravity and velocity; 1 ... m one load each.
    zeros = jnp.zeros((model.n, 6, m), q.dtype)
    F1 = jnp.concatenate([bias[..., None], zeros], -1)
    c = jnp.concatenate([kin.c[..., None], zeros], -1)
    t = jnp.concatenate([model.body_v(tau + model.passive_force(q, v))[..., None],
                         jax.vmap(model.body_v, out_axes=-1)(loads)], -1)

    # A floating base is eliminated on its own (`_wide_root`): in the tree passes its joint has
    # no columns (S = 0, D = 1, u = 0), so it hands its articulated inertia and force on
    # unchanged, and the ground it sits on moves with its joint acceleration S_r u_dot_r.
    root, w = _wide_root(model)
    S, t_scan, pad_scan = kin.S[..., :w], t[:, :w], pad[:, :w]
    if root is not None:
        S, t_scan = _set_row(S, root, 0.0), _set_row(t_scan, root, 0.0)
        pad_scan = _set_row(pad_scan, root, 1.0)

    def triangularize(received, inp):
        (IA, pA), (S, c, t, padding) = received, inp
        U = IA @ S
        D = S.T @ U + jnp.diag(padding)
        u = t - S.T @ pA
        Ia = IA - U @ _solve(D, U.T)
        pa = pA + Ia @ c + U @ _solve(D, u)
        return (U, D, u), (Ia, pa)

    (U, D, u), (I_root, F_root) = backward_pass(model.topology, triangularize, (kin.I, F1),
                                                (S, c, t_scan, pad_scan))
    ground = jnp.concatenate([gravity_acceleration(model)[:, None], jnp.zeros((6, m), q.dtype)], 1)
    root_factor = None
    if root is not None:              # its own elimination, 6 x 6 (received: I_root, F_2)
        S_r = kin.S[root]
        U_r = I_root @ S_r
        D_r = S_r.T @ U_r + jnp.diag(pad[root])
        u_r = t[root] - S_r.T @ (F_root - I_root @ c[root])
        u_dot_root = _solve(D_r, u_r - U_r.T @ (ground + c[root]))
        ground = ground + S_r @ u_dot_root
        root_factor = (S_r, U_r, D_r)

    def substitute(parent, inp):
        (a_parent, _), (S, c, U, D, u) = parent, inp
        a_prime = a_parent + c
        qdd = _solve(D, u - U.T @ a_prime)
        return a_prime + S @ qdd, qdd

    _, qdd = forward_pass(model.topology, substitute,
                          (ground, jnp.zeros((w, 1 + m), q.dtype)), (S, c, U, D, u))
    if root is not None:
        qdd = _set_row(_widen(qdd, model.width), root, u_dot_root)
    flat = jax.vmap(model.flat_v, in_axes=-1)(qdd)          # (1 + m, nv)
    return (flat[0], flat[1:]), Factor(S, U, D, root_factor)
