"""The mechanism scenes (planar four-bar, slider-crank, Bricard's mechanism) closed by cut joints
and solved with Jerkovsky 1978's coupled Lagrange multipliers (`Coupled`), each against an
independent minimal-coordinate reference: the scene's closed-form position analysis, the one-dof
Lagrangian L(theta, omega) = T - V in that coordinate (differentiated by jax) and scipy's DOP853;
for the driven slider-crank, the same Lagrangian's inverse dynamics gives the motor torque."""

import functools

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from mbjax.integrate import RK4, simulate
from mbjax.loops import ClosedSystem, Coupled, Revolute, Weld, project_velocity
from mbjax._src.loops import gauss_newton, numerical_rank
from mbjax.rigid import kinetic_energy, potential_energy
from mbjax.scenes import bricard, four_bar, slider_crank


def one_dof(model, joint_angles):
    """terms(theta, omega) -> (m, h) of the one-dof Lagrangian L = m(theta) omega^2 / 2 -
    V(q(theta)), with m(theta) = 2 T(q(theta), q'(theta)) the generalized mass: Lagrange's
    equation is m theta_ddot + h = Q, h = m'(theta) omega^2 / 2 + V'(theta), Q the generalized
    force on theta."""
    def mass(theta):
        return 2 * kinetic_energy(model, joint_angles(theta), jax.jacfwd(joint_angles)(theta))

    def potential(theta):
        return potential_energy(model, joint_angles(theta))

    def terms(theta, omega):
        m, dm = jax.value_and_grad(mass)(theta)
        return m, 0.5 * dm * omega**2 + jax.grad(potential)(theta)

    return terms


def dop853(model, joint_angles, theta0, omega0, ts):
    """theta(ts) of the free one-dof motion, scipy's DOP853 at tolerance 1e-12."""
    terms = one_dof(model, joint_angles)

    @jax.jit
    def rhs(y):
        m, h = terms(y[0], y[1])
        return jnp.array([y[1], -h / m])

    sol = solve_ivp(lambda t, y: np.asarray(rhs(jnp.asarray(y))), (0.0, float(ts[-1])),
                    [float(theta0), float(omega0)], method="DOP853", rtol=1e-12, atol=1e-12,
                    t_eval=ts)
    assert sol.success
    return sol.y[0]


def residual(loops, qs, ts=None):
    """max |Phi| over the states (jitted: op-by-op dispatch of a vmap costs seconds)."""
    ts = jnp.zeros(len(qs)) if ts is None else ts
    return float(jnp.abs(jax.jit(jax.vmap(loops.phi))(qs, ts)).max())


def energies(system, sol):
    return jax.jit(jax.vmap(system.energy))(sol.qs, sol.vs)


def on_motion(f, thetas):
    """f (a closed-form position analysis, or any map) at each of thetas, jitted."""
    return jax.jit(jax.vmap(f))(jnp.asarray(thetas))


# -- planar four-bar ------------------------------------------------------------------------------

def test_four_bar_closed_by_a_planar_pin_matches_minimal_coordinates():
    """The four-bar closed by a `PointOnLine()` cut (2 equations of rank 2: no redundancy to
    report) follows the one-dof DOP853 solution to 1e-8 over 0.5 s, on the closed-form loop,
    energy to 1e-8."""
    system, q0, v0 = four_bar.build()
    loops = system.loops
    assert loops.m == 2
    ts = np.array([0.0, 0.25, 0.5])
    sol = simulate(system, RK4(), q0, v0, dt=5e-4, t1=0.5, saveat=ts)
    assert sol.messages() == ["success"]                     # 2 independent equations
    ref = dop853(system.tree.model, four_bar.joint_angles, four_bar.THETA0, four_bar.OMEGA0, ts)
    np.testing.assert_allclose(sol.qs[:, 0], ref, rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.qs, on_motion(four_bar.joint_angles, sol.qs[:, 0]),
                               rtol=0, atol=1e-8)
    assert residual(loops, sol.qs) < 1e-8
    E = energies(system, sol)
    assert float(jnp.abs(E / E[0] - 1).max()) < 1e-8


def test_four_bar_revolute_closure_is_redundant():
    system, q0, _ = four_bar.build(Revolute())
    loops = system.loops
    rank = jax.jit(lambda q: numerical_rank(loops.jacobian(q) @ loops.jacobian(q).T))(q0)
    assert loops.m == 5 and int(rank) == 2
    with pytest.raises(ValueError, match="closure must be one of"):
        four_bar.build(Weld())
    with pytest.raises(TypeError, match="kind must be a cut-joint kind"):
        four_bar.build("revolute")


# -- slider-crank ---------------------------------------------------------------------------------

