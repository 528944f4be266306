"""Multi-phase problems through contact (issue 45): knots that carry their own system, impulse
knots at touchdown, the contact costs and the quasi-static guess, against Crocoddyl's own gait
builder (`crocoddyl.utils.quadruped.SimpleQuadrupedalGaitProblem`) on example-robot-data's
ANYmal (`mbjax_harness.crocoddyl.gaits`), and a multi-phase problem of one phase against the
one-system problem it restates."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax.contact import PointContact, stance
from mbjax.rigid import TreeSystem
from mbjax.trajopt import (ILQR, Impulse, Knot, Problem, control_residual, friction_cone_residual,
                           knot_wrenches, optimal_cost, solve, state_residual)
from mbjax_harness.crocoddyl.terms import crocoddyl_working
from tests.conftest import example_robots

WHY = crocoddyl_working()
crocoddyl_only = pytest.mark.skipif(WHY is not None, reason=str(WHY))


def _rollout(problem, us):
    return eqx.filter_jit(lambda p, u: p.rollout(u))(problem, us)


def _cost(problem, xs, us):
    return float(eqx.filter_jit(lambda p, x, u: p.cost(x, u))(problem, xs, us))


def _agrees_with_crocoddyl(example, scale, seed, guess, tolerance):
    """The quasi-static guess is Crocoddyl's `quasiStatic` (to `guess`), and under the guess
    perturbed by normal noise of `scale` N m each of Crocoddyl's steps and impulses from mbjax's
    state lands on mbjax's next state (to `tolerance`) and the two costs agree (relative)."""
    problem, croc = example.problem, example.crocoddyl()
    to_croc = example.controls(croc)
    for mine, theirs in zip(to_croc(example.us0), croc.quasiStatic([croc.x0] * croc.T),
                            strict=True):
        np.testing.assert_allclose(mine, theirs, atol=guess)
    noise = np.random.default_rng(seed).normal(scale=scale, size=example.us0.shape)
    us = jnp.asarray(example.us0 + noise)
    xs = _rollout(problem, us)
    xs_croc, us_croc = example.to_crocoddyl(xs), to_croc(us)
    for k, model in enumerate(croc.runningModels):
        data = model.createData()
        model.calc(data, xs_croc[k], us_croc[k])
        np.testing.assert_allclose(data.xnext, xs_croc[k + 1], atol=tolerance)
    np.testing.assert_allclose(_cost(problem, xs, us), croc.calc(list(xs_croc), us_croc),
                               rtol=tolerance)


def test_knots_of_one_system_restate_the_one_system_problem():
    """A problem written knot by knot with one system and per-knot targets: one phase (one
    compiled step), and its rollout, cost and expansion are those of the one-system problem with
    the same costs, knot for knot."""
    model = mbjax.model.chain(3)
    system = TreeSystem(model)
    q0, v0 = jnp.zeros(3), jnp.zeros(3)
    targets = np.linspace(0.0, 1.0, 6)[:, None] * np.ones(3)
    knots = [Knot(system, (state_residual(model, t), control_residual(3, weight=1e-2)))
             for t in targets]
    multi = Problem(knots, q0, v0, dt=0.05, terminal=state_residual(model, targets[-1]))
    assert len(multi.knots.templates) == 1 and multi.horizon == 6
    us = jnp.asarray(np.random.default_rng(0).normal(size=(6, 3)))
    xs = _rollout(multi, us)
    for k, t in enumerate(targets):          # each knot's cost is its own target's
        one = Problem(system, q0, v0, dt=0.05, horizon=6,
                      running=(state_residual(model, t), control_residual(3, weight=1e-2)),
                      terminal=state_residual(model, targets[-1]))
        np.testing.assert_allclose(xs, _rollout(one, us), rtol=1e-14, atol=1e-14)
        got = jax.tree.map(lambda a: a[k], multi.linearize(xs, us))
        want = jax.tree.map(lambda a: a[k], one.linearize(xs, us))
        jax.tree.map(lambda a, b: np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12), got,
                     want)


def test_a_problem_of_one_system_is_its_knot_repeated():
    """`Problem(system, ..., running=)` holds the schedule of `[Knot(system, running)] * N`:
    leaf for leaf the same problem, one phase, each knot's time k dt exactly, no jumps; and
    its iterates are the knots' bit for bit."""
    model = mbjax.model.chain(3)
    system = TreeSystem(model)
    q0, v0 = jnp.full(3, 0.3), jnp.zeros(3)
    running = (state_residual(model, jnp.zeros(3)), control_residual(3, weight=1e-2))
    args = dict(dt=0.07, terminal=state_residual(model, jnp.zeros(3)))
    one = Problem(system, q0, v0, horizon=9, running=running, **args)
    knots = Problem([Knot(system, running)] * 9, q0, v0, **args)
    assert bool(eqx.tree_equal(one, knots))
    assert one.n_phases == 1 and one.jumps() is None
    assert one.times().tolist() == [k * 0.07 for k in range(9)]
    a, b = (solve(p, ILQR(iterations=3)) for p in (one, knots))
    np.testing.assert_array_equal(a.us, b.us)


