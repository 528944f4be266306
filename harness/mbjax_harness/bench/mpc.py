"""`mbjax bench mpc`: model-predictive control against Crocoddyl's MPC loop on the same plant.

mbjax's `MPC` and Crocoddyl's loop run the same problems on the same plant, in the same run.

Problems (`SCENARIOS`):

    arm-track       the shipped 7-dof arm's flange following a 0.1 m circle (one turn in 2 s) at
                    100 Hz, a 0.5 s horizon (50 knots), pushed at its flange (30 N for 0.1 s
                    at t = 1 s) and carrying 0.3 kg the controller does not know of
                    (`mbjax.scenes.arm.tracking_controller`, `tracking_plant`)
    kinova-payload  the Kinova arm of Crocoddyl's `arm_manipulation_fwddyn.py` (its start and
                    target, the costs a position reach that settles) at 100 Hz, a 0.5 s
                    horizon, with 0.5 kg in the gripper that the controller does not know of
    anymal-trot     ANYmal (example-robot-data) trotting in place at 50 Hz: Crocoddyl's trot
                    (its knots, the touchdown impulses left out; swings of 15 knots, the feet
                    lifted 5 cm) as a cycle of 34 knots of 10 ms, a 0.2 s horizon; the plant finds its own contacts (the feet's spheres
                    on a floor, `mbjax.contact.ContactSystem`, semi-implicit Euler at 1 ms);
                    the task error is the base's drift from where it stood

Each tick both controllers solve the horizon from the plant's state with one FDDP iteration
(mbjax: `ILQR(iterations=1, **CROCODDYL_SCHEDULE)`, Crocoddyl: `SolverFDDP.solve(xs, us, 1,
False)`), warm-started from their previous solution shifted by the knots of a tick (Crocoddyl's
infeasible start), after a first solve to convergence from the controls that hold the start
(the trot's from its quasi-static controls, `mbjax.trajopt.quasi_static`). The plant is the same
mbjax system for both (RK4 at 1 ms for the arms, the plan's controls held with its feedback
gains between ticks: `mbjax.trajopt.follow`), so the two loops differ only in their
controllers. Both loops run in Python, a tick at a time, so that each tick's solve is timed
(`solve_ms_median`, `solve_ms_max`: mbjax's jitted `MPC.tick`, Crocoddyl's reference update and
`solve`, single-threaded); mbjax's jitted `closed_loop` runs the same loop as one program too
(`closed_loop_s`, and `loop_agreement`, its largest state difference from the Python loop).

`tracking_error` is the task error's root mean square over the ticks (the flange's or gripper's
distance to its target [m]); `closed_loop_cost` is the sum over the ticks of the first knot's
running cost at the plant's state and the applied control (the horizon problem's
`Problem.step_cost`); `status` is the closed loop's (`ClosedLoop.status`) for both, on the same
plant. Crocoddyl's row also has `lockstep_ticks` and `lockstep_cost_rtol` (`lockstep`: both
controllers fed the same states, the ticks before their controls part and their costs' largest
difference until then).

Batch (`arm-track-batch`): `ROBOTS` arms, each its own circle (centres spread over a 0.1 m cube),
their first plans and closed loops as one program split over the CPU's devices (`jax.vmap`
through `mbjax.trajopt.sweep`, and `lax.map` on each device), against the same number of
Crocoddyl loops one after the other (their first solves not timed).
"""

import os
import platform
import statistics
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from mbjax import Status, trajopt
from mbjax.integrate import RK4, SemiImplicitEuler
from mbjax.rigid import TreeSystem, inverse_dynamics
from mbjax.scenes import arm
from mbjax_harness import peers
from mbjax_harness.crocoddyl.terms import _crocoddyl_point, _crocoddyl_shooting, _crocoddyl_terms, crocoddyl_working
from mbjax_harness.timing import write_jsonl

NAME = "mpc"
TICKS, QUICK_TICKS = 300, 60
ROBOTS, QUICK_ROBOTS = 64, 4
BATCH_TICKS, QUICK_BATCH_TICKS = 100, 20
KINOVA_PAYLOAD = 0.5          # [kg]
ARM_PAYLOAD = 0.3             # [kg]


@dataclass
class Scenario:
    """One MPC problem, for both engines."""

    controller: trajopt.MPC
    plan: trajopt.Plan          # the first plan (mbjax's solve to convergence)
    plant: object               # the mbjax system both controllers drive
    q0: np.ndarray
    v0: np.ndarray
    error: Callable             # (t, q) -> the task error [m]
    crocoddyl: Callable         # () -> (SolverFDDP of the first horizon, update(t, x_pin))
    to_pin: Callable            # mbjax (q, v) -> Crocoddyl's x
    from_pin: Callable          # Crocoddyl's x -> mbjax x
    gains: Callable = None      # Crocoddyl's K (nu, ndx) -> mbjax's gains; None for -K
    integrator: object = None   # the plant's integrator; None for RK4