SLIDER_TS = np.linspace(0.0, 0.3, 7)          # 0.3 s at 20 rad/s: about one revolution
SLIDER_THETA = slider_crank.THETA0 + slider_crank.RATE * SLIDER_TS


def check_driven_slider_crank(loops, ts, qs, vs, torque):
    """Positions and velocities against the closed-form kinematics to round-off, and the motor
    torque against the one-dof Lagrangian's inverse dynamics: at constant speed (theta_ddot = 0)
    the torque on the crank is h(theta, rate)."""
    theta = slider_crank.THETA0 + slider_crank.RATE * np.asarray(ts)
    np.testing.assert_allclose(qs, on_motion(slider_crank.joint_angles, theta), rtol=0,
                               atol=1e-12)
    np.testing.assert_allclose(qs[:, 2], slider_crank.slider_position(theta), rtol=0, atol=1e-12)
    velocities = on_motion(jax.jacfwd(slider_crank.joint_angles), theta) * slider_crank.RATE
    np.testing.assert_allclose(vs, velocities, rtol=0, atol=1e-10)
    assert residual(loops, qs, ts) < 1e-12
    terms = one_dof(loops.tree.model, slider_crank.joint_angles)
    _, h = jax.jit(jax.vmap(terms, (0, None)))(jnp.asarray(theta), slider_crank.RATE)
    scale = float(jnp.abs(h).max())
    assert scale > 1.0                                      # inertia and gravity both load it
    assert float(jnp.abs(torque - h).max()) < 1e-10 * scale


def test_driven_slider_crank_kinematics_and_motor_torque():
    """With the crank driven the mechanism has no degree of freedom: mbjax's position analysis
    (Gauss-Newton on Phi(q, t) = 0 from a perturbed guess) and velocity analysis (A v + B = 0) give the
    closed-form kinematics; the multiplier of the `Prescribed` row (`loads(...)[-1]`) is the torque
    the motor applies to the crank, about +z."""
    system, _, _ = slider_crank.build()
    loops = system.loops

    @jax.jit
    @jax.vmap
    def analysis(t, guess):
        q = gauss_newton(loops, guess, t, iterations=10)
        v = project_velocity(loops, q, jnp.zeros(3), t)
        return q, v, system.loads(t, q, v)[-1]

    guesses = on_motion(slider_crank.joint_angles, SLIDER_THETA) + jnp.array([0.05, -0.05, 0.01])
    qs, vs, torque = analysis(jnp.asarray(SLIDER_TS), guesses)
    check_driven_slider_crank(loops, SLIDER_TS, qs, vs, torque)


@pytest.mark.slow
def test_driven_slider_crank_simulation():
    """The same along a simulation, projected onto Phi(q, t) = 0 and A v + B = 0 after every
    step (without projection RK4's drift leaves about 1e-9)."""
    closed, q0, v0 = slider_crank.build()
    system = ClosedSystem(closed.tree, closed.closures, projection=True)
    loops = system.loops
    sol = simulate(system, RK4(), q0, v0, dt=1e-3, t1=SLIDER_TS[-1], saveat=SLIDER_TS)
    assert sol.messages() == ["success"]
    torque = jax.jit(jax.vmap(system.loads))(sol.ts, sol.qs, sol.vs)[:, -1]
    check_driven_slider_crank(loops, sol.ts, sol.qs, sol.vs, torque)


@pytest.mark.slow          # the four-bar's test covers a free loop against DOP853 by default
def test_free_slider_crank_matches_minimal_coordinates():
    system, q0, v0 = slider_crank.build(driven=False)
    sol = simulate(system, RK4(), q0, v0, dt=2.5e-4, t1=0.3, saveat=SLIDER_TS)
    assert sol.messages() == ["success"]
    ref = dop853(system.tree.model, slider_crank.joint_angles, slider_crank.THETA0, slider_crank.RATE,
                 SLIDER_TS)
    np.testing.assert_allclose(sol.qs[:, 0], ref, rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.qs, on_motion(slider_crank.joint_angles, sol.qs[:, 0]),
                               rtol=0, atol=1e-8)
    E = energies(system, sol)
    assert float(jnp.abs(E - E[0]).max()) < 1e-8 * float(jnp.abs(E).max())


@pytest.mark.slow
def test_gradient_through_a_slider_crank_rollout_matches_finite_differences():
    """d(crank angle at 0.1 s)/d(slider mass) of the free slider-crank, reverse mode through the
    constrained rollout against central differences."""
    closed, q0, v0 = slider_crank.build(driven=False)

    def crank_angle(m_slider):
        system = eqx.tree_at(lambda s: s.tree.model.mass, closed,
                             closed.tree.model.mass.at[2].set(m_slider))
        return simulate(system, RK4(), q0, v0, dt=1e-3, t1=0.1, saveat=[0.1]).qs[-1, 0]

    m0, eps = float(closed.tree.model.mass[2]), 1e-5
    fd = (crank_angle(m0 + eps) - crank_angle(m0 - eps)) / (2 * eps)
    grad = jax.grad(crank_angle)(m0)
    assert abs(float(fd)) > 1e-3
    np.testing.assert_allclose(grad, fd, rtol=1e-6)