def test_phases_are_counted_and_alike_knots_that_do_not_group_are_named():
    """Knots alike but for their arrays make one phase (`Problem.n_phases`); a knot whose cost
    tuple lacks a term makes a second, and the warning names the two knots and the difference,
    so that a user learns why a schedule compiles more than once."""
    model = mbjax.model.chain(3)
    system = TreeSystem(model)
    q0, v0 = jnp.zeros(3), jnp.zeros(3)
    targets = np.linspace(0.0, 1.0, 4)[:, None] * np.ones(3)
    costs = [(state_residual(model, t), control_residual(3, weight=1e-2)) for t in targets]
    terminal = state_residual(model, targets[-1])
    one = Problem([Knot(system, c) for c in costs], q0, v0, dt=0.05, terminal=terminal)
    assert one.n_phases == 1
    assert Problem(system, q0, v0, dt=0.05, horizon=4, running=costs[0],
                   terminal=terminal).n_phases == 1
    knots = [Knot(system, c) for c in costs[:2]] + [Knot(system, costs[2][:1])] + [
        Knot(system, costs[3])]
    with pytest.warns(UserWarning, match=r"knots\[1\] and knots\[2\].*2 entries in one, 1 in") as caught:
        two = Problem(knots, q0, v0, dt=0.05, terminal=terminal)
    assert caught[0].filename == __file__          # the user's line, not the library's
    assert two.n_phases == 2 and two.knots.phase == (0, 0, 1, 0)


@pytest.mark.slow     # 35 s: two programs of a solve through contacts
def test_a_contact_problem_rolls_its_first_guess_out_in_its_first_step():
    """ILQR rolls out the first guess of a problem whose knots solve contacts in its first
    step's forward pass (one forward pass to compile, not two): the history starts at the
    rollout's cost, and the iterates are those of the same problem started from that rollout
    given as a state trajectory (the route of a rollout, then its cost)."""
    model = mbjax.model.chain(4)
    q0, v0 = jnp.array([0.3, -0.4, 0.5, 0.2]), jnp.zeros(4)
    phase = stance(TreeSystem(model), q0, [PointContact("body3")])
    knot = Knot(phase, (state_residual(model, q0 + 0.1), control_residual(4, weight=1e-2),
                        friction_cone_residual(phase, 0.7)))
    problem = Problem([knot] * 5, q0, v0, dt=0.02, terminal=state_residual(model, q0 + 0.1))
    us0 = jnp.asarray(np.random.default_rng(0).normal(scale=0.1, size=(5, 4)))
    xs = _rollout(problem, us0)
    fresh, given = (solve(problem, ILQR(iterations=3), us0, states) for states in (None, xs))
    assert int(fresh.iterations) == int(given.iterations) == 3
    np.testing.assert_allclose(fresh.costs[0], _cost(problem, xs, us0), rtol=1e-12)
    np.testing.assert_allclose(fresh.costs, given.costs, rtol=1e-10)
    np.testing.assert_allclose(fresh.us, given.us, rtol=1e-9, atol=1e-12)


def test_bad_multi_phase_input_is_refused_by_name():
    model = mbjax.model.chain(3)
    system = TreeSystem(model)
    knot = Knot(system, control_residual(3))
    q0, v0 = jnp.zeros(3), jnp.zeros(3)
    with pytest.raises(ValueError, match="horizon must be the number of knots"):
        Problem([knot] * 4, q0, v0, dt=0.1, horizon=5, terminal=control_residual(3))
    with pytest.raises(ValueError, match="running: each knot"):
        Problem([knot] * 4, q0, v0, dt=0.1, running=control_residual(3),
                terminal=control_residual(3))
    with pytest.raises(ValueError, match="same number of controls"):
        Problem([knot, Knot(TreeSystem(model, actuation=[0]), control_residual(1))], q0, v0,
                dt=0.1, terminal=control_residual(3))
    with pytest.raises(TypeError, match=r"knots\[1\] must be a Knot"):
        Problem([knot, system], q0, v0, dt=0.1, terminal=control_residual(3))
    with pytest.raises(KeyError, match="no frame, body or joint named 'toe'"):
        Impulse(model, [PointContact("toe")], control_residual(3))
    phase = stance(system, q0, [PointContact("body2")])
    for mu in (0.0, -0.5, float("nan")):
        with pytest.raises(ValueError, match="mu must be a positive friction coefficient"):
            friction_cone_residual(phase, mu)
    with pytest.raises(ValueError, match="phase must be a stance"):
        friction_cone_residual(system, 0.7)


