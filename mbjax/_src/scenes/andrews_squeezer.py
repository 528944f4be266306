"""Andrews' squeezing mechanism: seven planar bodies, three closed loops, a spring and a motor.

The problem `andrews` of the IVP test set (F. Mazzia, C. Magherini et al., "Test Set for IVP
Solvers", University of Bari, https://archimede.uniba.it/~testset/, problem "andrews"; from
E. Hairer and G. Wanner, Solving Ordinary Differential Equations II, 2nd ed., §VII.7, eqs 7.3-7.11
and Fig. 7.1-7.2, after Giles 1978 and Manning 1981; also benchmark A03 of the IFToMM library of
computational benchmark problems), built from mbjax bodies, joints and cut joints rather than from
the test set's hand-written mass matrix.

Constants, initial values and the reference solution at t = 0.03 s are the test set's. Where
they were read, the geometry, the tree, the cuts and the loads: the documentation site's
Details page (docs/details.md).
"""

from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.control import AbstractControl, Constant
from mbjax._src.loops import ClosedSystem, CutJoint
from mbjax._src.model.closures import PointOnLine
from mbjax._src.model import Model
from mbjax._src.rigid import TreeSystem
from mbjax._src.rigid.kinematics import forward_kinematics

# masses [kg] and moments of inertia about the centres of mass [kg m^2] (test set F)
m1, m2, m3, m4, m5, m6, m7 = 0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498
i1, i2, i3, i4, i5, i6, i7 = 2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5
# fixed points A, B, C [m]
xa, ya = -0.06934, -0.00227
xb, yb = -0.03635, 0.03273
xc, yc = 0.014, 0.072
# lengths [m]
d, da, e, ea = 28e-3, 115e-4, 2e-2, 1421e-5
rr, ra = 7e-3, 92e-5
ss, sa, sb, sc, sd = 35e-3, 1874e-5, 1043e-5, 18e-3, 2e-2
ta, tb = 2308e-5, 916e-5
u, ua, ub = 4e-2, 1228e-5, 449e-5
zf, zt = 2e-2, 4e-2
fa = 1421e-5
# driving torque [N m], spring stiffness [N/m] and rest length [m]
mom = 33e-3
c0, l0 = 4530.0, 7785e-5

T1 = 0.03
ANGLES = ("beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon")
TREE_ORDER = (0, 1, 2, 4, 3, 6, 5)      # q_tree = y[TREE_ORDER] and y = q_tree[TREE_ORDER]

# test set INITIAL: y(1..7); all velocities are zero
Y0 = (-0.0617138900142764496358948458001, 0.0, 0.455279819163070380255912382449,
      0.222668390165885884674473185609, 0.487364979543842550225598953530,
      -0.222668390165885884674473185609, 1.23054744454982119249735015568)
# test set SOLN: y(1..7) at t = 0.03 s (PSIDE, rtol = atol = 1e-14)
REFERENCE = (0.1581077119629904e2, -0.1575637105984298e2, 0.4082224013073101e-1,
             -0.5347301163226948e0, 0.5244099658805304e0, 0.5347301163226948e0,
             0.1048080741042263e1)


def to_testset(q: Array) -> Array:
    """Tree coordinates to the test set's order (beta, Theta, gamma, Phi, delta, Omega, epsilon).

    Args:
        q: tree coordinates [rad], shape (..., 7).

    Returns:
        The test set's y, shape (..., 7).
    """
    return q[..., jnp.array(TREE_ORDER)]


def from_testset(y) -> Array:
    """The test set's y(1..7) to tree coordinates (the inverse of `to_testset`).

    Args:
        y: the test set's coordinates [rad], shape (..., 7).

    Returns:
        Tree coordinates, shape (..., 7).
    """
    return jnp.asarray(y, dtype=float)[..., jnp.array(TREE_ORDER)]


