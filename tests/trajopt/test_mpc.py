"""Model-predictive control (`mbjax.trajopt.MPC`, `closed_loop`): the jitted closed loop equals
its ticks run one at a time; a tick equals one iteration of Crocoddyl's FDDP from the same warm
start (an independent solver, where installed); the closed loop's gradient in a plant's payload
equals central differences; a vmapped batch equals its members; bad input is named. The
closed loop is the README's (the same programs: the run's compilation cache serves both)."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import trajopt
from mbjax_harness.crocoddyl.terms import crocoddyl_working
from mbjax.rigid import inverse_dynamics, mass_matrix
from mbjax.scenes import arm

TICKS = 12                   # the short loops (gradient, batch)
Q0, V0 = np.asarray(arm.Q_REF), np.zeros(7)


@pytest.fixture(scope="module")
def controller():
    return arm.tracking_controller()


@pytest.fixture(scope="module")
def plan(controller):
    return arm.first_plan(controller)


def _run(controller, plan, payload=0.3, force=(0.0, 10.0, 0.0)):
    return trajopt.closed_loop(controller, arm.tracking_plant(payload=payload, force=force,
                                                              start=0.02),
                               Q0, V0, ticks=TICKS, dt=arm.PLANT_DT, plan=plan)


def test_closed_loop_equals_its_ticks(controller, plan):
    """`closed_loop` (the README's: 1.5 s, 0.3 kg unknown, a 30 N push at 1 s) is `MPC.tick`
    then `follow` over the control period, tick after tick; the feedback acts between ticks
    (the applied controls change within a period); one FDDP iteration a tick keeps the flange
    within 1 cm of its circle (rms) through the payload and the push."""
    plant = arm.tracking_plant(payload=0.3)
    run = trajopt.closed_loop(controller, plant, arm.Q_REF, jnp.zeros(7), ticks=150,
                              dt=1e-3, plan=plan)
    assert run.messages() == ["success"]
    tick = eqx.filter_jit(controller.tick)
    steps = int(round(arm.MPC_DT / arm.PLANT_DT))
    follow = eqx.filter_jit(lambda plan, t, q, v: trajopt.follow(
        controller, plan, plant, t, q, v, dt=arm.PLANT_DT, steps=steps))
    q, v, current = jnp.asarray(Q0), jnp.asarray(V0), plan
    acted = 0.0
    for i in range(150):
        t = jnp.asarray(i * arm.MPC_DT)
        current, report = tick(current, t, q, v)
        assert int(report.iterations) == int(run.iterations[i]) == 1
        q, v, us = follow(current, t, q, v)
        np.testing.assert_allclose(us[0], run.us[i], atol=1e-10)
        np.testing.assert_allclose(q, run.qs[i + 1], atol=1e-10)
        acted = max(acted, float(jnp.max(jnp.abs(us[-1] - us[0]))))
    assert acted > 1e-3                                              # the gains act
    errors = arm.tracking_error(controller.problem.arm, controller.problem.centre, run.ts,
                                run.qs)
    assert float(jnp.sqrt(jnp.mean(errors**2))) < 0.01 and float(errors.max()) < 0.03


@pytest.mark.skipif(crocoddyl_working() is not None, reason="Crocoddyl unavailable")
def test_tick_is_one_crocoddyl_iteration():
    """A tick from a plan shifted and a measured state off the plan equals one iteration of
    Crocoddyl's FDDP (its `SolverFDDP.solve(xs, us, 1, False)`) on the same horizon from the
    same warm start: the cost to 1e-6 relative (3e-7 measured), the first control to 1e-5 N m
    of 30 (2e-6 measured) and the gains (Crocoddyl's -K) to 1e-4 of 600 (7e-5 measured); a
    different step length would move the cost by 1e-3. The control weight is raised to 0.1
    here: with the scene's 1e-4 (Q_uu's smallest eigenvalue about 1e-6) the two solvers' steps
    differ by 1e-4 relative in the flat directions while the trajectories' costs agree to
    1e-14."""
    from mbjax_harness.bench.mpc import crocoddyl_tracking

    controller = arm.tracking_controller(weights=(100.0, 1e-2, 1e-1, 1e3, 1.0))
    plan = arm.first_plan(controller)
    solver, update = crocoddyl_tracking(controller.problem, plan)
    np.testing.assert_allclose(np.asarray(solver.us), plan.us, atol=1e-5)   # the first solve
    q = Q0 + 0.01 * np.sin(np.arange(7.0))
    v = 0.05 * np.cos(np.arange(7.0))
    t = arm.MPC_DT
    new, report = eqx.filter_jit(controller.tick)(plan, jnp.asarray(t), q, v)
    x = np.concatenate([q, v])
    update(t, x)
    xs = [np.asarray(a) for a in np.asarray(plan.xs)][1:] + [np.asarray(plan.xs[-1])]
    xs[0] = x
    us = [np.asarray(a) for a in np.asarray(plan.us)][1:] + [np.asarray(plan.us[-1])]
    solver.solve(xs, us, 1, False)
    np.testing.assert_allclose(float(report.cost), solver.cost, rtol=1e-6)
    np.testing.assert_allclose(new.us[0], solver.us[0], atol=1e-5)
    np.testing.assert_allclose(new.feedback[0], -solver.K[0], atol=1e-4)


def test_gradient_in_payload(controller, plan):
    """d/d(payload) of the closed loop's tracking cost, forward mode through every tick's solve
    and the plant's steps, equals central differences (1e-6 relative)."""
    def cost(payload):
        run = _run(controller, plan, payload=payload)
        flanges = jax.vmap(lambda q: arm.flange(controller.problem.arm, q))(run.qs)
        return jnp.mean(jnp.sum((flanges - arm.track_target(controller.problem.centre,
                                                            run.ts))**2, axis=1))

    gradient = jax.jacfwd(cost)(0.3)
    h = 1e-4
    central = (cost(0.3 + h) - cost(0.3 - h)) / (2 * h)
    assert np.isfinite(gradient) and abs(float(gradient)) > 0
    np.testing.assert_allclose(gradient, central, rtol=1e-6)


def test_vmapped_loops_equal_their_members(controller, plan):
    """Two arms with their own circles in one vmapped closed loop run as each alone (both
    from the first plan of the first circle)."""
    centres = controller.problem.centre + jnp.array([[0.0, 0.0, 0.0], [0.02, -0.03, 0.01]])
    plant = arm.tracking_plant(payload=0.3, force=(0.0, 10.0, 0.0), start=0.02)

    def one(centre):
        c = arm.tracking_controller(centre=centre)
        return trajopt.closed_loop(c, plant, Q0, V0, ticks=TICKS, dt=arm.PLANT_DT, plan=plan)

    batch = jax.jit(jax.vmap(one))(centres)
    assert batch.messages() == ["success"] * 2
    alone = one(centres[1])
    np.testing.assert_allclose(batch.qs[1], alone.qs, atol=1e-9)


def test_errors_are_named(controller, plan):
    plant = arm.tracking_plant()
    with pytest.raises(TypeError, match="problem must be a function"):
        trajopt.MPC(3.0)
    with pytest.raises(TypeError, match="solver must be an iterative solver"):
        trajopt.MPC(controller.problem, trajopt.Shooting())
    with pytest.raises(ValueError, match="shift must be a positive int"):
        trajopt.MPC(controller.problem, shift=0)
    with pytest.raises(ValueError, match="must be longer than shift"):
        trajopt.MPC(arm.Tracking(controller.problem.arm, horizon=3), shift=3).init(0.0, Q0, V0)
    with pytest.raises(TypeError, match="must return a mbjax.trajopt.Problem"):
        trajopt.MPC(lambda t, q, v: None).init(0.0, Q0, V0)
    with pytest.raises(TypeError, match="plant must be an mbjax system"):
        trajopt.closed_loop(controller, "arm", Q0, V0, ticks=2, dt=1e-3, plan=plan)
    with pytest.raises(ValueError, match="ticks must be a positive int"):
        trajopt.closed_loop(controller, plant, Q0, V0, ticks=0, dt=1e-3, plan=plan)
    with pytest.raises(ValueError, match="must divide the control period"):
        trajopt.closed_loop(controller, plant, Q0, V0, ticks=2, dt=3e-3, plan=plan)


def test_payload_identities():
    """`Model.with_payload`: a point mass m at the flange adds m to the body, its gravity
    torque J^T m g to the joints' and m J^T J to the mass matrix (J the point's Jacobian), and
    0 kg changes nothing; bad input is named."""
    model = arm.model()
    q = jnp.asarray(Q0) + 0.1
    loaded = model.with_payload(0.7, body=model.n - 1, point=arm.FLANGE)
    np.testing.assert_allclose(loaded.mass.sum() - model.mass.sum(), 0.7, rtol=1e-14)
    J = jax.jacfwd(lambda q: arm.flange(model, q))(q)
    zero = jnp.zeros(7)
    np.testing.assert_allclose(
        inverse_dynamics(loaded, q, zero, zero) - inverse_dynamics(model, q, zero, zero),
        -0.7 * J.T @ model.gravity, atol=1e-12)
    np.testing.assert_allclose(mass_matrix(loaded, q) - mass_matrix(model, q), 0.7 * J.T @ J,
                               atol=1e-12)
    same = model.with_payload(0.0, body=model.names[-1], point=arm.FLANGE)
    np.testing.assert_allclose(same.inertia, model.inertia, atol=1e-15)
    with pytest.raises(ValueError, match="body must be one of"):
        model.with_payload(1.0, body="nope")
    with pytest.raises(ValueError, match="mass must not be negative"):
        model.with_payload(-1.0, body=0)
    with pytest.raises(ValueError, match="point of shape"):
        model.with_payload(1.0, body=0, point=(0.0, 0.0))


def test_cycle_windows_wrap_and_refuse_what_does_not_group():
    """`Cycle.window(t, n)` is the n knots from the knot of t on, the cycle repeated (t may be
    traced); knots that would make two phases, and impulses, are refused by name."""
    from mbjax.rigid import TreeSystem

    model = arm.model()
    system = TreeSystem(model)
    knots = [trajopt.Knot(system, eqx.Partial(_offset, c=jnp.asarray(float(k)))) for k in range(4)]
    cycle = trajopt.Cycle(knots, 0.1)
    assert cycle.period == 4
    window = jax.jit(lambda t: jnp.stack([k.running.keywords["c"] for k in cycle.window(t, 6)]))
    np.testing.assert_array_equal(window(0.3), [3, 0, 1, 2, 3, 0])
    np.testing.assert_array_equal(window(0.5), [1, 2, 3, 0, 1, 2])
    with pytest.raises(ValueError, match="alike but for their arrays"):
        trajopt.Cycle([knots[0], trajopt.Knot(system, _other)], 0.1)
    with pytest.raises(TypeError, match="knots\\[1\\] must be a Knot"):
        trajopt.Cycle([knots[0], trajopt.Impulse(model, [], _other)], 0.1)


def _offset(q, v, u, *, c):
    return jnp.concatenate([q - c, v])


def _other(q, v, u):
    return v