def _identity_pin():
    return (lambda q, v: np.concatenate([np.asarray(q), np.asarray(v)]),
            lambda x: np.asarray(x))


def arm_track(payload: float = ARM_PAYLOAD, centre=None) -> Scenario:
    controller = arm.tracking_controller(centre=centre)
    problem = controller.problem
    plan = eqx.filter_jit(arm.first_plan)(controller)
    q0, v0 = np.asarray(arm.Q_REF), np.zeros(7)
    model = problem.arm

    def error(t, q):
        return float(jnp.linalg.norm(arm.flange(model, q) - arm.track_target(problem.centre, t)))

    def crocoddyl():
        return crocoddyl_tracking(problem, plan)

    return Scenario(controller, plan, arm.tracking_plant(payload=payload), q0, v0, error,
                    crocoddyl, *_identity_pin())


def crocoddyl_tracking(tracking, plan):
    """`mbjax.scenes.arm.Tracking`'s horizon as Crocoddyl's shooting problem, a goal residual
    per knot (its reference moved each tick), and its FDDP solver warm from mbjax's first
    plan's converged solve (solved again by Crocoddyl to convergence)."""
    import crocoddyl
    import pinocchio as pin

    from mbjax.data import ARM7

    model = pin.buildModelFromUrdf(str(ARM7))
    frame = _crocoddyl_point(model, model.njoints - 1, arm.FLANGE, "flange")
    state = crocoddyl.StateMultibody(model)
    actuation = crocoddyl.ActuationModelFull(state)
    nu, nv = actuation.nu, model.nv
    q_ref = np.asarray(arm.Q_REF)
    zero = jnp.zeros(nv)
    gravity = np.asarray(inverse_dynamics(tracking.arm, jnp.asarray(q_ref), zero, zero))
    x_ref = np.concatenate([q_ref, np.zeros(nv)])
    w = np.asarray(tracking.weights)
    goals, models = [], []
    for k in range(tracking.horizon + 1):
        goal = crocoddyl.ResidualModelFrameTranslation(state, frame, np.zeros(3), nu)
        goals.append(goal)
        if k < tracking.horizon:
            terms = [("goal", goal, None, w[0]),
                     ("state", crocoddyl.ResidualModelState(state, x_ref, nu), None, w[1]),
                     ("control", crocoddyl.ResidualModelControl(state, gravity), None, w[2])]
        else:
            terms = [("goal", goal, None, w[3]),
                     ("velocity", crocoddyl.ResidualModelState(state, x_ref, nu),
                      np.r_[np.zeros(nv), np.ones(nv)], w[4])]
        costs = _crocoddyl_terms(state, nu, terms)
        dam = crocoddyl.DifferentialActionModelFreeFwdDynamics(state, actuation, costs)
        models.append(crocoddyl.IntegratedActionModelEuler(
            dam, arm.MPC_DT if k < tracking.horizon else 0.0))
    centre = np.asarray(tracking.centre)

    def update(t, x):
        targets = np.asarray(arm.track_target(centre, t + arm.MPC_DT
                                              * np.arange(tracking.horizon + 1)))
        for goal, target in zip(goals, targets, strict=True):
            goal.reference = target
        problem.x0 = x

    problem = crocoddyl.ShootingProblem(x_ref.copy(), models[:-1], models[-1])
    problem.nthreads = 1
    solver = crocoddyl.SolverFDDP(problem)
    update(0.0, x_ref)
    xs = [np.asarray(x) for x in np.asarray(plan.xs)]
    us = [np.asarray(u) for u in np.asarray(plan.us)]
    solver.solve(xs, us, 100, False)
    return solver, update


KINOVA_FRAME, KINOVA_TARGET = "j2s6s200_end_effector", np.array([0.6, 0.2, 0.5])
# Crocoddyl's weights: the gripper's position, the configuration's and the velocity's
# regularization, the control's (about the torque that holds the start); at the end, the
# position and the velocity
KINOVA_WEIGHTS = {"goal": 100.0, "q": 1e-3, "v": 0.1, "control": 1e-2, "goal_end": 1e3,
                  "v_end": 1.0}


