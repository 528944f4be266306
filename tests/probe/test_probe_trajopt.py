"""Probes of trajectory optimisation (`mbjax.trajopt`) (issue 43, item 5): inputs drawn by
hypothesis, each answered by a clear error naming the argument, a status, or the right answer
against an independent reference (the slider's transfer written as a linear least-squares problem
and solved by NumPy and SciPy's bounded solver, its finite differences); never a silent NaN.

One problem layout carries every solve: a mass on a slider (no gravity) moved from (q0, v0) toward
a goal in 10 held-force steps, least effort plus a terminal residual. Its targets and weights are
leaves (`eqx.Partial`), so every drawn problem reuses one compiled solver."""

from functools import partial

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import Phase, assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import lsq_linear

from mbjax import Status
from mbjax.integrate import RK4
from mbjax.model import Model
from mbjax.rigid import TreeSystem
from mbjax.trajopt import ILQR, MultipleShooting, Problem, optimal_cost, solve, sweep

# one xdist worker runs the module, so its programs compile once (the group tests/conftest.py
# adds comes after xdist has read the groups)
pytestmark = pytest.mark.xdist_group("tests/probe/test_probe_trajopt.py")

# XLA flushes subnormal numbers to zero on the CPU: draws keep clear of them
floats = partial(st.floats, allow_subnormal=False)
FEW = settings(max_examples=15, deadline=None)
# a defect's test stops at its first failing example: no shrinking
DEFECT = settings(max_examples=10, deadline=None, phases=[Phase.explicit, Phase.generate])
MASS, DT, HORIZON = 2.0, 0.1, 10
SLIDER = TreeSystem(Model([-1], "prismatic", mass=[MASS], inertia=[np.eye(3)],
                          axis=[1.0, 0.0, 0.0], gravity=(0.0, 0.0, 0.0)))


def running(q, v, u, w):
    return w * u


def terminal(q, v, goal, wq, wv):
    return jnp.concatenate([wq * (q - goal), wv * v])


def problem(goal=1.0, w=1.0, wq=10.0, wv=1.0, q0=0.0, v0=0.0, **kw):
    args = dict(dt=DT, horizon=HORIZON, running=eqx.Partial(running, w=jnp.asarray(w)),
                terminal=eqx.Partial(terminal, goal=jnp.asarray(goal), wq=jnp.asarray(wq),
                                     wv=jnp.asarray(wv)))
    return Problem(SLIDER, jnp.array([q0]), jnp.array([v0]), **{**args, **kw})


def least_squares(goal=1.0, w=1.0, wq=10.0, wv=1.0, q0=0.0, v0=0.0):
    """The transfer as min 1/2 |A u - y|^2: held forces u_k move the mass exactly to
    q_N = q0 + N dt v0 + dt^2 / m sum (N - k - 1/2) u_k, v_N = v0 + dt / m sum u_k; the running
    cost w^2 u_k^2 dt / 2 is the row sqrt(dt) w."""
    k = np.arange(HORIZON)
    A = np.vstack([np.sqrt(DT) * w * np.eye(HORIZON),
                   wq * DT**2 * (HORIZON - k - 0.5)[None] / MASS,
                   wv * DT * np.ones((1, HORIZON)) / MASS])
    y = np.concatenate([np.zeros(HORIZON), [wq * (goal - q0 - HORIZON * DT * v0)], [-wv * v0]])
    return A, y


def _cost(A, y, u):
    r = A @ u - y
    return 0.5 * r @ r


targets = dict(goal=floats(-5, 5), w=floats(0.1, 10), wq=floats(1, 100), wv=floats(0, 10),
               q0=floats(-1, 1), v0=floats(-1, 1))


# -- the right answer --------------------------------------------------------------------------------

