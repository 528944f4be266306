"""Probes of closed loops (`mbjax.loops`, the cut joints of `mbjax.model`) (issue 43, item 5):
inputs drawn by hypothesis, each answered by a clear error naming the argument, a status, or the
right answer against an independent reference (the four-bar's forward kinematics written in NumPy,
central finite differences); never a silent NaN.

One tree carries every probe: the four-bar scene's crank, coupler and rocker (three revolute
joints about z), closed by cut joints drawn here."""

import functools
from typing import NamedTuple

import equinox as eqx
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import Phase, given, settings
from hypothesis import strategies as st

from mbjax import Status, lie, simulate
from mbjax.integrate import RK4
from mbjax.loops import (ClosedSystem, Coupled, CutJoint, Loops, Stabilized, consistent_state,
                         project_configuration, project_velocity)
from mbjax.loops import PointOnLine, Spherical
from mbjax.scenes import four_bar

# one xdist worker runs the module, so its programs compile once (the group tests/conftest.py
# adds comes after xdist has read the groups)
pytestmark = pytest.mark.xdist_group("tests/probe/test_probe_loops.py")

A_, B_, C_, D_ = four_bar.A_, four_bar.B_, four_bar.C_, four_bar.D_
# XLA flushes subnormal numbers to zero on the CPU: draws keep clear of them
floats = functools.partial(st.floats, allow_subnormal=False)
FEW = settings(max_examples=15, deadline=None)
# a defect's test stops at its first failing example: no shrinking (each would compile anew)
DEFECT = settings(max_examples=10, deadline=None, phases=[Phase.explicit, Phase.generate])
PIN = dict(origin_a=(B_, 0.0, 0.0), origin_b=(C_, 0.0, 0.0))     # the coupler-rocker pin


class Scene(NamedTuple):
    tree: object            # the four-bar's tree
    q0: np.ndarray          # its start on the loop
    v0: np.ndarray
    closed: ClosedSystem    # the tree closed at the pin by a spherical cut joint


@functools.cache
def _scene() -> Scene:
    """The probes' tree and closed system, built on first use (collection stays quick)."""
    system, q0, v0 = four_bar.build(closure=PointOnLine())
    return Scene(system.tree, np.asarray(q0), np.asarray(v0),
                 ClosedSystem(system.tree, [CutJoint(Spherical(), 1, 2, **PIN)]))


