"""The RNEA's directional derivative in (q, v), written out: two vector passes, no derivative of
a rotation matrix.

For trees of revolute and prismatic joints, in ground coordinates at the ground origin (see
`kinematics`): turning joint j by dq_j moves its outward set rigidly about the screw S_j, so
every ground-frame quantity X that rides on a body k of that set changes by S_j x X (motion
vectors: S_j x m, forces: S_j x* f, inertias: S_j x* I - I S_j x). Differentiating the RNEA
(`rnea`: V_k, A_k, f_k = I_k A_k + V_k x* I_k V_k, F_k the sum of the f of k's outward set,
tau_k = S_k . F_k) with that rule and collecting the sums over outward sets (the analysis of
Carpentier and Mansard, RSS 2018, "Analytical derivatives of rigid body dynamics algorithms",
here for one direction at a time) gives, with U_j = V and B_j = A of j's parent (the ground's:
0 and -g) and Y_j = S_j x U_j,

    g2_j = dq_j (Y_j x U_j - S_j x B_j) - 2 dv_j Y_j,      g3_j = dq_j Y_j - dv_j S_j
    (P2, P3) = the outward sums of (g2, g3)                 (one outward pass)
    L_k = I_k P2_k - P3_k x* h_k - I_k (P3_k x V_k) - V_k x* I_k P3_k + dq_k S_k x* F_k
    dtau_k = S_k . (the sum of L over k's outward set) + damping_k dv_k      (one inward pass)

with h_k = I_k V_k. It is linear in (dq, dv), so reverse mode transposes it into the same two
passes run the other way: the adjoint's RNEA VJP at the solved accelerations
(`mbjax.rigid.adjoint`) without differentiating the kinematics. Agrees with `jax.jvp` of
`inverse_dynamics` to rounding (tests/rigid/test_adjoint.py).
"""

import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax.model import Model
from mbjax.rigid.kinematics import body_kinematics, gravity_acceleration
from mbjax.spatial import cross_force, cross_motion
from mbjax.tree import backward_pass, forward_pass
from mbjax.tree.take import take

# the joints whose configuration moves their outward set along S alone (S constant in the body)
JOINTS = ("revolute", "prismatic")


def applies(model: Model) -> bool:
    """Whether every joint of the tree is revolute or prismatic."""
    return all(kind in JOINTS for kind in model.joint_types)


def rnea_jvp(model: Model, q: Array, v: Array, a: Array, dq: Array, dv: Array) -> Array:
    """d tau = d/de RNEA(model, q + e dq, v + e dv, a) at e = 0 (armature and damping included),
    for a tree of revolute and prismatic joints (`applies`)."""
    kin = body_kinematics(model, q, v)
    S, V, I = kin.S[..., 0], kin.V, kin.I           # noqa: E741 (the papers' name)
    ground = gravity_acceleration(model)
    A = _outward_sum(model, S * model.body_v(a) + kin.c, ground)
    h = _times(I, V)
    F = _inward_sum(model, _times(I, A) + cross_force(V, h))
    U = _parent(model, V, jnp.zeros_like(ground))
    B = _parent(model, A, ground)
    Y = cross_motion(S, U)
    dq_, dv_ = model.body_v(dq), model.body_v(dv)   # (n, 1)
    g = jnp.concatenate([dq_ * (cross_motion(Y, U) - cross_motion(S, B)) - 2 * dv_ * Y,
                         dq_ * Y - dv_ * S], -1)
    P = _outward_sum(model, g, jnp.zeros(12, q.dtype))
    P2, P3 = P[:, :6], P[:, 6:]
    L = (_times(I, P2) - cross_force(P3, h) - _times(I, cross_motion(P3, V))
         - cross_force(V, _times(I, P3)) + dq_ * cross_force(S, F))
    dtau = jnp.sum(S * _inward_sum(model, L), -1, keepdims=True)
    return model.flat_v(dtau) + model.damping * dv


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
