"""Inverse dynamics by the recursive Newton-Euler algorithm (Featherstone, RBDA §5.3).

An outward pass gives body accelerations a[k] = a[parent] + S[k] q_ddot[k] + c[k] (Anderson 1993
eqs 25, 27 with the remainder terms of eqs 29, 31; gravity enters as the ground acceleration -g);
each body needs the wrench f[k] = I[k] a[k] + V[k] x* I[k] V[k] (Jerkovsky 1978 eq 9's
mu sigma_dot + Y, per body). An inward pass sums the wrenches of each body's outward set (Jerkovsky 1978
eq 20: the system j-bar) and projects them on the joint axes: tau[k] = S[k]^T f_bar[k]. All in
ground coordinates at the ground origin (see `kinematics`), so the passes are plain sums.
"""

import jax.numpy as jnp
from jax import Array

from mbjax._src.model import Model
from mbjax._src.rigid.kinematics import Kinematics, body_kinematics, gravity_acceleration
from mbjax._src.spatial import cross_force, shift_force
from mbjax._src.tree import backward_pass, forward_pass


def rnea_passes(model: Model, q: Array, v: Array, a: Array,
                f_ext: Array | None) -> tuple[Array, Kinematics, Array]:
    """(f_bar, the kinematics, acc): the wrench f_bar (n, 6) that each body's outward set needs
    and the body accelerations acc (n, 6, gravity in them), ground frame at the ground origin."""
    kin = body_kinematics(model, q, v)
    joint_acc = jnp.einsum("kij,kj->ki", kin.S, model.body_v(a)) + kin.c
    acc = forward_pass(model.topology, lambda a_parent, da: a_parent + da,
                       gravity_acceleration(model), joint_acc)
    f = (jnp.einsum("kij,kj->ki", kin.I, acc)
         + cross_force(kin.V, jnp.einsum("kij,kj->ki", kin.I, kin.V)))
    if f_ext is not None:
        f = f - shift_force(f_ext, kin.p)
    f_bar, _ = backward_pass(model.topology, lambda f_k, _: (f_k, f_k), f)
    return f_bar, kin, acc


def joint_wrenches(model: Model, q: Array, v: Array, a: Array, f_ext: Array | None = None) -> Array:
    """The wrench each joint transmits to its outward system (n, 6) for joint accelerations a
    (nv,): (torque about the joint origin; force) in body coordinates. Its projection on the joint
    axes is tau; the rest are the constraint forces K_c of Jerkovsky 1978 eq 76."""
    f_bar, kin, _ = rnea_passes(model, q, v, a, f_ext)
    Rt = jnp.swapaxes(kin.R, -1, -2)
    torque = f_bar[:, :3] - jnp.cross(kin.p, f_bar[:, 3:])         # about the hinge
    return jnp.concatenate([jnp.einsum("kij,kj->ki", Rt, torque),
                            jnp.einsum("kij,kj->ki", Rt, f_bar[:, 3:])], -1)


def inverse_dynamics(model: Model, q: Array, v: Array, a: Array, f_ext: Array | None = None) -> Array:
    """Joint forces tau (nv,) that give accelerations a at state (q, v) under gravity and the
    external wrenches f_ext (n, 6) (world frame, (torque about body k's origin; force)), with
    the joints' armature, damping and springs."""
    f_bar, kin, _ = rnea_passes(model, q, v, a, f_ext)
    return (model.flat_v(jnp.einsum("kij,ki->kj", kin.S, f_bar))
            + model.armature * a - model.passive_force(q, v))
