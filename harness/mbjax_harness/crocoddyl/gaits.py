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

Both sides write Crocoddyl's costs term by term (`mbjax_harness.crocoddyl.examples` says how
weights fold into residuals): its state and control regularisation, centre-of-mass and swing-foot
tracking, friction cones with its quadratic barrier, the state bounds' barrier; an impulse
knot's costs are not weighted by dt, as Crocoddyl's impulse models' are not.
"""

from functools import partial

import equinox as eqx
import jax.numpy as jnp
import numpy as np

from mbjax.contact import PointContact, SurfaceContact, stance
from mbjax.loops import Coupled
from mbjax.integrate import SemiImplicitEuler
from mbjax.model import state_from_pinocchio
from mbjax.rigid import TreeSystem, center_of_mass, frame_pose
from mbjax.trajopt import (Impulse, Knot, Problem, barrier_residual, com_residual,
                           control_residual, frame_residual, friction_cone_residual,
                           quasi_static, state_residual, wrench_cone_residual)
from mbjax_harness.crocoddyl.examples import Example, _converter, _load, _robot

MU = 0.7                     # the examples' friction coefficient
FEET = ("LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT")
SOLES = ("right_sole_link", "left_sole_link")
SOLE = (0.1, 0.05)           # the biped's sole, length and width [m] (its wrench cone's box)


def _controls(croc_problem):
    """mbjax's controls (N, nu) as Crocoddyl's list: an impulse model takes none."""
    sizes = [m.nu for m in croc_problem.runningModels]
    return lambda us: [np.asarray(u, float)[:n] for u, n in zip(us, sizes, strict=True)]


class _Gait:
    """The pieces of Crocoddyl's gait builders in mbjax: its models' costs, knot by knot.

    Every knot is written over all the feet, so that the gait is two phases, whatever its
    schedule (`mbjax.trajopt.Problem` compiles each distinct phase once): each stance holds the
    support feet and has the others in the air (`active=False`), and a task that Crocoddyl's
    model of that knot lacks (the CoM of a double support, a foot not swinging) is there with
    the weight 0, which adds nothing to the cost.

    Args:
        model, q0: the robot and its standing configuration (the state costs' reference).
        kind: `PointContact` (a quadruped's feet: friction cones, translations tracked) or
            `SurfaceContact` (a biped's soles: wrench cones, placements tracked; spatial, as
            Crocoddyl's `ContactModel6D`).
        feet: the feet's frames and their positions at q0, a dict.
        weights: the state weights of a step's knot and of an impulse's, mbjax's tangent order.
        bounds: (lower, upper) of the state barrier, or None.
        gain: the contacts' Baumgarte Kd (Crocoddyl's (0, Kd)).
        impulse_track: the weight of an impulse's foot tracking.
    """

    def __init__(self, model, q0, kind, feet, weights, bounds, gain, impulse_track):
        self.model, self.q0, self.kind, self.feet = model, q0, kind, dict(feet)
        self.tree = TreeSystem(model, actuation=range(6, model.nv))
        self.nu = model.nv - 6
        self.state_weights, self.impulse_weights = weights
        self.method = Coupled(baumgarte=(gain / 2, 0.0))
        self.impulse_track = impulse_track
        self.bounds = () if bounds is None else (barrier_residual(
            state_residual(model, model.neutral()), *bounds, weight=1e3),)

    def regularisation(self, weights):
        return state_residual(self.model, self.q0, weight=10.0 * np.asarray(weights) ** 2)

    def contacts(self, down):
        """Every foot, those in `down` on the ground and the others in the air."""
        return [self.kind(f, active=f in down) for f in self.feet]

    def tracks(self, swing, weight):
        """`createSwingFootModel`'s foot tasks: each foot of `swing` (pairs (frame, target))
        tracked with `weight`, the others with 0."""
        rotation = None if self.kind is PointContact else np.eye(3)
        targets = dict(swing)
        return [frame_residual(self.model, f, targets.get(f, p), rotation,
                               weight=weight if f in targets else 0.0)
                for f, p in self.feet.items()]

    def knot(self, support, com=None, swing=()):
        """`createSwingFootModel`: the support feet held, the swing feet and CoM tracked."""
        contacts = self.contacts(support)
        phase = stance(self.tree, self.q0, contacts, method=self.method)
        costs = [friction_cone_residual(phase, MU, weight=10.0)
                 if self.kind is PointContact else
                 wrench_cone_residual(phase, MU, *SOLE, weight=10.0),
                 com_residual(self.model, np.zeros(3) if com is None else com,
                              weight=0.0 if com is None else 1e6),
                 *self.tracks(swing, 1e6), self.regularisation(self.state_weights),
                 control_residual(self.nu, weight=0.1), *self.bounds]
        return Knot(phase, tuple(costs))

    def impulse_costs(self, swing):
        return (*self.tracks(swing, self.impulse_track), self.regularisation(self.impulse_weights))

    def impulse(self, landing, swing):
        """`createImpulseModel`: the landing feet stopped, still tracked."""
        return Impulse(self.model, self.contacts(landing), self.impulse_costs(swing))

    def footsteps(self, com, feet, length, height, knots, support, swing):
        """`createFootstepModels`: a step's knots, then its impulse; com and feet move on.
        Returns the knots and the last swing task."""
        out, fraction, half = [], len(swing) / (len(support) + len(swing)), knots / 2
        for k in range(knots):
            z = height * k / half if k < half else height * (1 - (k - half) / half)
            dp = np.array([length * (k + 1) / knots, 0.0, z])
            task = [(f, feet[f] + dp) for f in swing]
            out.append(self.knot(support, com + np.array([length * (k + 1) / knots, 0, 0])
                                 * fraction, task))
        out.append(self.impulse(swing, task))
        com += np.array([length * fraction, 0.0, 0.0])
        for f in swing:
            feet[f] = feet[f] + np.array([length, 0.0, 0.0])
        return out, task


def _start(robot, configuration, feet, locked=()):
    """mbjax's model (the `locked` joints fixed at the configuration), its standing state, the
    feet's positions and the gait's CoM reference (the feet's mean at the CoM's height), as the
    builders compute them."""
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
    positions = {f: np.asarray(frame_pose(model, q0, f)[1]) for f in feet}
    com = np.mean([positions[f] for f in feet], axis=0)
    com[2] = float(center_of_mass(model, q0)[2])
    return model, q_pin0, q0, v0, positions, com


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


def _weights(base, joints, velocity, nv):
    """Crocoddyl's state weights (base linear, base angular, joints; then the velocity's)
    in mbjax's tangent order (the base's angular part first)."""
    nj = nv - 6
    w = np.r_[base, [joints] * nj, velocity]
    return w[np.r_[3:6, 0:3, 6:2 * nv]]


def _anymal_start():
    """ANYmal standing as `SimpleQuadrupedalGaitProblem` starts it, and its `_Gait` (the
    builder's state weights, joint and velocity bounds, Baumgarte Kd and impulse tracking):
    (robot, model, q_pin0, q0, v0, feet, com, gait)."""
    robot = _robot("anymal")
    model, q_pin0, q0, v0, feet, com = _start(robot, "standing", FEET)
    nv, nj = model.nv, model.nv - 6
    weights = (_weights([0.0] * 3 + [500.0] * 3, 0.01, [10.0] * 6 + [1.0] * nj, nv),
               _weights([1.0] * 6, 10.0, [10.0] * nv, nv))
    lower = np.r_[[-np.inf] * 6, [-9.42] * nj, [-np.inf] * 6, [-15.0] * nj]
    gait = _Gait(model, q0, PointContact, feet, weights, (lower, -lower), 50.0, 1e7)
    return robot, model, q_pin0, q0, v0, feet, com, gait


def _anymal(schedule, builder: str, step_length, step_height, dt, step_knots,
            support_knots) -> Example:
    """ANYmal's gait of `schedule(gait, com, feet, support, lengths)` (the knots after the
    first double support), with `SimpleQuadrupedalGaitProblem`'s `builder` as Crocoddyl's."""
    robot, model, q_pin0, q0, v0, feet, com, gait = _anymal_start()
    support = [gait.knot(FEET) for _ in range(support_knots)]

    def steps(length, legs, swing):
        return gait.footsteps(com, feet, length, step_height, step_knots, legs, swing)[0]

    knots = support + schedule(support, steps, step_length)
    # the last double-support model is the terminal one: its state costs alone
    terminal = (gait.regularisation(gait.state_weights), *gait.bounds)
    problem = Problem(knots, q0, v0, dt=dt, terminal=terminal, integrator=SemiImplicitEuler())

    def crocoddyl():
        from crocoddyl.utils.quadruped import SimpleQuadrupedalGaitProblem

        x0 = np.concatenate([q_pin0, np.zeros(robot.model.nv)])
        return getattr(SimpleQuadrupedalGaitProblem(robot.model, *FEET), builder)(
            x0, step_length, step_height, dt, step_knots, support_knots)

    return Example(problem, np.asarray(quasi_static(problem)), crocoddyl, "SolverFDDP",
                   _converter(model), controls=_controls)


def anymal_walk(step_length=0.25, step_height=0.15, dt=1e-2, step_knots=25,
                support_knots=2) -> Example:
    """Crocoddyl's walk: each foot steps in turn, RH, RF, LH, LF, the first two half steps."""
    lf, rf, lh, rh = FEET

    def schedule(support, steps, length):
        return (steps(0.5 * length, [lf, rf, lh], [rh]) + steps(0.5 * length, [lf, lh, rh], [rf])
                + support + steps(length, [lf, rf, rh], [lh]) + steps(length, [rf, lh, rh], [lf]))

    return _anymal(schedule, "createWalkingProblem", step_length, step_height, dt, step_knots,
                   support_knots)


