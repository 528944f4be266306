"""mbjax.lie against Borri 1990 App. A identities, scipy and finite differences."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from jax.test_util import check_grads
from scipy.spatial.transform import Rotation

from mbjax._src import lie

EPS = 1e-13
rng = np.random.default_rng(0)


def random_rotvec(angle):
    e = rng.normal(size=3)
    return jnp.asarray(angle * e / np.linalg.norm(e))


# Angles from 0 through the Taylor cut-off (0.5) to near 2 pi, where Gamma^-1 is singular.
ANGLES = [0.0, 1e-12, 1e-9, 1e-6, 1e-3, 0.3, 0.4999, 0.5001, 1.0, 2.0, 3.0, np.pi - 1e-9, 4.0, 6.0]
vectors = st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3).map(jnp.asarray)


@pytest.mark.parametrize("angle", ANGLES)
def test_exp_matches_scipy(angle):
    r = random_rotvec(angle)
    np.testing.assert_allclose(lie.exp(r), Rotation.from_rotvec(np.array(r)).as_matrix(), atol=EPS)


@settings(max_examples=30, deadline=None)
@given(vectors)
def test_log_matches_scipy(r):
    R = Rotation.from_rotvec(np.array(r)).as_matrix()
    np.testing.assert_allclose(lie.log(jnp.asarray(R)), Rotation.from_matrix(R).as_rotvec(),
                               atol=1e-12)


def test_log_near_pi_is_principal_and_exact():
    for angle in (np.pi - 1e-6, np.pi - 1e-12, np.pi):
        r = random_rotvec(angle)
        back = lie.log(lie.exp(r))
        assert float(jnp.linalg.norm(back)) <= np.pi + 1e-12
        np.testing.assert_allclose(lie.exp(back), lie.exp(r), atol=1e-12)


@pytest.mark.parametrize("angle", ANGLES)
def test_identities_A24_A25_A26(angle):
    r = random_rotvec(angle)
    R, G, Gi = lie.exp(r), lie.gamma(r), lie.gamma_inv(r)
    tol = 1e-12 if angle < 5 else 1e-9  # Gamma^-1 grows like 1/|2 pi - phi|
    np.testing.assert_allclose(R, G @ Gi.T, atol=tol)              # A.24
    np.testing.assert_allclose(R, Gi.T @ G, atol=tol)              # A.24
    np.testing.assert_allclose(Gi.T - Gi, lie.hat(r), atol=tol)    # A.25
    np.testing.assert_allclose(R, jnp.eye(3) + G @ lie.hat(r), atol=EPS)  # A.26
    np.testing.assert_allclose(R, jnp.eye(3) + lie.hat(r) @ G, atol=EPS)  # A.26
    np.testing.assert_allclose(G @ Gi, jnp.eye(3), atol=tol)


@pytest.mark.parametrize("angle", ANGLES)
def test_det_gamma_A28(angle):
    r = random_rotvec(angle)
    # 2 (1 - cos phi) / phi^2 = (sin(phi/2) / (phi/2))^2, written without cancellation
    expected = np.sinc(angle / (2 * np.pi)) ** 2
    np.testing.assert_allclose(lie.det_gamma(r), expected, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(jnp.linalg.det(lie.gamma(r)), expected, rtol=1e-11, atol=1e-15)


@pytest.mark.parametrize("angle", [0.0, 1e-9, 0.2, 1.3, 3.0, 5.5])
def test_curl_of_gamma_A43(angle):
    """d h_k / d r^i - d h_i / d r^k = h_i x h_k for the columns h_k = Gamma e_k (eq A.43)."""
    r = random_rotvec(angle)
    G = lie.gamma(r)
    dG = jax.jacfwd(lie.gamma)(r)  # dG[a, k, i] = d Gamma_ak / d r_i
    for i in range(3):
        for k in range(3):
            np.testing.assert_allclose(dG[:, k, i] - dG[:, i, k], jnp.cross(G[:, i], G[:, k]),
                                       atol=1e-12)


@pytest.mark.parametrize("angle", [0.0, 0.1, 1.0, 2.5, 5.0])
def test_angular_velocity_is_gamma_r_dot(angle):
    """omega x I = R_dot R^T (eq A.11) by central differences equals Gamma(r) r_dot (eq A.16)."""
    r0, v, a = random_rotvec(angle), random_rotvec(0.7), random_rotvec(0.3)
    r_of_t = lambda t: r0 + t * v + t**2 * a  # noqa: E731
    h = 1e-5
    R_dot = (lie.exp(r_of_t(h)) - lie.exp(r_of_t(-h))) / (2 * h)
    omega_fd = lie.vee(R_dot @ lie.exp(r0).T)
    np.testing.assert_allclose(lie.gamma(r0) @ v, omega_fd, atol=1e-9)


@pytest.mark.parametrize("angle", [2 * np.pi - 0.3, 2 * np.pi + 0.4, 3 * np.pi + 0.1, 9.0, 20.0])
def test_rescale_A29_A36(angle):
    r = random_rotvec(angle)
    r_p = lie.rescale(r)
    assert float(jnp.linalg.norm(r_p)) <= np.pi + 1e-12
    np.testing.assert_allclose(lie.exp(r_p), lie.exp(r), atol=1e-12)       # same rotation
    dr_p = jax.jacfwd(lie.rescale)(r)                                      # eq A.34
    np.testing.assert_allclose(lie.gamma(r_p) @ dr_p, lie.gamma(r), atol=1e-10)  # eq A.36


def test_rescale_is_identity_on_principal_vectors():
    for angle in (0.0, 1e-9, 1.0, 3.0):
        r = random_rotvec(angle)
        np.testing.assert_allclose(lie.rescale(r), r, atol=0)


def test_series_and_closed_form_agree_at_the_cutoff():
    e = jnp.array([0.6, 0.0, 0.8])
    for f in (lie.exp, lie.gamma, lie.gamma_inv):
        below, above = f(0.5 * (1 - 1e-12) * e), f(0.5 * (1 + 1e-12) * e)
        np.testing.assert_allclose(below, above, atol=1e-15)


FUNCTIONS = {
    "exp": lie.exp,
    "log_exp": lambda r: lie.log(lie.exp(r)),
    "gamma": lie.gamma,
    "gamma_inv": lie.gamma_inv,
    "det_gamma": lie.det_gamma,
    "rescale": lie.rescale,
    "quat": lie.quat_from_rotvec,
    "rotvec_quat": lambda r: lie.rotvec_from_quat(lie.quat_from_rotvec(r)),
}


# Each function and its derivatives jitted once per module: the parametrized tests below (three
# points near zero, three angles) then share one compilation per (function, derivative) instead
# of compiling it per case (the Hessian of log(exp(r)) alone takes seconds to compile).
JITTED = {name: jax.jit(f) for name, f in FUNCTIONS.items()}
DERIVATIVES = {name: (jax.jit(jax.jacfwd(f)), jax.jit(jax.jacrev(f)),
                      jax.jit(jax.jacfwd(jax.jacrev(f))))
               for name, f in FUNCTIONS.items()}


@pytest.mark.parametrize("name", FUNCTIONS)
@pytest.mark.parametrize("r", [jnp.zeros(3), jnp.array([1e-9, 0.0, 0.0]),
                               jnp.array([1e-9, -2e-9, 5e-10])])
def test_derivatives_finite_at_zero(name, r):
    for derivative in DERIVATIVES[name]:
        assert bool(jnp.all(jnp.isfinite(derivative(r)))), name


def test_derivatives_at_zero_are_exact():
    E = jnp.stack([lie.hat(e) for e in jnp.eye(3)], axis=-1)  # d (r x I) / d r
    z = jnp.zeros(3)
    np.testing.assert_allclose(DERIVATIVES["exp"][0](z), E, atol=0)
    np.testing.assert_allclose(DERIVATIVES["gamma"][0](z), 0.5 * E, atol=0)
    np.testing.assert_allclose(DERIVATIVES["gamma_inv"][0](z), -0.5 * E, atol=0)
    np.testing.assert_allclose(DERIVATIVES["log_exp"][0](z), jnp.eye(3), atol=0)
    grad_R = jax.grad(lambda R: jnp.sum(lie.log(R)))(jnp.eye(3))
    assert bool(jnp.all(jnp.isfinite(grad_R)))


@pytest.mark.parametrize("angle", [1e-4, 0.3, 2.0])
def test_gradients_against_finite_differences(angle):
    r = random_rotvec(angle)
    for name in ("exp", "gamma", "gamma_inv", "log_exp"):
        # first derivatives of the jitted function (one compile of its jvp and vjp per module)
        check_grads(JITTED[name], (r,), order=1, modes=("fwd", "rev"), atol=1e-6, rtol=1e-6)
        # second derivatives: central differences of the (jitted) Jacobian
        J, _, H = DERIVATIVES[name]
        h = 1e-5
        for i in range(3):
            dr = jnp.zeros(3).at[i].set(h)
            np.testing.assert_allclose(H(r)[..., i], (J(r + dr) - J(r - dr)) / (2 * h),
                                       atol=1e-7)


@pytest.mark.parametrize("bad", [2 * jnp.eye(3), jnp.diag(jnp.array([1.0, 1.0, -1.0])),
                                 jnp.eye(3).at[0, 1].set(1e-3)])
def test_log_of_a_non_rotation_raises(bad):
    with pytest.raises(Exception, match="not a rotation"):
        lie.log(bad)
    with pytest.raises(Exception, match="not a rotation"):
        jax.jit(lie.log)(bad).block_until_ready()
    with pytest.raises(ValueError, match="3x3"):
        lie.log(jnp.eye(4))


def test_vmap_and_jit_compose():
    rs = jnp.asarray(rng.normal(size=(7, 3)))
    Rs = jax.jit(jax.vmap(lie.exp))(rs)
    np.testing.assert_allclose(Rs, Rotation.from_rotvec(np.array(rs)).as_matrix(), atol=EPS)


@pytest.mark.parametrize("angle", [0.0, 1e-5, 0.3, 0.6, 2.0])
def test_float32_follows_float64_to_single_precision(angle):
    """The series/closed-form switch holds in float32 too: results agree with float64 to a few
    float32 ulps, and derivatives stay finite at zero."""
    r64 = random_rotvec(angle)
    r32 = r64.astype(jnp.float32)
    eps32 = float(jnp.finfo(jnp.float32).eps)
    for f in (lie.exp, lie.gamma, lie.gamma_inv, lie.quat_from_rotvec):
        out32 = f(r32)
        assert out32.dtype == jnp.float32
        np.testing.assert_allclose(out32, f(r64), atol=10 * eps32)
        assert bool(jnp.all(jnp.isfinite(jax.jacfwd(f)(jnp.zeros(3, jnp.float32)))))
