"""The RNEA's directional derivative in (q, v), written out: two vector passes, no derivative of
a rotation matrix.

For trees of revolute, prismatic, spherical and free joints, in ground coordinates at the ground
origin (see `kinematics`): moving joint j along one column S_c of its motion subspace moves its
outward set, body j included, rigidly about the screw S_c, so every ground-frame quantity X that
rides on a body of that set changes by S_c x X (motion vectors: S_c x m, forces: S_c x* f,
inertias: S_c x* I - I S_c x). This needs the columns fixed in body j (a universal joint's first
axis is fixed in its parent instead: not covered). Differentiating the RNEA
(`rnea.rnea_passes`: V_k, A_k, f_k = I_k A_k + V_k x* I_k V_k, F_k the sum of the f of k's
outward set, tau_k = S_k^T F_k) with that rule and collecting the sums over outward sets (the
analysis of Carpentier and Mansard, RSS 2018, "Analytical derivatives of rigid body dynamics
algorithms", here for one direction at a time) gives, with e_j the joint's increments along
its columns (dq itself for a revolute or prismatic joint), U_j = V and B_j = A of j's parent
(the ground's: 0 and -g) and h_k = I_k V_k,

    s_j = S_j e_j,  w_j = S_j dv_j                                 (the joint's twists)
    g2_j = (s_j x U_j) x U_j - s_j x B_j - w_j x U_j - w_j x V_j,   g3_j = s_j x U_j - w_j
    (P2, P3) = the outward sums of (g2, g3)                         (one outward pass)
    o_k = s_k x* F_k
    L_k = I_k P2_k - P3_k x* h_k - I_k (P3_k x V_k) - V_k x* I_k P3_k + o_k
    dtau_k = S_k^T (the sum of L over k's outward set - o_k) + damping_k dv_k + stiffness_k dq_k
                                                                           (one inward pass)

The formulas are linear in the columns of S, so each joint enters through its two twists s and
w. It is linear in (dq, dv), so reverse mode transposes it into the same two passes run the
other way: the adjoint's RNEA VJP at the solved accelerations (`mbjax._src.rigid.adjoint`) without
differentiating the kinematics. Agrees with `jax.jvp` of `inverse_dynamics` to rounding
(tests/rigid/test_adjoint.py).
"""

import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.linalg import unrolled_dot
from mbjax._src.linear_map import linear_map
from mbjax._src.model import Model
from mbjax._src.rigid import rnea
from mbjax._src.rigid.kinematics import (columns, fixed_in_body, gravity_acceleration,
                                         increments_matrix, joint_increments)
from mbjax._src.rigid.rnea import rnea_passes
from mbjax._src.rigid.tangents import instantiate, is_zero
from mbjax._src.spatial import cross_force, cross_motion, skew
from mbjax._src.tree import backward_pass, forward_pass, outward_sum
from mbjax._src.rigid.crba import assemble, coordinate_paths
from mbjax._src.tree.take import take

def applies(model: Model) -> bool:
    """Whether every joint of the tree is revolute, prismatic, spherical or free."""
    return fixed_in_body(model)


def rnea_jvp(model: Model, q: Array, v: Array, a: Array, dq: Array, dv: Array) -> Array:
    """d tau = d/de RNEA(model, q + e dq, v + e dv, a) at e = 0 (armature, damping and springs
    included), for a tree of the joints `applies` accepts. dq is a tangent of the coordinates q
    (a quaternion's included, as the RNEA reads it, normalized)."""
    F, kin, A = rnea_passes(model, q, v, a, None)
    S, V, I = kin.S, kin.V, kin.I                     # noqa: E741 (the papers' name)
    h = _times(I, V)
    ground = gravity_acceleration(model)
    U = _parent(model, V, jnp.zeros_like(ground))
    B = _parent(model, A, ground)
    # the joints' twists along (dq, dv): s = S e, w = S dv (the formulas are linear in S's columns)
    s, w = columns(S, joint_increments(model, q, v, dq)), columns(S, model.body_v(dv))
    sU = cross_motion(s, U)
    g = jnp.concatenate([cross_motion(sU, U) - cross_motion(s, B) - cross_motion(w, U)
                         - cross_motion(w, V), sU - w], -1)
    P = _outward_sum(model, g, jnp.zeros(12, q.dtype))
    P2, P3 = P[:, :6], P[:, 6:]
    own = cross_force(s, F)
    L = (_times(I, P2) - cross_force(P3, h) - _times(I, cross_motion(P3, V))
         - cross_force(V, _times(I, P3)) + own)
    dtau = jnp.einsum("kic,ki->kc", S, _inward_sum(model, L) - own)
    spring = model.stiffness * take(dq, model._spring_gather())
    return model.flat_v(dtau) + model.damping * dv + spring


