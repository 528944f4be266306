"""A 7-dof arm from a URDF (`mbjax.data.ARM7`) under controls and forces: held in a pose by a PD
servo with the gravity torque there as feed-forward, driven by a torque spline, pushed at its
flange, and sampled the way MuJoCo applies a control (a zero-order hold per step).

`build()` gives the servoed arm; `reach_loss` is the rollout loss whose gradient with respect to
the spline's knots and a link mass the tour, the tests and notebook 09 take; `reach_problem` is
the arm-reach trajectory-optimisation problem (`mbjax.trajopt`); `tracking_controller` is a
model-predictive controller whose flange follows a circle (`Tracking`, `first_plan`), and
`tracking_plant` the arm it drives, with a payload and a push it does not know of.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.control import PD, AbstractControl, CubicSpline
from mbjax.data import ARM7
from mbjax._src.integrate import RK4, SemiImplicitEuler, simulate
from mbjax._src.model import Model
from mbjax._src.model.urdf import load_urdf
from mbjax._src.rigid import TreeSystem, forward_kinematics, inverse_dynamics, mass_matrix
from mbjax._src.trajopt import ILQR, Problem
from mbjax._src.trajopt.ilqr import CROCODDYL_SCHEDULE
from mbjax._src.trajopt.knots import Knot
from mbjax._src.trajopt.mpc import MPC, Plan

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
    """A world force on the last body (at the system's `external_point`) from `start` for
    `duration`.

    An `external=` load: called as (t, q, v), it returns wrenches (n_bodies, 6).

    Args:
        force: the force in the world frame, shape (3,) [N].
        n_bodies: the model's number of bodies.
        duration: how long the push lasts [s].
        start: when it starts [s].
    """

    force: Array
    n_bodies: int = eqx.field(static=True)
    duration: float = eqx.field(static=True)
    start: float = eqx.field(static=True, default=0.0)

    def __call__(self, t, q, v):
        on = ((t >= self.start) & (t < self.start + self.duration)).astype(self.force.dtype)
        return jnp.zeros((self.n_bodies, 6), self.force.dtype).at[-1, 3:].set(on * self.force)


def pushed(arm: Model, force=(30.0, 0.0, 0.0), duration: float = 0.1, start: float = 0.0,
           control: AbstractControl | None = None) -> TreeSystem:
    """The arm pushed at its flange, by default under its servo.

    Args:
        arm: the arm's model.
        force: the push in the world frame, shape (3,) [N].
        duration: how long the push lasts [s].
        start: when it starts [s].
        control: the arm's control; None for `servo(arm)`.

    Returns:
        The `TreeSystem` with the control and the push as external load.
    """
    points = jnp.zeros((arm.n, 3)).at[-1].set(jnp.asarray(FLANGE))
    control = servo(arm) if control is None else control
    return TreeSystem(arm, control, external=Push(jnp.asarray(force, float), arm.n, duration,
                                                  start), external_point=points)


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


# model-predictive tracking: the flange follows a circle under a receding-horizon controller
TRACK_RADIUS, TRACK_PERIOD = 0.1, 2.0          # [m], [s]: the circle, in the y-z plane
MPC_DT, MPC_HORIZON = 0.01, 50                 # 100 Hz ticks, a 0.5 s horizon
PLANT_DT = 1e-3                                # [s]: the plant's RK4 step
# Crocoddyl's weights w (cost w/2 |r|^2): the goal, the state's and the control's
# regularization along the way; the goal and the velocity at the horizon's end
TRACK_WEIGHTS = (100.0, 1e-2, 1e-4, 1e3, 1.0)


def track_target(centre: Array, t) -> Array:
    """The moving target at time t: a circle of TRACK_RADIUS in the y-z plane through
    `centre` (where it starts), one turn in TRACK_PERIOD.

    Args:
        centre: the start [m], shape (3,).
        t: the time [s], any shape.

    Returns:
        The target [m], shape t.shape + (3,).
    """
    phase = 2 * jnp.pi * jnp.asarray(t) / TRACK_PERIOD
    return centre + TRACK_RADIUS * jnp.stack([jnp.zeros_like(phase), jnp.sin(phase),
                                              1.0 - jnp.cos(phase)], axis=-1)


def _track_running(q, v, u, *, arm, target, q_ref, gravity, weights):
    w = jnp.sqrt(weights)
    return jnp.concatenate([w[0] * (flange(arm, q) - target), w[1] * (q - q_ref), w[1] * v,
                            w[2] * (u - gravity)])


def _track_terminal(q, v, *, arm, target, weights):
    w = jnp.sqrt(weights)
    return jnp.concatenate([w[3] * (flange(arm, q) - target), w[4] * v])


class Tracking(eqx.Module):
    """The arm's tracking problem over a receding horizon, `MPC`'s problem(t, q, v): the flange
    follows the circle `track_target(centre, .)` at each knot t + k MPC_DT of the horizon, with
    Crocoddyl's residual costs weighted by `weights` (TRACK_WEIGHTS's order; differentiable), and
    semi-implicit Euler steps (Crocoddyl's). The knots differ only in their targets: one phase.

    Args:
        arm: the controller's model of the arm.
        centre: the circle's start [m], shape (3,); None for the flange's place at Q_REF.
        weights: the five weights, shape (5,); None for TRACK_WEIGHTS.
        horizon: the knots of the horizon (static).
    """

    arm: Model
    centre: Array
    weights: Array
    horizon: int = eqx.field(static=True)

    def __init__(self, arm: Model, centre=None, weights=None, horizon: int = MPC_HORIZON):
        self.arm = arm
        self.centre = (flange(arm, jnp.asarray(Q_REF)) if centre is None
                       else jnp.asarray(centre, float))
        self.weights = jnp.asarray(TRACK_WEIGHTS if weights is None else weights, float)
        self.horizon = horizon

    def __call__(self, t, q, v) -> Problem:
        q_ref = jnp.asarray(Q_REF)
        zero = jnp.zeros(self.arm.nv)
        gravity = inverse_dynamics(self.arm, q_ref, zero, zero)
        targets = track_target(self.centre, t + MPC_DT * jnp.arange(self.horizon + 1))
        system = TreeSystem(self.arm)
        knots = [Knot(system, eqx.Partial(_track_running, arm=self.arm, target=targets[k],
                                          q_ref=q_ref, gravity=gravity, weights=self.weights))
                 for k in range(self.horizon)]
        return Problem(knots, q, v, dt=MPC_DT, integrator=SemiImplicitEuler(),
                       terminal=eqx.Partial(_track_terminal, arm=self.arm,
                                            target=targets[-1], weights=self.weights))


def tracking_controller(arm: Model | None = None, centre=None, weights=None,
                        horizon: int = MPC_HORIZON, solver=None) -> MPC:
    """The arm's model-predictive controller: `Tracking`'s horizon re-solved at 100 Hz, one
    FDDP iteration a tick by default.

    Args:
        arm: the controller's model; None for `model()`.
        centre: the circle's start [m]; None for the flange's place at Q_REF.
        weights: the cost weights (TRACK_WEIGHTS's order); None for TRACK_WEIGHTS.
        horizon: the knots of the horizon.
        solver: the solver of a tick; None for `MPC`'s default.

    Returns:
        The `mbjax.trajopt.MPC`.
    """
    arm = model() if arm is None else arm
    return MPC(Tracking(arm, centre, weights, horizon), solver)


@eqx.filter_jit
def first_plan(controller: MPC) -> Plan:
    """The controller's first plan from rest at Q_REF: its horizon solved to convergence
    (Crocoddyl's schedule) from the torques that hold the pose, in one compiled program.

    Args:
        controller: from `tracking_controller`.

    Returns:
        The `Plan` to start `closed_loop` from.
    """
    arm = controller.problem.arm
    q0, v0 = jnp.asarray(Q_REF), jnp.zeros(arm.nv)
    hold_torque = inverse_dynamics(arm, q0, v0, v0)
    return controller.init(0.0, q0, v0, jnp.tile(hold_torque, (controller.problem.horizon, 1)),
                           solver=ILQR(**CROCODDYL_SCHEDULE))


def tracking_plant(arm: Model | None = None, payload=0.0, force=(0.0, 30.0, 0.0),
                   start: float = 1.0, duration: float = 0.1) -> TreeSystem:
    """The arm the tracking controller drives: a payload at its flange the controller does not
    know of, and a push at the flange.

    Args:
        arm: the arm's model; None for `model()`.
        payload: the mass at the flange [kg].
        force: the push in the world frame [N].
        start: when the push starts [s].
        duration: how long it lasts [s].

    Returns:
        The plant, a `TreeSystem` (its control is replaced by the controller's).
    """
    arm = model() if arm is None else arm
    arm = arm.with_payload(payload, body=arm.n - 1, point=FLANGE)
    return pushed(arm, force, duration, start)


def tracking_error(arm: Model, centre: Array, ts: Array, qs: Array) -> Array:
    """The flange's distance to the target at each time.

    Args:
        arm: the arm's model.
        centre: the circle's start [m], shape (3,).
        ts: times [s], shape (n,).
        qs: configurations, shape (n, 7).

    Returns:
        The distances [m], shape (n,).
    """
    flanges = jax.vmap(lambda q: flange(arm, q))(qs)
    return jnp.linalg.norm(flanges - track_target(centre, ts), axis=1)
