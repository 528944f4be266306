"""The acrobot: a double pendulum driven at its elbow only, swung up from hanging to upright.

Two uniform 1 m, 1 kg links on parallel revolute joints about y, hanging along -z at q = 0;
the shoulder is unpowered (`actuation=[1]`), the elbow's torque unbounded by default (from the
zero first guess, a tightly bounded swing-up settles on a poor local optimum: it wants a better
guess; see benchmarks/README.md).
Upright is q = (pi, 0), the tip 2 m above the shoulder. `swingup_problem` asks for the tip there at rest
after DURATION, with a small control and velocity regularization on the way; the controls
start at zero from a slightly tilted rest (a hanging pendulum at exactly q = 0 is a stationary
point of the problem as well).
"""

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.integrate import RK4
from mbjax._src.model import Model
from mbjax._src.rigid import TreeSystem, forward_kinematics
from mbjax._src.trajopt import Problem

LENGTH, MASS = 1.0, 1.0                          # [m], [kg] per link
DT, DURATION = 0.01, 3.0                         # [s]
Q0 = np.array([0.02, 0.0])                       # [rad]: just off the hanging equilibrium


def model() -> Model:
    """The acrobot's two-link tree (two uniform 1 m, 1 kg links on revolute joints about y).

    Returns:
        The `Model`, hanging along -z at q = 0.
    """
    inertia = np.diag([MASS * LENGTH**2 / 12, MASS * LENGTH**2 / 12, 1e-4])
    return Model([-1, 0], "revolute", mass=[MASS, MASS], inertia=[inertia, inertia],
                 com=[[0.0, 0.0, -LENGTH / 2]] * 2, axis=[[0.0, 1.0, 0.0]] * 2,
                 placement_translation=[[0.0, 0.0, 0.0], [0.0, 0.0, -LENGTH]])


def tip(model: Model, q: Array) -> Array:
    """The second link's free end in the world.

    Args:
        model: the acrobot's model.
        q: configuration (shoulder, elbow) [rad], shape (2,).

    Returns:
        The tip's position [m], shape (3,).
    """
    R, p = forward_kinematics(model, q)
    return p[-1] + R[-1] @ jnp.array([0.0, 0.0, -LENGTH])


def _running(q, v, u, *, acrobot, goal):
    return jnp.concatenate([0.1 * (tip(acrobot, q) - goal), 0.01 * v, 0.1 * u])


def _terminal(q, v, *, acrobot, goal):
    return jnp.concatenate([100.0 * (tip(acrobot, q) - goal), 10.0 * v])


def swingup_problem(arm: Model | None = None, steps: int = round(DURATION / DT),
                    torque_limit: float | None = None, integrator=RK4()) -> Problem:
    """The swing-up from hanging to upright at rest as a trajectory-optimisation problem.

    Least-squares residuals: along the way 0.1 (tip - goal), 0.01 v and 0.1 u; at the end
    100 (tip - goal) and 10 v; the elbow's torque within +-torque_limit; steps of DT by
    `integrator`, from rest at Q0.

    Args:
        arm: the model; None for `model()`.
        steps: the horizon in steps of DT (DURATION / DT by default).
        torque_limit: the bound on the elbow's torque [N m]; None for none.
        integrator: the integrator of each step.

    Returns:
        The `mbjax.trajopt.Problem`, its control the elbow torque (nu = 1).
    """
    acrobot = model() if arm is None else arm
    goal = jnp.array([0.0, 0.0, 2 * LENGTH])
    running = eqx.Partial(_running, acrobot=acrobot, goal=goal)
    terminal = eqx.Partial(_terminal, acrobot=acrobot, goal=goal)
    bound = None if torque_limit is None else float(torque_limit)
    return Problem(TreeSystem(acrobot, actuation=[1]), Q0, np.zeros(2), dt=DT, horizon=steps,
                   running=running, terminal=terminal, lower=None if bound is None else -bound,
                   upper=bound, integrator=integrator)