# -- Bricard's mechanism (IFToMM benchmark A04) ----------------------------------------------------

BRICARD_TS = np.linspace(0.0, bricard.DURATION, 11)


def _twist(w, p):
    """4 x 4 twist matrix of a unit rotation about the axis w through the point p."""
    X = np.zeros((4, 4))
    X[:3, :3] = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
    X[:3, 3] = -np.cross(w, p)
    return X


def test_bricard_closed_form_closes_the_loop():
    """The closed-form motion against two independent loop closures: mbjax's cut-joint residual
    and the product of exponentials of the six joint twists around the loop (Brockett's formula,
    numpy/scipy only), which must be the identity with the cut joint turned by psi as well."""
    system, q0, _ = bricard.build()
    loops = system.loops
    phis = np.linspace(-0.4, np.pi + 0.4, 9)
    qs = on_motion(bricard.joint_angles, phis)
    assert residual(loops, qs) < 1e-14
    for phi, q in zip(phis, np.asarray(qs)):
        G = np.eye(4)
        for w, p, angle in zip(bricard.AXES, bricard.CORNERS, [*q, q[1]]):
            G = G @ expm(_twist(w, p) * angle)
        np.testing.assert_allclose(G, np.eye(4), rtol=0, atol=1e-13, err_msg=f"phi = {phi}")
    # the cut's 5 equations have rank 4 along the motion (one degree of freedom)
    ranks = jax.jit(jax.vmap(lambda q: numerical_rank(loops.jacobian(q) @ loops.jacobian(q).T)))(qs)
    assert loops.m == 5 and set(np.asarray(ranks).tolist()) == {4}


@functools.cache
def bricard_run(projection: bool):
    closed, q0, v0 = bricard.build()
    system = ClosedSystem(closed.tree, closed.closures,
                          Coupled(baumgarte=(0.0, 0.0) if projection else (10.0, 10.0)), projection)
    return system, simulate(system, RK4(), q0, v0, dt=1e-3, t1=bricard.DURATION,
                            saveat=BRICARD_TS)


@functools.cache
def bricard_reference():
    return dop853(bricard.model(), bricard.joint_angles, 0.0, 0.0, BRICARD_TS)


def check_bricard(projection: bool, *, angle_tol, residual_tol, energy_tol):
    system, sol = bricard_run(projection)
    assert bool(sol.ok) and sol.messages() == ["redundant (first at t = 0 s)"]        # 5 equations of rank 4
    assert bool(jnp.all(jnp.isfinite(sol.qs)) & jnp.all(jnp.isfinite(sol.vs)))
    assert residual(system.loops, sol.qs) < residual_tol
    E = energies(system, sol)
    assert float(jnp.abs(E - E[0]).max()) < energy_tol * float(jnp.abs(E[0]))
    ref = bricard_reference()
    assert float(np.ptp(ref)) > 2.5                         # it swings phi = 0 ... about pi
    np.testing.assert_allclose(sol.qs[:, 0], ref, rtol=0, atol=angle_tol)
    np.testing.assert_allclose(sol.qs, on_motion(bricard.joint_angles, sol.qs[:, 0]),
                               rtol=0, atol=residual_tol)
    model = system.tree.model
    p3 = on_motion(lambda q: bricard.point_p3(model, q), sol.qs)
    p3_ref = on_motion(lambda phi: bricard.point_p3(model, bricard.joint_angles(phi)), ref)
    np.testing.assert_allclose(p3, p3_ref, rtol=0, atol=2 * angle_tol)


def test_bricard_benchmark_with_projection():
    """Benchmark A04, 10 s from rest (RK4, 1 ms): finite, redundancy reported while ok, residual
    at round-off, energy to 1e-10 relative, and the motion (joint angles and the benchmark's
    point P3) on the one-dof reference to 1e-9."""
    check_bricard(True, angle_tol=1e-9, residual_tol=1e-11, energy_tol=1e-10)


@pytest.mark.slow
def test_bricard_benchmark_with_baumgarte():
    """The same 10 s without projection, Baumgarte (alpha, beta) = (10, 10) 1/s holding Phi (the
    feedback perturbs the motion slightly: 4e-9 rad against the reference)."""
    check_bricard(False, angle_tol=2e-8, residual_tol=1e-10, energy_tol=1e-8)