@crocoddyl_only
@pytest.mark.slow
def test_short_walk_is_crocoddyls_problem():
    """ANYmal's walk with short steps, built in both libraries: the quasi-static guess is
    Crocoddyl's `quasiStatic` (to 1e-10 N m), and under perturbed controls (feet pushing,
    pulling and slipping: every cone, tracking and impulse cost active) each of Crocoddyl's
    steps and impulses from mbjax's state lands on mbjax's next state and the two costs agree
    to 1e-10."""
    example_robots(["anymal_b_simple/anymal"])          # skips without example-robot-data
    from mbjax_harness.crocoddyl.gaits import anymal_walk

    example = anymal_walk(step_knots=4, support_knots=1)
    problem = example.problem
    # every stance holds the four feet, some in the air: one stance phase and one impulse phase
    assert problem.horizon == 22 and len(problem.knots.templates) == 2
    _agrees_with_crocoddyl(example, scale=3.0, seed=1, guess=1e-10, tolerance=1e-10)
    # the quasi-static guess holds the robot at rest at x0: on every stance knot the ground
    # carries its weight (the momentum balance, which no part of the stance computes), and a
    # foot in the air, or an impulse's knot, carries nothing
    wrenches = np.asarray(knot_wrenches(problem, jnp.broadcast_to(problem.x0, (22, problem.nx)),
                                        example.us0))
    model = problem.knots.knot(0, 0).system.tree.model
    weight = float(model.mass.sum()) * 9.81
    impulses = [k for k in range(22) if problem.knots.phase[k] == 1]
    stances = [k for k in range(22) if k not in impulses]
    np.testing.assert_allclose(wrenches[stances, :, 5].sum(axis=1), weight, rtol=1e-9)
    assert not np.any(wrenches[impulses])
    assert problem.jumps().tolist() == [k in impulses for k in range(22)]
    swing = problem.knots.knot(0, 2).system.closures        # the first step's knots: RH lifted
    assert [float(j.active) for j in swing] == [1.0, 1.0, 1.0, 0.0]
    assert not np.any(wrenches[2, 3])


@crocoddyl_only
@pytest.mark.slow
def test_anymal_walk_reaches_fddps_optimum():
    """Crocoddyl's ANYmal walk (108 knots, 2 phases): iLQR with Crocoddyl's schedule, from the
    quasi-static guess, ends within 1e-6 of FDDP's optimum, and its controls, rolled out in
    Crocoddyl's dynamics, cost there what they cost here (feasible in Crocoddyl's problem)."""
    from mbjax._src.trajopt.ilqr import CROCODDYL_SCHEDULE
    from mbjax_harness.crocoddyl.solver import CrocoddylSolver
    from mbjax_harness.crocoddyl.gaits import anymal_walk

    example = anymal_walk()
    croc_problem = example.crocoddyl()
    to_croc = example.controls(croc_problem)
    result = solve(example.problem, ILQR(iterations=100, **CROCODDYL_SCHEDULE),
                   jnp.asarray(example.us0))
    # the steps resolve the motion once the touchdowns' jumps, the model's, are left out of the
    # check (with them in, the increments across each impulse read 1.16)
    assert result.messages() == ["success"] and float(result.resolution) < 1.0
    croc = CrocoddylSolver(croc_problem, to_croc(example.us0))
    croc.solve(100)
    assert float(result.cost) <= croc.solver.cost * (1 + 1e-6)
    us = to_croc(result.us)
    np.testing.assert_allclose(croc_problem.calc(croc_problem.rollout(us), us), result.cost,
                               rtol=1e-8)


@crocoddyl_only
@pytest.mark.slow
def test_short_talos_step_is_crocoddyls_problem():
    """Talos's legs (upper body locked in both libraries) stepping with each foot, soles held
    as surface contacts with wrench-cone costs: the quasi-static guess is Crocoddyl's, and under
    perturbed controls each step and impulse of Crocoddyl from mbjax's state lands on mbjax's
    next state and the costs agree to 1e-10 (the soles are `SurfaceContact(spatial=True)`,
    which hold the spatial acceleration as Crocoddyl's `ContactModel6D` does)."""
    example_robots(["talos_data/talos_reduced"])
    from mbjax_harness.crocoddyl.gaits import talos_step

    example = talos_step(step_knots=4, support_knots=1)
    _agrees_with_crocoddyl(example, scale=0.3, seed=0, guess=1e-9, tolerance=1e-10)


