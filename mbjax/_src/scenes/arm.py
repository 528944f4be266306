"""A 7-dof arm from a URDF (`mbjax.data.ARM7`) under controls and forces: held in a pose by a PD
servo with the gravity torque there as feed-forward, driven by a torque spline, pushed at its
flange, and sampled the way MuJoCo applies a control (a zero-order hold per step).

`build()` gives the servoed arm; `reach_loss` is the rollout loss whose gradient with respect to
the spline's knots and a link mass the tour, the tests and notebook 09 take; `reach_problem` is
the arm-reach trajectory-optimisation problem (`mbjax.trajopt`).
"""

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.control import PD, AbstractControl, CubicSpline
from mbjax.data import ARM7
from mbjax._src.integrate import RK4, simulate
from mbjax._src.model import Model
from mbjax._src.model.urdf import load_urdf
from mbjax._src.rigid import TreeSystem, forward_kinematics, inverse_dynamics, mass_matrix
from mbjax._src.trajopt import Problem

Q_REF = np.array([0.0, -0.4, 0.0, -2.0, 0.0, 1.6, 0.8])        # [rad], inside every joint's limits
BANDWIDTH = 15.0                                                 # [rad/s] of each joint's servo
DAMPING_RATIO = 0.7
FLANGE = np.array([0.0, 0.0, 0.107])                             # on the last link's z axis [m]
DT = 2e-3                                                        # [s]
TARGET_OFFSET = np.array([0.05, -0.05, 0.03])                    # the reach: from the pose [m]
REACH = np.array([0.0, 0.4, 0.0])          # the trajectory-optimisation reach: 0.4 m sideways
REACH_DT, REACH_STEPS = 0.01, 100


def model() -> Model:
    """The 7-dof arm loaded from its URDF (`mbjax.data.ARM7`).

    Returns:
        The arm's `Model`, nq = nv = 7.
    """
    return load_urdf(ARM7)


def servo(arm: Model) -> PD:
    """A joint PD servo holding the arm at Q_REF.

    The gravity torque at Q_REF (the inverse dynamics at rest) is the feed-forward; each
    joint's gains come from its diagonal mass-matrix entry M_ii, kp = M_ii w^2 and
    kd = 2 zeta w M_ii, so every joint has the bandwidth w = BANDWIDTH (the wrist joints'
    inertia is a hundredth of the shoulder's: equal gains would make them stiff for an
    explicit step).

    Args:
        arm: the arm's model.

    Returns:
        The `mbjax.control.PD` servo.
    """
    q_ref = jnp.asarray(Q_REF)
    inertia = jnp.diag(mass_matrix(arm, q_ref))
    gravity = inverse_dynamics(arm, q_ref, jnp.zeros(arm.nv), jnp.zeros(arm.nv))
    return PD(inertia * BANDWIDTH**2, 2 * DAMPING_RATIO * BANDWIDTH * inertia, q_ref,
              feedforward=gravity)


def flange(arm: Model, q: Array) -> Array:
    """The flange's position in the world.

    Args:
        arm: the arm's model.
        q: configuration [rad], shape (7,).

    Returns:
        The flange's position [m], shape (3,).
    """
    R, p = forward_kinematics(arm, q)
    return p[-1] + R[-1] @ jnp.asarray(FLANGE)


class Push(AbstractControl):
    """A world force on the last body (at the system's `external_point`) from t = 0 to `duration`.

    An `external=` load: called as (t, q, v), it returns wrenches (n_bodies, 6).

    Args:
        force: the force in the world frame, shape (3,) [N].
        n_bodies: the model's number of bodies.
        duration: how long the push lasts [s].
    """

    force: Array
    n_bodies: int = eqx.field(static=True)
    duration: float = eqx.field(static=True)

    def __call__(self, t, q, v):
        on = (t < self.duration).astype(self.force.dtype)
        return jnp.zeros((self.n_bodies, 6), self.force.dtype).at[-1, 3:].set(on * self.force)


def pushed(arm: Model, force=(30.0, 0.0, 0.0), duration: float = 0.1) -> TreeSystem:
    """The servoed arm pushed at its flange.

    Args:
        arm: the arm's model.
        force: the push in the world frame, shape (3,) [N].
        duration: how long the push lasts [s].

    Returns:
        The `TreeSystem` with the servo as control and the push as external load.
    """
    points = jnp.zeros((arm.n, 3)).at[-1].set(jnp.asarray(FLANGE))
    return TreeSystem(arm, servo(arm), external=Push(jnp.asarray(force, float), arm.n, duration),
                      external_point=points)


