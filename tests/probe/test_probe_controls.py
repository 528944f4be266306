"""Probes of `mbjax.control` (issue 43, item 5): inputs drawn by hypothesis, each answered by a
clear error naming the argument, a status, or the right answer against an independent reference
(NumPy's formula, a closed-form motion); never a silent NaN.

The controls are used as users use them: called directly, and through
`mbjax.rigid.TreeSystem(model, control=...)` and `mbjax.simulate`. One slider (a point mass on a
prismatic joint, no gravity) carries every simulation, so each kind of control compiles once."""

import warnings
from functools import partial

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import scipy.linalg
from hypothesis import Phase, example, given, settings
from hypothesis import strategies as st

from mbjax import Status, simulate
from mbjax.control import (PD, Constant, CubicSpline, MLPPolicy, SampleAndHold, Saturated, Sum,
                           ZeroOrderHold)
from mbjax.integrate import RK4
from mbjax.model import Model
from mbjax.rigid import TreeSystem

# one xdist worker runs the module, so its programs compile once (the group tests/conftest.py
# adds comes after xdist has read the groups)
pytestmark = pytest.mark.xdist_group("tests/probe/test_probe_controls.py")

MASS = 2.0
SLIDER = Model([-1], "prismatic", mass=[MASS], inertia=[np.eye(3)], axis=[1.0, 0.0, 0.0],
               gravity=(0.0, 0.0, 0.0))
N = 3                                   # the state size of the direct calls
# XLA flushes subnormal numbers to zero on the CPU: draws keep clear of them
floats = partial(st.floats, allow_subnormal=False)
FEW = settings(max_examples=15, deadline=None)
# a defect's test stops at its first failing example: no shrinking (each may compile anew)
DEFECT = settings(max_examples=10, deadline=None, phases=[Phase.explicit, Phase.generate])


def _call(control, q=None, v=None):
    q = jnp.arange(1.0, N + 1) * 0.1 if q is None else q
    v = -jnp.arange(1.0, N + 1) if v is None else v
    return control(jnp.asarray(0.3), q, v)


# -- PD ---------------------------------------------------------------------------------------------

@FEW
@given(st.data())
def test_pd_indices_outside_the_state_are_named_and_inside_give_the_servo_law(data):
    m = data.draw(st.integers(1, 3))
    q_index = data.draw(st.lists(st.integers(-2 * N, 2 * N), min_size=m, max_size=m))
    v_index = data.draw(st.lists(st.integers(-2 * N, 2 * N), min_size=m, max_size=m))
    kp, kd = data.draw(floats(0, 100)), data.draw(floats(0, 10))
    pd = PD(kp, kd, q_ref=0.5, v_ref=-0.25, feedforward=1.5, q_index=q_index, v_index=v_index)
    outside = [name for name, index in (("q_index", q_index), ("v_index", v_index))
               if any(not -N <= i < N for i in index)]
    if outside:
        with pytest.raises(ValueError, match=rf"PD's {outside[0]} .* out of range"):
            _call(pd)
        return
    q, v = np.arange(1.0, N + 1) * 0.1, -np.arange(1.0, N + 1)
    expected = kp * (0.5 - q[q_index]) + kd * (-0.25 - v[v_index]) + 1.5
    np.testing.assert_allclose(_call(pd), expected, rtol=1e-14, atol=1e-12)


@FEW
@given(name=st.sampled_from(["kp", "kd", "q_ref", "v_ref", "feedforward"]),
       shape=st.sampled_from([(2,), (4,), (N, 1), (1, N), (0,)]))
def test_pd_gains_of_the_wrong_length_are_named(name, shape):
    gains = dict(kp=1.0, kd=1.0, q_ref=0.0)
    gains[name] = np.ones(shape)
    with pytest.raises(ValueError, match=rf"PD's {name} must be a scalar or have shape \({N},\)"):
        _call(PD(**gains))


@DEFECT
@given(floats(0.01, N - 0.01).filter(lambda x: x != int(x)))
def test_pd_fractional_indices_are_refused(index):
    with pytest.raises((TypeError, ValueError), match="q_index"):
        _call(PD(1.0, 1.0, 0.0, q_index=[index], v_index=[0]))


# -- Sum ---------------------------------------------------------------------------------------------

