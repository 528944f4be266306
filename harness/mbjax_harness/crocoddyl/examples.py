"""Crocoddyl's contact-free examples (its repository's `examples/`), each built twice: as an
`mbjax.trajopt.Problem` and as Crocoddyl's shooting problem, from the same example-robot-data
URDF, residuals, weights, horizon, step (semi-implicit Euler: Crocoddyl's
`IntegratedActionModelEuler`) and first guess.

    kinova-reach        `arm_manipulation_fwddyn.py`: the Kinova arm's gripper to a placement
                        (its continuous joints regularised through `difference`)
    double-pendulum     `double_pendulum_fwddyn.py`: swing-up, the shoulder alone actuated
    quadrotor           `quadrotor_fwddyn.py`: the hector quadrotor (a free base) to a
                        placement, four thrusters through an actuation matrix
    quadrotor-bounded   `quadrotor_ubound.py`: the same with thrusts in [0.1, 5] N (Crocoddyl's
                        BoxDDP)

The URDF's joint damping, which Pinocchio reads but its forward dynamics do not apply, is set
to zero on the mbjax side (the double pendulum's 0.05 N m s). Each starts from Crocoddyl's own
first guess where it has none: the quasi-static controls that hold x0 (zero for the pendulum). Crocoddyl's weights multiply 1/2 |r|^2 (a weighted-quadratic activation per component); mbjax
folds each into its residual as sqrt(weight) (`mbjax.trajopt.state_residual` and friends). The
mbjax problems are written as a user would, in mbjax's layout (a free joint's q = (position,
quaternion wxyz), v = (omega; v) in the body frame); `to_crocoddyl` converts states.
"""

from dataclasses import dataclass
from typing import Callable

import equinox as eqx
import jax.numpy as jnp
import numpy as np

from mbjax import load_urdf
from mbjax.model import Model
from mbjax.integrate import SemiImplicitEuler
from mbjax.model import state_from_pinocchio, state_to_pinocchio
from mbjax.rigid import TreeSystem, inverse_dynamics
from mbjax.trajopt import Problem, control_residual, frame_residual, state_residual


@dataclass
class Example:
    """One example in both libraries."""

    problem: Problem            # mbjax's
    us0: np.ndarray             # the common first guess, (horizon, nu)
    crocoddyl: Callable         # () -> Crocoddyl's ShootingProblem
    solver: str                 # Crocoddyl's solver: "SolverFDDP" or "SolverBoxDDP"
    to_crocoddyl: Callable      # mbjax states (N + 1, nx) -> Crocoddyl's (N + 1, nx_pin)
    final_error: Callable | None = None     # mbjax q -> the task's remaining error [m]
    # Crocoddyl's problem -> (mbjax controls (N, nu) -> Crocoddyl's list, an impulse's empty)
    controls: Callable | None = None
    # the first guess's states, (N + 1, nx), where the example starts infeasible (Crocoddyl's
    # xs); None for the rollout of us0
    states0: np.ndarray | None = None


def _robot(name: str):
    import example_robot_data

    return example_robot_data.load(name)


def _load(robot, **kwargs):
    """The robot's URDF in mbjax without joint damping: Pinocchio reads it, but its forward
    dynamics, and so Crocoddyl's, do not apply it."""
    model = load_urdf(robot.urdf, **kwargs)
    return eqx.tree_at(lambda m: m.damping, model, jnp.zeros(model.nv))


def _converter(model):
    def convert(xs):
        qs, vs = np.asarray(xs)[:, :model.nq], np.asarray(xs)[:, model.nq:]
        return np.array([np.concatenate([np.asarray(a) for a in state_to_pinocchio(model, q, v)])
                         for q, v in zip(qs, vs, strict=True)])
    return convert