def kinova_payload(payload: float = KINOVA_PAYLOAD, horizon: int = 50) -> Scenario:
    """The Kinova arm (example-robot-data) from its `arm_up` pose, its gripper held at a point
    0.25 m away under a payload it does not know of (Crocoddyl's `arm_manipulation_fwddyn.py`
    arm and target, its costs made a position reach that settles: the wrists' velocities
    regularized)."""
    from mbjax.model import state_from_pinocchio, state_to_pinocchio
    from mbjax.rigid import frame_pose
    from mbjax.trajopt import control_residual, frame_residual, state_residual
    from mbjax_harness.crocoddyl.examples import _load, _robot

    robot = _robot("kinova")
    model = _load(robot)
    q_pin0 = robot.model.referenceConfigurations["arm_up"]
    q0, v0 = (np.asarray(x) for x in state_from_pinocchio(model, q_pin0, np.zeros(model.nv)))
    nv, w = model.nv, KINOVA_WEIGHTS
    gravity = np.asarray(inverse_dynamics(model, jnp.asarray(q0), jnp.zeros(nv), jnp.zeros(nv)))
    state_weights = np.r_[np.full(nv, w["q"]), np.full(nv, w["v"])]
    end_weights = np.r_[np.zeros(nv), np.full(nv, w["v_end"])]
    running = (frame_residual(model, KINOVA_FRAME, KINOVA_TARGET, weight=w["goal"]),
               state_residual(model, q0, weight=state_weights),
               control_residual(nv, gravity, weight=w["control"]))
    terminal = (frame_residual(model, KINOVA_FRAME, KINOVA_TARGET, weight=w["goal_end"]),
                state_residual(model, q0, weight=end_weights))

    def horizon_problem(t, q, v):
        return trajopt.Problem(TreeSystem(model), q, v, dt=arm.MPC_DT, horizon=horizon,
                               running=running, terminal=terminal,
                               integrator=SemiImplicitEuler())

    controller = trajopt.MPC(horizon_problem)
    plan = eqx.filter_jit(controller.init)(0.0, q0, v0, np.tile(gravity, (horizon, 1)),
                                           trajopt.ILQR(**trajopt.CROCODDYL_SCHEDULE))
    index = model.frame_names.index(KINOVA_FRAME)
    plant = TreeSystem(model.with_payload(payload, body=model.frame_parents[index],
                                          point=model.frame_translation[index]))

    def error(t, q):
        return float(jnp.linalg.norm(frame_pose(model, q, KINOVA_FRAME)[1] - KINOVA_TARGET))

    def to_pin(q, v):
        return np.concatenate([np.asarray(a) for a in state_to_pinocchio(model, q, v)])

    def from_pin(x):
        q, v = state_from_pinocchio(model, x[:-nv], x[-nv:])
        return np.concatenate([np.asarray(q), np.asarray(v)])

    def crocoddyl():
        import crocoddyl as croc

        state = croc.StateMultibody(robot.model)
        actuation = croc.ActuationModelFull(state)
        x0 = np.concatenate([q_pin0, np.zeros(nv)])
        goal = croc.ResidualModelFrameTranslation(
            state, robot.model.getFrameId(KINOVA_FRAME), KINOVA_TARGET, nv)
        regularization = croc.ResidualModelState(state, x0, nv)
        running = [("goal", goal, None, w["goal"]),
                   ("state", regularization, state_weights, 1.0),
                   ("control", croc.ResidualModelControl(state, gravity), None, w["control"])]
        terminal = [("goal", goal, None, w["goal_end"]),
                    ("velocity", regularization, end_weights, 1.0)]
        problem = _crocoddyl_shooting(state, actuation, x0, arm.MPC_DT, horizon, running,
                                            terminal)
        problem.nthreads = 1
        solver = croc.SolverFDDP(problem)
        solver.solve([to_pin(*np.split(x, [model.nq])) for x in np.asarray(plan.xs)],
                     [np.asarray(u) for u in np.asarray(plan.us)], 100, False)

        def update(t, x):
            problem.x0 = x
        return solver, update

    return Scenario(controller, plan, plant, q0, v0, error, crocoddyl, to_pin, from_pin)


# a swing of 15 knots lifting the feet 5 cm: with 10 knots and 10 cm, on MuJoCo's default
# contacts (solref 0.02 s), both engines' loops blew up after 0.5 s (stable on stiffer ones)
TROT_DT, TROT_HORIZON, TROT_STEP_KNOTS, TROT_SUPPORT_KNOTS, TROT_HEIGHT = 0.01, 20, 15, 2, 0.05
TROT_SHIFT = 2                      # two knots of 10 ms a tick: 50 Hz
TROT_TICKS = 100                    # 2 s


