"""Loop closures and the coupled Lagrange-multiplier solution (Jerkovsky 1978 eqs 85-93) on a planar
four-bar, against an independent minimal-coordinate solution (closed-form loop, one-dof
Lagrangian, scipy's DOP853)."""

import re

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mbjax import Status
from mbjax.integrate import RK4, simulate
from mbjax.loops import ClosedSystem, CutJoint, Loops, Prescribed, Stabilized
from mbjax.loops import Revolute, Spherical
from mbjax._src.loops import coupled_acceleration
from mbjax.rigid import kinetic_energy, potential_energy
from mbjax.scenes import four_bar
from mbjax._src.scenes.four_bar import OMEGA0, THETA0, joint_angles

# the four-bar scene closed by the spatial revolute cut joint: 5 equations of rank 2
SYSTEM, Q0, V0 = four_bar.build(closure=Revolute())
LOOPS, TREE = SYSTEM.loops, SYSTEM.tree
MODEL = TREE.model


def minimal_rhs(y):
    """theta_ddot of the one-dof Lagrangian L(theta, omega) = T - V."""
    def lagrangian(theta, omega):
        q = joint_angles(theta)
        return (kinetic_energy(MODEL, q, jax.jacfwd(joint_angles)(theta) * omega)
                - potential_energy(MODEL, q))
    theta, omega = y
    m = jax.grad(jax.grad(lagrangian, 1), 1)(theta, omega)
    mixed = jax.grad(jax.grad(lagrangian, 1), 0)(theta, omega)
    return jnp.array([omega, (jax.grad(lagrangian, 0)(theta, omega) - mixed * omega) / m])


@pytest.mark.slow     # by default the redundant closure's motion is covered by Bricard's benchmark
                      # (5 equations of rank 4, against its one-dof reference) and the four-bar
                      # against DOP853 by test_mechanisms' planar-pin closure
def test_four_bar_matches_minimal_coordinates():
    rhs = jax.jit(minimal_rhs)
    ref = solve_ivp(lambda t, y: np.asarray(rhs(jnp.asarray(y))), (0.0, 0.5), [THETA0, OMEGA0],
                    method="DOP853", rtol=1e-12, atol=1e-12)
    system = SYSTEM
    sol = simulate(system, RK4(), Q0, V0, dt=5e-4, t1=0.5, saveat=[0.5])
    assert bool(sol.ok) and sol.messages() == ["redundant (first at t = 0 s)"]    # 5 equations of rank 2
    assert abs(float(sol.qs[-1, 0]) - ref.y[0, -1]) < 1e-8
    assert float(jnp.abs(LOOPS.phi(sol.qs[-1])).max()) < 1e-8
    E0, E1 = system.energy(Q0, V0), system.energy(sol.qs[-1], sol.vs[-1])
    assert abs(float(E1 / E0) - 1) < 1e-8


def test_redundant_planar_closure_is_detected_and_finite():
    """A spatial revolute cut joint closes a planar loop with 5 equations of rank 2."""

    @jax.jit                  # one compilation (op-by-op dispatch of the passes takes far longer)
    def solved(q, v):
        v_dot, K_c, rank = coupled_acceleration(LOOPS, q, v)
        return v_dot, K_c, rank, LOOPS.jacobian(q), LOOPS.acceleration_bias(q, v)

    v_dot, K_c, rank, A, b = solved(Q0, V0)
    assert LOOPS.m == 5 and int(rank) == 2
    assert bool(jnp.all(jnp.isfinite(v_dot)) & jnp.all(jnp.isfinite(K_c)))
    np.testing.assert_allclose(A @ v_dot + b, 0.0, atol=1e-10)


def test_constraint_derivatives_by_autodiff_match_finite_differences():
    """A v + B is dPhi/dt and A a + b is d^2 Phi/dt^2 along q(t) = q0 + v t + a t^2 / 2."""
    loops = Loops(TREE, [*LOOPS.closures, Prescribed(0, q0=0.1, rate=0.7)])
    q, v, a, t, h = Q0 + 0.01, V0 + 0.1, jnp.array([0.3, -0.2, 0.5]), 0.2, 1e-4

    @jax.jit                  # one compilation (op-by-op dispatch of the passes takes far longer)
    def derivatives(q, v, a, t):
        path = jax.vmap(lambda s: loops.phi(q + v * s + a * s**2 / 2, t + s))
        return (loops.rate(q, v, t), loops.jacobian(q, t) @ a + loops.acceleration_bias(q, v, t),
                path(jnp.array([-h, 0.0, h])))

    rate, second, (down, mid, up) = derivatives(q, v, a, t)
    np.testing.assert_allclose(rate, (up - down) / (2 * h), atol=1e-8)
    np.testing.assert_allclose(second, (up - 2 * mid + down) / h**2, atol=1e-5)


