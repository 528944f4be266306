"""A planar four-bar linkage: crank, coupler and rocker on a ground link, gravity -y.

The tree is the crank (body 0, revolute at the ground origin) carrying the coupler (body 1,
revolute at the crank's tip), and the rocker (body 2, revolute at the ground point (D, 0, 0));
the loop is cut at the coupler-rocker pin. All joint axes are z; each link is a uniform bar
along its body x axis from its joint.

The cut joint is, by default, a planar pin: a `PointOnLine()` cut joint (the coupler's tip on the
rocker's z line through its tip), 2 equations of full rank. `closure=Revolute()` uses the spatial
revolute cut joint instead, 5 equations of which only 2 are independent in a planar loop: the
redundancy that `Status.REDUNDANT` reports (Jerkovsky 1978 §VI's multipliers then come from the
least-squares solve of `mbjax/_src/loops/multipliers.py`).

`joint_angles(theta)` is the closed-form position analysis (two circles' intersection, elbow-up
branch), the minimal-coordinate reference of the tests.
"""

import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src.loops import ClosedSystem, CutJoint
from mbjax._src.model.closures import AbstractCutKind, PointOnLine, Revolute, check_cut_kind
from mbjax._src.model import Model
from mbjax._src.rigid import TreeSystem

A_, B_, C_, D_ = 0.1, 0.35, 0.25, 0.4          # crank, coupler, rocker, ground link [m]
LENGTHS = np.array([A_, B_, C_])
MASSES = np.array([0.5, 1.0, 0.8])             # [kg]
GRAVITY = 9.81
THETA0, OMEGA0 = 0.3, 2.0                      # initial crank angle [rad] and rate [rad/s]
CLOSURES = (PointOnLine(), Revolute())


def model(gravity=(0.0, -GRAVITY, 0.0)) -> Model:
    """The tree: crank and coupler from the ground origin, rocker from (D, 0, 0).

    Args:
        gravity: the acceleration of gravity, shape (3,) [m/s^2]; -y (in the linkage's plane)
            by default.

    Returns:
        The tree's `Model`, three revolute joints about z.
    """
    inertia = np.array([np.diag([1e-5, m * L**2 / 12, m * L**2 / 12])
                        for m, L in zip(MASSES, LENGTHS)])
    return Model([-1, 0, -1], "revolute", mass=MASSES, inertia=inertia,
                 com=np.stack([LENGTHS / 2, 0 * LENGTHS, 0 * LENGTHS], 1), axis=[0.0, 0.0, 1.0],
                 placement_translation=[[0, 0, 0], [A_, 0, 0], [D_, 0, 0]],
                 gravity=gravity)


def joint_angles(theta):
    """The tree coordinates of the closed four-bar at crank angle theta.

    Closed-form position analysis (two circles' intersection), elbow-up branch.

    Args:
        theta: the crank angle [rad], a scalar.

    Returns:
        (crank angle, coupler angle relative to the crank, rocker angle) [rad], shape (3,).
    """
    P = jnp.array([A_ * jnp.cos(theta), A_ * jnp.sin(theta)])        # crank tip
    e = jnp.array([D_, 0.0]) - P
    r = jnp.linalg.norm(e)
    x = (r**2 + B_**2 - C_**2) / (2 * r)                              # along P -> rocker pivot
    u = e / r
    Q = P + x * u + jnp.sqrt(B_**2 - x**2) * jnp.array([-u[1], u[0]])  # coupler-rocker pin
    phi = jnp.arctan2(Q[1] - P[1], Q[0] - P[0])
    psi = jnp.arctan2(Q[1], Q[0] - D_)
    return jnp.array([theta, phi - theta, psi])


def build(closure: AbstractCutKind = PointOnLine(), theta0=THETA0, omega0=OMEGA0):
    """The scene: the four-bar started on the loop.

    A `ClosedSystem` with coupled multipliers (rebuild it from `system.tree` and
    `system.closures` for another method).

    Args:
        closure: the cut joint's kind: `mbjax.loops.PointOnLine()` (the planar pin, 2
            equations) or `mbjax.loops.Revolute()` (the spatial revolute joint, 5 redundant
            equations).
        theta0: the initial crank angle [rad].
        omega0: the initial crank rate [rad/s].

    Returns:
        system: the `ClosedSystem`.
        q0: the tree configuration on the loop, shape (3,).
        v0: the tree velocity on the loop, shape (3,).

    Raises:
        ValueError: closure is not one of `CLOSURES`.
        TypeError: closure is not a cut-joint kind (a string, say).
    """
    closure = check_cut_kind(closure)
    if closure not in CLOSURES:
        raise ValueError(f"closure must be one of {CLOSURES}, got {closure!r}")
    cut = CutJoint(closure, 1, 2, origin_a=(B_, 0.0, 0.0), origin_b=(C_, 0.0, 0.0))
    system = ClosedSystem(TreeSystem(model()), [cut])
    q0 = joint_angles(jnp.asarray(theta0, float))
    v0 = jax.jacfwd(joint_angles)(jnp.asarray(theta0, float)) * omega0
    return system, q0, v0


CRANK_GOAL = THETA0 + np.pi / 2                # [rad]: the trajectory-optimisation target
CRANK_DT, CRANK_STEPS = 0.01, 100              # [s], knots: 1 s


def _crank_running(q, v, u):
    return u


def _crank_terminal(q, v, *, goal):
    return jnp.concatenate([100.0 * (q[:1] - goal), 10.0 * v])


def crank_problem(goal=CRANK_GOAL, steps: int = CRANK_STEPS):
    """The crank turned rest-to-rest with least effort, as a trajectory-optimisation problem.

    The four-bar lies on a table (gravity -z, normal to its plane; planar pin closure,
    projection on), driven by a torque on its crank from rest at crank angle THETA0 to rest at
    `goal` after `steps` steps of CRANK_DT (RK4): the running residual is the torque u (cost
    1/2 u^2 dt), the terminal residuals 100 (theta_N - goal) and 10 v_N. Each step ends on the
    loop by the projection, so iLQR's linearization is that of the projected step.

    Args:
        goal: the final crank angle [rad].
        steps: the horizon in steps of CRANK_DT.

    Returns:
        The `mbjax.trajopt.Problem`, its control the crank torque (nu = 1).
    """
    from mbjax._src.rigid import TreeSystem
    from mbjax._src.trajopt import Problem

    cut = CutJoint(PointOnLine(), 1, 2, origin_a=(B_, 0.0, 0.0), origin_b=(C_, 0.0, 0.0))
    table = model(gravity=(0.0, 0.0, -GRAVITY))
    system = ClosedSystem(TreeSystem(table, actuation=[0]), [cut], projection=True)
    q0 = joint_angles(jnp.asarray(THETA0, float))
    return Problem(system, q0, jnp.zeros(3), dt=CRANK_DT, horizon=steps,
                   running=_crank_running,
                   terminal=jax.tree_util.Partial(_crank_terminal, goal=jnp.asarray(goal, float)))