def anymal_trot(step_length: float = 0.0) -> Scenario:
    """ANYmal trotting at 50 Hz: Crocoddyl's trot (`createTrottingProblem`'s knots: double
    supports, then each diagonal pair's swing, its feet lifted 5 cm; no touchdown impulses in
    the horizon, the plant's contacts stop the feet), knots of 10 ms, a 0.2 s horizon moved two
    knots a tick. In place, a cycle of 34 knots repeated; walking forward, `step_length` a step
    (the first a half step, as Crocoddyl's), the steps laid out for the whole run (the CoM's
    and the feet's targets move on). The plant finds its own contacts: the feet's spheres on a
    floor (`mbjax.contact.ContactSystem`, MuJoCo's soft contacts, friction 0.7), semi-implicit
    Euler at 1 ms. The task error is the base's distance from where a steady walk at the
    commanded speed (none in place) would have it."""
    import mbjax
    from mbjax.contact import ContactSystem
    from mbjax.model import Geoms, ground_plane, state_from_pinocchio
    from mbjax.trajopt import Cycle, quasi_static
    from mbjax_harness.crocoddyl.gaits import FEET, MU, _anymal_start, _converter

    robot, model, q_pin0, gait = _anymal_start()
    q0, v0 = gait.q0, jnp.zeros(model.nv)
    lf, rf, lh, rh = FEET
    support = gait.support(TROT_SUPPORT_KNOTS)
    targets = [gait.com, dict(gait.positions)]        # moved on by each step (`Gait.steps`)

    def step(swing, length):  # a diagonal pair's swing, its touchdown impulse left out
        knots, com, feet = gait.steps(*targets, swing, length, TROT_HEIGHT, TROT_STEP_KNOTS)
        targets[:] = com, feet
        return knots[:-1]

    def cycle_of(first):
        return (support + step([rf, lh], first * step_length) + support
                + step([lf, rh], step_length))

    knots = cycle_of(0.5)
    cycle_knots = len(knots)
    if step_length:                  # the whole run's steps, and a horizon more
        while len(knots) < TROT_TICKS * TROT_SHIFT + TROT_HORIZON:
            knots += cycle_of(1.0)
    cycle = Cycle(knots, TROT_DT)
    speed = step_length / (cycle_knots * TROT_DT)
    terminal = (gait.regularisation(), *gait.bounds)

    def horizon_problem(t, q, v):
        return trajopt.Problem(cycle.window(t, TROT_HORIZON), q, v, dt=TROT_DT,
                               terminal=terminal, integrator=SemiImplicitEuler())

    controller = trajopt.MPC(horizon_problem, shift=TROT_SHIFT)
    q0, v0 = jnp.asarray(q0), jnp.asarray(v0)
    us0 = quasi_static(horizon_problem(0.0, q0, v0))
    plan = eqx.filter_jit(controller.init)(0.0, q0, v0, us0,
                                           trajopt.ILQR(iterations=50,
                                                        **trajopt.CROCODDYL_SCHEDULE))
    # the plant: the feet's spheres (the URDF's collision geometry) on a floor under them
    g = model.geoms
    spheres = [i for i, kind in enumerate(g.kinds) if kind == "sphere"]
    R, p = mbjax.rigid.forward_kinematics(model, q0)
    floor = min(float((p[g.bodies[i]] + R[g.bodies[i]] @ g.position[i])[2] - g.size[i][0])
                for i in spheres)
    friction = [MU, 0.005, 1e-4]
    geoms = Geoms(("sphere",) * len(spheres), [g.bodies[i] for i in spheres],
                  np.asarray(g.size)[spheres], position=np.asarray(g.position)[spheres],
                  friction=[friction] * len(spheres)).join(ground_plane(height=floor,
                                                                        friction=friction))
    plant = ContactSystem(TreeSystem(model, actuation=range(6, model.nv)), geoms,
                          timestep=arm.PLANT_DT)
    to_pin_all = _converter(model)

    def to_pin(q, v):
        return to_pin_all(np.concatenate([np.asarray(q), np.asarray(v)])[None])[0]

    def from_pin(x):
        q, v = state_from_pinocchio(model, x[:model.nq], x[model.nq:])
        return np.concatenate([np.asarray(q), np.asarray(v)])

    nv = model.nv
    tangent = np.r_[3:6, 0:3, 6:nv]                  # mbjax's free-joint order (angular first)
    columns = np.r_[tangent, nv + tangent]

    def gains(K):
        return -np.asarray(K)[:, columns]

    def error(t, q):
        return float(jnp.linalg.norm(q[:3] - q0[:3] - jnp.array([speed * t, 0.0, 0.0])))

    def crocoddyl():
        import crocoddyl as croc
        import pinocchio as pin
        from crocoddyl.utils.quadruped import SimpleQuadrupedalGaitProblem

        builder = SimpleQuadrupedalGaitProblem(robot.model, *FEET)
        data = robot.model.createData()
        pin.forwardKinematics(robot.model, data, q_pin0)
        pin.updateFramePlacements(robot.model, data)
        ids = {f: robot.model.getFrameId(f) for f in FEET}
        at = {f: data.oMf[ids[f]].translation.copy() for f in FEET}
        com_ref = np.mean([at[f] for f in FEET], axis=0)
        com_ref[2] = pin.centerOfMass(robot.model, data, q_pin0)[2].item()
        double = [builder.createSwingFootModel(TROT_DT, [ids[f] for f in FEET])
                  for _ in range(TROT_SUPPORT_KNOTS)]

        def footstep(legs, swing, length):      # moves com_ref and the swing feet on
            return builder.createFootstepModels(
                com_ref, [at[f] for f in swing], length, TROT_HEIGHT, TROT_DT,
                TROT_STEP_KNOTS, [ids[f] for f in legs], [ids[f] for f in swing])[:-1]

        def cycle_of(first):
            return (double + footstep([lf, rh], [rf, lh], first * step_length) + double
                    + footstep([rf, lh], [lf, rh], step_length))

        models = cycle_of(0.5)
        while step_length and len(models) < len(knots):
            models += cycle_of(1.0)
        x0 = np.concatenate([q_pin0, np.zeros(robot.model.nv)])
        problem = croc.ShootingProblem(x0, models[:TROT_HORIZON],
                                       builder.createSwingFootModel(TROT_DT, list(ids.values())))
        problem.nthreads = 1
        solver = croc.SolverFDDP(problem)
        solver.solve(list(to_pin_all(np.asarray(plan.xs))),
                     [np.asarray(u) for u in np.asarray(plan.us)], 100, False)
        following = [TROT_HORIZON]

        def update(t, x):
            offset = int(round(t / TROT_DT))
            while following[0] < offset + TROT_HORIZON:
                model_ = models[following[0] % len(models)]
                problem.circularAppend(model_, model_.createData())
                following[0] += 1
            problem.x0 = x
        return solver, update

    return Scenario(controller, plan, plant, np.asarray(q0), np.asarray(v0), error, crocoddyl,
                    to_pin, from_pin, gains, SemiImplicitEuler())


