"""Probes of the time finite elements (`mbjax.tfe`) (issue 43, item 5): inputs drawn by
hypothesis, each answered by a clear error naming the argument, a status, or the right answer
against an independent reference (an isotropic body's closed-form rotation, Euler's equations
integrated by SciPy); never a silent NaN.

Every march is the same compiled program (a body about a fixed point, 8 elements of the
three-node primal form): the drawn bodies, states, steps and tolerances are its data."""

from functools import partial

import numpy as np
import pytest
from hypothesis import Phase, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from mbjax import Status
from mbjax._src.tfe import State
from mbjax.tfe import (Body, ConstantReference, Element, Mixed, PrimalUnsymmetric, initial_state,
                       solve_tfe)

# one xdist worker runs the module, so its programs compile once (the group tests/conftest.py
# adds comes after xdist has read the groups)
pytestmark = pytest.mark.xdist_group("tests/probe/test_probe_time_elements.py")

# XLA flushes subnormal numbers to zero on the CPU: draws keep clear of them
floats = partial(st.floats, allow_subnormal=False)
FEW = settings(max_examples=15, deadline=None)
# a defect's test stops at its first failing example: no shrinking (each would march anew)
DEFECT = settings(max_examples=10, deadline=None, phases=[Phase.explicit, Phase.generate])
N_ELEMENTS, DT = 8, 0.005
MARCH = dict(n_elements=N_ELEMENTS, form=PrimalUnsymmetric(), element=Element(3))
INERTIA = np.diag([0.1, 0.2, 0.25])
ASYMMETRIC = Body(1.0, INERTIA, gravity=(0.0, 0.0, 0.0), fixed_point=True)
STATE0 = initial_state(ASYMMETRIC, np.eye(3), [1.0, 0.5, -2.0])


def _march(body=ASYMMETRIC, state=STATE0, dt=DT, **kw):
    return solve_tfe(body, state, dt=dt, **{**MARCH, **kw})


def _rotation(quaternion):
    q = np.asarray(quaternion, float)
    return Rotation.from_quat(q / np.linalg.norm(q)).as_matrix()


def _euler(inertia, R0, Omega0, t1):
    """R(t1) of a torque-free body by SciPy: Euler's equations and R_dot = R [Omega]x."""
    def rhs(t, y):
        R, W = y[:9].reshape(3, 3), y[9:]
        hat = np.array([[0, -W[2], W[1]], [W[2], 0, -W[0]], [-W[1], W[0], 0]])
        return np.concatenate([(R @ hat).ravel(), np.linalg.solve(inertia, -np.cross(W, inertia @ W))])
    y = solve_ivp(rhs, (0.0, t1), np.concatenate([R0.ravel(), Omega0]), method="DOP853",
                  rtol=1e-12, atol=1e-12).y[:, -1]
    return y[:9].reshape(3, 3)


quaternions = st.lists(floats(-1, 1), min_size=4, max_size=4).filter(
    lambda x: np.linalg.norm(x) > 0.1)
rates = st.lists(floats(-3, 3), min_size=3, max_size=3)


# -- the right answer --------------------------------------------------------------------------------

@FEW
@given(quaternion=quaternions, Omega=rates, moment=floats(0.01, 10.0), dt=floats(1e-3, 0.05))
def test_an_isotropic_body_turns_at_its_constant_rate(quaternion, Omega, moment, dt):
    """R(t) = exp(t [w]x) R0 with w = R0 Omega in space, and the momentum J w constant."""
    R0, Omega = _rotation(quaternion), np.asarray(Omega)
    body = Body(1.0, moment * np.eye(3), gravity=(0.0, 0.0, 0.0), fixed_point=True)
    sol = _march(body, initial_state(body, R0, Omega), dt)
    t1 = N_ELEMENTS * 2 * dt                                   # three nodes: two spacings each
    assert sol.messages() == ["success"]
    np.testing.assert_allclose(sol.ts[-1], t1, rtol=1e-14)
    np.testing.assert_allclose(sol.R[-1], Rotation.from_rotvec(R0 @ Omega * t1).as_matrix() @ R0,
                               atol=1e-11)
    np.testing.assert_allclose(sol.p_hat, np.tile(moment * R0 @ Omega, (N_ELEMENTS + 1, 1)),
                               atol=1e-11 * (1 + moment * np.abs(Omega).max()))


