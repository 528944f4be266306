"""Crocoddyl's legged examples, each built twice from the same example-robot-data URDF, contact
schedule, weights, step (semi-implicit Euler) and first guess (the quasi-static controls): as a
multi-phase `mbjax.trajopt.Problem` of `Knot`s and `Impulse`s, and as Crocoddyl's shooting
problem from its own builder.

    anymal-walk     `examples/quadrupedal_gaits_fwddyn.py`'s walk: ANYmal, one cycle of
                    `SimpleQuadrupedalGaitProblem.createWalkingProblem` (step 0.25 m, height
                    0.15 m, dt 1e-2 s, 25 knots a step, 2 of double support): 108 knots
    anymal-trot     its trot (`createTrottingProblem`, the same defaults): the diagonal pairs
                    step in turn, 56 knots (the tour's scene, shorter)
    talos-step      `examples/bipedal_gaits_fwddyn.py`'s walk: Talos's legs (its upper body
                    locked at half-sitting in both libraries), one step of each foot,
                    `SimpleBipedGaitProblem.createWalkingProblem` (step
                    0.6 m, height 0.1 m, dt 3e-2 s, 15 knots a step, 4 of double support):
                    39 knots and the left foot's impulse model as the terminal cost

The mbjax side is `mbjax.gaits` (its `Gait`, `walk`, `trot` and `jump`). Both sides write
Crocoddyl's costs term by term (`mbjax_harness.crocoddyl.examples` says how
weights fold into residuals): its state and control regularisation, centre-of-mass and swing-foot
tracking, friction cones with its quadratic barrier, the state bounds' barrier; an impulse
knot's costs are not weighted by dt, as Crocoddyl's impulse models' are not.
"""

import equinox as eqx
import jax.numpy as jnp
import numpy as np

from mbjax.gaits import BIPED, QUADRUPED, Gait, jump, trot, walk
from mbjax.loops import Coupled
from mbjax.model import state_from_pinocchio
from mbjax.trajopt import quasi_static
from mbjax_harness.crocoddyl.examples import Example, _converter, _load, _robot

MU = 0.7                     # the examples' friction coefficient
FEET = ("LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT")
SOLES = ("right_sole_link", "left_sole_link")
SOLE = (0.1, 0.05)           # the biped's sole, length and width [m] (its wrench cone's box)


def _controls(croc_problem):
    """mbjax's controls (N, nu) as Crocoddyl's list: an impulse model takes none."""
    sizes = [m.nu for m in croc_problem.runningModels]
    return lambda us: [np.asarray(u, float)[:n] for u, n in zip(us, sizes, strict=True)]


def _start(robot, configuration, locked=()):
    """mbjax's model (the `locked` joints fixed at the configuration) and its standing state, as
    the builders start from it: (model, q_pin0, q0, v0)."""
    model = _load(robot, floating_base=True)
    q_pin0 = robot.model.referenceConfigurations[configuration].copy()
    q0, v0 = state_from_pinocchio(model, q_pin0, np.zeros(robot.model.nv))
    if locked:
        model = model.locked(locked, q0)
        q_pin0 = q_pin0[:model.nq]                   # the legs come first in Pinocchio's order
        q0, v0 = state_from_pinocchio(model, q_pin0, np.zeros(model.nv))
    # the rotors' inertias, which example-robot-data reads from the SRDF into Pinocchio's
    # model (0.1 kg m^2 on each of Talos's leg joints) and a URDF does not hold
    armature = np.asarray(robot.model.armature)[:model.nv]
    model = eqx.tree_at(lambda m: m.armature, model, jnp.asarray(armature))
    return model, q_pin0, q0, v0


def _talos_legs(robot):
    """Talos with its upper body locked at half-sitting, in Pinocchio (`buildReducedModel`):
    the legs its only joints, as mbjax's `Model.locked` makes it. (example-robot-data's
    `talos_legs` drops the upper body's mass instead, which no URDF describes.)"""
    import pinocchio as pin

    full = robot.model
    upper = [n for n in full.names[2:] if not n.startswith("leg_")]
    q = full.referenceConfigurations["half_sitting"]
    legs = pin.buildReducedModel(full, [full.getJointId(n) for n in upper], q)
    legs.referenceConfigurations["half_sitting"] = q[:legs.nq].copy()
    return legs, upper