TROT_FORWARD = 0.1                 # [m] a step: 0.29 m/s


SCENARIOS = {"arm-track": arm_track, "kinova-payload": kinova_payload, "anymal-trot": anymal_trot,
             "anymal-trot-forward": lambda: anymal_trot(TROT_FORWARD)}


@eqx.filter_jit
def _follow(controller, plant, integrator, plan, t, q, v, dt: float, steps: int):
    return trajopt.follow(controller, plan, plant, t, q, v, dt=dt, steps=steps,
                          integrator=integrator)


def plant_period(scenario: Scenario, dt: float, steps: int):
    """(plan, t, q, v) -> the plant over a control period (one compiled program for every
    scenario of the same shapes)."""
    integrator = scenario.integrator or RK4()
    return lambda plan, t, q, v: _follow(scenario.controller, scenario.plant, integrator, plan,
                                         t, q, v, dt, steps)


def _stage(scenario: Scenario):
    """(t, q, v, u) -> the horizon's first running cost (times dt) at the plant's state."""
    @jax.jit
    def stage(t, q, v, u):
        problem = scenario.controller.horizon(t, q, v)
        return problem.step_cost(problem.x0, u, 0)[1]
    return stage


def _summary(scenario, engine, ts, qs, vs, us, solve_s, stage, status) -> dict:
    errors = np.array([scenario.error(t, q) for t, q in zip(ts, qs, strict=True)])
    cost = float(sum(stage(t, q, v, u) for t, q, v, u in zip(ts[:-1], qs[:-1], vs[:-1], us,
                                                          strict=True)))
    return {"engine": engine, "solve_ms_median": 1e3 * statistics.median(solve_s),
            "solve_ms_max": 1e3 * max(solve_s), "tracking_error": float(np.sqrt(np.mean(errors**2))),
            "closed_loop_cost": cost, "status": status}


def mbjax_loop(scenario: Scenario, ticks: int, period, dt: float, steps: int):
    """mbjax's loop a tick at a time: (states, controls, solve seconds per tick, plans)."""
    tick = eqx.filter_jit(scenario.controller.tick)
    plan = scenario.plan
    q, v = jnp.asarray(scenario.q0), jnp.asarray(scenario.v0)
    qs, vs, us, seconds = [q], [v], [], []
    jax.block_until_ready(tick(plan, jnp.asarray(0.0), q, v))          # compiled
    for i in range(ticks):
        t = jnp.asarray(i * steps * dt)
        start = time.perf_counter()
        plan, report = jax.block_until_ready(tick(plan, t, q, v))
        seconds.append(time.perf_counter() - start)
        q, v, applied = period(plan, t, q, v)
        qs.append(q), vs.append(v), us.append(applied[0])
    return np.asarray(qs), np.asarray(vs), np.asarray(us), seconds


