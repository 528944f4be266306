"""The constraints of a closed mechanism at position, velocity and acceleration level (`Loops`,
whose docstring gives them)."""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.system.tree_system import AbstractTreeSystem
from mbjax._src.model.closures import GROUND, Coupling, CutJoint, Prescribed, cut_joint_rows


class Loops(eqx.Module):
    """A tree closed by cut joints and couplings and driven by prescribed motions: the
    constraints Phi(q, t) = 0 at position, velocity and acceleration level (see The constraints,
    below). `ClosedSystem` holds one; the loop algorithms are functions of it.

    Args:
        tree: any `AbstractTreeSystem`: rigid, or flexible with markers as frames n, n + 1, ...
        closures (Sequence): `CutJoint`s, `Coupling`s and `Prescribed` motions, at least one.

    Raises:
        TypeError: `tree` is not a tree system, or a closure of another type.
        ValueError: no closures, or one that names a body or coordinate the tree lacks (a
            `Prescribed` motion also needs nq == nv).

    The constraints:
        The constraints of a closed mechanism at position, velocity and acceleration level (Anderson
        1993 eqs 87-88, Jerkovsky 1978 eq 85), all by autodiff of the holonomic residual Phi(q, t):

        ```text
        Phi(q, t) = 0,    A(q, t) v + B(q, t) = 0,    A(q, t) v_dot + b(q, v, t) = 0,
        ```

        with A = dPhi/dq . dq/dv (the velocity constraint operator, (m, nv)), B = dPhi/dt and b =
        d/dt (A v + B) at fixed v, the "A_dot u + B_dot" of Anderson 1993 eq 92. Derivatives follow
        q along q_dot = tree.q_dot(q, v), so quaternion joints need no special case. Where the
        tree writes its bodies' motion out (`body_motion`, a rigid tree, whose derivatives are
        written out too: `mbjax/_src/rigid/motion.py`), `rate`, `jacobian`, `drift` (A v_dot + b)
        and `force` (A^t K), the terms the KKT system's derivatives differentiate
        (`mbjax/_src/loops/kkt.py`), take a cut joint's rates from its residual along its two
        frames' velocities and accelerations, and A^t K from the tree's inward pass of the
        wrenches on them (`body_forces`): no nested derivative of the tree's kinematics. Cut
        joints alike but for their arrays and bodies (a stance's feet) are one `vmap`
        (`cut_joint_rows`).
    """

    tree: AbstractTreeSystem
    closures: tuple

    def __init__(self, tree: AbstractTreeSystem, closures):
        if not isinstance(tree, AbstractTreeSystem):
            raise TypeError(f"tree must be a tree system (mbjax.rigid.TreeSystem, "
                            f"mbjax.flex.FlexibleSystem), got {type(tree).__name__}"
                            + ("; wrap the model: TreeSystem(model)"
                               if type(tree).__name__ == "Model" else ""))
        closures = tuple(closures)
        if not closures:
            raise ValueError("a closed system needs at least one cut joint or prescribed motion")
        for c in closures:
            if isinstance(c, CutJoint):
                for body in (c.body_a, c.body_b):
                    if body != GROUND and not 0 <= body < tree.n_frames:
                        raise ValueError(f"cut joint {c.kind!r}: body {body} is not in the tree "
                                         f"(0 ... {tree.n_frames - 1}, or -1 for the ground)")
            elif isinstance(c, Prescribed):
                if not c.dof < tree.nq or tree.nq != tree.nv:
                    raise ValueError(f"prescribed motion of coordinate {c.dof}: the tree has "
                                     f"{tree.nq} coordinates (and drives need nq == nv)")
            elif isinstance(c, Coupling):
                if not max(c.coordinate, c.reference) < tree.nq:
                    raise ValueError(f"coupling of coordinates {c.coordinate} and {c.reference}: "
                                     f"the tree has {tree.nq} coordinates")
            else:
                raise TypeError(f"closures must be CutJoint, Coupling or Prescribed, got "
                                f"{type(c).__name__}")
        self.tree = tree
        self.closures = closures

    @property
    def m(self) -> int:
        """Number of scalar constraint equations (redundant ones included)."""
        return sum(c.size for c in self.closures)

    def held(self) -> Array:
        """The number of equations held: `m` less those of cut joints let go (`CutJoint`'s
        `active`), a traced scalar."""
        return sum(c.rows if isinstance(c, CutJoint) else c.size for c in self.closures)

    def checked(self, q: Array, v: Array | None = None) -> None:
        """An error naming q or v where its shape is not the tree's (nq,) or (nv,)."""
        for name, x, n in (("q", q, self.tree.nq), ("v", v, self.tree.nv)):
            if x is not None and jnp.shape(x) != (n,):
                raise ValueError(f"{name} must have shape ({n},) for this tree, got "
                                 f"{jnp.shape(x)}")

    def phi(self, q: Array, t=0.0) -> Array:
        """The residual Phi(q, t), shape (m,), for q of shape (nq,) at time t [s]."""
        self.checked(q)
        if any(isinstance(c, CutJoint) for c in self.closures):
            R, p = self.tree.frames(q)
        else:                         # prescribed motions only: no kinematics to trace
            R = p = None
        return self._phi(R, p, q, t)

    def _phi(self, R, p, q, t) -> Array:
        def cut(joint, a, b):
            return joint.pose_residual(*a, *(b or (None, None))) * joint.active
        return cut_joint_rows(self.closures, cut, lambda c: c.residual(R, p, q, t), (R, p))

    def _rate(self, R, p, V, q, q_dot, t) -> Array:
        """A v + B from the frames' poses and spatial velocities V (world origin): a cut joint
        moves with its two frames (R_dot = omega x R, p_dot = v_O + omega x p), each closure on
        its own bodies alone, the other closures with q along q_dot."""
        def cut(joint, a, b):
            poses, motions = [], []
            for frame in (a, b):
                if frame is None:
                    poses += [None, None]
                    motions += [None, None]
                    continue
                R_, p_, V_ = frame
                poses += [R_, p_]
                motions += list(_pose_rates(R_, p_, V_))
            return jax.jvp(joint.pose_residual, poses, motions)[1] * joint.active

        def other(c):
            return jax.jvp(lambda q_, t_: c.residual(None, None, q_, t_), (q, t),
                           (q_dot, jnp.ones_like(t)))[1]
        return cut_joint_rows(self.closures, cut, other, (R, p, V))

    def rate(self, q: Array, v: Array, t=0.0) -> Array:
        """A v + B = dPhi/dt along the motion, shape (m,), for v of shape (nv,). Where the tree
        writes its bodies' motion out, a cut joint's rate is its residual's along its frames'
        velocities (`body_motion`), whose derivatives are written out too."""
        self.checked(q, v)
        t = jnp.asarray(t, q.dtype)
        motion = self.tree.body_motion(q, v)
        if motion is None:
            return jax.jvp(self.phi, (q, t), (self.tree.q_dot(q, v), jnp.ones((), q.dtype)))[1]
        R, p, V, _ = motion
        return self._rate(R, p, V, q, self.tree.q_dot(q, v), t)

    def jacobian(self, q: Array, t=0.0) -> Array:
        """The velocity constraint operator A, shape (m, nv): the rate is linear in v, A v + B.
        Where the tree writes its bodies' motion out, forward mode over v through the bodies'
        written-out velocity tangents (`body_motion`); otherwise reverse mode through the rate,
        one pass per constraint row, so O(m n) rather than O(n^2) for long chains."""
        self.checked(q)
        zero = jnp.zeros(self.tree.nv, q.dtype)
        if self.tree.body_motion(q, zero) is None:
            return jax.jacrev(lambda v: self.rate(q, v, t))(zero)
        return jax.jacfwd(lambda v: self.rate(q, v, t))(zero)

    def acceleration_bias(self, q: Array, v: Array, t=0.0) -> Array:
        """b = d/dt (A v + B) at fixed v, shape (m,), so that A v_dot + b is the second
        derivative of Phi."""
        return jax.jvp(lambda q_, t_: self.rate(q_, v, t_), (q, jnp.asarray(t, q.dtype)),
                       (self.tree.q_dot(q, v), jnp.ones((), q.dtype)))[1]

    def drift(self, q: Array, v: Array, v_dot: Array, t=0.0) -> Array:
        """A v_dot + b, the second derivative of Phi along the motion (q, v, v_dot), shape (m,).
        Where the tree writes its bodies' motion out (`body_motion`), a cut joint's is its
        residual's second derivative along its frames' velocities and accelerations, with no
        derivative of the tree's kinematics."""
        t = jnp.asarray(t, q.dtype)
        motion = self.tree.body_motion(q, v, v_dot)
        q_dot = self.tree.q_dot(q, v)
        if motion is None:
            return jax.jvp(lambda q_, v_, t_: self.rate(q_, v_, t_), (q, v, t),
                           (q_dot, v_dot, jnp.ones_like(t)))[1]
        R, p, V, A = motion
        R_dot, p_dot = _pose_rates(R, p, V)
        q_ddot = jax.jvp(self.tree.q_dot, (q, v), (q_dot, v_dot))[1]
        return jax.jvp(self._rate, (R, p, V, q, q_dot, t),
                       (R_dot, p_dot, A, q_dot, q_ddot, jnp.ones_like(t)))[1]

    def force(self, q: Array, K: Array | None, t=0.0) -> Array:
        """A^t K, the generalized force of the multipliers K, shape (nv,). Where the tree writes
        its bodies' motion out, the cut joints' loads are wrenches on their frames and the
        tree's inward pass sums them (`body_forces`), with no reverse pass through the tree's
        kinematics. K None for no loads (zero)."""
        if K is None:
            return jnp.zeros(self.tree.nv, q.dtype)
        t = jnp.asarray(t, q.dtype)
        v = jnp.zeros(self.tree.nv, q.dtype)
        if self.tree.body_motion(q, v) is None:
            return jax.vjp(lambda v_: self.rate(q, v_, t), v)[1](K)[0]
        R, p = self.tree.frames(q)                   # the loads act at rest: V = 0
        V = jnp.zeros((R.shape[0], 6), q.dtype)
        if all(isinstance(c, CutJoint) for c in self.closures):     # no term in q_dot
            wrenches = jax.vjp(lambda V_: self._rate(R, p, V_, q, None, t), V)[1](K)[0]
            return self.tree.body_forces(q, wrenches)
        q_dot, q_dot_transpose = jax.vjp(lambda v_: self.tree.q_dot(q, v_), v)
        wrenches, generalized = jax.vjp(lambda V_, qd: self._rate(R, p, V_, q, qd, t), V,
                                        q_dot)[1](K)
        return self.tree.body_forces(q, wrenches) + q_dot_transpose(generalized)[0]


def _pose_rates(R: Array, p: Array, V: Array) -> tuple[Array, Array]:
    """(R_dot, p_dot) = (omega x R, v_O + omega x p) of frames (..., 3, 3), (..., 3) moving with
    spatial velocities V = (omega; v_O) at the world origin, shape (..., 6)."""
    omega, v_origin = V[..., :3], V[..., 3:]
    return jnp.cross(omega[..., :, None], R, axis=-2), v_origin + jnp.cross(omega, p)
