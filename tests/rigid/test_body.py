"""The single rigid body against the closed form, a diffrax reference and MuJoCo."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.lie import Quaternion, RotationVector

from mbjax import lie
from mbjax_harness import peers
from mbjax.integrate import RK4, RKMK4, ImplicitMidpoint, simulate, solve_reference
from mbjax.rigid import RigidBody, torque_free_motion
from mbjax.scenes import heavy_top as top
from mbjax.scenes import torque_free_body as tfb


def test_closed_form_satisfies_euler_equations():
    """Omega(t) of eqs 8.7-8.8 obeys J Omega_dot + Omega x J Omega = 0 and R_dot = R hat(Omega)."""
    J = jnp.diag(jnp.array([tfb.J_TRANSVERSE, tfb.J_TRANSVERSE, tfb.J_AXIAL]))
    R0 = lie.exp(jnp.array([0.3, -0.2, 0.5]))
    motion = lambda t: torque_free_motion(tfb.J_AXIAL, tfb.J_TRANSVERSE, R0,  # noqa: E731
                                          jnp.array(tfb.OMEGA0), t)
    for t in (0.0, 0.7, 3.1, 6.0):
        R, Omega = motion(t)
        R_dot, Omega_dot = jax.jit(jax.jacfwd(motion))(t)
        np.testing.assert_allclose(J @ Omega_dot + jnp.cross(Omega, J @ Omega), 0, atol=1e-10)
        np.testing.assert_allclose(R_dot, R @ lie.hat(Omega), atol=1e-10)
        np.testing.assert_allclose(R @ J @ Omega, R0 @ J @ jnp.array(tfb.OMEGA0), atol=1e-12)


# quaternions by default; rotation-vector coordinates (their own compilation) run with -m slow
# and are covered by default by test_quaternion_and_rotation_vector_coordinates_agree
@pytest.mark.parametrize("rotation", [Quaternion(), pytest.param(RotationVector(), marks=pytest.mark.slow)],
                         ids=["quaternion", "rotvec"])
def test_torque_free_body_converges_to_closed_form(rotation):
    """RKMK4 approaches eqs 8.7-8.8 at fourth order over the whole 6 s (about 100 rad)."""
    body, q0, u0 = tfb.build(rotation)
    ts = np.linspace(0, tfb.DURATION, 13)
    errors = []
    for dt in (2e-3, 1e-3):
        sol = simulate(body, RKMK4(), q0, u0, dt=dt, t1=tfb.DURATION, saveat=ts)
        assert sol.messages() == ["success"]
        errors.append(float(jnp.max(tfb.rotation_errors(body, sol.qs, sol.ts))))
    assert errors[1] < 1e-8
    assert 14 < errors[0] / errors[1] < 18  # 2^4


def test_diffrax_reference_matches_closed_form():
    body, q0, u0 = tfb.build()
    sol = solve_reference(body, q0, u0, jnp.array([0.0, 3.0, tfb.DURATION]))
    assert bool(sol.ok)
    assert float(jnp.max(tfb.rotation_errors(body, sol.qs, sol.ts))) < 1e-8


def test_quaternion_and_rotation_vector_coordinates_agree():
    """Rotation vectors pass |r| = pi many times in 6 s (about 100 rad), rescaled by eq A.29."""
    runs = []
    for rotation in (Quaternion(), RotationVector()):
        body, q0, u0 = tfb.build(rotation)
        sol = simulate(body, RK4(), q0, u0, dt=1e-3, t1=tfb.DURATION, saveat=[tfb.DURATION])
        runs.append(body.rotation_matrix(sol.qs[-1]))
    np.testing.assert_allclose(runs[0], runs[1], atol=1e-9)


def test_implicit_midpoint_conserves_quadratic_invariants():
    """Midpoint conserves every quadratic invariant of (q, Omega): the kinetic energy, |J Omega|
    (= |h|) and |q|, even at a step as coarse as 0.05 s; the direction of h is not quadratic and
    only converges at second order."""
    body, q0, u0 = tfb.build()
    sol = simulate(body, ImplicitMidpoint(), q0, u0, dt=0.05, t1=tfb.DURATION)
    T = jax.jit(jax.vmap(body.kinetic_energy))(sol.qs, sol.vs)
    h_norm = jnp.linalg.norm(sol.vs @ body.inertia, axis=1)
    np.testing.assert_allclose(T, T[0], rtol=1e-13)
    np.testing.assert_allclose(h_norm, h_norm[0], rtol=1e-13)
    np.testing.assert_allclose(jnp.linalg.norm(sol.qs, axis=1), 1.0, atol=1e-14)


def test_heavy_top_against_diffrax_reference():
    body, q0, u0 = top.build()
    ref = solve_reference(body, q0, u0, jnp.array([0.0, 1.0]))
    sol = simulate(body, RKMK4(), q0, u0, dt=1e-4, t1=1.0, saveat=[1.0])
    err = jnp.linalg.norm(lie.log(body.rotation_matrix(sol.qs[-1]) @
                                  body.rotation_matrix(ref.qs[-1]).T))
    assert float(err) < 1e-9
    np.testing.assert_allclose(sol.vs[-1], ref.vs[-1], atol=1e-8)


@pytest.mark.skipif(not peers.available("mujoco"), reason="optional peer MuJoCo not installed")
def test_heavy_top_against_mujoco():
    """MuJoCo's ball joint (inertia shifted to the centre of mass) and mbjax agree."""
    body, q0, u0 = top.build()
    dt = 1e-4
    model, data = peers.mujoco_heavy_top(float(body.mass), np.asarray(body.inertia),
                                         np.asarray(body.com), top.GRAVITY, dt, "RK4")
    quat, Omega = peers.mujoco_rollout(model, data, np.asarray(q0), np.asarray(u0), 10_000)
    sol = simulate(body, RK4(), q0, u0, dt=dt, t1=1.0, saveat=[1.0])
    err = jnp.linalg.norm(lie.log(lie.quat_to_matrix(jnp.asarray(quat[0])) @
                                  body.rotation_matrix(sol.qs[-1]).T))
    assert float(err) < 1e-9
    np.testing.assert_allclose(Omega[0], sol.vs[-1], atol=1e-8)