def crocoddyl_loop(scenario: Scenario, ticks: int, period, dt: float, steps: int):
    """Crocoddyl's loop, on the same plant: (states, controls, solve seconds per tick, the
    controls last applied in each period). Each tick shifts its warm start by the knots the
    horizon moves (`update` moves the problem's models along), solves one FDDP iteration, and
    hands its first knots' controls and gains to the plant."""
    solver, update = scenario.crocoddyl()
    H = len(solver.problem.runningModels)
    gains = scenario.gains or (lambda K: -np.asarray(K))
    q, v = jnp.asarray(scenario.q0), jnp.asarray(scenario.v0)
    qs, vs, us, seconds, last = [q], [v], [], [], []
    for i in range(ticks):
        t = i * steps * dt
        x = scenario.to_pin(q, v)
        start = time.perf_counter()
        update(t, x)
        shift = scenario.controller.shift if i else 0       # the first plan is for t = 0
        xs = list(solver.xs)[shift:] + [solver.xs[-1]] * shift
        xs[0] = x
        us_ = list(solver.us)[shift:] + [solver.us[-1]] * shift
        solver.solve(xs, us_, 1, False)
        seconds.append(time.perf_counter() - start)
        # the plan's first state is the measured one (Crocoddyl's x0), taken in mbjax's layout
        # as it is: converted back, a continuous joint's angle would come back wrapped
        used = scenario.controller.shift               # the knots the plant runs through
        x_plan = [np.concatenate([np.asarray(q), np.asarray(v)])] + [
            scenario.from_pin(np.asarray(solver.xs[k])) for k in range(1, used)]
        # Crocoddyl's control law is u = u_k - K_k (x (-) x_k): mbjax's gains are -K
        plan = trajopt.Plan(jnp.asarray(t), jnp.asarray(x_plan + [x_plan[-1]] * (H + 1 - used)),
                            jnp.asarray([np.asarray(solver.us[k]) for k in range(H)]),
                            jnp.asarray([gains(solver.K[k]) for k in range(H)]))
        q, v, applied = period(plan, jnp.asarray(t), q, v)
        qs.append(q), vs.append(v), us.append(applied[0]), last.append(applied[-1])
    return np.asarray(qs), np.asarray(vs), np.asarray(us), seconds, np.asarray(last)


def lockstep(scenario: Scenario, ticks: int, period, dt: float, steps: int) -> dict:
    """Both controllers fed the same measured states (the plant driven by mbjax's plans):
    `lockstep_ticks`, the ticks before their first controls part by more than 1 % of the
    control's norm (all of them if they never do), and `lockstep_cost_rtol`, the largest
    relative difference of their horizon costs over those ticks. Each warm-starts from its own
    previous solution, so where one line search takes another step than the other's, the two
    chains part for good: this tells a controller that computes otherwise from one whose
    one-iteration solves took a different branch."""
    tick = eqx.filter_jit(scenario.controller.tick)
    solver, update = scenario.crocoddyl()
    plan = scenario.plan
    q, v = jnp.asarray(scenario.q0), jnp.asarray(scenario.v0)
    agree, worst = ticks, 0.0
    for i in range(ticks):
        t = i * steps * dt
        plan, report = tick(plan, jnp.asarray(t), q, v)
        x = scenario.to_pin(q, v)
        update(t, x)
        shift = scenario.controller.shift if i else 0
        xs = list(solver.xs)[shift:] + [solver.xs[-1]] * shift
        xs[0] = x
        solver.solve(xs, list(solver.us)[shift:] + [solver.us[-1]] * shift, 1, False)
        u = np.asarray(plan.us[0])
        if np.linalg.norm(u - np.asarray(solver.us[0])) > 1e-2 * np.linalg.norm(u):
            agree = i
            break
        worst = max(worst, abs(float(report.cost) - solver.cost) / abs(solver.cost))
        q, v, _ = period(plan, jnp.asarray(t), q, v)
    return {"lockstep_ticks": agree, "lockstep_cost_rtol": worst}


def single(name: str, ticks: int, common: dict) -> list[dict]:
    scenario = SCENARIOS[name]()
    dt = arm.PLANT_DT
    control_period = scenario.controller.period(0.0, scenario.q0, scenario.v0)
    steps = int(round(control_period / dt))
    period, stage = plant_period(scenario, dt, steps), _stage(scenario)
    ts = np.arange(ticks + 1) * control_period
    base = {**common, "problem": name, "control_rate_hz": 1.0 / control_period, "ticks": ticks,
            "horizon": scenario.plan.us.shape[0]}
    records = []

    integrator = scenario.integrator or RK4()
    start = time.perf_counter()
    run = trajopt.closed_loop(scenario.controller, scenario.plant, scenario.q0, scenario.v0,
                              ticks=ticks, dt=dt, plan=scenario.plan, integrator=integrator)
    jax.block_until_ready(run)
    compiled = time.perf_counter() - start
    start = time.perf_counter()
    run = jax.block_until_ready(trajopt.closed_loop(
        scenario.controller, scenario.plant, scenario.q0, scenario.v0, ticks=ticks, dt=dt,
        plan=scenario.plan, integrator=integrator))
    closed_s = time.perf_counter() - start
    status = run.messages()[0]

    qs, vs, us, seconds = mbjax_loop(scenario, ticks, period, dt, steps)
    record = {**base, **_summary(scenario, "mbjax", ts, qs, vs, us, seconds, stage, status),
              "closed_loop_s": closed_s, "closed_loop_compile_s": compiled - closed_s,
              "loop_agreement": float(np.max(np.abs(np.asarray(run.qs) - qs))),
              "iterations_mean": float(np.mean(np.asarray(run.iterations)))}
    records.append(record)
    if (why := crocoddyl_working()) is None:
        qs, vs, us, seconds, us_last = crocoddyl_loop(scenario, ticks, period, dt, steps)
        plant_status = _plant_status(scenario, ts, qs, vs, us_last)
        records.append({**base, **_summary(scenario, "crocoddyl", ts, qs, vs, us, seconds,
                                           stage, plant_status),
                        **lockstep(scenario, ticks, period, dt, steps)})
    else:
        records.append({**base, "engine": "crocoddyl", "skipped": why})
    return records