@FEW
@given(quaternion=quaternions, Omega=rates)
def test_an_asymmetric_body_follows_euler_equations(quaternion, Omega):
    R0, Omega = _rotation(quaternion), np.asarray(Omega)
    sol = _march(state=initial_state(ASYMMETRIC, R0, Omega))
    assert sol.messages() == ["success"]
    np.testing.assert_allclose(sol.R[-1], _euler(INERTIA, R0, Omega, float(sol.ts[-1])), atol=1e-7)


@FEW
@given(quaternion=quaternions, Omega=rates)
def test_the_initial_momentum_is_the_body_inertia_times_the_rate(quaternion, Omega):
    """p_hat = R0 J_bar Omega0 about a fixed point (the momentum of eq 3.19 in space)."""
    R0 = _rotation(quaternion)
    state = initial_state(ASYMMETRIC, R0, Omega)
    np.testing.assert_allclose(state.p_hat, R0 @ INERTIA @ np.asarray(Omega), atol=1e-14)


# -- bad arguments: errors or statuses ---------------------------------------------------------------

@FEW
@given(quaternion=quaternions, defect=st.sampled_from(["scaled", "perturbed", "reflected", "nan"]),
       size=floats(1e-4, 1.0), entry=st.integers(0, 8))
def test_an_initial_attitude_that_is_not_a_rotation_is_named(quaternion, defect, size, entry):
    R = _rotation(quaternion)
    if defect == "scaled":
        bad, message = (1.0 + size) * R, r"R0 must be a rotation matrix \(R\^T R = I"
    elif defect == "perturbed":
        bad, message = R.copy(), r"R0 must be a rotation matrix \(R\^T R = I"
        bad.flat[entry] += size
    elif defect == "reflected":
        bad, message = -R, "R0 has determinant -1: a reflection"
    else:
        bad, message = R.copy(), r"R0 must be a rotation matrix \(R\^T R = I"
        bad.flat[entry] = np.nan
    with pytest.raises(ValueError, match=message):
        initial_state(ASYMMETRIC, bad, [0.0, 0.0, 1.0])


@FEW
@given(field=st.sampled_from(["R", "x", "p_hat"]),
       shape=st.sampled_from([(), (2,), (4,), (6,), (3, 3), (2, 2), (3, 1), (1, 3, 3)]))
def test_a_state_of_the_wrong_shape_is_named(field, shape):
    good = {"R": (3, 3), "x": (3,), "p_hat": (3,)}
    if shape == good[field]:
        shape = (5,)
    parts = {"R": np.eye(3), "x": np.zeros(3), "p_hat": np.ones(3)}
    parts[field] = np.zeros(shape)
    with pytest.raises(ValueError, match=rf"state0\.{field} must (be a rotation matrix of shape "
                                         rf"\(3, 3\)|have shape \(3,\))"):
        _march(state=State(parts["R"], parts["x"], parts["p_hat"]))


@FEW
@given(st.sampled_from([tuple, list, dict]))
def test_a_state_that_is_not_a_state_is_named(kind):
    parts = (np.eye(3), np.zeros(3), np.ones(3))
    state = dict(R=parts[0], x=parts[1], p_hat=parts[2]) if kind is dict else kind(parts)
    with pytest.raises(TypeError, match="state0 must be a tfe.State"):
        _march(state=state)


@FEW
@given(st.one_of(st.integers(-3, 0), floats(0.5, 9.5), st.just("8"), st.just(None)))
def test_element_counts_that_are_not_positive_ints_are_named(n):
    with pytest.raises(ValueError, match="n_elements must be a positive int"):
        _march(n_elements=n)


@DEFECT
@given(st.just(True))
def test_a_boolean_element_count_is_named(n):
    with pytest.raises(ValueError, match="n_elements"):
        _march(n_elements=n)


@FEW
@given(st.sampled_from([0.0, np.nan, np.inf, -np.inf, 1e6, -1e6]))
def test_a_degenerate_step_is_named_or_flagged(dt):
    """dt = 0, NaN, inf or absurdly large: an error naming dt, or a status that is not a
    success; never a success with non-finite states."""
    try:
        sol = _march(dt=dt)
    except ValueError as error:
        assert "dt" in str(error)
        return
    finite = bool(np.isfinite(sol.R).all() and np.isfinite(sol.p_hat).all())
    assert not bool(sol.ok) or (finite and np.isfinite(dt))
    if not finite:
        assert int(sol.status) & Status.NONFINITE


