"""Bricard's mechanism, IFToMM multibody benchmark A04 (Gonzalez, Dopico, Lugris and
Cuadrado, "A benchmarking system for MBS simulation software", Multibody System Dynamics 16(2),
179-190, 2006; problem library http://lim.ii.udc.es/mbsbenchmark/dist/A04/A04_specification.xml,
reproduced in OpenSim by the Padua group, https://rehabenggroup.github.io/MBSbenchmarksInOpenSim,
and in Exudyn's TestModels/bricardMechanism.py).

Five bars of length 1 m and mass 1 kg (square cross-section 0.1 m, as in the OpenSim and Exudyn
reproductions) and the ground form a closed chain of six revolute joints, at the corners
P1 ... P6 of a unit cube's skew hexagon,

    P1 (0, 0, 0)  axis y      P2 (1, 0, 0)  axis z      P3 (1, -1, 0)  axis x
    P4 (1, -1, 1) axis y      P5 (0, -1, 1) axis z      P6 (0, 0, 1)   axis x,

bar k running from P_k to P_k+1 (k = 1 ... 5; the ground closes P6 -> P1). Every axis is
perpendicular to the two bars it joins. Grübler's count, 6 (6 - 1) - 5 * 6 = 0, says the chain is
a structure; the particular axes make it move with one degree of freedom. Gravity is -9.81 m/s^2 along y; the
mechanism starts at rest in the configuration above and the benchmark runs 10 s.

Tree: body k - 1 is bar k, in a chain from P1, every body frame at its bar's first joint and
parallel to the ground frame at q = 0; the joint at P6 (bar 5's tip to the ground) is cut: a
revolute cut joint, 5 equations of which only 4 are independent (the constraint Jacobian has
rank 4 along the whole motion), so the solvers report `Status.REDUNDANT` and use least-squares
multipliers.

Closed-form motion (`joint_angles`): along the mechanism's one-dof curve through q = 0 the tree
joints at P1, P3, P5 turn by one angle phi and those at P2, P4 by psi, with

    sin(phi) + sin(psi) + sin(phi) sin(psi) = 0,    psi = -asin(sin(phi) / (1 + sin(phi))),

(the threefold symmetry of the hexagon; found here by continuation of the loop residual and
checked to round-off by the tests against an independent product of the six joint transforms
around the loop). The formula holds for sin(phi) > -1/2, which covers the motion from rest: by
energy, phi swings between 0 and pi (V(q(pi)) = V(q(0)); one swing there and back takes
about 5 s).

The benchmark's output point P3 (initially (1, -1, 0)) is the joint between bars 2 and 3, the
origin of body 2: `point_p3`.
"""

import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src.loops import GROUND, ClosedSystem, CutJoint
from mbjax._src.model.closures import Revolute
from mbjax._src.model import Model
from mbjax._src.rigid import TreeSystem
from mbjax._src.rigid.kinematics import forward_kinematics

LENGTH = 1.0
MASS = 1.0
SECTION = 0.1            # side of the bars' square cross-section [m]
GRAVITY = 9.81
DURATION = 10.0
CORNERS = LENGTH * np.array(        # P1 ... P6
    [[0, 0, 0], [1, 0, 0], [1, -1, 0], [1, -1, 1], [0, -1, 1], [0, 0, 1]], float)
AXES = np.array([[0, 1, 0], [0, 0, 1], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 0]], float)
_ROT_Y = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])   # its z is the ground x


def model(section=SECTION) -> Model:
    """The open chain of the five bars from P1 (body k: bar k + 1, its joint at corner k).

    Args:
        section: the side of the bars' square cross-section [m].

    Returns:
        The tree's `Model`, five revolute joints, gravity -9.81 m/s^2 along y.
    """
    directions = np.diff(CORNERS, axis=0) / LENGTH           # unit bar directions at q = 0
    transverse = MASS * (LENGTH**2 + section**2) / 12
    axial = MASS * section**2 / 6
    inertia = np.array([transverse * np.eye(3) + (axial - transverse) * np.outer(d, d)
                        for d in directions])
    return Model(np.arange(5) - 1, "revolute", mass=np.full(5, MASS), inertia=inertia,
                 com=directions * LENGTH / 2, axis=AXES[:5],
                 placement_translation=np.vstack([np.zeros(3), directions[:4] * LENGTH]),
                 gravity=(0.0, -GRAVITY, 0.0))


def joint_angles(phi):
    """The tree coordinates on the mechanism's motion at parameter phi (closed form, see
    `mbjax.scenes.bricard`).

    Args:
        phi: the angle of the joints at P1, P3 and P5 [rad]; sin(phi) > -1/2.

    Returns:
        (phi, psi, phi, psi, phi) [rad], shape (5,).
    """
    psi = -jnp.arcsin(jnp.sin(phi) / (1 + jnp.sin(phi)))
    return jnp.stack([phi, psi, phi, psi, phi])


def point_p3(model: Model, q):
    """The benchmark's output point P3, the joint between bars 2 and 3, in the ground frame.

    Args:
        model: the tree's model.
        q: tree configuration [rad], shape (5,).

    Returns:
        P3's position [m], shape (3,).
    """
    return forward_kinematics(model, q)[1][2]


def build(phi0=0.0, phi_dot0=0.0, section=SECTION):
    """The scene: Bricard's mechanism at a point of its motion.

    The joint at P6 is a revolute cut joint (5 equations of rank 4, so the solvers report
    `Status.REDUNDANT`); the `ClosedSystem` uses coupled multipliers.

    Args:
        phi0: the start on the motion [rad] (0: the benchmark's start).
        phi_dot0: its rate [rad/s] (0: at rest, as in the benchmark).
        section: the side of the bars' square cross-section [m].

    Returns:
        system: the `ClosedSystem`.
        q0: the tree configuration, shape (5,).
        v0: the tree velocity, shape (5,).
    """
    phi0 = jnp.asarray(phi0, float)
    cut = CutJoint(Revolute(), 4, GROUND, origin_a=CORNERS[5] - CORNERS[4], origin_b=CORNERS[5],
                   rotation_a=_ROT_Y, rotation_b=_ROT_Y)
    system = ClosedSystem(TreeSystem(model(section)), [cut])
    return system, joint_angles(phi0), jax.jacfwd(joint_angles)(phi0) * phi_dot0