def _plant_status(scenario, ts, qs, vs, us) -> str:
    """The closed loop's status words for states not from `closed_loop` (Crocoddyl's loop):
    the plant's own flags at the ticks under the control last applied, and NONFINITE, as
    `ClosedLoop.status` counts them."""
    from mbjax.control import Constant

    flags = 0
    for t, q, v, u in zip(ts[1:], qs[1:], vs[1:], us, strict=True):
        flags |= int(scenario.plant.with_control(Constant(u)).check(t, jnp.asarray(q),
                                                                  jnp.asarray(v)))
    if not (np.all(np.isfinite(qs)) and np.all(np.isfinite(vs))):
        flags |= int(Status.NONFINITE)
    words = [f.name.lower().replace("_", " ") for f in Status if f and flags & f]
    return ", ".join(words) or "success"


def _centres(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    base = np.asarray(arm.flange(arm.model(), jnp.asarray(arm.Q_REF)))
    return base + rng.uniform(-0.05, 0.05, (n, 3))


def batch(robots: int, ticks: int, common: dict, repeats: int = 1) -> list[dict]:
    """`robots` arms, each its own circle, in one program against Crocoddyl's loops one after
    the other. Two ways of running mbjax's: `jax.vmap` of the closed loop split over the CPU's
    devices (`mbjax.trajopt.sweep`), and `lax.map` over each device's share (on a CPU a vmapped
    iteration of w members costs about w iterations: what pays is the cores)."""
    from jax.sharding import Mesh, PartitionSpec

    centres = jnp.asarray(_centres(robots))
    dt = arm.PLANT_DT
    plant = arm.tracking_plant(payload=ARM_PAYLOAD)
    q0, v0 = jnp.asarray(arm.Q_REF), jnp.zeros(7)
    base = {**common, "problem": "arm-track-batch", "ticks": ticks,
            "devices": len(jax.devices())}

    def first(centre):
        return arm.first_plan(arm.tracking_controller(centre=centre))

    def one(inputs):
        centre, plan = inputs
        run = trajopt.closed_loop(arm.tracking_controller(centre=centre), plant, q0, v0,
                                  ticks=ticks, dt=dt, plan=plan)
        return run.qs, run.status

    # the first plans (a solve to convergence each) apart: Crocoddyl's are not timed either
    plans = jax.block_until_ready(trajopt.sweep(first, centres, devices=jax.devices()))
    start = time.perf_counter()
    plans = jax.block_until_ready(trajopt.sweep(first, centres, devices=jax.devices()))
    plans_s = time.perf_counter() - start
    mesh = Mesh(np.asarray(jax.devices()), ("robots",))
    mapped = jax.jit(jax.shard_map(lambda x: jax.lax.map(one, x), mesh=mesh,
                                   in_specs=PartitionSpec("robots"),
                                   out_specs=PartitionSpec("robots"), check_vma=False))
    runs = {"vmap": lambda: trajopt.sweep(one, (centres, plans), devices=jax.devices()),
            "map": lambda: mapped((centres, plans))}
    for fn in runs.values():
        jax.block_until_ready(fn())                      # compiled
    crocoddyl = crocoddyl_working() is None
    steps = int(round(arm.MPC_DT / dt))
    loops = []
    if crocoddyl:
        for c in np.asarray(centres):
            scenario = arm_track(centre=c)
            solver, update = scenario.crocoddyl()        # its first solve, not timed
            first = ([np.array(x) for x in solver.xs], [np.array(u) for u in solver.us])
            loops.append((scenario, solver, update, first))
    # the engines in turns, each the fastest of `repeats` (this machine's slow spells fall on
    # both); Crocoddyl's loops each start again from their first solve
    best = {how: np.inf for how in runs} | {"crocoddyl": np.inf, "crocoddyl_loop": np.inf}
    finals, statuses, agreement = {}, {}, 0.0
    for _ in range(repeats):
        for how, fn in runs.items():
            start = time.perf_counter()
            qs, status = jax.block_until_ready(fn())
            best[how] = min(best[how], time.perf_counter() - start)
            finals[how], statuses[how] = np.asarray(qs), np.asarray(status)
        if not crocoddyl:
            continue
        total, solving = 0.0, 0.0
        for i, (scenario, solver, update, first) in enumerate(loops):
            solver.problem.x0 = first[0][0]
            solver.setCandidate(*first, False)       # each round from the first solve
            scenario.crocoddyl = lambda solver=solver, update=update: (solver, update)
            start = time.perf_counter()
            qs, _, _, seconds, _ = crocoddyl_loop(scenario, ticks, plant_period(scenario, dt, steps),
                                                   dt, steps)
            total += time.perf_counter() - start
            solving += sum(seconds)
            agreement = max(agreement, float(np.max(np.abs(qs - finals["map"][i]))))
        best["crocoddyl"] = min(best["crocoddyl"], solving)
        best["crocoddyl_loop"] = min(best["crocoddyl_loop"], total)
    records = [{**base, "engine": "mbjax", "how": how, "robots": robots, "seconds": best[how],
                "first_plans_s": plans_s,
                "failed": int(np.sum((statuses[how] & int(Status.failures())) != 0))}
               for how in runs]
    if not crocoddyl:
        return records + [{**base, "engine": "crocoddyl", "skipped": crocoddyl_working()}]
    # `seconds` counts Crocoddyl's solves alone: its loop's plant is mbjax's, called from
    # Python a period at a time (`loop_seconds`, the whole), which is not Crocoddyl's to pay
    records.append({**base, "engine": "crocoddyl", "how": "loop", "robots": robots,
                    "seconds": best["crocoddyl"], "loop_seconds": best["crocoddyl_loop"],
                    "largest_state_difference_from_mbjax": agreement})
    return records


def table(records: list[dict]) -> str:
    lines = ["| problem | engine | rate | solve median | solve max | tracking error | "
             "closed-loop cost | status | same plans |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in records:
        if "solve_ms_median" in r:
            lines.append(f"| {r['problem']} | {r['engine']} | {r['control_rate_hz']:.0f} Hz | "
                         f"{r['solve_ms_median']:.2f} ms | {r['solve_ms_max']:.2f} ms | "
                         f"{r['tracking_error'] * 1e3:.3f} mm | {r['closed_loop_cost']:.6g} | "
                         f"{r['status']} | {_lockstep_words(r)} |")
    for r in records:
        if "robots" in r:
            lines.append(f"| {r['problem']} | {r['engine']} ({r['how']}) | {r['robots']} "
                         f"robots | {r['seconds']:.2f} s | | | | | |")
    return "\n".join(lines)


def _lockstep_words(record: dict) -> str:
    if "lockstep_ticks" not in record:
        return ""
    return (f"{record['lockstep_ticks']} of {record['ticks']} ticks "
            f"(costs to {record['lockstep_cost_rtol']:.0e})")


def plot(records: list[dict], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in records if "solve_ms_median" in r]
    fig, ax = plt.subplots(figsize=(7, 3.5))
    for i, r in enumerate(rows):
        colour = "C0" if r["engine"] == "mbjax" else "C1"
        ax.barh(i, r["solve_ms_median"], color=colour)
        ax.plot([r["solve_ms_max"]], [i], "k|", markersize=12)
    ax.axvline(1e3 / rows[0]["control_rate_hz"] if rows else 10.0, color="r", ls="--",
               label="control period")
    ax.set_yticks(range(len(rows)), [f"{r['problem']} {r['engine']}" for r in rows])
    ax.set_xlabel("solve per tick [ms] (bar median, tick max)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def run(out: Path, quick: bool = False) -> list[dict]:
    common = {"suite": NAME, "machine": platform.machine(), "cpus": os.cpu_count(),
              "jax": jax.__version__, "date": time.strftime("%Y-%m-%d")}
    records = []
    ticks = QUICK_TICKS if quick else TICKS
    records += single("arm-track", ticks, common)
    for name in (("kinova-payload",) if quick else
                 ("kinova-payload", "anymal-trot", "anymal-trot-forward")):
        if (why := peers.missing("example_robot_data")) is None:
            records += single(name, TROT_TICKS if name.startswith("anymal") else ticks, common)
        else:
            records.append({**common, "problem": name, "skipped": why})
    records += batch(QUICK_ROBOTS if quick else ROBOTS,
                     QUICK_BATCH_TICKS if quick else BATCH_TICKS, common, 1 if quick else 3)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_jsonl(out / f"{NAME}.jsonl", records)
    plot(records, out / f"{NAME}.png")
    print(table(records))
    return records