def _times(I: Array, x: Array) -> Array:       # noqa: E741
    return jnp.einsum("kij,kj->ki", I, x)


def _outward_sum(model: Model, x: Array, ground: Array) -> Array:
    """ground plus the sum of x over each body's path from the ground (an outward pass)."""
    return forward_pass(model.topology, lambda parent, own: parent + own, ground, x)


def _inward_sum(model: Model, x: Array) -> Array:
    """The sum of x over each body's outward set (an inward pass)."""
    return backward_pass(model.topology, lambda received, _: (received, received), x)[0]


def _parent(model: Model, x: Array, ground: Array) -> Array:
    """Each body's parent's row of x (n, ...), `ground` for a base body."""
    parents = np.asarray(model.topology.parents)
    return take(jnp.concatenate([x, ground[None]]), np.where(parents < 0, model.n, parents))


def rnea_partials(model: Model, q: Array, v: Array, a: Array) -> tuple[Array, Array, Array]:
    """(d tau / d e, d tau / d v, d tau / d a = M), each (nv, nv): the RNEA's partial derivatives
    at (q, v, a) in the joints' increments e (the tangent space: `joint_increments`), in v and in
    a, for a tree of the joints `applies` accepts (damping, springs and armature included).

    `rnea_jvp` for every direction at once, with no pass per direction: a direction along a
    column of joint j has its twists at body j alone, so its outward sums P are (g2_j, g3_j) on
    j's outward set and zero elsewhere, and the inward sum of L collects, for joint k's row,
    Ic_k g2_j + Cc_k g3_j when j is on k's path (k included) and Ic_j g2_j + Cc_j g3_j + o_j when
    j is outward of k, with Ic and Cc the sums over a body's outward set of I and of
    C = I (V x) - (V x*) I - (. x* h), the linear map that takes P3 into L. That is Carpentier and
    Mansard's (RSS 2018) composite-body form of the RNEA derivatives: the outward sums of I,
    I (V x) and h (of which Cc is linear) by `tree.outward_sum`, and a few (nv, 6) by (6, 2 nv)
    products masked by the path matrix (Jerkovsky 1978 eq 1). The same composite inertias give
    the mass matrix (the composite-rigid-body algorithm, Featherstone RBDA §6.2):
    M[r, c] = s_r^T Ic_r s_c for c on r's path."""
    F, kin, A = rnea_passes(model, q, v, a, None)
    I, V = kin.I, kin.V                                  # noqa: E741 (the papers' name)
    h = _times(I, V)
    w, u = skew(V[:, :3]), skew(V[:, 3:])
    zero = jnp.zeros_like(w)
    IV = unrolled_dot(I, jnp.block([[w, zero], [u, w]]))                  # I (V x)
    # the sums over outward sets of I, I (V x) and h: Cc = IVc + IVc^T - (. x* hc)
    Ic, IVc, hc = outward_sum(model.topology, (I, IV, h))
    hn, hf = skew(hc[:, :3]), skew(hc[:, 3:])
    Cc = IVc + jnp.swapaxes(IVc, -1, -2) + jnp.block([[hn, hf], [hf, zero]])
    # per degree of freedom: its world column s and its body's quantities
    body = model.dof_body()
    s = jax.vmap(model.flat_v, in_axes=1, out_axes=1)(kin.S)             # (nv, 6)
    ground = gravity_acceleration(model)
    U, B = take(_parent(model, V, jnp.zeros_like(ground)), body), take(_parent(model, A, ground), body)
    Vd, Fd, Icd, Ccd = take(V, body), take(F, body), take(Ic, body), take(Cc, body)
    sU = cross_motion(s, U)
    g2 = jnp.concatenate([cross_motion(sU, U) - cross_motion(s, B),
                          -sU - cross_motion(s, Vd)])                    # (2 nv, 6): e, then v
    g3 = jnp.concatenate([sU, -s])
    o = jnp.concatenate([cross_force(s, Fd), jnp.zeros_like(s)])
    Y = (jnp.einsum("rij,rj->ri", jnp.concatenate([Icd, Icd]), g2)
         + jnp.einsum("rij,rj->ri", jnp.concatenate([Ccd, Ccd]), g3) + o)   # (2 nv, 6)
    rows_I, rows_C = jnp.einsum("ri,rij->rj", s, Icd), jnp.einsum("ri,rij->rj", s, Ccd)
    path, outward = coordinate_paths(model)           # c's body on r's path; strictly outward
    path2, outward2 = np.tile(path, 2), np.tile(outward, 2)
    D = path2 * (rows_I @ g2.T + rows_C @ g3.T) + outward2 * (s @ Y.T)
    M = assemble(model, rows_I @ s.T)
    nv = model.nv
    return D[:, :nv] + jnp.diag(model.stiffness), D[:, nv:] + jnp.diag(model.damping), M