class PointSpring(AbstractControl):
    """A linear spring from a point on a body to a fixed anchor, as a control of the tree.

    Energy V = stiffness (L - rest_length)^2 / 2 with L the length; force on the point
    F = -stiffness (L - rest_length) (x - anchor) / L, generalized force J^T F with J = dx/dv
    (Hairer & Wanner II §VII.7, the test set's fx, fy and ff(3); here for any tree, by a
    reverse-mode pass through the kinematics). Call as force(t, q, v) -> (nv,). All parameters
    are leaves: differentiable and sweepable.

    Args:
        model: the tree the spring acts on.
        body: the body carrying the spring's end.
        point: the spring's end in the body's frame, shape (3,) [m].
        anchor: the fixed end in the ground frame, shape (3,) [m].
        stiffness: spring stiffness [N/m].
        rest_length: rest length [m].

    Raises:
        ValueError: body is not a body of the model.
    """

    model: Model
    body: int = eqx.field(static=True)
    point: Array
    anchor: Array
    stiffness: Array
    rest_length: Array

    def __init__(self, model: Model, body: int, point, anchor, stiffness, rest_length):
        if not 0 <= body < model.n:
            raise ValueError(f"body {body} is not in the model (0 ... {model.n - 1})")
        self.model, self.body = model, int(body)
        self.point = jnp.asarray(point, float)
        self.anchor = jnp.asarray(anchor, float)
        self.stiffness = jnp.asarray(stiffness, float)
        self.rest_length = jnp.asarray(rest_length, float)

    def position(self, q: Array) -> Array:
        """The spring's end on the body, in the ground frame.

        Args:
            q: tree configuration, shape (nq,).

        Returns:
            Its position [m], shape (3,).
        """
        R, p = forward_kinematics(self.model, q)
        return p[self.body] + R[self.body] @ self.point

    def energy(self, q: Array) -> Array:
        """The spring's potential energy.

        Args:
            q: tree configuration, shape (nq,).

        Returns:
            The energy [J], a scalar.
        """
        length = jnp.linalg.norm(self.position(q) - self.anchor)
        return 0.5 * self.stiffness * (length - self.rest_length) ** 2

    def __call__(self, t, q: Array, v: Array) -> Array:
        delta = self.position(q) - self.anchor
        length = jnp.linalg.norm(delta)
        F = -self.stiffness * (length - self.rest_length) / length * delta
        # J v = d/dt position along q_dot = q_dot(q, v); J^T F by one reverse pass of that map
        def velocity(w):
            return jax.jvp(self.position, (q,), (self.model.q_dot(q, w),))[1]

        return jax.vjp(velocity, jnp.zeros_like(v))[1](F)[0]


class Squeezer(NamedTuple):
    """What `build` returns: the driven tree, its cut joints and the initial state.

    Args:
        tree: the tree, driven by the motor torque `tau` plus the `spring`.
        closures: the three `PointOnLine()` cut joints.
        spring: the `PointSpring`.
        tau: the constant motor torque, shape (7,) [N m].
        q0: the test set's initial configuration in tree order [rad], shape (7,).
        v0: the initial velocity (zeros), shape (7,).
    """

    tree: TreeSystem
    closures: tuple
    spring: PointSpring
    tau: Array
    q0: Array
    v0: Array

    def system(self, method=None, **kwargs) -> ClosedSystem:
        """The closed mechanism: `ClosedSystem(tree, closures, method, **kwargs)`.

        Args:
            method: the closed-loop method (a strategy of `mbjax.loops`); None for the
                default.
            **kwargs: further `ClosedSystem` arguments.

        Returns:
            The `ClosedSystem`.
        """
        return ClosedSystem(self.tree, self.closures, method, **kwargs)


def build() -> Squeezer:
    """Andrews' squeezing mechanism of the IVP test set (see `mbjax.scenes.andrews_squeezer`).

    Returns:
        A `Squeezer` (tree, closures, spring, tau, q0, v0); `.system()` closes it.
    """
    parents = (-1, 0, -1, -1, 3, -1, 5)
    mass = (m1, m2, m3, m5, m4, m7, m6)
    moments = np.array([i1, i2, i3, i5, i4, i7, i6])
    inertia = moments[:, None, None] * np.diag([0.5, 0.5, 1.0])    # thin plates in the x-y plane
    com = [(ra, 0, 0), (-da, 0, 0), (sa, sb, 0), (ta, tb, 0), (0, -(e - ea), 0), (ua, ub, 0),
           (zf - fa, 0, 0)]
    placement = [(0, 0, 0), (rr, 0, 0), (xb, yb, 0), (xa, ya, 0), (zt, 0, 0), (xa, ya, 0),
                 (0, -u, 0)]
    model = Model(parents, "revolute", mass=mass, inertia=inertia, com=com, axis=(0.0, 0.0, 1.0),
                  placement_translation=placement, gravity=(0.0, 0.0, 0.0),
                  names=("crank_beta", "rod_Theta", "gamma", "delta", "Phi", "epsilon", "Omega"))
    P = (-d, 0.0, 0.0)                     # the rod's far end, where the three loops close
    cuts = [CutJoint(PointOnLine(), 1, 2, origin_a=P, origin_b=(0.0, -ss, 0.0)),
            CutJoint(PointOnLine(), 1, 4, origin_a=P, origin_b=(0.0, -e, 0.0)),
            CutJoint(PointOnLine(), 1, 6, origin_a=P, origin_b=(zf, 0.0, 0.0))]
    spring = PointSpring(model, 2, point=(sd, -sc, 0.0), anchor=(xc, yc, 0.0), stiffness=c0,
                         rest_length=l0)
    tau = jnp.zeros(7).at[0].set(mom)
    tree = TreeSystem(model, Constant(tau) + spring)
    return Squeezer(tree, tuple(cuts), spring, tau, from_testset(Y0), jnp.zeros(7))
