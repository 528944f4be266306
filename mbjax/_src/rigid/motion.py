"""The bodies' motion (poses, spatial velocities, accelerations) and the generalized force of
wrenches on them, with their derivatives in (q, v, v_dot) written out.

A closed tree's constraints read its bodies' motion and load them with wrenches
(`mbjax._src.loops.constraints`); the KKT system's derivatives differentiate both along every
direction of the state (`mbjax._src.loops.kkt`). Forward mode through the outward pass would
differentiate products of rotations body by body; for the joints whose columns are fixed in
their own body (`fixed_in_body`) the tangents are sums over each body's path instead, as in
`rnea_derivatives` (Carpentier and Mansard, RSS 2018; Pinocchio's
`computeForwardKinematicsDerivatives`). In ground components at the ground origin, with s_j =
S_j e_j (e_j joint j's increments along dq), w_j = S_j dv_j, alpha_j = S_j da_j, U_j and B_j the
velocity and acceleration of j's parent (the ground's: 0), and the sums over body k's path from
the ground:

    delta_k = sum s_j                                        (the body's displacement twist)
    dR_k = delta_k,w x R_k,   dp_k = delta_k,w x p_k + delta_k,v
    dV_k = delta_k x V_k - sum (s_j x U_j - w_j)
    dA_k = delta_k x A_k - sum (s_j x U_j - w_j) x V_k
           + sum ((s_j x U_j) x U_j - s_j x B_j - w_j x (U_j + V_j) + alpha_j)

(per joint: dA_k/de_j = s_j x (A_k - B_j) - (s_j x U_j) x (V_k - U_j), dA_k/dv_j = w_j x (V_k -
U_j - V_j), dA_k/da_j = alpha_j, summed),

and the generalized force tau = S^T F of the wrenches W (F the sums over outward sets) moves by
d tau = S^T (sum over outward sets of dW - delta x* F): each column rides on its own body.
"""

import functools

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.model import Model
from mbjax._src.rigid.rnea_derivatives import _parent
from mbjax._src.rigid.kinematics import (body_kinematics, columns, fixed_in_body,
                                         forward_kinematics, joint_increments, to_ground)
from mbjax._src.rigid.tangents import instantiate, is_zero
from mbjax._src.spatial import cross_force, cross_motion
from mbjax._src.tree import outward_sum, path_sum


def body_motion(model: Model, q: Array, v: Array, v_dot: Array) -> tuple[Array, Array, Array, Array]:
    """(R, p, V, A): every body's rotation (n, 3, 3) and origin (n, 3), spatial velocity and
    acceleration (no gravity in it) (n, 6), (angular; linear) in ground components at the
    ground origin. Derivative in (q, v, v_dot) written out (see the module) for the joints
    `fixed_in_body` accepts; JAX's own in the model and for other joints."""
    if fixed_in_body(model):
        return _motion(model, q, v, v_dot)
    return _motion.fun(model, q, v, v_dot)


def body_forces(model: Model, q: Array, wrenches: Array) -> Array:
    """The generalized force S^T F of wrenches (n, 6) on the bodies, (torque about the ground
    origin; force) in ground components, F their sums over each body's outward set: J^T w
    summed over the bodies, shape (nv,). Derivative in q written out (see the module)."""
    if fixed_in_body(model):
        return _forces(model, q, wrenches)
    return _forces.fun(model, q, wrenches)


@jax.custom_jvp
def _motion(model: Model, q: Array, v: Array, a: Array):
    kin = body_kinematics(model, q, v)
    A = path_sum(model.topology, columns(kin.S, model.body_v(a)) + kin.c)
    return kin.R, kin.p, kin.V, A


@functools.partial(_motion.defjvp, symbolic_zeros=True)
def _motion_jvp(primals, tangents):
    model, q, v, a = primals
    d_model, dq, dv, da = tangents
    kin = body_kinematics(model, q, v)
    S, V = kin.S, kin.V
    A = path_sum(model.topology, columns(S, model.body_v(a)) + kin.c)
    ground = jnp.zeros(6, V.dtype)
    U, B = _parent(model, V, ground), _parent(model, A, ground)
    zero = jnp.zeros_like(V)
    s = columns(S, joint_increments(model, q, v, dq)) if not is_zero(dq) else zero
    sU = cross_motion(s, U)
    rest = cross_motion(sU, U) - cross_motion(s, B)
    w = zero
    if not is_zero(dv):
        w = columns(S, model.body_v(dv))
        rest = rest - cross_motion(w, U + V)
    if not is_zero(da):
        rest = rest + columns(S, model.body_v(da))
    delta, moved, rest = path_sum(model.topology, (s, sU - w, rest))
    dV = cross_motion(delta, V) - moved
    dA = cross_motion(delta, A) - cross_motion(moved, V) + rest
    dR = jnp.cross(delta[:, :3, None], kin.R, axis=-2)
    dp = jnp.cross(delta[:, :3], kin.p) + delta[:, 3:]
    out = (dR, dp, dV, dA)
    if not is_zero(d_model):
        _, moved_m = jax.jvp(lambda m: _motion.fun(m, q, v, a), (model,),
                             (instantiate(d_model, model),))
        out = jax.tree.map(jnp.add, out, moved_m)
    return (kin.R, kin.p, V, A), out


def _subspaces(model: Model, q: Array) -> Array:
    """The joints' motion subspaces S (n, 6, width) in ground components at the ground origin."""
    R, p = forward_kinematics(model, q)
    _, _, S_local, _ = model.joints(q, jnp.zeros(model.nv, q.dtype))
    return to_ground(R, p, S_local)


@jax.custom_jvp
def _forces(model: Model, q: Array, wrenches: Array) -> Array:
    F = outward_sum(model.topology, wrenches)
    return model.flat_v(jnp.einsum("kic,ki->kc", _subspaces(model, q), F))


@functools.partial(_forces.defjvp, symbolic_zeros=True)
def _forces_jvp(primals, tangents):
    model, q, wrenches = primals
    d_model, dq, dW = tangents
    S = _subspaces(model, q)
    F = outward_sum(model.topology, wrenches)
    dF = jnp.zeros_like(F)
    if not is_zero(dW):
        dF = outward_sum(model.topology, dW)
    if not is_zero(dq):
        still = jnp.zeros(model.nv, q.dtype)
        delta = path_sum(model.topology, columns(S, joint_increments(model, q, still, dq)))
        dF = dF - cross_force(delta, F)
    dtau = model.flat_v(jnp.einsum("kic,ki->kc", S, dF))
    if not is_zero(d_model):
        dtau = dtau + jax.jvp(lambda m: _forces.fun(m, q, wrenches), (model,),
                              (instantiate(d_model, model),))[1]
    return model.flat_v(jnp.einsum("kic,ki->kc", S, F)), dtau