def _tangent(fixed: tuple, x: Array) -> Array:
    """d RNEA along x = (dq, dv) at the fixed (model, q, v, a): `rnea_jvp`."""
    model, q, v, a = fixed
    dq, dv = jnp.split(x, [model.nq])
    return rnea_jvp(model, q, v, a, dq, dv)


def _tangents(fixed: tuple, xs: Array) -> Array:
    """`_tangent` for a batch xs (B, nq + nv) at one state (`jax.jacfwd`): the partial
    derivatives once (`rnea_partials`, Pinocchio's `computeRNEADerivatives`) and a product."""
    model, q, v, a = fixed
    if xs.shape[0] < 4:
        return jax.vmap(lambda x: _tangent(fixed, x))(xs)
    D_e, D_v, _ = rnea_partials(model, q, v, a)
    D_q = D_e @ increments_matrix(model, q, v)
    return xs[:, :model.nq] @ D_q.T + xs[:, model.nq:] @ D_v.T


_rnea_tangent = linear_map("rnea_tangent", _tangent, _tangents)


@jax.custom_jvp
def inverse_dynamics(model: Model, q: Array, v: Array, a: Array) -> Array:
    """The RNEA (`mbjax.inverse_dynamics` without external wrenches) whose derivative in (q, v)
    is written out: `rnea_jvp` along one direction, `rnea_partials` formed once for a batch of
    them (`jax.jacfwd`); in the model's parameters and in a, JAX's own. For a tree of the joints
    `applies` accepts."""
    return rnea.inverse_dynamics(model, q, v, a)


def _inverse_dynamics_jvp(primals, tangents):
    model, q, v, a = primals
    dmodel, dq, dv, da = tangents
    tau = rnea.inverse_dynamics(model, q, v, a)
    dq, dv = (instantiate(t, x) for t, x in ((dq, q), (dv, v)))
    dtau = _rnea_tangent((model, q, v, a), jnp.concatenate([dq, dv]))
    others = [(i, t) for i, t in ((0, dmodel), (3, da)) if not is_zero(t)]
    if others:
        def moved(*xs):
            full = list(primals)
            for (i, _), x in zip(others, xs, strict=True):
                full[i] = x
            return rnea.inverse_dynamics(*full)
        dtau = dtau + jax.jvp(moved, [primals[i] for i, _ in others],
                              [instantiate(t, primals[i]) for i, t in others])[1]
    return tau, dtau


inverse_dynamics.defjvp(_inverse_dynamics_jvp, symbolic_zeros=True)