def test_free_body_falls_and_spins_independently():
    J = jnp.diag(jnp.array([2.0, 3.0, 4.0]))
    body = RigidBody(1.5, J, gravity=(0.0, 0.0, -9.81))
    x0, v0, W0 = jnp.array([1.0, 2.0, 3.0]), jnp.array([0.5, -1.0, 4.0]), jnp.array([1.0, 2.0, 0.5])
    q0, u0 = body.initial_state(jnp.eye(3), W0, x0, v0)
    sol = simulate(body, RKMK4(), q0, u0, dt=1e-3, t1=2.0, saveat=[2.0])
    t = 2.0
    np.testing.assert_allclose(body.position(sol.qs[-1]),
                               x0 + v0 * t + 0.5 * jnp.array([0, 0, -9.81]) * t**2, atol=1e-12)
    E = jax.jit(jax.vmap(body.energy))(jnp.stack([q0, sol.qs[-1]]), jnp.stack([u0, sol.vs[-1]]))
    np.testing.assert_allclose(E[1], E[0], rtol=1e-9)


def test_gradient_through_a_rollout_matches_finite_differences():
    """d(final tilt of the top) / d(initial spin) through 2000 RKMK4 steps."""
    body, q0, _ = top.build()

    def tilt(spin):
        sol = simulate(body, RKMK4(), q0, jnp.array([0.0, 0.0, spin]), dt=1e-3, t1=2.0,
                       saveat=[2.0])
        return body.rotation_matrix(sol.qs[-1])[2, 2]

    g = jax.grad(tilt)(50.0)
    h = 1e-4
    fd = (tilt(50.0 + h) - tilt(50.0 - h)) / (2 * h)
    assert bool(jnp.isfinite(g))
    np.testing.assert_allclose(g, fd, rtol=1e-6)


def test_bad_bodies_are_rejected():
    with pytest.raises(ValueError, match="positive-definite"):
        RigidBody(1.0, jnp.diag(jnp.array([1.0, 1.0, -1.0])))
    with pytest.raises(ValueError, match="symmetric"):
        RigidBody(1.0, jnp.eye(3).at[0, 1].set(0.1))
    with pytest.raises(ValueError, match="triangle"):
        RigidBody(1.0, jnp.diag(jnp.array([1.0, 1.0, 3.0])))
    with pytest.raises(ValueError, match="3x3"):
        RigidBody(1.0, jnp.eye(2))
    with pytest.raises(ValueError, match="mass"):
        RigidBody(0.0, jnp.eye(3))
    with pytest.raises(TypeError, match="rotation must be mbjax.lie.Quaternion"):
        RigidBody(1.0, jnp.eye(3), rotation="euler")
    with pytest.raises(ValueError, match="centre of mass"):
        RigidBody(1.0, jnp.eye(3), com=(0.0, 0.0, 1.0))


def test_parameters_vmap_without_recompiling():
    """A sweep over the top's mass: one compiled function, one trajectory per mass."""
    body, q0, u0 = top.build()
    masses = jnp.linspace(1.0, 3.0, 5)

    def final_energy(mass):
        b = RigidBody(mass, body.inertia, com=body.com, gravity=body.gravity, fixed_point=True)
        sol = simulate(b, ImplicitMidpoint(), q0, u0, dt=0.01, t1=1.0, saveat=[0.0, 1.0])
        return b.energy(sol.qs[-1], sol.vs[-1]) - b.energy(sol.qs[0], sol.vs[0])

    drift = jax.jit(jax.vmap(final_energy))(masses)
    np.testing.assert_allclose(drift, 0.0, atol=1e-10)