def anymal_trot(step_length=0.25, step_height=0.15, dt=1e-2, step_knots=25,
                support_knots=2) -> Example:
    """Crocoddyl's trot (`createTrottingProblem`): the diagonal pairs RF-LH (a half step) and
    LF-RH step in turn."""
    lf, rf, lh, rh = FEET

    def schedule(support, steps, length):
        return steps(0.5 * length, [lf, rh], [rf, lh]) + support + steps(length, [rf, lh], [lf, rh])

    return _anymal(schedule, "createTrottingProblem", step_length, step_height, dt, step_knots,
                   support_knots)


def anymal_jump(jump_height=0.15, jump_length=(0.0, 0.3, 0.0), dt=1e-2, ground_knots=10,
                flying_knots=20) -> Example:
    """Crocoddyl's jump (`createJumpingProblem`, its example's parameters): the four feet on
    the ground, a flight of 2 `flying_knots` (written as stances with every foot in the air,
    the CoM driven up and along for the first half), the four feet landing `jump_length`
    further, and `ground_knots` on the ground there, the last one the terminal model. Its
    `states0` is the example's infeasible start, x0 at every knot."""
    robot, model, q_pin0, q0, v0, feet, com, gait = _anymal_start()
    length = np.asarray(jump_length, float)
    ground = {f: p * np.array([1.0, 1.0, 0.0]) for f, p in feet.items()}    # soles at z = 0
    rise = np.r_[length[:2] / 2, length[2] / 2 + jump_height]
    landed = com + np.r_[length[:2], length[2] - feet[FEET[1]][2]]          # Crocoddyl's df
    knots = ([gait.knot(FEET) for _ in range(ground_knots)]
             + [gait.knot([], com + rise * (k + 1) / flying_knots) for k in range(flying_knots)]
             + [gait.knot([]) for _ in range(flying_knots)]
             + [gait.impulse(FEET, [(f, ground[f] + length) for f in FEET])]
             + [gait.knot(FEET, landed) for _ in range(ground_knots - 1)])
    # the last landed model is the terminal one: its state and CoM costs
    terminal = (com_residual(model, landed, weight=1e6), gait.regularisation(gait.state_weights),
                *gait.bounds)
    problem = Problem(knots, q0, v0, dt=dt, terminal=terminal, integrator=SemiImplicitEuler())

    def crocoddyl():
        from crocoddyl.utils.quadruped import SimpleQuadrupedalGaitProblem

        x0 = np.concatenate([q_pin0, np.zeros(robot.model.nv)])
        return SimpleQuadrupedalGaitProblem(robot.model, *FEET).createJumpingProblem(
            x0, jump_height, list(jump_length), dt, ground_knots, flying_knots)

    states0 = np.tile(np.asarray(problem.x0), (problem.horizon + 1, 1))
    return Example(problem, np.asarray(quasi_static(problem)), crocoddyl, "SolverFDDP",
                   _converter(model), controls=_controls, states0=states0)


