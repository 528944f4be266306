"""Carpal Wrist dynamics: the autodiff Lagrangian (eq 6.16) against the independent Newton-Euler
route, identities between its terms, and the chapter's rotation variant."""

import jax
import jax.numpy as jnp
import numpy as np

from mbjax.scenes import carpal_wrist as cw
from mbjax.wrist import CarpalWrist


def _states(w, n=24, seed=0):
    rng = np.random.default_rng(seed)
    theta = np.asarray(cw.home(w)) + rng.uniform(-0.35, 0.35, (n, 3))
    return theta, rng.normal(0, 2.0, (n, 3)), rng.normal(0, 20.0, (n, 3))


def test_lagrangian_and_newton_euler_torques_agree():
    w = cw.wrist()
    theta, theta_dot, theta_ddot = _states(w)
    lagrange = jax.jit(jax.vmap(w.inverse_dynamics))(theta, theta_dot, theta_ddot)
    newton = jax.jit(jax.vmap(w.newton_euler_torques))(theta, theta_dot, theta_ddot)
    assert np.abs(lagrange).max() > 1.0                 # torques of order N m, not all gravity
    np.testing.assert_allclose(lagrange, newton, rtol=0, atol=1e-10)


def test_eom_terms_reassemble_the_inverse_dynamics_and_invert_the_forward():
    w = cw.wrist()
    theta, theta_dot, theta_ddot = _states(w, n=8, seed=1)
    A, B, C = jax.jit(jax.vmap(w.eom_terms))(theta, theta_dot)
    tau = jax.jit(jax.vmap(w.inverse_dynamics))(theta, theta_dot, theta_ddot)
    np.testing.assert_allclose(jnp.einsum("nij,nj->ni", A, theta_ddot) + B + C, tau, atol=1e-11)
    np.testing.assert_allclose(jax.jit(jax.vmap(w.forward_dynamics))(theta, theta_dot, tau), theta_ddot,
                               rtol=1e-11, atol=1e-9)
    # A symmetric positive definite, B quadratic in theta_dot, C = dV/dtheta = gravity only
    np.testing.assert_allclose(A, np.swapaxes(A, 1, 2), atol=1e-15)
    assert np.all(np.linalg.eigvalsh(np.asarray(A)) > 0)
    B2 = jax.jit(jax.vmap(lambda q, v: w.eom_terms(q, 2 * v)[1]))(theta, theta_dot)
    np.testing.assert_allclose(B2, 4 * B, rtol=1e-12, atol=1e-12)
    C0 = jax.jit(jax.vmap(lambda q: CarpalWrist(w.base_radius, w.link_length, tool_mass=w.tool_mass,
                                        tool_inertia=w.tool_inertia, tool_com=w.tool_com,
                                        gravity=0.0).eom_terms(q, jnp.zeros(3))[2]))(theta)
    np.testing.assert_allclose(C0, 0.0, atol=1e-15)


def test_mass_matrix_is_the_jacobians_inertia():
    """A = m J_v^T J_v + J_w^T (R I R^T) J_w with the Newton-Euler route's Jacobians."""
    from mbjax._src.wrist import newton_euler
    from mbjax._src.wrist.kinematics import forward_kinematics
    w = cw.wrist()
    theta = cw.home(w) + jnp.array([0.2, -0.1, 0.3])
    J_v, J_w = jax.jit(jax.jacfwd(lambda v: newton_euler.tool_velocity(w, theta, v)))(jnp.zeros(3))
    R = forward_kinematics(w, theta).rotation
    A = w.tool_mass * J_v.T @ J_v + J_w.T @ R @ w.tool_inertia @ R.T @ J_w
    np.testing.assert_allclose(w.mass_matrix(theta), A, rtol=1e-12, atol=1e-16)


def test_gravity_torques_match_finite_differences_of_the_potential():
    w = cw.wrist()
    theta = cw.home(w) + jnp.array([0.1, 0.25, -0.2])
    C = w.eom_terms(theta, jnp.zeros(3))[2]
    V = lambda t: float(w.tool_mass * w.gravity * w.forward_kinematics(jnp.asarray(t)).com[2])  # noqa: E731
    h = 1e-6
    fd = [(V(theta + h * e) - V(theta - h * e)) / (2 * h) for e in np.eye(3)]
    np.testing.assert_allclose(C, fd, rtol=1e-8, atol=1e-10)