def test_gradient_through_a_constrained_rollout_matches_finite_differences():
    system = SYSTEM
    direction = jax.jit(jax.jacfwd(joint_angles))(THETA0)

    def final_crank(omega):
        return simulate(system, RK4(), Q0, direction * omega, dt=1e-3, t1=0.1, saveat=[0.1]).qs[-1, 0]

    eps = 1e-5
    fd = (final_crank(OMEGA0 + eps) - final_crank(OMEGA0 - eps)) / (2 * eps)
    np.testing.assert_allclose(jax.grad(final_crank)(OMEGA0), fd, rtol=1e-7)


def test_ill_posed_closures_get_clear_errors():
    with pytest.raises(ValueError, match="two different bodies"):
        CutJoint(Revolute(), 1, 1)
    with pytest.raises(TypeError, match="kind must be a cut-joint kind"):
        CutJoint("hinge", 0, 1)
    with pytest.raises(ValueError, match="not in the tree"):
        Loops(TREE, [CutJoint(Spherical(), 0, 7)])
    with pytest.raises(ValueError, match="at least one"):
        ClosedSystem(TREE, [])


@pytest.mark.slow     # the closed chain's test covers the same agreement by default
def test_order_n_stabilization_agrees_with_the_coupled_solution():
    """Anderson 1993's eta - Gamma f_c (m + 1 passes of the O(n) recursion) against Jerkovsky 1978's dense
    Lagrange multipliers, the same RK4 steps: the two trajectories agree to round-off."""
    ts = np.linspace(0.0, 0.5, 6)
    coupled = simulate(SYSTEM, RK4(), Q0, V0, dt=1e-3, t1=0.5, saveat=ts)
    recursive = simulate(ClosedSystem(TREE, SYSTEM.closures, Stabilized()), RK4(), Q0, V0,
                         dt=1e-3, t1=0.5, saveat=ts)
    assert recursive.messages() == coupled.messages() == ["redundant (first at t = 0 s)"]
    np.testing.assert_allclose(recursive.qs, coupled.qs, atol=1e-12)
    np.testing.assert_allclose(recursive.vs, coupled.vs, atol=1e-10)


@pytest.mark.slow
def test_epsilon_dynamics_keeps_the_velocity_error_at_epsilon_times_the_loads():
    """Eqs 89-93: started from f_c = (A v + B) / epsilon, A v + B = epsilon f_c at all times."""
    system = ClosedSystem(TREE, SYSTEM.closures, Stabilized(epsilon=1e-2))
    u0 = system.initial_state(Q0, V0, consistent=False)
    sol = simulate(system, RK4(), Q0, u0, dt=5e-4, t1=0.2, saveat=np.linspace(0.0, 0.2, 5))
    # the velocity error epsilon f_c moves Phi past the default tolerance: the status says so
    assert Status(int(sol.status)) == Status.CONSTRAINT_VIOLATED | Status.REDUNDANT
    assert re.fullmatch(r"constraint violated \(first at t = 0\.\d+ s\), redundant \(first at "
                        r"t = 0 s\)", sol.messages()[0]), sol.messages()
    rates = jax.jit(jax.vmap(LOOPS.rate))(sol.qs, sol.vs[:, :3])
    np.testing.assert_allclose(rates, 1e-2 * sol.vs[:, 3:], atol=1e-9)
    assert float(jnp.abs(sol.vs[-1, 3:]).max()) > 1.0        # the loads did act


def test_a_velocity_state_of_the_wrong_length_is_a_named_error():
    """simulate checks v0 against the method's state: v (nv,) for the coupled method, (v, f_c)
    (nv + m,) for Stabilized(epsilon > 0)."""
    nv = MODEL.nv
    with pytest.raises(ValueError, match=rf"v0.*\({nv},\)"):
        simulate(SYSTEM, RK4(), Q0, jnp.zeros(nv + 1), dt=1e-3, t1=2e-3)
    epsilon = ClosedSystem(TREE, SYSTEM.closures, Stabilized(epsilon=1e-2))
    m = LOOPS.m
    assert epsilon.state_sizes() == (MODEL.nq, nv + m)
    with pytest.raises(ValueError, match=rf"v0.*\({nv + m},\)"):
        simulate(epsilon, RK4(), Q0, V0, dt=1e-3, t1=2e-3)           # v without the loads
    u0 = epsilon.initial_state(Q0, V0)
    assert simulate(epsilon, RK4(), Q0, u0, dt=1e-3, t1=2e-3).vs.shape[-1] == nv + m
