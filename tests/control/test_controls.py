"""Controls and external wrenches on every system, each against an independent computation:
closed forms (a force on a point mass, a torque on a body), the generalized forces J^T f from
autodiff of the body positions, the Carpal Wrist's closed-form Newton-Euler Jacobians, and the
exact sums a sampled control must reproduce."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import Dense, Recursive
from mbjax.control import PD, Constant, CubicSpline, MLPPolicy, SampleAndHold, Saturated, Sum, ZeroOrderHold
from mbjax.integrate import RK4, simulate
from mbjax.model import Model, chain
from mbjax.rigid import RigidBody, TreeSystem, forward_dynamics, forward_kinematics
from mbjax.scenes import carpal_wrist as cw
from mbjax.wrist import WristSystem
from mbjax._src.wrist import newton_euler


def test_zero_order_hold_takes_the_value_of_its_interval_and_holds_it_over_a_step():
    u = ZeroOrderHold(jnp.arange(5.0) ** 2, dt=0.1, t0=1.0)
    times = jnp.array([0.0, 1.0, 1.05, 1.1 - 1e-12, 1.1, 1.3, 9.0])
    np.testing.assert_array_equal(jax.vmap(lambda t: u(t, None, None)[0])(times),
                                  [0.0, 0.0, 0.0, 1.0, 1.0, 9.0, 16.0])
    held = u.hold(jnp.asarray(1.2), None, None)
    assert isinstance(held, Constant) and float(held(5.0, None, None)[0]) == 4.0
    law = PD(2.0, 0.5, jnp.ones(2))
    sampled = SampleAndHold(law).hold(0.0, jnp.zeros(2), jnp.zeros(2))
    np.testing.assert_array_equal(sampled(1.0, jnp.ones(2), jnp.ones(2)), [2.0, 2.0])


def test_sampled_force_on_a_point_mass_integrates_exactly():
    """A unit mass on a slider under a zero-order-held force u_k: the motion is piecewise
    quadratic, which RK4 integrates exactly when every stage of step k sees u_k (`hold`);
    x_N = dt^2 sum_k (N - k - 1/2) u_k."""
    slider = Model([-1], "prismatic", mass=[1.0], inertia=[np.eye(3)], axis=[1.0, 0.0, 0.0],
                   gravity=(0.0, 0.0, 0.0))
    dt, n = 0.01, 20
    u = jnp.sin(jnp.arange(n) * 0.7) + 0.3
    system = TreeSystem(slider, ZeroOrderHold(u, dt))
    sol = simulate(system, RK4(), jnp.zeros(1), jnp.zeros(1), dt=dt, t1=n * dt, saveat=[n * dt])
    k = jnp.arange(n)
    np.testing.assert_allclose(sol.qs[-1, 0], dt**2 * jnp.sum((n - k - 0.5) * u), rtol=1e-13)
    np.testing.assert_allclose(sol.vs[-1, 0], dt * jnp.sum(u), rtol=1e-13)


def test_cubic_spline_fits_cubics_and_stays_inside_its_limit():
    ts = np.linspace(0.0, 2.0, 41)
    values = np.stack([0.3 * ts**3 - ts, 0.1 * ts**2 + 0.2], 1)
    spline = CubicSpline.fit(ts, values, 9, 2.0)
    np.testing.assert_allclose(jax.vmap(spline)(ts), values, atol=1e-10)
    saturated = CubicSpline(jnp.full((6, 2), 50.0), 1.0, limit=2.0)
    assert float(jnp.abs(saturated(0.5)).max()) <= 2.0
    np.testing.assert_allclose(CubicSpline.constant([0.5, -1.0], 5, 1.0, limit=2.0)(0.3), [0.5, -1.0])


def test_pd_sum_saturation_and_policy():
    q, v = jnp.array([0.1, 0.2, 0.3, 0.4]), jnp.array([1.0, 2.0, 3.0])
    pd = PD(10.0, 1.0, q_ref=jnp.array([0.0, 1.0]), feedforward=0.5, q_index=[1, 3], v_index=[0, 2])
    np.testing.assert_allclose(pd(0.0, q, v), [10 * -0.2 - 1.0 + 0.5, 10 * 0.6 - 3.0 + 0.5])
    both = pd + Constant([1.0, 1.0])
    assert isinstance(both, Sum)
    np.testing.assert_allclose(both(0.0, q, v), pd(0.0, q, v) + 1.0)
    np.testing.assert_allclose(Saturated(Constant([100.0]), 3.0)(0.0, q, v), [3.0])
    policy = MLPPolicy(4 + 3, 2, key=jax.random.key(0), width=8)
    np.testing.assert_array_equal(policy(0.0, q, v), 0.0)       # starts as no control at all
    grads = eqx.filter_grad(lambda p: jnp.sum(p(0.0, q, v)))(policy)
    assert float(jnp.abs(grads.mlp.layers[-1].bias).max()) > 0
    with pytest.raises(ValueError, match="q_index and v_index"):
        PD(1.0, 1.0, 0.0, q_index=[0])


def test_bad_controls_get_clear_errors():
    model = chain(3)
    with pytest.raises(TypeError, match="an instance"):
        TreeSystem(model, PD)
    with pytest.raises(TypeError, match="callable"):
        TreeSystem(model, "torque")
    with pytest.raises(ValueError, match=r"tau\) must have shape \(2,\)"):
        TreeSystem(model, jnp.zeros(3), actuation=[0, 2])
    with pytest.raises(ValueError, match="distinct indices"):
        TreeSystem(model, actuation=[0, 3])
    system = TreeSystem(model, lambda t, q, v: jnp.zeros(2))
    with pytest.raises(ValueError, match=r"control returned shape \(2,\).*expects \(3,\)"):
        system.acceleration(0.0, model.neutral(), jnp.zeros(3))
    system = TreeSystem(model, external=lambda t, q, v: jnp.zeros(6))
    with pytest.raises(ValueError, match=r"shape \(3, 6\)"):
        system.acceleration(0.0, model.neutral(), jnp.zeros(3))


def _generalized(model, q, wrench, point):
    """J^T f from autodiff of the world positions of the points and orientations (no recursion)."""
    def power(v):
        def pose(s):
            R, p = forward_kinematics(model, q + s * v)
            return R, p + jnp.einsum("kij,kj->ki", R, point)
        (R, _), (R_dot, x_dot) = jax.jvp(pose, (0.0,), (1.0,))
        W = R_dot @ jnp.swapaxes(R, -1, -2)
        omega = jnp.stack([W[:, 2, 1], W[:, 0, 2], W[:, 1, 0]], -1)
        return jnp.sum(wrench[:, :3] * omega) + jnp.sum(wrench[:, 3:] * x_dot)
    return jax.grad(power)(jnp.zeros(model.nv))


@pytest.mark.parametrize("method", [Recursive(), Dense()], ids=["recursive", "dense"])
def test_external_wrenches_and_actuation_on_a_tree(method):
    """A chain with a control on two of its joints and a world wrench on every body at a body
    point: the same accelerations as the plain forward dynamics under tau = B u + J^T f."""
    model = chain(4, seed=3)
    rng = np.random.default_rng(0)
    q, v = jnp.asarray(rng.normal(size=4)), jnp.asarray(rng.normal(size=4))
    wrench, point = jnp.asarray(rng.normal(size=(4, 6))), jnp.asarray(rng.normal(size=(4, 3)))
    u = jnp.array([0.7, -0.4])
    system = TreeSystem(model, Constant(u), actuation=[1, 3], external=lambda t, q_, v_: wrench,
                        external_point=point, method=method)

    @jax.jit
    def both(q, v):
        tau = jnp.zeros(4).at[jnp.array([1, 3])].set(u) + _generalized(model, q, wrench, point)
        return system.acceleration(0.0, q, v), forward_dynamics(model, q, v, tau), tau

    a, expected, tau = both(q, v)
    assert float(jnp.abs(tau).min()) > 1e-3
    np.testing.assert_allclose(a, expected, rtol=1e-11, atol=1e-11)


def test_rigid_body_control_and_external_wrench():
    """A free body: a world force at a point off the centre of mass accelerates the centre by
    F / m and turns the body by (R r) x F; a body-frame control torque adds to it."""
    J = np.diag([1.0, 2.0, 3.0])
    R0 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    F, r, torque = np.array([1.0, 2.0, -0.5]), np.array([0.1, 0.0, 0.3]), np.array([0.2, 0.0, 0.1])
    wrench = jnp.concatenate([jnp.zeros(3), F])[None]
    body = RigidBody(2.0, J, control=jnp.concatenate([torque, jnp.zeros(3)]),
                     external=lambda t, q, u: wrench, external_point=r)
    q, u = body.initial_state(R0, np.zeros(3))
    a = body.acceleration(0.0, q, u)
    np.testing.assert_allclose(a[3:], body.gravity + F / 2.0, rtol=1e-14)
    expected = np.linalg.solve(J, torque + R0.T @ np.cross(R0 @ r, F))
    np.testing.assert_allclose(a[:3], expected, rtol=1e-13, atol=1e-15)
    with pytest.raises(ValueError, match=r"shape \(6,\)"):
        RigidBody(2.0, J, control=jnp.zeros(3))


def test_wrist_external_wrench_through_the_newton_euler_jacobians():
    """The tool wrench's motor torques by the reverse pass of `external_torques` against the
    closed-form Jacobians of the Newton-Euler route: tau = J_v^T F + J_omega^T n at the centre
    of mass; a wrench at another point adds the moment of its force."""
    system, theta, _ = cw.servo()
    wrist = system.model
    F, n = jnp.array([1.0, -2.0, 3.0]), jnp.array([0.1, 0.2, -0.3])
    J_v, J_omega = jax.jacfwd(newton_euler.tool_velocity, argnums=2)(wrist, theta, jnp.zeros(3))
    expected = J_v.T @ F + J_omega.T @ n
    at_com = WristSystem(wrist, external=lambda t, q, u: jnp.concatenate([n, F])[None],
                         external_point=wrist.tool_com)
    np.testing.assert_allclose(at_com.torques(0.0, theta, jnp.zeros(3)), expected, rtol=1e-12)
    lever = jnp.array([0.0, 0.02, 0.1])
    elsewhere = WristSystem(wrist, external=lambda t, q, u: jnp.concatenate([n, F])[None],
                            external_point=wrist.tool_com + lever)
    R = wrist.forward_kinematics(theta).rotation
    np.testing.assert_allclose(elsewhere.torques(0.0, theta, jnp.zeros(3)),
                               J_v.T @ F + J_omega.T @ (n + jnp.cross(R @ lever, F)), rtol=1e-12)


def test_pd_checks_its_indices_and_gains_against_the_state():
    """An index past the state (a gather would clamp it and servo the last coordinate), a gain
    of the wrong length and a servo of every coordinate on a floating base (nq != nv) are named
    errors, inside a simulation too; negative indices count from the end, as in NumPy."""
    q, v = jnp.array([0.1, 0.2, 0.3, 0.4]), jnp.array([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match=r"q_index \[4\] out of range for a state of 4"):
        PD(1.0, 1.0, 0.0, q_index=[1, 4], v_index=[0, 1])(0.0, q, v)
    with pytest.raises(ValueError, match=r"v_index \[3\] out of range for a state of 3"):
        PD(1.0, 1.0, 0.0, q_index=[1, 2], v_index=[0, 3])(0.0, q, v)
    with pytest.raises(ValueError, match=r"kp must be a scalar or have shape \(2,\) or \(2, 2\).*\(3,\)"):
        PD(jnp.ones(3), 1.0, 0.0, q_index=[1, 2], v_index=[0, 1])(0.0, q, v)
    with pytest.raises(ValueError, match="nq == nv.*nq = 4, nv = 3"):
        PD(1.0, 1.0, 0.0)(0.0, q, v)
    np.testing.assert_allclose(PD(2.0, 0.0, 0.0, q_index=[-1], v_index=[-1])(0.0, q, v), [-0.8])
    model = chain(3)
    system = TreeSystem(model, PD(jnp.full(4, 10.0), 1.0, 0.0))               # 4 gains, 3 joints
    with pytest.raises(ValueError, match=r"kp must be a scalar or have shape \(3,\) or \(3, 3\)"):
        simulate(system, RK4(), model.neutral(), jnp.zeros(3), dt=0.01, t1=0.02)


def test_pd_matrix_gains_place_every_mode_of_the_arm():
    """Gains w^2 M and 2 w M with the arm's mass matrix M at the target make the linearized
    closed loop M a = -kp e - kd e_dot exactly e_ddot = -w^2 e - 2 w e_dot: every eigenvalue of
    M^-1 kp is w^2 (against scalar multiples of M's diagonal, which leave a spread of modes);
    the law is kp @ e, and a (m, m + 1) gain is refused by name."""
    import mbjax
    arm = mbjax.load_urdf(mbjax.data.ARM7)
    q0, w = arm.home(), 10.0
    M = mbjax.mass_matrix(arm, q0)
    servo = PD(w**2 * M, 2 * w * M, q0)
    e, e_dot = jnp.linspace(-0.1, 0.1, 7), jnp.linspace(0.2, -0.3, 7)
    np.testing.assert_allclose(servo(0.0, q0 - e, -e_dot), M @ (w**2 * e + 2 * w * e_dot),
                               rtol=1e-12)
    np.testing.assert_allclose(np.linalg.eigvals(np.linalg.solve(M, w**2 * M)).real, w**2)
    spread = np.linalg.eigvals(np.linalg.solve(M, w**2 * np.diag(np.diag(M)))).real
    assert spread.max() / spread.min() > 10
    with pytest.raises(ValueError, match=r"kd must be a scalar or have shape \(7,\) or \(7, 7\)"):
        PD(1.0, jnp.ones((7, 8)), q0)(0.0, q0, jnp.zeros(7))