def build():
    """The scene: the arm held at Q_REF by its servo, at rest.

    Returns:
        system: the servoed arm, a `TreeSystem`.
        q0: Q_REF [rad], shape (7,).
        v0: zeros, shape (7,).
    """
    arm = model()
    return TreeSystem(arm, servo(arm)), jnp.asarray(Q_REF), jnp.zeros(arm.nv)


def reach_loss(arm: Model, knots: Array, link_mass: Array, steps: int, link: int = 3) -> Array:
    """The reach loss of the servoed arm driven by a torque spline, to differentiate.

    1e4 |flange(T) - target|^2 + 1e-3 |knots|^2 over T = steps DT (RK4), the target
    TARGET_OFFSET from the flange's place at Q_REF.

    Args:
        arm: the arm's model.
        knots: the spline's control points, shape (n_knots, 7) [N m].
        link_mass: the mass given to link `link` [kg].
        steps: the number of steps of DT.
        link: the link whose mass is set.

    Returns:
        The loss, a scalar.
    """
    arm = eqx.tree_at(lambda m: m.mass, arm, arm.mass.at[link].set(link_mass))
    system = TreeSystem(arm, servo(arm) + CubicSpline(knots, duration=steps * DT))
    T = steps * DT
    sol = simulate(system, RK4(), jnp.asarray(Q_REF), jnp.zeros(arm.nv), dt=DT, t1=T, saveat=[T])
    miss = flange(arm, sol.qs[-1]) - flange(arm, jnp.asarray(Q_REF)) - jnp.asarray(TARGET_OFFSET)
    return 1e4 * miss @ miss + 1e-3 * jnp.sum(knots**2)


def _reach_running(q, v, u, *, arm, target, q0, gravity):
    return jnp.sqrt(2.0) * jnp.concatenate([0.1 * (flange(arm, q) - target), 1e-2 * (q - q0),
                                            1e-2 * v, 1e-2 * (u - gravity)])


def _reach_terminal(q, v, *, arm, target):
    return jnp.sqrt(2.0) * jnp.concatenate([100.0 * (flange(arm, q) - target), v])


def reach_target(arm: Model, offset=REACH) -> Array:
    """Where the reach takes the flange: `offset` from its place at Q_REF.

    Args:
        arm: the arm's model.
        offset: the displacement in the world frame, shape (3,) [m].

    Returns:
        The target [m], shape (3,).
    """
    return flange(arm, jnp.asarray(Q_REF)) + jnp.asarray(offset, dtype=float)


def reach_problem(offset=REACH, steps: int = REACH_STEPS, arm: Model | None = None,
                  integrator=RK4()) -> Problem:
    """The arm-reach trajectory-optimisation problem.

    The arm from rest at Q_REF, unpowered but for the controls, to its flange moved by
    `offset` at rest after `steps` steps of REACH_DT (`integrator`, torques held over each
    step). Least-squares residuals (1/2 |r|^2 is the cost) weighted as Crocoddyl's arm examples
    weight theirs: along the way the reach (0.1) and small state and control regularizations
    (1e-2, the controls about the torque that holds Q_REF); at the end the reach (100) and the
    velocity (1). The costs are `eqx.Partial`s of module-level functions, so problems for other
    targets or models share one compiled `solve`. `hold(problem)` is a good first guess.

    Args:
        offset: the reach in the world frame, shape (3,) [m].
        steps: the horizon in steps of REACH_DT.
        arm: the model; None for `model()`.
        integrator: the integrator of each step.

    Returns:
        The `mbjax.trajopt.Problem`, its controls the seven joint torques.
    """
    arm = model() if arm is None else arm
    q0, v0 = jnp.asarray(Q_REF), jnp.zeros(arm.nv)
    target = reach_target(arm, offset)
    gravity = inverse_dynamics(arm, q0, v0, v0)
    return Problem(TreeSystem(arm), q0, v0, dt=REACH_DT, horizon=steps,
                   running=eqx.Partial(_reach_running, arm=arm, target=target, q0=q0,
                                       gravity=gravity),
                   terminal=eqx.Partial(_reach_terminal, arm=arm, target=target),
                   integrator=integrator)


def hold(problem: Problem) -> Array:
    """Controls that hold the start pose against gravity: a first guess for `reach_problem`.

    Args:
        problem: the reach problem.

    Returns:
        The gravity torque at the start, repeated, shape (horizon, nv) [N m].
    """
    arm = problem.system.model
    return jnp.tile(inverse_dynamics(arm, problem.q0, problem.v0, problem.v0),
                    (problem.horizon, 1))