def kinova_reach() -> Example:
    robot = _robot("kinova")
    model = _load(robot)
    q_pin0 = robot.model.referenceConfigurations["arm_up"]
    q0, v0 = state_from_pinocchio(model, q_pin0, np.zeros(robot.model.nv))
    frame, target = "j2s6s200_end_effector", np.array([0.6, 0.2, 0.5])
    nu = model.nv
    running = (frame_residual(model, frame, target, np.eye(3), weight=1.0),
               state_residual(model, q0, weight=0.1), control_residual(nu, weight=0.1))
    terminal = frame_residual(model, frame, target, np.eye(3), weight=1e3)
    problem = Problem(TreeSystem(model), q0, v0, dt=1e-2, horizon=100, running=running,
                      terminal=terminal, integrator=SemiImplicitEuler())

    def crocoddyl():
        import crocoddyl as croc
        import pinocchio as pin

        from mbjax_harness.crocoddyl.terms import _crocoddyl_shooting

        state = croc.StateMultibody(robot.model)
        actuation = croc.ActuationModelFull(state)
        x0 = np.concatenate([q_pin0, np.zeros(robot.model.nv)])
        placement = croc.ResidualModelFramePlacement(
            state, robot.model.getFrameId(frame), pin.SE3(np.eye(3), target), nu)
        running = [("gripperPose", placement, None, 1.0),
                   ("xReg", croc.ResidualModelState(state, x0, nu), None, 0.1),
                   ("uReg", croc.ResidualModelControl(state, nu), None, 0.1)]
        return _crocoddyl_shooting(state, actuation, x0, 1e-2, 100, running,
                                   [("gripperPose", placement, None, 1e3)])

    # Crocoddyl's first guess without one: the quasi-static torques, which hold x0
    hold = inverse_dynamics(model, q0, jnp.zeros(nu), jnp.zeros(nu))
    return Example(problem, np.tile(np.asarray(hold), (100, 1)), crocoddyl, "SolverFDDP",
                   _converter(model))


def double_pendulum() -> Example:
    robot = _robot("double_pendulum")
    model = _load(robot)
    dt, horizon = 1e-2, 100
    q0 = jnp.array([3.14, 0.0])
    shoulder = np.array([[1.0], [0.0]])                 # actLink=1: the first joint's torque
    problem = Problem(TreeSystem(model, actuation=shoulder), q0, jnp.zeros(2), dt=dt,
                      horizon=horizon,
                      running=(control_residual(1, weight=1e-4 / dt), Upright(1e-5 / dt)),
                      terminal=Upright(100.0), integrator=SemiImplicitEuler())

    def crocoddyl():
        import crocoddyl as croc
        from crocoddyl.utils.pendulum import ActuationModelDoublePendulum, CostModelDoublePendulum

        state = croc.StateMultibody(robot.model)
        actuation = ActuationModelDoublePendulum(state, actLink=1)
        activation = croc.ActivationModelWeightedQuad(np.array([1.0] * 4 + [0.1] * 2))

        def costs(terms):
            c = croc.CostModelSum(state, 1)
            for name, cost, weight in terms:
                c.addCost(name, cost, weight)
            return c

        def action(terms, step):
            return croc.IntegratedActionModelEuler(croc.DifferentialActionModelFreeFwdDynamics(
                state, actuation, costs(terms)), step)

        u_reg = croc.CostModelResidual(state, croc.ResidualModelControl(state, 1))
        pend = CostModelDoublePendulum(state, activation, 1)
        x0 = np.array([3.14, 0.0, 0.0, 0.0])
        return croc.ShootingProblem(
            x0, [action([("uReg", u_reg, 1e-4 / dt), ("xGoal", pend, 1e-5 / dt)], dt)] * horizon,
            action([("xGoal", pend, 100.0)], dt))

    return Example(problem, np.zeros((horizon, 1)), crocoddyl, "SolverFDDP", _converter(model))


class Upright(eqx.Module):
    """Crocoddyl's `CostModelDoublePendulum` as residuals: (sin q, 1 - cos q, v), weighted
    (1, 1, 1, 1, 0.1, 0.1) and by `weight`."""

    weight: float

    def __call__(self, q, v, u=None):
        w = jnp.sqrt(self.weight * jnp.array([1.0] * 4 + [0.1] * 2))
        return w * jnp.concatenate([jnp.sin(q), 1.0 - jnp.cos(q), v])


# Crocoddyl's quadrotor example: thrusters at d_cog along the body's x and y axes, thrust along
# the body's z, rotor torque cm / cf per unit thrust, spinning CCW (-1) and CW (+1) in turn
D_COG, CF, CM = 0.1525, 6.6e-5, 1e-6
THRUSTERS = ((D_COG, 0.0, -1.0), (0.0, D_COG, 1.0), (-D_COG, 0.0, -1.0), (0.0, -D_COG, 1.0))
TARGET = np.array([1.0, 0.0, 1.0])