@FEW
@given(**targets)
def test_the_transfer_is_the_least_squares_solution(goal, w, wq, wv, q0, v0):
    A, y = least_squares(goal, w, wq, wv, q0, v0)
    u = np.linalg.lstsq(A, y, rcond=None)[0]
    assume(_cost(A, y, u) > 1e-12)          # a start already optimal: the defect's test below
    result = solve(problem(goal, w, wq, wv, q0, v0))
    assert result.messages() == ["success"]
    np.testing.assert_allclose(result.cost, _cost(A, y, u), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(result.us[:, 0], u, atol=1e-6 * (1 + np.abs(u).max()))


@FEW
@given(goal=floats(-5, 5), lower=floats(-3, 1), width=floats(0.1, 4))
def test_a_bounded_transfer_is_scipys_bounded_least_squares(goal, lower, width):
    upper = lower + width
    result = solve(problem(goal, lower=lower, upper=upper), us0=np.zeros((HORIZON, 1)))
    A, y = least_squares(goal)
    reference = lsq_linear(A, y, bounds=(lower, upper), method="bvls", tol=1e-14)
    assert result.messages() == ["success"]
    assert np.all(result.us >= lower) and np.all(result.us <= upper)
    # a zero optimum (goal 0 inside the bounds) is 0 against SciPy's round-off
    np.testing.assert_allclose(result.cost, _cost(A, y, reference.x), rtol=1e-8, atol=1e-20)


@settings(max_examples=5, deadline=None)
@given(goal=floats(-5, 5), wq=floats(1, 100))
def test_the_optimal_cost_gradient_is_the_least_squares_optimum_finite_difference(goal, wq):
    """dJ*/d(goal, wq) by the envelope theorem against central differences of the optimum that
    NumPy's least squares gives."""
    def optimum(goal, wq):
        A, y = least_squares(goal, wq=wq)
        return _cost(A, y, np.linalg.lstsq(A, y, rcond=None)[0])

    grad = jax.grad(lambda th: optimal_cost(lambda p: problem(p[0], wq=p[1]), th))(
        jnp.array([goal, wq]))
    h = 1e-5
    fd = [(optimum(goal + h, wq) - optimum(goal - h, wq)) / (2 * h),
          (optimum(goal, wq + h * wq) - optimum(goal, wq - h * wq)) / (2 * h * wq)]
    np.testing.assert_allclose(grad, fd, rtol=1e-6, atol=1e-8)


@DEFECT
@given(v0=floats(-1, 1).filter(lambda v: v != 0), q0=floats(-1, 1),
       solver=st.sampled_from([ILQR(), MultipleShooting()]))
def test_a_first_guess_that_is_already_optimal_is_converged(v0, q0, solver):
    """Coasting at v0 reaches the goal q0 + N dt v0 with no force: u* = 0 is the first guess and
    the optimal cost is zero (no terminal velocity weight)."""
    goal = q0 + HORIZON * DT * v0
    result = solve(problem(goal, wv=0.0, q0=q0, v0=v0), solver)
    assert abs(float(result.cost)) < 1e-20
    assert result.messages() == ["success"]


# -- the problem's arguments -------------------------------------------------------------------------

@FEW
@given(name=st.sampled_from(["q0", "v0"]), n=st.integers(0, 4).filter(lambda n: n != 1))
def test_states_of_the_wrong_length_are_named(name, n):
    state = dict(q0=np.zeros(1), v0=np.zeros(1))
    state[name] = np.zeros(n)
    with pytest.raises(ValueError, match=rf"{name} must have shape \(1,\) for this system"):
        Problem(SLIDER, state["q0"], state["v0"], dt=DT, horizon=3, running=running,
                terminal=terminal)


@FEW
@given(dt=st.one_of(floats(max_value=0.0), st.sampled_from([np.nan, "0.1", [0.1], (0.1, 0.2)])))
def test_steps_that_are_not_positive_numbers_are_named(dt):
    with pytest.raises((TypeError, ValueError), match="dt must be a positive number"):
        problem(dt=dt)


@DEFECT
@given(st.sampled_from([None, 1j, object()]))
def test_steps_that_are_not_numbers_are_named(dt):
    with pytest.raises((TypeError, ValueError), match="dt must be a positive number"):
        problem(dt=dt)


@FEW
@given(horizon=st.one_of(st.integers(-5, 0), floats(0.5, 9.5), st.sampled_from(["3", None])))
def test_horizons_that_are_not_positive_ints_are_named(horizon):
    with pytest.raises(ValueError, match="horizon must be a positive int"):
        problem(horizon=horizon)


@settings(max_examples=1, deadline=None)         # dt is static: each value compiles the solver
@given(st.just(np.inf))
def test_an_unbounded_step_is_named_or_flagged(dt):
    try:
        result = solve(problem(dt=dt))
    except ValueError as error:
        assert "dt" in str(error)
        return
    assert not bool(result.ok)
    if not np.isfinite(result.cost):
        assert int(result.status) & Status.NONFINITE


@FEW
@given(lower=floats(-10, 10), gap=floats(1e-6, 10))
def test_bounds_that_cross_are_named(lower, gap):
    with pytest.raises(ValueError, match="lower must not exceed upper"):
        problem(lower=lower, upper=lower - gap)


@FEW
@given(name=st.sampled_from(["lower", "upper"]), shape=st.sampled_from([(2,), (0,), (1, 1), (HORIZON,)]))
def test_bounds_of_the_wrong_shape_are_named(name, shape):
    with pytest.raises(ValueError, match=rf"{name} must be a scalar or have one entry per actuated"):
        problem(**{name: np.zeros(shape)})


@settings(max_examples=1, deadline=None)     # a NaN keeps the solver busy to its last iteration
@given(name=st.sampled_from(["lower", "upper"]), value=st.sampled_from([np.nan]))
def test_nan_bounds_are_named_or_flagged(name, value):
    try:
        result = solve(problem(**{name: value}), us0=np.zeros((HORIZON, 1)))
    except ValueError as error:
        assert name in str(error)
        return
    assert not bool(result.ok) and int(result.status) & Status.NONFINITE


@FEW
@given(st.sampled_from(["running", "terminal"]), st.sampled_from([(2, 2), (1, 1, 1)]))
def test_costs_that_are_not_scalars_or_vectors_are_named(which, shape):
    def bad_running(q, v, u):
        return jnp.ones(shape) * u[0]

    def bad_terminal(q, v):
        return jnp.ones(shape) * q[0]

    kw = {"running": bad_running} if which == "running" else {"terminal": bad_terminal}
    with pytest.raises(ValueError, match=r"a cost must return a scalar or a vector of residuals, "
                                         rf"got shape \({', '.join(map(str, shape))}\)"):
        solve(problem(**kw))


@FEW
@given(st.sampled_from([3.0, "cost", None]))
def test_costs_that_are_not_callable_are_named(cost):
    with pytest.raises(TypeError, match=r"running\(q, v, u\) must be a callable"):
        problem(running=cost)


@FEW
@given(st.sampled_from([ILQR, "ilqr", RK4()]), st.sampled_from([RK4, "rk4"]))
def test_solvers_and_integrators_that_are_not_instances_are_named(solver, integrator):
    with pytest.raises(TypeError, match="solver must be a solver instance"):
        solve(problem(), solver)
    with pytest.raises(TypeError, match="integrator must be an instance such as RK4()"):
        problem(integrator=integrator)


# -- the first guess ---------------------------------------------------------------------------------

@FEW
@given(st.sampled_from([(HORIZON,), (HORIZON - 1, 1), (HORIZON + 1, 1), (HORIZON, 2), (1, HORIZON),
                        (HORIZON, 1, 1), ()]))
def test_first_guesses_of_the_wrong_shape_are_named(shape):
    with pytest.raises(ValueError, match=rf"us0 must be \(horizon, nu\) = \({HORIZON}, 1\)"):
        solve(problem(), us0=np.zeros(shape))


@FEW
@given(entry=st.integers(0, HORIZON - 1), value=st.sampled_from([np.nan, np.inf, -np.inf, 1e300]),
       bounded=st.booleans())
def test_nonfinite_first_guesses_are_flagged_or_solved(entry, value, bounded):
    """A non-finite (or overflowing) guess: the status says non-finite, or, inside bounds that
    clip it, the optimum is reached; never a success with a NaN."""
    us0 = np.zeros((HORIZON, 1))
    us0[entry] = value
    # (one compiled program for both: no bounds are infinite ones)
    kw = dict(lower=-1.0, upper=1.0) if bounded else dict(lower=-np.inf, upper=np.inf)
    result = solve(problem(goal=0.5, **kw), us0=us0)
    finite = bool(np.isfinite(result.us).all() and np.isfinite(result.cost))
    if bool(result.ok):
        A, y = least_squares(goal=0.5)
        reference = lsq_linear(A, y, bounds=(-1.0, 1.0) if bounded else (-np.inf, np.inf),
                               method="bvls", tol=1e-14)
        assert finite
        np.testing.assert_allclose(result.cost, _cost(A, y, reference.x), rtol=1e-8)
    elif not finite:
        assert int(result.status) & Status.NONFINITE


@settings(max_examples=5, deadline=None)
@given(st.sampled_from([np.nan, np.inf]))
def test_optimal_cost_of_a_failed_solve_raises_by_name(value):
    us0 = np.full((HORIZON, 1), value)
    with pytest.raises(Exception, match="the run failed with status nonfinite"):
        optimal_cost(lambda goal: problem(goal), 1.0, us0=us0)


# -- sweeps ------------------------------------------------------------------------------------------

@FEW
@given(st.lists(floats(-1e3, 1e3), min_size=1, max_size=5), st.booleans())
def test_a_sweep_is_the_map_of_its_function(values, on_devices):
    params = {"a": np.asarray(values), "b": 2.0 * np.asarray(values)}
    out = sweep(lambda p: p["a"] * p["b"] + 1.0, params,
                devices=jax.devices() if on_devices else None)
    np.testing.assert_allclose(out, [2.0 * x * x + 1.0 for x in values], rtol=1e-15)


@FEW
@given(st.sampled_from([[], (), "cpu", [0], [None], 3]))
def test_sweep_devices_that_are_not_devices_are_named(devices):
    with pytest.raises((TypeError, ValueError), match="devices must be"):
        sweep(lambda p: p, np.ones(3), devices=devices)


@FEW
@given(st.lists(st.integers(0, 4), min_size=2, max_size=3).filter(lambda s: len(set(s)) > 1))
def test_sweep_params_without_a_shared_leading_axis_are_named(sizes):
    params = {f"p{i}": np.ones(n) if n else np.float64(1.0) for i, n in enumerate(sizes)}
    with pytest.raises(ValueError, match="params must be a pytree whose array leaves all share a "
                                         "leading"):
        sweep(lambda p: p, params)
