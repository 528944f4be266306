"""A slider-crank in a vertical plane: steel crank and connecting rod, a steel slider on a
horizontal guide through the crank's pivot, gravity -y: the rigid counterpart of Anderson 1993 §3.1's
slider-crank (there a flexible rod, 6 in crank, 12 in rod, 125.6 rad/s).

Tree (joint axes z for the pins, x for the guide):
    body 0  crank, revolute at the ground origin, a bar of length R along its x axis;
    body 1  connecting rod, revolute at the crank's tip (R, 0, 0), a bar of length L;
    body 2  slider, prismatic along the ground x axis, q = its position x.
The loop is cut at the rod-slider pin: a `PointOnLine()` cut joint (the rod's tip on the
slider's z line), 2 equations of full rank (planar pin; R < L, so no configuration is singular).

With `driven=True` the crank turns at constant speed, q_0 = theta0 + rate t, a `Prescribed`
motion (rheonomic constraint, Jerkovsky 1978 eq 85 with B = dPhi/dt): the mechanism has no degree of
freedom left, and the multiplier of the prescribed row is the motor torque on the crank (about
+z; `ClosedSystem.loads(...)[-1]`, since that row of A is e_0, A^t K_c puts it on the crank
coordinate). With `driven=False` the crank is free and `rate` is its initial speed.

Closed-form kinematics (`slider_position`, `joint_angles`): the rod's tip lies on the guide,
R sin(theta) + L sin(phi) = 0, so x = R cos(theta) + sqrt(L^2 - (R sin(theta))^2) and the rod's
absolute angle is phi = atan2(-R sin(theta), x - R cos(theta)).
"""

import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src.loops import ClosedSystem, CutJoint, Prescribed
from mbjax._src.model.closures import PointOnLine
from mbjax._src.model import Model
from mbjax._src.rigid import TreeSystem

DENSITY = 7850.0                   # steel [kg/m^3]
R_ = 0.1                           # crank length [m]
L_ = 0.3                           # connecting rod length [m]
WIDTH, THICKNESS = 0.02, 0.01      # the bars' cross-section (in the plane, across it) [m]
BLOCK = (0.05, 0.04, 0.03)         # the slider's edges (x, y, z) [m]
GRAVITY = 9.81
THETA0 = 0.0                       # initial crank angle [rad]
RATE = 20.0                        # crank speed (driven) or initial crank speed (free) [rad/s]


def _bar(length):
    """Mass, centre of mass and central inertia of a steel bar along x from the origin."""
    m = DENSITY * length * WIDTH * THICKNESS
    inertia = m / 12 * np.diag([WIDTH**2 + THICKNESS**2, length**2 + THICKNESS**2,
                                length**2 + WIDTH**2])
    return m, np.array([length / 2, 0.0, 0.0]), inertia


def model() -> Model:
    """The tree: crank, rod on the crank, slider on the ground guide.

    Returns:
        The tree's `Model`: two revolute joints about z and a prismatic joint along x.
    """
    a, b, c = BLOCK
    m_block = DENSITY * a * b * c
    block = (m_block, np.zeros(3), m_block / 12 * np.diag([b**2 + c**2, a**2 + c**2, a**2 + b**2]))
    bodies = [_bar(R_), _bar(L_), block]
    return Model([-1, 0, -1], ["revolute", "revolute", "prismatic"],
                 mass=np.array([m for m, _, _ in bodies]),
                 com=np.array([c for _, c, _ in bodies]),
                 inertia=np.array([i for _, _, i in bodies]),
                 axis=[[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]],
                 placement_translation=[[0.0, 0.0, 0.0], [R_, 0.0, 0.0], [0.0, 0.0, 0.0]],
                 gravity=(0.0, -GRAVITY, 0.0))


def slider_position(theta):
    """The slider's position x(theta) = R cos(theta) + sqrt(L^2 - (R sin(theta))^2).

    Args:
        theta: the crank angle [rad].

    Returns:
        x [m], theta's shape.
    """
    return R_ * jnp.cos(theta) + jnp.sqrt(L_**2 - (R_ * jnp.sin(theta))**2)


def joint_angles(theta):
    """The tree coordinates of the closed mechanism at crank angle theta, in closed form.

    Args:
        theta: the crank angle [rad], a scalar.

    Returns:
        (crank angle [rad], rod angle relative to the crank [rad], slider position [m]),
            shape (3,).
    """
    x = slider_position(theta)
    phi = jnp.arctan2(-R_ * jnp.sin(theta), x - R_ * jnp.cos(theta))   # rod's absolute angle
    return jnp.array([theta, phi - theta, x])


def build(rate=RATE, theta0=THETA0, driven: bool = True):
    """The scene: the slider-crank at crank angle theta0 turning at `rate`.

    A `ClosedSystem` with coupled multipliers. Driven, the prescribed row's multiplier is the
    motor torque on the crank (`ClosedSystem.loads(...)[-1]`).

    Args:
        rate: the crank speed [rad/s]: constant when driven, initial when free.
        theta0: the initial crank angle [rad].
        driven: drive the crank at constant speed (a `Prescribed` motion appended after the
            cut joint) or leave it free.

    Returns:
        system: the `ClosedSystem`.
        q0: the tree configuration on the loop, shape (3,).
        v0: the tree velocity on the loop, shape (3,).
    """
    theta0 = jnp.asarray(theta0, float)
    closures = [CutJoint(PointOnLine(), 1, 2, origin_a=(L_, 0.0, 0.0))]
    if driven:
        closures.append(Prescribed(0, q0=theta0, rate=rate))
    system = ClosedSystem(TreeSystem(model()), closures)
    return system, joint_angles(theta0), jax.jacfwd(joint_angles)(theta0) * rate