def talos_step(step_length=0.6, step_height=0.1, dt=3e-2, step_knots=15,
               support_knots=4) -> Example:
    robot = _robot("talos")
    pin_model, upper = _talos_legs(robot)
    model, q_pin0, q0, v0, feet, com = _start(robot, "half_sitting", SOLES, upper)
    nv = model.nv
    weights = (_weights([0.0] * 3 + [500.0] * 3, 0.01, [10.0] * nv, nv),
               _weights([1.0] * 6, 0.1, [10.0] * nv, nv))
    sole = partial(SurfaceContact, spatial=True)        # ContactModel6D's spatial acceleration
    gait = _Gait(model, q0, sole, feet, weights, None, 30.0, 1e8)
    right, left = SOLES
    support = [gait.knot(SOLES) for _ in range(support_knots)]
    knots = support + gait.footsteps(com, feet, 0.5 * step_length, step_height, step_knots,
                                     [left], [right])[0]
    steps, task = gait.footsteps(com, feet, step_length, step_height, step_knots, [right],
                                 [left])
    knots += support + steps[:-1]
    # the left foot's impulse model is the terminal one: its costs at the last state
    problem = Problem(knots, q0, v0, dt=dt, terminal=gait.impulse_costs(task),
                      integrator=SemiImplicitEuler())

    def crocoddyl():
        from crocoddyl.utils.biped import SimpleBipedGaitProblem

        builder = SimpleBipedGaitProblem(pin_model, *SOLES)
        x0 = np.concatenate([q_pin0, np.zeros(pin_model.nv)])
        return builder.createWalkingProblem(x0, step_length, step_height, dt, step_knots,
                                            support_knots)

    return Example(problem, np.asarray(quasi_static(problem)), crocoddyl, "SolverFDDP",
                   _converter(model), controls=_controls)


GAITS = {"anymal-walk": anymal_walk, "talos-step": talos_step, "anymal-jump": anymal_jump}