def thruster_matrix() -> np.ndarray:
    """The (6, 4) actuation matrix of the four thrusters on a free joint, in mbjax's order
    (body torque; body force): thrust u_i along z at (x_i, y_i, 0) gives the force u_i z and the
    torque (p_i x z) u_i +- (cm / cf) z u_i (CW: plus, CCW: minus, as Crocoddyl's
    `ActuationModelFloatingBaseThrusters`)."""
    z = np.array([0.0, 0.0, 1.0])
    columns = [np.concatenate([np.cross([x, y, 0.0], z) + spin * CM / CF * z, z])
               for x, y, spin in THRUSTERS]
    return np.stack(columns, 1)


def hector() -> Model:
    """The hector quadrotor as a free body, from its URDF's inertial data (example-robot-data's
    `hector_description`: 1.477 kg, inertia diag(0.01152, 0.01152, 0.0218) kg m^2), for where
    example-robot-data is not installed."""
    return Model([-1], "free", mass=[1.477], inertia=[np.diag([0.01152, 0.01152, 0.0218])],
                 names=["base_link"], joint_names=["root_joint"])


def quadrotor_problem(model: Model, bounded: bool = False) -> tuple[Problem, np.ndarray]:
    """Crocoddyl's quadrotor problem in mbjax for a free-floating `model` (its body
    "base_link"), and its first guess, the hover thrust."""
    dt, horizon = 3e-2, 33
    # Crocoddyl's state weights, (v, omega) of the configuration's tangent then of the velocity,
    # in mbjax's (omega, v) order
    weights = np.r_[[1000.0] * 3, [0.1] * 3, [1000.0] * 6]
    running = (state_residual(model, model.neutral(), weight=1e-6 * weights),
               control_residual(4, weight=1e-6),
               frame_residual(model, "base_link", TARGET, np.eye(3), weight=1e-2))
    terminal = frame_residual(model, "base_link", TARGET, np.eye(3), weight=3.0)
    lower, upper = (0.1, 5.0) if bounded else (None, None)
    problem = Problem(TreeSystem(model, actuation=thruster_matrix()), model.neutral(),
                      jnp.zeros(6), dt=dt, horizon=horizon, running=running, terminal=terminal,
                      lower=lower, upper=upper, integrator=SemiImplicitEuler())
    hover = float(-model.gravity[2] * np.sum(np.asarray(model.mass))) / 4
    return problem, np.full((horizon, 4), hover)


def quadrotor(bounded: bool = False) -> Example:
    robot = _robot("hector")
    model = _load(robot, floating_base=True)
    problem, us0 = quadrotor_problem(model, bounded)

    def crocoddyl():
        import crocoddyl as croc
        import pinocchio as pin

        from mbjax_harness.crocoddyl.terms import _crocoddyl_shooting

        state = croc.StateMultibody(robot.model)
        kinds = {-1.0: croc.ThrusterType.CCW, 1.0: croc.ThrusterType.CW}
        actuation = croc.ActuationModelFloatingBaseThrusters(state, [
            croc.Thruster(pin.SE3(np.eye(3), np.array([x, y, 0.0])), CM / CF, kinds[spin])
            for x, y, spin in THRUSTERS])
        pose = croc.ResidualModelFramePlacement(state, robot.model.getFrameId("base_link"),
                                                pin.SE3(np.eye(3), TARGET), 4)
        running = [("xReg", croc.ResidualModelState(state, state.zero(), 4),
                    np.r_[[0.1] * 3, [1000.0] * 3, [1000.0] * 6], 1e-6),
                   ("uReg", croc.ResidualModelControl(state, 4), None, 1e-6),
                   ("trackPose", pose, None, 1e-2)]
        x0 = np.concatenate([robot.q0, np.zeros(6)])
        return _crocoddyl_shooting(state, actuation, x0, problem.dt, problem.horizon, running,
                                   [("goalPose", pose, None, 3.0)],
                                   bounds=(0.1, 5.0) if bounded else None)

    return Example(problem, us0, crocoddyl, "SolverBoxDDP" if bounded else "SolverFDDP",
                   _converter(model))


EXAMPLES = {"kinova-reach": kinova_reach, "double-pendulum": double_pendulum,
            "quadrotor": quadrotor, "quadrotor-bounded": lambda: quadrotor(bounded=True)}
