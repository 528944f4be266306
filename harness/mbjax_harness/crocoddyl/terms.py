"""Crocoddyl's side of the comparisons, in its own terms: whether it works here
(`crocoddyl_working`), frames, cost sums and shooting problems with semi-implicit Euler steps,
and the shipped arm's reach and the acrobot's swing-up as Crocoddyl problems (`mbjax bench
trajopt`'s `arm-reach` and `acrobot-swingup`).
"""

import numpy as np

from mbjax_harness.peers import available


def crocoddyl_working() -> str | None:
    """None when Crocoddyl imports and its forward dynamics agree with Pinocchio's `aba` (to
    1e-9 relative on a random 7-dof state), else why not: crocoddyl 3.2.1 with pin 4.1.0
    imports but returns accelerations of about 1e-309 (pin 4.0.0 is right)."""
    if not (available("crocoddyl") and available("pinocchio")):
        return "crocoddyl is not installed (pip install 'mbjax[bench]')"
    import crocoddyl
    import pinocchio as pin

    from mbjax.data import ARM7

    model = pin.buildModelFromUrdf(str(ARM7))
    rng = np.random.default_rng(0)
    q, v, tau = (rng.uniform(-1.0, 1.0, model.nv) for _ in range(3))
    expected = pin.aba(model, model.createData(), q, v, tau)
    state = crocoddyl.StateMultibody(model)
    dam = crocoddyl.DifferentialActionModelFreeFwdDynamics(
        state, crocoddyl.ActuationModelFull(state), crocoddyl.CostModelSum(state, model.nv))
    data = dam.createData()
    dam.calc(data, np.concatenate([q, v]), tau)
    if not np.allclose(data.xout, expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max()):
        return (f"crocoddyl {crocoddyl.__version__} with pin {pin.__version__} disagrees with "
                "pin.aba (a known mismatch: use pin 4.0.0 with crocoddyl 3.2.1)")
    return None


def _crocoddyl_point(model, joint: int, offset, name: str) -> int:
    """A frame `name` at `offset` in joint `joint`'s frame of a Pinocchio model."""
    import pinocchio as pin

    frame = pin.Frame(name, joint, 0, pin.SE3(np.eye(3), np.asarray(offset, float)),
                      pin.FrameType.OP_FRAME)
    return model.addFrame(frame)


def _crocoddyl_terms(state, nu: int, terms) -> "object":
    """A CostModelSum from (name, residual, weights or None, weight) tuples: each term is
    weight/2 |diag(sqrt(weights)) r|^2, Crocoddyl's quadratic activation."""
    import crocoddyl

    costs = crocoddyl.CostModelSum(state, nu)
    for name, residual, weights, weight in terms:
        cost = (crocoddyl.CostModelResidual(state, residual) if weights is None else
                crocoddyl.CostModelResidual(
                    state, crocoddyl.ActivationModelWeightedQuad(np.asarray(weights, float)),
                    residual))
        costs.addCost(name, cost, float(weight))
    return costs


def _crocoddyl_shooting(state, actuation, x0, dt: float, horizon: int, running, terminal,
                        bounds=None):
    """Crocoddyl's shooting problem with semi-implicit Euler steps (its
    `IntegratedActionModelEuler`: v+ = v + dt a, q+ = q + dt v+, running costs times dt), the
    controls within `bounds` = (lower, upper) where given (for its box solvers)."""
    import crocoddyl

    def model(terms, step):
        costs = _crocoddyl_terms(state, actuation.nu, terms)
        dam = crocoddyl.DifferentialActionModelFreeFwdDynamics(state, actuation, costs)
        action = crocoddyl.IntegratedActionModelEuler(dam, step)
        if bounds is not None:
            action.u_lb, action.u_ub = (np.full(actuation.nu, float(b)) for b in bounds)
        return action

    return crocoddyl.ShootingProblem(np.asarray(x0, float), [model(running, dt)] * horizon,
                                     model(terminal, 0.0))


def crocoddyl_reach(urdf: str, q0, target, gravity_torque, flange, dt: float, horizon: int):
    """`mbjax.scenes.arm.reach_problem`'s costs in Crocoddyl's terms (mbjax's residual c r, cost
    1/2 c^2 |r|^2, is Crocoddyl's residual r with weight c^2):
    running 0.02 |p - target|^2 / 2 + 2e-4 |x - x0|^2 / 2 + 2e-4 |u - g|^2 / 2, terminal
    2e4 |p - target|^2 / 2 + 2 |v|^2 / 2, p the flange. Returns (problem, set_target)."""
    import crocoddyl
    import pinocchio as pin

    model = pin.buildModelFromUrdf(urdf)
    frame = _crocoddyl_point(model, model.njoints - 1, flange, "flange")
    state = crocoddyl.StateMultibody(model)
    actuation = crocoddyl.ActuationModelFull(state)
    nu, nv = actuation.nu, model.nv
    x0 = np.concatenate([np.asarray(q0, float), np.zeros(nv)])
    goal = crocoddyl.ResidualModelFrameTranslation(state, frame, np.asarray(target, float), nu)
    running = [("goal", goal, None, 0.02),
               ("state", crocoddyl.ResidualModelState(state, x0, nu), None, 2e-4),
               ("control", crocoddyl.ResidualModelControl(state, np.asarray(gravity_torque, float)),
                None, 2e-4)]
    terminal = [("goal", goal, None, 2e4),
                ("velocity", crocoddyl.ResidualModelState(state, x0, nu),
                 np.r_[np.zeros(nv), np.ones(nv)], 2.0)]
    problem = _crocoddyl_shooting(state, actuation, x0, dt, horizon, running, terminal)

    def set_target(target):
        goal.reference = np.asarray(target, float)

    return problem, set_target


def crocoddyl_swingup(urdf: str, q0, goal, length: float, dt: float, horizon: int):
    """`mbjax.scenes.acrobot.swingup_problem`'s costs in Crocoddyl's terms: running
    0.01 |p - goal|^2 / 2 + 1e-4 |v|^2 / 2 + 0.01 u^2 / 2, terminal 1e4 |p - goal|^2 / 2 +
    100 |v|^2 / 2, p the tip; the elbow alone actuated (Crocoddyl's own double-pendulum
    actuation, `crocoddyl.utils.pendulum`, a Python model called at every knot)."""
    import crocoddyl
    import pinocchio as pin
    from crocoddyl.utils.pendulum import ActuationModelDoublePendulum

    model = pin.buildModelFromXML(urdf)
    frame = _crocoddyl_point(model, model.njoints - 1, [0.0, 0.0, -length], "tip")
    state = crocoddyl.StateMultibody(model)
    actuation = ActuationModelDoublePendulum(state, actLink=2)
    nu, nv = actuation.nu, model.nv
    x0 = np.concatenate([np.asarray(q0, float), np.zeros(nv)])
    tip = crocoddyl.ResidualModelFrameTranslation(state, frame, np.asarray(goal, float), nu)
    velocity = crocoddyl.ResidualModelState(state, np.zeros(model.nq + nv), nu)
    only_v = np.r_[np.zeros(nv), np.ones(nv)]
    running = [("tip", tip, None, 0.01), ("velocity", velocity, only_v, 1e-4),
               ("control", crocoddyl.ResidualModelControl(state, nu), None, 0.01)]
    terminal = [("tip", tip, None, 1e4), ("velocity", velocity, only_v, 100.0)]
    return _crocoddyl_shooting(state, actuation, x0, dt, horizon, running, terminal)
