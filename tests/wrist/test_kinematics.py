"""Carpal Wrist kinematics against `docs/carpal-wrist-model.md`: its check values, FK(IK(x)) == x over
the workspace, the Jacobian three ways, the singularity measures on both singularities, and
unreachable poses."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.scenes import carpal_wrist as cw
from mbjax.wrist import CarpalWrist
from mbjax._src.wrist import kinematics as kin


def unit_wrist(**kw):
    return CarpalWrist(0.5, 1.0, tool_mass=1.0, tool_inertia=np.eye(3) * 0.1, **kw)


def test_check_values_of_the_model_note():
    pose = unit_wrist().forward_kinematics(jnp.array([2.0, 2.0, 2.0]))
    np.testing.assert_allclose(pose.plunge, np.sin(2.0), rtol=0, atol=1e-15)
    assert abs(float(pose.beta)) < 1e-15
    np.testing.assert_allclose(pose.centre, [0.0, 0.0, 2 * np.sin(2.0)], rtol=0, atol=1e-15)
    np.testing.assert_allclose(pose.rotation, np.eye(3), atol=1e-15)


def test_knees_lie_on_the_midplane_and_the_plate_is_their_mirror():
    w = cw.wrist()
    theta = jnp.array([1.9, 2.5, 2.2])
    pose, knees = w.forward_kinematics(theta), kin.knees(w, theta)
    # every knee at the same distance h = N . m_i from the base centre's side of the plane
    h = knees @ pose.normal
    np.testing.assert_allclose(h, h[0], atol=1e-15)
    # the distal plate is the base plate mirrored in the midplane: c_D = 2 h N, R = H diag(1,1,-1)
    np.testing.assert_allclose(pose.centre, 2 * h[0] * pose.normal, atol=1e-15)
    H = np.eye(3) - 2 * np.outer(pose.normal, pose.normal)
    np.testing.assert_allclose(pose.rotation, H @ np.diag([1.0, 1.0, -1.0]), atol=1e-15)
    # and R = Rz(alpha) Ry(beta) Rz(-alpha): the zero-twist (constant-velocity) plate
    a, b = float(pose.alpha), float(pose.beta)
    Rz = lambda x: np.array([[np.cos(x), -np.sin(x), 0], [np.sin(x), np.cos(x), 0], [0, 0, 1]])  # noqa: E731
    Ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
    np.testing.assert_allclose(pose.rotation, Rz(a) @ Ry @ Rz(-a), atol=1e-15)
    np.testing.assert_allclose(np.linalg.det(np.asarray(pose.rotation)), 1.0, atol=1e-14)
    # the legs' joints: the distal revolutes sit on the plate (d_i = c_D + R b_i), each link is l
    b, m, d = np.asarray(w.leg_points(theta))
    np.testing.assert_allclose(b[:, 2], 0.0, atol=1e-15)
    np.testing.assert_allclose(d, pose.centre + b @ np.asarray(pose.rotation).T, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(m - b, axis=1), w.link_length, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(d - m, axis=1), w.link_length, atol=1e-14)


def _workspace_samples(w, n=2000, seed=0):
    rng = np.random.default_rng(seed)
    alpha = rng.uniform(-np.pi, np.pi, n)
    beta = rng.uniform(0.01, 1.4, n)
    plunge = rng.uniform(0.02, 0.095, n)
    ok = np.asarray(w.reachable(alpha, beta, plunge))
    return alpha[ok], beta[ok], plunge[ok]


def test_fk_of_ik_is_the_identity_over_the_workspace():
    w = cw.wrist()
    alpha, beta, plunge = _workspace_samples(w)
    assert len(alpha) > 500
    theta = jax.jit(jax.vmap(w.inverse_kinematics))(alpha, beta, plunge)
    pose = jax.jit(jax.vmap(w.forward_kinematics))(theta)
    np.testing.assert_allclose(pose.plunge, plunge, rtol=0, atol=1e-12)
    np.testing.assert_allclose(pose.beta, beta, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.angle(np.exp(1j * (np.asarray(pose.alpha) - alpha))), 0.0, atol=1e-12)
    # and IK(FK(theta)) == theta on the knees-out branch
    theta2 = jax.jit(jax.vmap(lambda t: w.solve_inverse_kinematics(*(lambda p: (p.plunge, p.slope))(
        w.forward_kinematics(t)))[0]))(theta)
    np.testing.assert_allclose(theta2, theta, rtol=0, atol=1e-11)


def test_home_pose_is_regular_and_differentiable():
    """beta = 0 is a singular chart for (alpha, beta), not for the wrist: the pose, the Jacobian
    and gradients through them are finite there."""
    w = cw.wrist()
    home = cw.home(w)
    pose = w.forward_kinematics(home)
    assert float(pose.beta) == 0.0 and float(pose.alpha) == 0.0
    grads = jax.jit(jax.jacfwd(lambda t: jnp.concatenate([w.forward_kinematics(t).centre,
                                                  w.forward_kinematics(t).rotation.ravel(),
                                                  jnp.stack([w.forward_kinematics(t).beta,
                                                             w.forward_kinematics(t).alpha])])))(home)
    assert np.all(np.isfinite(grads))
    rev = jax.grad(lambda t: w.forward_kinematics(t).beta + w.forward_kinematics(t).com.sum())(home)
    assert np.all(np.isfinite(rev))
    theta0, ok = w.solve_inverse_kinematics(cw.HOME_PLUNGE, jnp.zeros(2))
    assert bool(ok)
    g = jax.jit(jax.jacfwd(lambda s: w.solve_inverse_kinematics(cw.HOME_PLUNGE, s)[0]))(jnp.zeros(2))
    assert np.all(np.isfinite(g))


def test_jacobian_autodiff_closed_form_and_finite_differences():
    w = cw.wrist()
    rng = np.random.default_rng(1)
    for theta in cw.home(w) + rng.uniform(-0.4, 0.4, (5, 3)):
        J = np.asarray(w.jacobian(theta))
        np.testing.assert_allclose(w.jacobian_closed_form(theta), J, rtol=0, atol=1e-13)
        n = lambda t: np.asarray(kin._normal_plunge(w, jnp.asarray(t)))  # noqa: E731
        h = 1e-6
        fd = np.stack([(n(theta + h * e) - n(theta - h * e)) / (2 * h) for e in np.eye(3)], axis=1)
        np.testing.assert_allclose(fd, J, rtol=0, atol=1e-8)


def test_jacobian_of_the_chart_matches_the_velocity_of_the_knees():
    """(p, g)_dot = K^-1 D theta_dot: every knee's velocity lies in the moving midplane."""
    w = cw.wrist()
    theta, theta_dot = jnp.array([2.1, 2.4, 2.0]), jnp.array([0.3, -0.7, 0.2])
    (p, g), (p_dot, g_dot) = jax.jvp(lambda t: kin.midplane(w, t), (theta,), (theta_dot,))
    np.testing.assert_allclose(kin.chart_jacobian(w, theta) @ theta_dot,
                               jnp.concatenate([p_dot[None], g_dot]), atol=1e-13)