def _rz(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _frames(q):
    """The four-bar tree's frames (R, p) by hand: the crank at the origin, the coupler at the
    crank's tip, the rocker at (D, 0, 0); the ground as frame -1."""
    return {-1: (np.eye(3), np.zeros(3)),
            0: (_rz(q[0]), np.zeros(3)),
            1: (_rz(q[0] + q[1]), _rz(q[0]) @ np.array([A_, 0.0, 0.0])),
            2: (_rz(q[2]), np.array([D_, 0.0, 0.0]))}


def _gap(q, body_a, body_b, origin_a, origin_b):
    """A spherical cut joint's residual p_A - p_B from `_frames`."""
    frames = _frames(np.asarray(q, float))
    (Ra, pa), (Rb, pb) = frames[body_a], frames[body_b]
    return pa + Ra @ np.asarray(origin_a, float) - pb - Rb @ np.asarray(origin_b, float)


def _pin_gap(q):
    return _gap(q, 1, 2, PIN["origin_a"], PIN["origin_b"])


angles = floats(-np.pi, np.pi)
points = st.lists(floats(-1.0, 1.0), min_size=3, max_size=3)


# -- cut joints: bodies, frames, origins -------------------------------------------------------------

@FEW
@given(body_a=st.integers(-4, 6), body_b=st.integers(-4, 6), q=st.lists(angles, min_size=3, max_size=3))
def test_cut_joint_bodies_are_checked_against_the_tree_and_valid_ones_close_the_gap(body_a, body_b, q):
    n = _scene().tree.n_frames
    if body_a == body_b:
        with pytest.raises(ValueError, match=f"two different bodies, got body {body_a} twice"):
            CutJoint(Spherical(), body_a, body_b)
        return
    if body_a < 0:
        with pytest.raises(ValueError, match="body_a must be a body of the model"):
            CutJoint(Spherical(), body_a, body_b)
        return
    joint = CutJoint(Spherical(), body_a, body_b, **PIN)
    bad = next((b for b in (body_a, body_b) if b != -1 and not 0 <= b < n), None)
    if bad is not None:
        with pytest.raises(ValueError, match=rf"body {bad} is not in the tree \(0 \.\.\. {n - 1}"):
            ClosedSystem(_scene().tree, [joint])
        return
    loops = ClosedSystem(_scene().tree, [joint]).loops
    np.testing.assert_allclose(loops.phi(jnp.asarray(q)), _gap(q, body_a, body_b, **PIN), atol=1e-14)


@FEW
@given(body=st.one_of(floats(0.0, 2.0), st.text(max_size=2), st.none()))
def test_cut_joint_bodies_that_are_not_ints_are_named(body):
    with pytest.raises(TypeError, match="body_a and body_b must be body indices"):
        CutJoint(Spherical(), body, 2)


@FEW
@given(kind=st.text(max_size=12) | st.sampled_from(
    ["spherical", "revolute", "universal", "weld", "spatial_weld", "prismatic", "point_on_line",
     "point_on_plane"]))
def test_unknown_cut_joint_kinds_are_named(kind):
    with pytest.raises(TypeError, match=r"kind must be a cut-joint kind, one of .*Spherical\(\)"):
        CutJoint(kind, 1, 2)


quaternions = st.lists(floats(-1, 1), min_size=4, max_size=4).filter(
    lambda x: np.linalg.norm(x) > 0.1)


@FEW
@given(quaternion=quaternions, which=st.sampled_from(["rotation_a", "rotation_b"]),
       defect=st.sampled_from(["scaled", "perturbed", "reflected", "nan", "shape"]),
       size=floats(1e-4, 1.0), entry=st.integers(0, 8))
def test_cut_joint_frames_that_are_not_rotations_are_named(quaternion, which, defect, size, entry):
    q = np.asarray(quaternion) / np.linalg.norm(quaternion)
    R = np.asarray(lie.quat_to_matrix(jnp.asarray(q)))
    CutJoint(Spherical(), 1, 2, **{which: R})                   # a rotation to round-off builds
    if defect == "scaled":
        bad, message = (1.0 + size) * R, "must be a rotation matrix"
    elif defect == "perturbed":
        bad, message = R.copy(), "must be a rotation matrix"
        bad.flat[entry] += size
    elif defect == "reflected":
        bad, message = R @ np.diag([1.0, 1.0, -1.0]), "a reflection, not a rotation"
    elif defect == "nan":
        bad, message = R.copy(), "must be a rotation matrix"
        bad.flat[entry] = np.nan
    else:
        bad, message = R[:2], r"must be a rotation matrix of shape \(3, 3\)"
    with pytest.raises(ValueError, match=rf"cut joint Spherical\(\): {which} .*{message}"):
        CutJoint(Spherical(), 1, 2, **{which: bad})


@FEW
@given(which=st.sampled_from(["origin_a", "origin_b"]),
       shape=st.sampled_from([(), (2,), (4,), (3, 1), (1, 3), (0,)]))
def test_cut_joint_origins_of_the_wrong_shape_are_named(which, shape):
    with pytest.raises(ValueError, match=rf"{which} must be a point of shape \(3,\)"):
        CutJoint(Spherical(), 1, 2, **{which: np.zeros(shape)})


@DEFECT
@given(which=st.sampled_from(["origin_a", "origin_b"]), entry=st.integers(0, 2),
       value=st.sampled_from([np.nan, np.inf, -np.inf]))
def test_cut_joint_origins_that_are_not_finite_are_named(which, entry, value):
    origin = np.zeros(3)
    origin[entry] = value
    with pytest.raises(ValueError, match=which):
        CutJoint(Spherical(), 1, 2, **{which: origin})


# -- the residual and its Jacobian against NumPy -----------------------------------------------------

@eqx.filter_jit
def _phi_and_jacobian(joint, q):
    loops = Loops(_scene().tree, [joint])
    return loops.phi(q), loops.jacobian(q)


@FEW
@given(q=st.lists(angles, min_size=3, max_size=3), origin_a=points, origin_b=points)
def test_spherical_residual_is_the_hand_written_gap_and_its_jacobian_the_finite_differences(
        q, origin_a, origin_b):
    joint = CutJoint(Spherical(), 1, 2, origin_a=origin_a, origin_b=origin_b)
    phi, A = _phi_and_jacobian(joint, jnp.asarray(q))
    np.testing.assert_allclose(phi, _gap(q, 1, 2, origin_a, origin_b), atol=1e-14)
    h = 1e-6
    fd = np.stack([(_gap(np.asarray(q) + h * e, 1, 2, origin_a, origin_b)
                    - _gap(np.asarray(q) - h * e, 1, 2, origin_a, origin_b)) / (2 * h)
                   for e in np.eye(3)], axis=1)
    np.testing.assert_allclose(A, fd, atol=1e-8)


# -- consistent initial conditions -------------------------------------------------------------------

@FEW
@given(theta=angles, dq=st.lists(floats(-0.05, 0.05), min_size=3, max_size=3),
       v=st.lists(floats(-3, 3), min_size=3, max_size=3))
def test_consistent_state_lands_on_the_loop(theta, dq, v):
    """Projected from near the loop: the hand-written gap is zero and the velocity is along the
    loop (the gap's finite-difference derivative along v vanishes)."""
    start = np.asarray(four_bar.joint_angles(jnp.asarray(theta))) + np.asarray(dq)
    q, v = consistent_state(_scene().closed, start, np.asarray(v))
    q, v = np.asarray(q), np.asarray(v)
    assert np.linalg.norm(_pin_gap(q)) < 1e-10
    h = 1e-6
    rate = (_pin_gap(q + h * v) - _pin_gap(q - h * v)) / (2 * h)
    np.testing.assert_allclose(rate, 0.0, atol=1e-7 * (1 + np.abs(v).max()))


@FEW
@given(nq=st.integers(0, 5), nv=st.integers(0, 5))
def test_consistent_state_of_the_wrong_length_is_named(nq, nv):
    if (nq, nv) == (3, 3):
        nq = 4
    with pytest.raises(ValueError, match=rf"q and v must have shapes \(3,\) and \(3,\), got "
                                         rf"\({nq},\) and \({nv},\)"):
        consistent_state(_scene().closed, np.zeros(nq), np.zeros(nv))


@FEW
@given(which=st.sampled_from(["q", "v"]), entry=st.integers(0, 2),
       value=st.sampled_from([np.nan, np.inf, -np.inf]))
def test_consistent_state_that_is_not_finite_is_named(which, entry, value):
    state = {"q": _scene().q0.copy(), "v": _scene().v0.copy()}
    state[which][entry] = value
    with pytest.raises(ValueError, match="the initial state has non-finite entries"):
        consistent_state(_scene().closed, state["q"], state["v"])


@DEFECT
@given(st.sampled_from([0.0, -1.0, -1e-12, np.nan]))
def test_consistent_state_tolerance_that_is_not_positive_is_named(tol):
    with pytest.raises(ValueError, match="tol"):
        consistent_state(_scene().closed, _scene().q0, _scene().v0, tol=tol)


# -- the closed system's state -----------------------------------------------------------------------

@DEFECT
@given(nq=st.integers(1, 5), nv=st.integers(1, 5))
def test_initial_state_of_the_wrong_length_is_named(nq, nv):
    if (nq, nv) == (3, 3):
        nv = 2
    with pytest.raises(ValueError, match=r"\bq\b|\bv\b"):
        _scene().closed.initial_state(np.zeros(nq), np.zeros(nv))


@DEFECT
@given(which=st.sampled_from(["phi", "configuration", "velocity"]),
       n=st.sampled_from([2, 4]))
def test_projections_of_a_state_of_the_wrong_length_are_named(which, n):
    loops = _scene().closed.loops
    call = {"phi": lambda: loops.phi(jnp.zeros(n)),
            "configuration": lambda: project_configuration(loops, jnp.zeros(n)),
            "velocity": lambda: project_velocity(loops, _scene().q0, jnp.zeros(n))}[which]
    with pytest.raises(ValueError, match=r"\b[qv]\b.*\(3,\)"):
        call()


@FEW
@given(name=st.sampled_from(["q0", "v0"]), n=st.integers(0, 6).filter(lambda n: n != 3))
def test_simulating_a_state_of_the_wrong_length_is_named(name, n):
    q0, u0 = (np.zeros(n), _scene().v0) if name == "q0" else (_scene().q0, np.zeros(n))
    with pytest.raises(ValueError, match=rf"{name} must have shape \(3,\) for this system"):
        simulate(_scene().closed, RK4(), q0, u0, dt=1e-3, t1=2e-3)


@FEW
@given(offset=st.one_of(st.just(0.0), floats(1e-4, 0.1), floats(-0.1, -1e-4),
                        st.sampled_from([np.nan, np.inf])),
       entry=st.integers(0, 2))
def test_a_start_off_the_loop_is_flagged_and_a_nonfinite_one_is_nonfinite(offset, entry):
    """The status at the start: constraint violated exactly where the hand-written gap exceeds
    the system's tolerance (1e-6); a non-finite start is non-finite, never a success."""
    q0 = _scene().q0.copy()
    q0[entry] += offset
    sol = simulate(_scene().closed, RK4(), q0, _scene().v0, dt=1e-3, t1=3e-3)
    status = int(sol.status)
    if not np.isfinite(offset):
        assert status & Status.NONFINITE and not bool(sol.ok)
        return
    gap = np.linalg.norm(_pin_gap(q0))
    tolerance = _scene().closed.tolerance
    assert bool(status & Status.CONSTRAINT_VIOLATED) == (gap > tolerance)
    assert bool(sol.ok) == (gap <= tolerance)


# -- loop methods ------------------------------------------------------------------------------------

@FEW
@given(alpha=st.one_of(floats(0, 1e3), st.sampled_from([-1.0, -1e-9, np.nan])),
       beta=st.one_of(floats(0, 1e3), st.sampled_from([-1.0, -1e-9])),
       epsilon=st.one_of(floats(0, 1.0), st.sampled_from([-1.0, np.nan])))
def test_loop_method_gains_that_are_negative_or_nan_are_named(alpha, beta, epsilon):
    if alpha >= 0 and beta >= 0:
        assert Coupled(baumgarte=(alpha, beta)).baumgarte == (alpha, beta)
    else:
        with pytest.raises(ValueError, match=r"baumgarte must be two gains \(alpha, beta\) >= 0"):
            Coupled(baumgarte=(alpha, beta))
    if epsilon >= 0:
        assert Stabilized(epsilon=epsilon).epsilon == epsilon
    else:
        with pytest.raises(ValueError, match="epsilon and kappa must be >= 0"):
            Stabilized(epsilon=epsilon)


@DEFECT
@given(floats(0, 1e3))
def test_a_nan_baumgarte_beta_is_named(alpha):
    with pytest.raises(ValueError, match="baumgarte"):
        Coupled(baumgarte=(alpha, np.nan))


@DEFECT
@given(floats(0, 10))
def test_a_single_baumgarte_gain_is_named(gain):
    with pytest.raises((TypeError, ValueError), match="baumgarte"):
        Coupled(baumgarte=gain)