def _variant(model: str, axial: float, com=(0.0, 0.0, 0.08)):
    return CarpalWrist(cw.BASE_RADIUS, cw.LINK_LENGTH, tool_mass=cw.TOOL_MASS,
                       tool_inertia=np.diag([4e-3, 4e-3, axial]), tool_com=com, rotation_model=model)


def test_chapter_variant_differs_by_the_twist_and_agrees_when_it_cannot_matter():
    """The chapter's R = Rz(alpha) Ry(beta) has the physical tool axis, but its angular velocity
    differs by alpha_dot R e3: the two models agree when the tool's centre of mass is on its axis
    and its axial inertia vanishes (the difference is linear in the axial inertia), and differ
    otherwise."""
    theta = cw.home() + jnp.array([0.3, -0.2, 0.1])
    theta_dot, theta_ddot = jnp.array([0.5, 1.0, -0.8]), jnp.array([3.0, -2.0, 1.0])
    diffs = []
    for axial in (1e-3, 1e-6, 1e-9):
        phys, chap = _variant("physical", axial), _variant("chapter", axial)
        assert np.allclose(phys.forward_kinematics(theta).rotation[:, 2],
                           chap.forward_kinematics(theta).rotation[:, 2], atol=1e-15)
        diffs.append(float(jnp.abs(phys.inverse_dynamics(theta, theta_dot, theta_ddot)
                                   - chap.inverse_dynamics(theta, theta_dot, theta_ddot)).max()))
    assert diffs[0] > 1e-4
    np.testing.assert_allclose(diffs[1] / diffs[0], 1e-3, rtol=1e-3)
    np.testing.assert_allclose(diffs[2] / diffs[0], 1e-6, rtol=1e-3)
    off_axis = _variant("physical", 1e-9, com=cw.TOOL_COM), _variant("chapter", 1e-9, com=cw.TOOL_COM)
    d = jnp.abs(off_axis[0].inverse_dynamics(theta, theta_dot, theta_ddot)
                - off_axis[1].inverse_dynamics(theta, theta_dot, theta_ddot)).max()
    assert d > 1e-4


def test_gradients_of_the_dynamics_in_parameters_are_finite_and_match_finite_differences():
    theta, theta_dot, tau = cw.home() + 0.1, jnp.array([0.2, -0.3, 0.4]), jnp.array([0.1, -1.0, -0.5])

    def accel(mass):
        w = CarpalWrist(cw.BASE_RADIUS, cw.LINK_LENGTH, tool_mass=mass, tool_inertia=cw.TOOL_INERTIA,
                        tool_com=cw.TOOL_COM)
        return w.forward_dynamics(theta, theta_dot, tau)
    g = jax.jit(jax.jacfwd(accel))(1.5)
    h = 1e-6
    np.testing.assert_allclose(g, (accel(1.5 + h) - accel(1.5 - h)) / (2 * h), rtol=1e-6, atol=1e-7)


def test_eom_terms_equal_the_derivatives_of_the_kinetic_energy():
    """eom_terms reads A, B and C from the pose's derivatives (T quadratic in theta_dot); here
    they are taken from T and V themselves, the Lagrangian form of eq 6.16, for both rotations."""
    from mbjax._src.wrist import dynamics

    def lagrange_terms(w, q, v):
        dT_dv = jax.jacfwd(dynamics.kinetic_energy, argnums=2)
        A = jax.jacfwd(dT_dv, argnums=2)(w, q, v)
        mixed = jax.jvp(lambda th: dT_dv(w, th, v), (q,), (v,))[1]
        B = mixed - jax.jacfwd(dynamics.kinetic_energy, argnums=1)(w, q, v)
        return A, B, jax.grad(dynamics.potential_energy, argnums=1)(w, q)

    for rotation_model in ("physical", "chapter"):
        w = cw.wrist(rotation_model)
        theta, theta_dot, _ = _states(w, n=6, seed=3)
        ours = jax.jit(jax.vmap(w.eom_terms))(theta, theta_dot)
        theirs = jax.jit(jax.vmap(lambda q, v, w=w: lagrange_terms(w, q, v)))(theta, theta_dot)
        for a, b in zip(ours, theirs, strict=True):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