def test_singularity_measures_vanish_on_both_singularities():
    w = unit_wrist()
    # direct: rho1 rho2 + rho2 rho3 + rho3 rho1 = 0 with rho_i = 0.5 - cos(theta_i)
    rho = np.array([0.5, 0.5, -0.25])                 # 0.25 - 0.125 - 0.125 = 0
    theta = np.arccos(0.5 - rho)
    m = w.singularity_measures(theta)
    assert abs(float(m.direct)) < 1e-14
    assert float(m.condition) < 1e-12
    # inverse: a knee circle tangent to the midplane, a_i = +-1 (the workspace boundary)
    g = jnp.array([0.3, -0.2])
    k = kin.leg_directions(w) @ g
    plunge = w.link_length * jnp.sqrt(1 + k[0] ** 2) - w.base_radius * k[0]   # a_1 = 1 exactly
    theta, ok = w.solve_inverse_kinematics(plunge, g)
    assert bool(ok)
    m = w.singularity_measures(theta)
    assert abs(float(m.inverse)) < 1e-7
    assert float(m.condition) < 1e-6
    # far from both at the home pose
    m = cw.wrist().singularity_measures(cw.home())
    assert float(m.inverse) > 0.6 and float(m.direct) == pytest.approx(1.0)


def test_unreachable_pose_raises_and_the_status_route_stays_finite():
    w = cw.wrist()
    with pytest.raises(eqx.EquinoxRuntimeError, match="out of reach"):
        jax.block_until_ready(w.inverse_kinematics(0.3, 0.5, 0.2))     # plunge beyond the legs
    with pytest.raises(eqx.EquinoxRuntimeError, match="out of reach"):
        jax.block_until_ready(eqx.filter_jit(w.inverse_kinematics)(0.0, 0.4, 0.12))
    theta, ok = w.solve_inverse_kinematics(0.2, jnp.array([0.5, 0.0]))
    assert not bool(ok) and np.all(np.isfinite(theta))
    assert np.all(np.isfinite(jax.jit(jax.jacfwd(lambda p: w.solve_inverse_kinematics(p, jnp.array([0.5, 0.0]))[0]))(0.2)))
    assert not bool(w.reachable(0.0, 0.0, 0.11)) and bool(w.reachable(0.0, 0.0, 0.09))


def test_bad_parameters_are_rejected():
    with pytest.raises(ValueError, match="positive"):
        CarpalWrist(-0.5, 1.0, tool_mass=1.0, tool_inertia=np.eye(3))
    with pytest.raises(ValueError, match="positive definite"):
        CarpalWrist(0.5, 1.0, tool_mass=1.0, tool_inertia=np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(ValueError, match="rotation_model"):
        CarpalWrist(0.5, 1.0, tool_mass=1.0, tool_inertia=np.eye(3), rotation_model="euler")