@FEW
@given(st.lists(st.sampled_from([(), (1,), (2,), (3,)]), min_size=2, max_size=4), st.data())
def test_sums_of_controls_of_different_lengths_are_named_and_equal_ones_add(shapes, data):
    values = [np.asarray(data.draw(st.lists(floats(-1e3, 1e3), min_size=int(np.prod(s)),
                                            max_size=int(np.prod(s)))), float).reshape(s)
              for s in shapes]
    total = Constant(values[0])
    for value in values[1:]:
        total = total + value            # `a + b` with the constant on the right, as users write it
    assert isinstance(total, Sum) and len(total.terms) == len(values)
    if len({s for s in shapes if s != ()}) > 1:
        with pytest.raises(ValueError, match="the terms of a Sum of controls must give forces of "
                                             "one length"):
            _call(total)
        return
    np.testing.assert_allclose(_call(total), sum(values), rtol=1e-14, atol=1e-12)


# -- Saturated --------------------------------------------------------------------------------------

@FEW
@given(st.lists(floats(-1e6, 1e6), min_size=N, max_size=N), floats(1e-3, 1e3))
def test_saturation_is_limit_tanh_and_stays_inside_its_limit(x, limit):
    tau = _call(Saturated(Constant(x), limit))
    np.testing.assert_allclose(tau, limit * np.tanh(np.asarray(x) / limit), rtol=1e-14, atol=1e-300)
    assert np.all(np.abs(tau) <= limit)


@DEFECT
@given(st.sampled_from([0.0, -1.0, -1e-3, np.nan, -np.inf]))
def test_saturation_limit_that_is_not_positive_is_named(limit):
    with pytest.raises(ValueError, match="limit"):
        _call(Saturated(Constant(np.zeros(N)), limit))


# -- CubicSpline -------------------------------------------------------------------------------------

@FEW
@given(coefficients=st.lists(floats(-5, 5), min_size=8, max_size=8),
       duration=floats(0.5, 5.0), t0=floats(-1.0, 1.0), where=floats(0.0, 1.0))
def test_cubic_spline_fit_reproduces_cubics(coefficients, duration, t0, where):
    """A uniform cubic B-spline spans the cubics: the least-squares fit of samples of one is
    the cubic itself, everywhere in the span."""
    c = np.asarray(coefficients).reshape(4, 2)
    ts = t0 + np.linspace(0.0, duration, 41)

    def cubic(t):
        s = t - t0
        return c[0] + c[1] * s + c[2] * s**2 + c[3] * s**3

    spline = CubicSpline.fit(ts, np.stack([cubic(t) for t in ts]), 8, duration, t0=t0)
    t = t0 + where * duration
    scale = 1.0 + np.abs(c).sum() * max(1.0, duration) ** 3
    np.testing.assert_allclose(spline(jnp.asarray(t)), cubic(t), atol=1e-9 * scale)


@FEW
@given(rows=st.integers(0, 3), duration=st.sampled_from([0.0, -1.0, np.nan, -np.inf]))
def test_cubic_spline_too_few_knots_or_a_bad_duration_are_named(rows, duration):
    with pytest.raises(ValueError, match=r"knots must be \(n_knots >= 4, m\)"):
        CubicSpline(np.ones((rows, 2)), 1.0)
    with pytest.raises(ValueError, match="duration must be positive"):
        CubicSpline(np.ones((5, 2)), duration)


@DEFECT
@given(value=floats(1.0, 1e6), sign=st.sampled_from([1.0, -1.0]), limit=floats(0.1, 10.0))
def test_cubic_spline_constant_outside_its_limit_is_named(value, sign, limit):
    with pytest.raises(ValueError, match="limit"):
        CubicSpline.constant(sign * value * limit, 5, 1.0, limit=limit)


# -- ZeroOrderHold -----------------------------------------------------------------------------------

@FEW
@given(st.one_of(floats(max_value=0.0), st.just(np.nan)))
def test_zero_order_hold_step_that_is_not_positive_is_named(dt):
    with pytest.raises(ValueError, match="dt must be (positive|finite)"):
        ZeroOrderHold(np.ones(4), dt)


@DEFECT
@given(floats(-10, 10))
def test_zero_order_hold_of_a_scalar_is_named(value):
    with pytest.raises(ValueError, match="values"):
        ZeroOrderHold(value, 0.1)


@DEFECT
@given(st.sampled_from([np.nan, np.inf, -np.inf]))
def test_zero_order_hold_start_that_is_not_finite_is_named(t0):
    with pytest.raises(ValueError, match="t0"):
        ZeroOrderHold(np.arange(4.0), 0.1, t0=t0)


