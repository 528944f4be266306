"""Configurations on their Lie group: `Model.integrate` and `Model.difference` against Pinocchio's
`integrate` and `difference` (after the state converters) on floating robots of
example-robot-data and on a spherical joint, their inverse relation, and finite derivatives at
zero and half turns."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax.lie import quat_to_matrix
from mbjax.model import Model, state_to_pinocchio
from mbjax.rigid import TreeSystem
from mbjax_harness.peers import random_state
from tests.conftest import example_robots

pin = pytest.importorskip("pinocchio")

QUICK_ROBOTS = ("hector/quadrotor_base", "solo/solo12", "kinova/kinova", "panda/panda")


def _against_pinocchio(model, pin_model, seed: int) -> float:
    """max |mbjax - Pinocchio| of integrate and difference at random states (Pinocchio's layout)."""
    q0, v, _ = random_state(model, seed)
    q1, _, _ = random_state(model, seed + 1)
    q0, q1, v = jnp.asarray(q0), jnp.asarray(q1), jnp.asarray(v)
    pq0, pv = (np.asarray(x) for x in state_to_pinocchio(model, q0, v))
    pq1 = np.asarray(state_to_pinocchio(model, q1, v)[0])
    integrated = np.asarray(state_to_pinocchio(model, model.integrate(q0, v), v)[0])
    difference = np.asarray(state_to_pinocchio(model, q0, model.difference(q0, q1))[1])
    return max(np.abs(integrated - pin.integrate(pin_model, pq0, pv)).max(),
               np.abs(difference - pin.difference(pin_model, pq0, pq1)).max())


def _floating_difference(path) -> float | None:
    try:
        model = mbjax.load_urdf(path, floating_base=True)
    except ValueError:               # a file that is not a robot
        return None
    pin_model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    return max(_against_pinocchio(model, pin_model, seed) for seed in (0, 2))


@pytest.mark.filterwarnings("ignore::mbjax.model.ModelWarning")   # implausible CAD inertias
def test_integrate_and_difference_equal_pinocchios():
    """A quadrotor, a quadruped, an arm with continuous joints and one with prismatic fingers,
    on free bases."""
    paths = example_robots(QUICK_ROBOTS)
    assert len(paths) == len(QUICK_ROBOTS)
    for path in paths:
        assert _floating_difference(path) < 1e-12, path


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::mbjax.model.ModelWarning")
def test_integrate_and_difference_on_every_floating_robot():
    worst = {path.stem: _floating_difference(path) for path in example_robots()}
    worst = {name: d for name, d in worst.items() if d is not None}
    assert len(worst) > 60 and max(worst.values()) < 1e-12, worst


def test_spherical_joint_equals_pinocchios():
    """A ball joint carrying a hinge (no URDF has one): Pinocchio's JointModelSpherical."""
    model = Model([-1, 0], ["spherical", "revolute"], mass=[1.0, 1.0],
                  inertia=[np.eye(3), np.eye(3)], axis=[[0, 0, 1], [0, 1, 0]],
                  placement_translation=[[0, 0, 0], [0, 0, -0.5]], lower=[-1, -1, -1, -1, -2],
                  upper=[1, 1, 1, 1, 2])
    pm = pin.Model()
    ball = pm.addJoint(0, pin.JointModelSpherical(), pin.SE3.Identity(), "joint0")
    pm.addJoint(ball, pin.JointModelRY(), pin.SE3(np.eye(3), np.array([0, 0, -0.5])), "joint1")
    assert max(_against_pinocchio(model, pm, seed) for seed in (0, 3)) < 1e-13


def test_difference_inverts_integrate_with_finite_derivatives_at_zero_and_half_turns():
    """difference(q, integrate(q, v)) = v; its Jacobian in v is the identity at v = 0 and
    finite (and equal to central differences) at a half turn of the free and ball joints."""
    model = Model([-1, 0, 1, 2], ["free", "spherical", "revolute", "universal"],
                  mass=[1.0] * 4, inertia=[np.eye(3)] * 4)
    q, _, _ = random_state(model, 5)
    q = jnp.asarray(q)
    rng = np.random.default_rng(1)
    for v in (jnp.zeros(model.nv), jnp.asarray(rng.normal(size=model.nv)),
              jnp.r_[jnp.pi, 0, 0, 0.3, 0.2, 0.1, 0, jnp.pi - 1e-9, 0, 0.5, 0.1, 0.2]):
        np.testing.assert_allclose(model.difference(q, model.integrate(q, v)), v, atol=1e-8)
        J = jax.jacfwd(lambda w: model.difference(q, model.integrate(q, w)))(v)
        assert np.isfinite(J).all()
        if not jnp.any(v):
            np.testing.assert_allclose(J, np.eye(model.nv), atol=1e-12)
    # at a half turn the quaternion may change sign (kept in q's hemisphere, as Pinocchio's):
    # compare what it describes, the rotation matrices and the positions
    half = jnp.r_[0, 0, jnp.pi, 0.3, 0.2, 0.1, 0, 0, jnp.pi, 0.5, 0.1, 0.2]

    def placed(w):
        q1 = model.integrate(q, w)
        return jnp.concatenate([q1[:3], quat_to_matrix(q1[3:7]).ravel(),
                                quat_to_matrix(q1[7:11]).ravel(), q1[11:]])

    J = jax.jacfwd(placed)(half)
    h = 1e-6
    fd = np.stack([(placed(half + h * e) - placed(half - h * e)) / (2 * h)
                   for e in np.eye(model.nv)], 1)
    assert np.isfinite(J).all()
    np.testing.assert_allclose(J, fd, atol=1e-7)


def test_continuous_angles_wrap_and_limited_ones_do_not():
    """Pinocchio's wrap for a joint without limits; without it (`wrap=False`, the systems' chart:
    mbjax's angles count turns) the exact inverse of integrate, which the solvers' feedback and
    defects use (a wrapped feedback jumps where a trajectory's change passes half a turn: iLQR
    stalled on the acrobot's swing-up at 200 iterations instead of 65)."""
    model = Model([-1, 0], "revolute", mass=[1.0, 1.0], inertia=[np.eye(3)] * 2,
                  lower=[-np.inf, -4.0], upper=[np.inf, 4.0])
    q0, q1 = jnp.array([3.0, 3.0]), jnp.array([-3.0, -3.0])
    np.testing.assert_allclose(model.difference(q0, q1), [2 * np.pi - 6.0, -6.0], atol=1e-15)
    np.testing.assert_allclose(model.difference(q0, q1, wrap=False), [-6.0, -6.0], atol=1e-15)
    np.testing.assert_allclose(TreeSystem(model).difference(q0, q1), [-6.0, -6.0], atol=1e-15)


def test_the_chart_rate_is_the_derivative_of_the_chart():
    """local_rate (what RKMK4 integrates) against the chart itself: d/dt integrate(q0, xi(t))
    with xi_dot = local_rate(q0, xi, v) is the configuration's rate q_dot(q, v) there, for the
    SE(3) chart of a free joint (its translation's rate carries Gamma's derivative)."""
    model = Model([-1, 0], ["free", "spherical"], mass=[1.0] * 2, inertia=[np.eye(3)] * 2)
    q0, v, _ = random_state(model, 11)
    rng = np.random.default_rng(4)
    xi = jnp.asarray(rng.normal(size=model.nv))
    q0, v = jnp.asarray(q0), jnp.asarray(v)
    xi_dot = model.local_rate(q0, xi, v)
    _, q_rate = jax.jvp(lambda x: model.integrate(q0, x), (xi,), (xi_dot,))
    np.testing.assert_allclose(q_rate, model.q_dot(model.integrate(q0, xi), v), atol=1e-12)


def test_every_systems_difference_inverts_its_retract():
    """The chart a trajectory optimiser steps in, for each kind of system: retract(q0,
    difference(q0, q1)) = q1 (rotations compared as matrices), for a floating tree, a flexible
    arm, a closed four-bar and a rigid body in both rotation coordinates."""
    from mbjax.flex import FlexibleSystem
    from mbjax.lie import Quaternion, RotationVector
    from mbjax.rigid import RigidBody
    from mbjax.scenes import four_bar, slewing_beam

    rng = np.random.default_rng(3)
    floating = Model([-1, 0], ["free", "revolute"], mass=[1.0] * 2, inertia=[np.eye(3)] * 2)
    arm = slewing_beam.model()
    closed = four_bar.build()[0]

    def placement(q):             # the free joint's rotation as a matrix, the rest as they are
        return jnp.concatenate([q[:3], quat_to_matrix(q[3:7]).ravel(), q[7:]])

    def body(rotation):
        system = RigidBody(1.0, np.eye(3), rotation=rotation)
        n = rotation.size
        return system, n + 3, lambda q: jnp.concatenate([rotation.to_matrix(q[:n]).ravel(), q[n:]])

    cases = [(TreeSystem(floating), floating.nq, placement), (FlexibleSystem(arm), arm.nq, None),
             (closed, closed.tree.nq, None), body(Quaternion()), body(RotationVector())]
    for system, nq, seen in cases:
        q0, q1 = (system.project(jnp.asarray(rng.uniform(-1.0, 1.0, nq))) for _ in range(2))
        back = system.retract(q0, system.difference(q0, q1))
        seen = seen or (lambda q: q)
        np.testing.assert_allclose(seen(back), seen(q1), atol=1e-12, err_msg=type(system).__name__)