def _anymal_start():
    """ANYmal standing as `SimpleQuadrupedalGaitProblem` starts it, and its `Gait` (the
    builder's state weights, its joint and velocity bounds): (robot, model, q_pin0, gait)."""
    robot = _robot("anymal")
    model, q_pin0, q0, _ = _start(robot, "standing")
    nj = model.nv - 6
    lower = np.r_[[-np.inf] * 6, [-9.42] * nj, [-np.inf] * 6, [-15.0] * nj]
    gait = Gait(model, q0, FEET, mu=MU, weights=QUADRUPED, bounds=(lower, -lower))
    return robot, model, q_pin0, gait


def _example(model, problem, crocoddyl, states0=None) -> Example:
    return Example(problem, np.asarray(quasi_static(problem)), crocoddyl, "SolverFDDP",
                   _converter(model), controls=_controls, states0=states0)


def _anymal(schedule, builder: str, *args) -> Example:
    """ANYmal's gait `schedule(gait, *args)` (`mbjax.gaits`), with `SimpleQuadrupedalGaitProblem`'s
    `builder` of the same arguments as Crocoddyl's."""
    robot, model, q_pin0, gait = _anymal_start()

    def crocoddyl():
        from crocoddyl.utils.quadruped import SimpleQuadrupedalGaitProblem

        x0 = np.concatenate([q_pin0, np.zeros(robot.model.nv)])
        return getattr(SimpleQuadrupedalGaitProblem(robot.model, *FEET), builder)(x0, *args)

    return _example(model, schedule(gait, *args), crocoddyl)


def anymal_walk(step_length=0.25, step_height=0.15, dt=1e-2, step_knots=25,
                support_knots=2) -> Example:
    """Crocoddyl's walk: each foot steps in turn, RH, RF, LH, LF, the first two half steps."""
    return _anymal(walk, "createWalkingProblem", step_length, step_height, dt, step_knots,
                   support_knots)


def anymal_trot(step_length=0.25, step_height=0.15, dt=1e-2, step_knots=25,
                support_knots=2) -> Example:
    """Crocoddyl's trot (`createTrottingProblem`): the diagonal pairs RF-LH (a half step) and
    LF-RH step in turn."""
    return _anymal(trot, "createTrottingProblem", step_length, step_height, dt, step_knots,
                   support_knots)


def anymal_jump(jump_height=0.15, jump_length=(0.0, 0.3, 0.0), dt=1e-2, ground_knots=10,
                flying_knots=20) -> Example:
    """Crocoddyl's jump (`createJumpingProblem`, its example's parameters). Its `states0` is the
    example's infeasible start, x0 at every knot."""
    robot, model, q_pin0, gait = _anymal_start()
    problem = jump(gait, jump_height, jump_length, dt, ground_knots, flying_knots)

    def crocoddyl():
        from crocoddyl.utils.quadruped import SimpleQuadrupedalGaitProblem

        x0 = np.concatenate([q_pin0, np.zeros(robot.model.nv)])
        return SimpleQuadrupedalGaitProblem(robot.model, *FEET).createJumpingProblem(
            x0, jump_height, list(jump_length), dt, ground_knots, flying_knots)

    states0 = np.tile(np.asarray(problem.x0), (problem.horizon + 1, 1))
    return _example(model, problem, crocoddyl, states0)


def talos_step(step_length=0.6, step_height=0.1, dt=3e-2, step_knots=15,
               support_knots=4) -> Example:
    """Crocoddyl's biped walk: Talos's legs (its upper body locked at half-sitting in both
    libraries), a half step of the right foot, then a step of the left."""
    robot = _robot("talos")
    pin_model, upper = _talos_legs(robot)
    model, q_pin0, q0, _ = _start(robot, "half_sitting", upper)
    # `SimpleBipedGaitProblem`: spatial soles (ContactModel6D), Baumgarte Kd 30
    gait = Gait(model, q0, SOLES, sole=SOLE, mu=MU, weights=BIPED,
                method=Coupled(baumgarte=(15.0, 0.0)), impulse_tracking=1e8)

    def crocoddyl():
        from crocoddyl.utils.biped import SimpleBipedGaitProblem

        builder = SimpleBipedGaitProblem(pin_model, *SOLES)
        x0 = np.concatenate([q_pin0, np.zeros(pin_model.nv)])
        return builder.createWalkingProblem(x0, step_length, step_height, dt, step_knots,
                                            support_knots)

    problem = walk(gait, step_length, step_height, dt, step_knots, support_knots)
    return _example(model, problem, crocoddyl)


GAITS = {"anymal-walk": anymal_walk, "talos-step": talos_step, "anymal-jump": anymal_jump}