HOLD_DT, HOLD_STEPS = 0.01, 12
HELD = floats(-100, 100)


def _held(u):
    system = TreeSystem(SLIDER, ZeroOrderHold(np.asarray(u), HOLD_DT))
    t1 = HOLD_STEPS * HOLD_DT
    return simulate(system, RK4(), jnp.zeros(1), jnp.zeros(1), dt=HOLD_DT, t1=t1, saveat=[t1])


@FEW
@given(st.lists(HELD, min_size=HOLD_STEPS, max_size=HOLD_STEPS))
def test_held_force_on_a_point_mass_integrates_exactly(u):
    """Piecewise-constant force u_k on a mass m: x_N = dt^2 / m sum_k (N - k - 1/2) u_k and
    v_N = dt / m sum_k u_k, which RK4 integrates exactly when every stage sees u_k."""
    u = np.asarray(u)
    sol = _held(u)
    k = np.arange(HOLD_STEPS)
    scale = HOLD_DT * np.abs(u).sum() / MASS
    # no failure but, at most, the default check's INACCURATE (its defect's test is below)
    assert int(sol.status) & ~int(Status.INACCURATE) == 0
    np.testing.assert_allclose(sol.qs[-1, 0], HOLD_DT**2 / MASS * np.sum((HOLD_STEPS - k - 0.5) * u),
                               atol=1e-13 * scale + 1e-300)
    np.testing.assert_allclose(sol.vs[-1, 0], HOLD_DT / MASS * u.sum(), atol=1e-13 * scale + 1e-300)


@pytest.mark.xfail(strict=True, reason="issue 43: simulate's default resolution check flags a held "
                   "force that RK4 integrates exactly (a coast, then forces reversing between steps) "
                   "as INACCURATE ('the steps do not resolve the motion: step x rate reached 1.5')")
@DEFECT
@example(u=[1.0, -1.5, 0.0, 0.0, 0.0, 0.0, 2.0, -4.0, 3.0, 0.0, -2.0, 0.0])
@given(u=st.lists(HELD, min_size=HOLD_STEPS, max_size=HOLD_STEPS))
def test_an_exactly_integrated_held_force_is_not_flagged_inaccurate(u):
    assert _held(u).messages() == ["success"]


@FEW
@given(kp=floats(0.0, 100.0), kd=floats(0.0, 10.0), target=floats(-1, 1), x0=floats(-1, 1),
       v0=floats(-2, 2))
def test_a_sampled_servo_is_the_discrete_time_loop(kp, kd, target, x0, v0):
    """SampleAndHold(PD): u_k = kp (r - x_k) - kd v_k held over step k, so (exactly, for RK4)
    x_(k+1) = x_k + dt v_k + dt^2 u_k / (2 m), v_(k+1) = v_k + dt u_k / m (NumPy's recursion)."""
    system = TreeSystem(SLIDER, SampleAndHold(PD(kp, kd, target)))
    t1 = HOLD_STEPS * HOLD_DT
    sol = simulate(system, RK4(), jnp.array([x0]), jnp.array([v0]), dt=HOLD_DT, t1=t1)
    x, v, xs = x0, v0, [x0]
    for _ in range(HOLD_STEPS):
        u = kp * (target - x) - kd * v
        x, v = x + HOLD_DT * v + HOLD_DT**2 * u / (2 * MASS), v + HOLD_DT * u / MASS
        xs.append(x)
    assert int(sol.status) & int(Status.failures()) & ~int(Status.INACCURATE) == 0
    np.testing.assert_allclose(sol.qs[:, 0], xs, atol=1e-12 * (1 + abs(x0) + abs(v0) + abs(target)))


# -- PD through simulate -----------------------------------------------------------------------------

SERVO_DT, SERVO_T1 = 0.002, 0.4


def _servo(kp, kd, target, x0, v0):
    system = TreeSystem(SLIDER, PD(kp, kd, target))
    return simulate(system, RK4(), jnp.array([x0]), jnp.array([v0]), dt=SERVO_DT, t1=SERVO_T1,
                    saveat=[SERVO_T1])


@FEW
@given(kp=floats(0.0, 50.0), kd=floats(0.0, 10.0), target=floats(-1, 1),
       x0=floats(-1, 1), v0=floats(-2, 2))