@FEW
@given(floats(-DT, -1e-3))
def test_a_negative_step_is_named_or_marches_back_in_time(dt):
    """Either refused by name, or the march back in time: R(t) with t < 0 by SciPy (Euler's
    equations are reversible)."""
    try:
        sol = _march(dt=dt)
    except ValueError as error:
        assert "dt" in str(error)
        return
    t1 = float(sol.ts[-1])
    assert t1 < 0 and sol.messages() == ["success"]
    # backwards: R(t1) is R(-t1) of the motion with the rate reversed, W = -Omega (Euler's
    # equations are quadratic in the rate)
    expected = _euler(INERTIA, np.eye(3), -np.array([1.0, 0.5, -2.0]), -t1)
    np.testing.assert_allclose(sol.R[-1], expected, atol=1e-7)


@FEW
@given(st.sampled_from([0.0, -1.0, -1e-10, np.nan]))
def test_a_newton_tolerance_that_cannot_be_met_is_named_or_flagged(tol):
    try:
        sol = _march(tol=tol)
    except ValueError as error:
        assert "tol" in str(error)
        return
    assert int(sol.status) & Status.NOT_CONVERGED and not bool(sol.ok)


@DEFECT
@given(st.just(np.inf))
def test_an_infinite_newton_tolerance_is_named_or_still_right(tol):
    try:
        sol = _march(tol=tol)
    except ValueError as error:
        assert "tol" in str(error)
        return
    assert not bool(sol.ok) or np.abs(
        np.asarray(sol.R[-1]) - _euler(INERTIA, np.eye(3), np.array([1.0, 0.5, -2.0]),
                                       float(sol.ts[-1]))).max() < 1e-7


@DEFECT
@given(entry=st.integers(0, 2), value=st.sampled_from([np.nan, np.inf]))
def test_a_nonfinite_initial_position_is_named_or_flagged(entry, value):
    x0 = np.zeros(3)
    x0[entry] = value
    try:
        state = initial_state(ASYMMETRIC, np.eye(3), [1.0, 0.5, -2.0], x0=x0)
        sol = _march(state=state)
    except ValueError as error:
        assert "x0" in str(error) or "state0.x" in str(error)
        return
    assert np.isfinite(sol.x).all() or not bool(sol.ok)


@FEW
@given(entry=st.integers(0, 2), value=st.sampled_from([np.nan, np.inf, -np.inf]))
def test_a_nonfinite_initial_rate_is_flagged(entry, value):
    Omega = np.array([1.0, 0.5, -2.0])
    Omega[entry] = value
    try:
        sol = _march(state=initial_state(ASYMMETRIC, np.eye(3), Omega))
    except ValueError as error:
        assert "Omega0" in str(error)
        return
    assert int(sol.status) & Status.NONFINITE and not bool(sol.ok)


@DEFECT
@given(st.sampled_from([0, 1, 2, 4, 6]))
def test_an_initial_rate_of_the_wrong_length_is_named(n):
    with pytest.raises(ValueError, match="Omega0"):
        initial_state(ASYMMETRIC, np.eye(3), np.ones(n))


@FEW
@given(st.text(max_size=20) | st.sampled_from(["constant", "constant_velocity", ConstantReference]))
def test_unknown_references_are_named(reference):
    with pytest.raises(TypeError, match="reference must be a reference strategy"):
        _march(reference=reference)


@DEFECT
@given(st.sampled_from(["mixed", Mixed, 3]))
def test_a_form_that_is_not_a_form_instance_is_named(form):
    with pytest.raises(TypeError, match="form"):
        _march(form=form)


@DEFECT
@given(st.integers(-5, -1))
def test_a_negative_iteration_count_is_named(max_iter):
    with pytest.raises(ValueError, match="max_iter"):
        _march(max_iter=max_iter)


@FEW
@given(mass=st.sampled_from([0.0, -1.0, np.nan, -np.inf]),
       com=st.sampled_from([(0.0, 0.0), (np.nan, 0.0, 0.0), (0.0, np.inf, 0.0)]))
def test_body_masses_and_centres_that_are_not_physical_are_named(mass, com):
    with pytest.raises(ValueError, match="mass must be positive"):
        Body(mass, INERTIA)
    with pytest.raises(ValueError, match="com must be a finite 3-vector"):
        Body(1.0, INERTIA, com=com)


@DEFECT
@given(st.sampled_from([(0.0, 0.0), (0.0, 0.0, -9.81, 0.0), ()]))
def test_gravity_of_the_wrong_shape_is_named(gravity):
    try:
        body = Body(1.0, INERTIA, com=(0.0, 0.0, 0.1), gravity=gravity, fixed_point=True)
        _march(body=body, state=initial_state(body, np.eye(3), [0.0, 0.0, 1.0]))
    except ValueError as error:
        assert "gravity" in str(error)
        return
    raise AssertionError("a body with gravity of shape "
                         f"{np.shape(gravity)} marched without an error")