@crocoddyl_only
@pytest.mark.slow
def test_the_jump_from_an_infeasible_start_reaches_fddps_optimum():
    """Crocoddyl's ANYmal jump (`createJumpingProblem`: 40 flying knots written as stances with
    every foot in the air, a landing impulse) built in both libraries: the quasi-static guess is
    Crocoddyl's, each of Crocoddyl's steps from mbjax's states lands on mbjax's next state and
    the costs agree; from the example's infeasible start (x0 held at every knot), ILQR (FDDP's
    gaps) ends at FDDP's optimum from the same start within 1e-8 (relative), converged, its
    trajectory the rollout of its controls."""
    example_robots(["anymal_b_simple/anymal"])
    from mbjax._src.trajopt.ilqr import CROCODDYL_SCHEDULE
    from mbjax_harness.crocoddyl.solver import CrocoddylSolver
    from mbjax_harness.crocoddyl.gaits import anymal_jump

    example = anymal_jump()
    problem, states0 = example.problem, jnp.asarray(example.states0)
    assert problem.horizon == 60 and len(problem.knots.templates) == 2
    _agrees_with_crocoddyl(example, scale=3.0, seed=2, guess=1e-10, tolerance=1e-9)
    result = solve(problem, ILQR(iterations=100, **CROCODDYL_SCHEDULE),
                   jnp.asarray(example.us0), states0)
    croc = example.crocoddyl()
    fddp = CrocoddylSolver(croc, example.controls(croc)(example.us0),
                           xs0=example.to_crocoddyl(states0))
    assert fddp.solve(100)
    assert result.messages() == ["success"]
    assert abs(float(result.cost) - fddp.solver.cost) < 1e-8 * fddp.solver.cost
    np.testing.assert_allclose(problem.rollout(result.us),
                               jnp.concatenate([result.qs, result.vs], axis=1), atol=1e-12)


@crocoddyl_only
@pytest.mark.slow
def test_the_trots_optimal_cost_is_differentiable_in_the_trunks_mass():
    """Co-design through contact: on Crocoddyl's trot, `optimal_cost`'s gradient with respect to
    the trunk's mass and inertia scale (the envelope theorem, one reverse pass through every
    stance and impulse) equals central differences of gaits re-solved at scale 1 +- 1e-3."""
    from mbjax._src.trajopt.ilqr import CROCODDYL_SCHEDULE
    from mbjax_harness.crocoddyl.gaits import anymal_trot

    example = anymal_trot()
    problem, us0 = example.problem, jnp.asarray(example.us0)
    model = problem.knots.knot(0, 0).system.tree.model
    mass0, inertia0 = model.mass, model.inertia

    def build(scale):               # every knot's model shares these two arrays
        mass, inertia = mass0.at[0].multiply(scale), inertia0.at[0].multiply(scale)
        return jax.tree.map(lambda x: mass if x is mass0 else inertia if x is inertia0 else x,
                            problem)

    solver = ILQR(iterations=200, tolerance=1e-12, **CROCODDYL_SCHEDULE)
    slope = jax.grad(lambda s: optimal_cost(build, s, solver, us0, throw=False))(1.0)
    h = 1e-3
    central = (float(optimal_cost(build, 1.0 + h, solver, us0, throw=False))
               - float(optimal_cost(build, 1.0 - h, solver, us0, throw=False))) / (2 * h)
    assert abs(central) > 1.0                     # the design matters
    assert abs(float(slope) - central) < 1e-5 * abs(central)


@crocoddyl_only
@pytest.mark.slow
def test_multiple_shooting_reaches_fddps_optimum_on_the_short_walk():
    """`MultipleShooting` over a multi-phase problem (the knots' states as unknowns, the
    defects across stances and impulses by its augmented Lagrangian): from the quasi-static
    guess it ends at the optimum of Crocoddyl's FDDP on the same short walk."""
    example_robots(["anymal_b_simple/anymal"])
    from mbjax.trajopt import MultipleShooting
    from mbjax_harness.crocoddyl.solver import CrocoddylSolver
    from mbjax_harness.crocoddyl.gaits import anymal_walk

    example = anymal_walk(step_knots=4, support_knots=1)
    result = solve(example.problem, MultipleShooting(), jnp.asarray(example.us0))
    assert result.messages() == ["success"]
    croc_problem = example.crocoddyl()
    croc = CrocoddylSolver(croc_problem, example.controls(croc_problem)(example.us0))
    croc.solve(100)
    assert abs(float(result.cost) - croc.solver.cost) < 1e-8 * croc.solver.cost