def test_pd_servo_on_a_slider_is_the_damped_oscillator(kp, kd, target, x0, v0):
    """m x'' = kp (r - x) - kd x': (x - r, x')(t) = expm(A t) (x0 - r, v0), A = [[0, 1],
    [-kp/m, -kd/m]] (SciPy's matrix exponential)."""
    sol = _servo(kp, kd, target, x0, v0)
    A = np.array([[0.0, 1.0], [-kp / MASS, -kd / MASS]])
    error, rate = scipy.linalg.expm(A * SERVO_T1) @ np.array([x0 - target, v0])
    assert bool(sol.ok)
    np.testing.assert_allclose([sol.qs[-1, 0], sol.vs[-1, 0]], [target + error, rate], atol=1e-7)


@FEW
@given(gain=st.sampled_from(["kp", "kd", "target"]),
       value=st.sampled_from([np.nan, np.inf, -np.inf, 1e308, -1e308]))
def test_nonfinite_gains_give_a_nonfinite_status_not_a_silent_nan(gain, value):
    args = dict(kp=4.0, kd=1.0, target=0.5, x0=0.1, v0=0.0)
    args[gain] = value
    sol = _servo(**args)
    finite = bool(np.all(np.isfinite(sol.qs)) and np.all(np.isfinite(sol.vs)))
    if not finite:
        assert int(sol.status) & Status.NONFINITE and not bool(sol.ok)
        assert sol.messages()[0].startswith("nonfinite")
    else:
        assert bool(sol.ok)


# -- the control's forces through TreeSystem ---------------------------------------------------------

@jax.jit
def _acceleration(system, q, v):
    return system.acceleration(jnp.asarray(0.0), q, v)


@FEW
@given(size=st.integers(0, 4), force=floats(-1e3, 1e3))
def test_constant_forces_of_the_wrong_length_are_named_and_the_right_one_accelerates(size, force):
    if size != 1:
        with pytest.raises(ValueError, match=r"constant control \(tau\) must have shape \(1,\)"):
            TreeSystem(SLIDER, np.full(size, force))
        return
    a = _acceleration(TreeSystem(SLIDER, np.full(1, force)), jnp.zeros(1), jnp.zeros(1))
    np.testing.assert_allclose(a, [force / MASS], rtol=1e-14, atol=1e-300)


@FEW
@given(shape=st.sampled_from([(), (2,), (1, 1), (0,)]))
def test_a_control_law_returning_the_wrong_shape_is_named(shape):
    system = TreeSystem(SLIDER, lambda t, q, v: jnp.zeros(shape))
    with pytest.raises(ValueError, match=r"the control returned shape .*expects \(1,\)"):
        system.acceleration(0.0, jnp.zeros(1), jnp.zeros(1))


@DEFECT
@given(floats(0.1, 10.0))
def test_a_control_law_returning_complex_forces_is_named(imag):
    system = TreeSystem(SLIDER, lambda t, q, v: jnp.ones(1) + 1j * imag)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(TypeError, match="control"):
            system.acceleration(0.0, jnp.zeros(1), jnp.zeros(1))


# -- MLPPolicy ---------------------------------------------------------------------------------------

@settings(max_examples=10, deadline=None)     # each size is a new network: eager ops compile anew
@given(n_in=st.integers(1, 8), n_out=st.integers(1, 2), time=st.booleans(), seed=st.integers(0, 99))
def test_mlp_policy_of_the_wrong_input_size_is_named_and_the_untrained_one_is_zero(n_in, n_out,
                                                                                     time, seed):
    policy = MLPPolicy(n_in, n_out, key=jax.random.key(seed), width=4, time=time)
    if n_in != 2 * N:
        with pytest.raises(ValueError, match=rf"MLPPolicy takes {n_in + time} inputs"):
            _call(policy)
        return
    np.testing.assert_array_equal(_call(policy), np.zeros(n_out))     # its last layer starts at 0


@DEFECT
@given(st.integers(-5, -1))
def test_mlp_policy_negative_depth_is_named(depth):
    with pytest.raises(ValueError, match="depth"):
        MLPPolicy(2 * N, 1, key=jax.random.key(0), depth=depth)


@DEFECT
@given(st.sampled_from([0.0, -1.0, np.nan]))
def test_mlp_policy_limit_that_is_not_positive_is_named(limit):
    with pytest.raises(ValueError, match="limit"):
        _call(MLPPolicy(2 * N, 1, key=jax.random.key(0), width=4, limit=limit))
